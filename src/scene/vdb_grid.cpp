// OpenVDB reading/writing and the conversion to NanoVDB. The only translation
// unit of the library that includes OpenVDB (its headers are slow to compile).
#include "scene/vdb_grid.h"

#include <nanovdb/util/OpenToNanoVDB.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <mutex>
#include <sstream>

#include "core/error.h"
#include "core/file_status.h"

namespace ub {

namespace {

void initOpenVdb() {
    static std::once_flag once;
    std::call_once(once, [] { openvdb::initialize(); });
}

std::string quoted(const std::string& s) {
    return "'" + s + "'";
}

}  // namespace

/// What the values of a grid are: densities (finite, >= 0) or a bounded quantity such as an
/// albedo (finite, in [0, maxAllowed]).
struct ValueCheck {
    std::string quantity = "density";
    float maxAllowed = std::numeric_limits<float>::infinity();
};

/// Validates an OpenVDB float grid and converts it (friend of VdbGrid).
struct VdbGridBuilder {
    static std::shared_ptr<const VdbGrid> build(const openvdb::FloatGrid& grid,
                                                const std::string& label,
                                                const std::string& gridName,
                                                const ValueCheck& check = ValueCheck()) {
        auto fail = [&](const std::string& what) {
            throw InputError(label, "grid " + quoted(gridName) + " " + what);
        };
        const openvdb::math::Transform& xform = grid.transform();
        if (!xform.isLinear())
            fail("has a non-linear (" + xform.mapType() +
                 ") transform; only linear (affine) grid transforms are supported");
        if (grid.activeVoxelCount() == 0) fail("is empty (no active voxels)");

        // Every stored value (active or not, voxels and tiles) and the background are
        // densities (or albedos): they must be finite, >= 0 (and <= maxAllowed).
        const bool bounded = check.maxAllowed < std::numeric_limits<float>::infinity();
        float maxValue = grid.background();
        auto checkValue = [&](float v, const openvdb::Coord& ijk, bool background) {
            if (!std::isfinite(v) || v < 0 || v > check.maxAllowed) {
                std::ostringstream os;
                const std::string& q = check.quantity;
                const bool vowel =
                    !q.empty() && std::string("aeiou").find(q[0]) != std::string::npos;
                if (!std::isfinite(v))
                    os << "has a non-finite " << q << " " << v;
                else if (v < 0)
                    os << "has a negative " << q << " " << v;
                else
                    os << "has " << (vowel ? "an " : "a ") << q << " " << v;
                if (background)
                    os << " as its background value";
                else
                    os << " at voxel (" << ijk.x() << ", " << ijk.y() << ", " << ijk.z() << ")";
                if (bounded)
                    os << "; " << check.quantity << " values must be finite and lie in [0, "
                       << check.maxAllowed << "]";
                else
                    os << "; densities must be finite and >= 0";
                fail(os.str());
            }
            maxValue = std::max(maxValue, v);
        };
        checkValue(grid.background(), openvdb::Coord(), true);
        for (auto it = grid.cbeginValueAll(); it; ++it) checkValue(*it, it.getCoord(), false);

        std::shared_ptr<VdbGrid> out(new VdbGrid());
        out->handle_ = nanovdb::openToNanoVDB(grid);
        out->grid_ = out->handle_.grid<float>();
        if (!out->grid_) fail("conversion to NanoVDB failed");
        out->name_ = gridName;
        out->path_ = label;
        out->maxValue_ = maxValue;
        out->background_ = grid.background();
        out->activeVoxels_ = grid.activeVoxelCount();
        // OpenVDB matrices act on row vectors (p' = p * M); ub::Transform on columns.
        openvdb::math::Mat4d m = xform.baseMap()->getAffineMap()->getMat4();
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j) out->indexToLocal_.m[i][j] = float(m(j, i));
        return out;
    }
};

namespace {

/// Opens `path` and reads grid `gridName` (any value type). `fail` throws.
template <typename Fail>
openvdb::GridBase::Ptr readNamedGrid(const std::string& path, const std::string& gridName,
                                     Fail&& fail) {
    initOpenVdb();
    if (!pathExists(path)) fail("file not found");
    if (isDirectory(path)) fail("is a directory, expected a .vdb file");

    openvdb::io::File file(path);
    openvdb::GridPtrVecPtr metadata;
    try {
        file.open(/*delayLoad=*/false);
        metadata = file.readAllGridMetadata();
    } catch (const std::exception& e) {
        fail(std::string("not a readable OpenVDB file (") + e.what() + ")");
    }

    openvdb::GridBase::ConstPtr meta;
    std::string present;
    for (const openvdb::GridBase::Ptr& g : *metadata) {
        present +=
            (present.empty() ? "" : ", ") + quoted(g->getName()) + " (" + g->valueType() + ")";
        if (g->getName() == gridName && !meta) meta = g;
    }
    if (!meta)
        fail("no grid of that name in the file; grids present: " +
             (present.empty() ? std::string("none") : present));

    openvdb::GridBase::Ptr base;
    try {
        base = file.readGrid(gridName);
        file.close();
    } catch (const std::exception& e) {
        fail(std::string("reading the grid failed (") + e.what() + ")");
    }
    return base;
}

/// Channel c of a vec3 grid as a float grid with the same transform, topology (active
/// states) and values.
openvdb::FloatGrid::Ptr vec3Channel(const openvdb::Vec3SGrid& vec, int c) {
    openvdb::FloatGrid::Ptr out = openvdb::FloatGrid::create(vec.background()[c]);
    out->setName(vec.getName());
    out->setTransform(vec.transform().copy());
    openvdb::FloatGrid::Accessor acc = out->getAccessor();
    for (auto it = vec.cbeginValueAll(); it; ++it) {
        const float v = (*it)[c];
        if (it.isVoxelValue()) {
            if (it.isValueOn())
                acc.setValueOn(it.getCoord(), v);
            else
                acc.setValueOff(it.getCoord(), v);
        } else {
            out->tree().fill(it.getBoundingBox(), v, it.isValueOn());
        }
    }
    return out;
}

}  // namespace

std::shared_ptr<const VdbGrid> VdbGrid::load(const std::string& path, const std::string& gridName) {
    auto fail = [&](const std::string& what) {
        throw InputError(path, "cannot load grid " + quoted(gridName) + ": " + what);
    };
    openvdb::GridBase::Ptr base = readNamedGrid(path, gridName, fail);
    openvdb::FloatGrid::Ptr grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
    if (!grid)
        fail("grid holds values of type " + quoted(base->valueType()) + " (grid type " +
             base->type() + "), expected a float (density) grid");
    return VdbGridBuilder::build(*grid, path, gridName);
}

std::vector<std::shared_ptr<const VdbGrid>> VdbGrid::loadChannels(const std::string& path,
                                                                  const std::string& gridName,
                                                                  const std::string& quantity,
                                                                  float maxAllowed) {
    auto fail = [&](const std::string& what) {
        throw InputError(path, "cannot load grid " + quoted(gridName) + ": " + what);
    };
    openvdb::GridBase::Ptr base = readNamedGrid(path, gridName, fail);
    const ValueCheck check{quantity, maxAllowed};
    if (openvdb::FloatGrid::Ptr grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base))
        return {VdbGridBuilder::build(*grid, path, gridName, check)};
    if (openvdb::Vec3SGrid::Ptr vec = openvdb::gridPtrCast<openvdb::Vec3SGrid>(base)) {
        std::vector<std::shared_ptr<const VdbGrid>> out;
        for (int c = 0; c < 3; ++c)
            out.push_back(VdbGridBuilder::build(*vec3Channel(*vec, c), path, gridName, check));
        return out;
    }
    fail("grid holds values of type " + quoted(base->valueType()) + " (grid type " + base->type() +
         "), expected a float (1 channel) or vec3s (3 channels) " + quantity + " grid");
    return {};
}

namespace {

openvdb::math::Transform::Ptr denseTransform(const DenseFloatGrid& dense) {
    openvdb::math::Transform::Ptr xform =
        openvdb::math::Transform::createLinearTransform(double(dense.voxelSize));
    xform->postTranslate(openvdb::Vec3d(dense.origin.x, dense.origin.y, dense.origin.z));
    return xform;
}

/// allActive: every voxel of the dense box is active (a grid whose zeros are values, such as
/// an albedo); otherwise zeros stay inactive background (a fog volume).
openvdb::FloatGrid::Ptr denseToOpenVdb(const DenseFloatGrid& dense, const std::string& name,
                                       bool allActive = false) {
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
    grid->setName(name);
    grid->setGridClass(openvdb::GRID_FOG_VOLUME);
    grid->setTransform(denseTransform(dense));
    openvdb::FloatGrid::Accessor acc = grid->getAccessor();
    for (int k = 0; k < dense.nz; ++k)
        for (int j = 0; j < dense.ny; ++j)
            for (int i = 0; i < dense.nx; ++i) {
                float v = dense.at(i, j, k);
                if (v != 0.0f || allActive) acc.setValue(openvdb::Coord(i, j, k), v);
            }
    grid->pruneGrid(0.0f);  // exact: only blocks of identical values become tiles
    return grid;
}

openvdb::GridBase::Ptr denseToOpenVdb(const DenseVdbGrid& g, const std::string& path) {
    if (g.channels.size() == 1) return denseToOpenVdb(g.channels[0], g.name);
    if (g.channels.size() != 3)
        throw InputError(path, "grid " + quoted(g.name) + ": " + std::to_string(g.channels.size()) +
                                   " channels (a VDB grid is written with 1 or 3)");
    const DenseFloatGrid& c0 = g.channels[0];
    for (const DenseFloatGrid& c : g.channels)
        if (c.nx != c0.nx || c.ny != c0.ny || c.nz != c0.nz ||
            c.values.size() != size_t(c0.nx) * c0.ny * c0.nz)
            throw InputError(path, "grid " + quoted(g.name) + ": channels of different sizes");
    openvdb::Vec3SGrid::Ptr grid = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    grid->setName(g.name);
    grid->setTransform(denseTransform(c0));
    openvdb::Vec3SGrid::Accessor acc = grid->getAccessor();
    for (int k = 0; k < c0.nz; ++k)
        for (int j = 0; j < c0.ny; ++j)
            for (int i = 0; i < c0.nx; ++i) {
                openvdb::Vec3s v(g.channels[0].at(i, j, k), g.channels[1].at(i, j, k),
                                 g.channels[2].at(i, j, k));
                if (v != openvdb::Vec3s(0.0f)) acc.setValue(openvdb::Coord(i, j, k), v);
            }
    grid->pruneGrid(0.0f);
    return grid;
}

}  // namespace

std::shared_ptr<const VdbGrid> VdbGrid::fromDense(const DenseFloatGrid& dense,
                                                  const std::string& gridName,
                                                  const std::string& label) {
    initOpenVdb();
    if (dense.values.size() != size_t(dense.nx) * dense.ny * dense.nz)
        throw InputError(label, "grid " + quoted(gridName) +
                                    ": dense value count does not "
                                    "match its dimensions");
    return VdbGridBuilder::build(*denseToOpenVdb(dense, gridName), label, gridName);
}

std::shared_ptr<const VdbGrid> VdbGrid::constant(float value, const std::string& label) {
    initOpenVdb();
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(value);
    grid->setName("constant");
    grid->tree().setValue(openvdb::Coord(0, 0, 0), value);
    return VdbGridBuilder::build(*grid, label, "constant");
}

std::shared_ptr<const VdbGrid> VdbGrid::fromDenseChecked(const DenseFloatGrid& dense,
                                                         const std::string& gridName,
                                                         const std::string& label,
                                                         const std::string& quantity,
                                                         float maxAllowed) {
    initOpenVdb();
    if (dense.values.size() != size_t(dense.nx) * dense.ny * dense.nz)
        throw InputError(label, "grid " + quoted(gridName) +
                                    ": dense value count does not "
                                    "match its dimensions");
    return VdbGridBuilder::build(*denseToOpenVdb(dense, gridName, /*allActive=*/true), label,
                                 gridName, ValueCheck{quantity, maxAllowed});
}

void writeDenseVdb(const std::string& path, const std::vector<DenseVdbGrid>& grids) {
    initOpenVdb();
    openvdb::GridPtrVec out;
    for (const DenseVdbGrid& g : grids) out.push_back(denseToOpenVdb(g, path));
    try {
        openvdb::io::File(path).write(out);
    } catch (const std::exception& e) {
        throw InputError(path, std::string("cannot write the VDB file (") + e.what() + ")");
    }
}

void writeDenseFloatVdb(const std::string& path, const std::string& gridName,
                        const DenseFloatGrid& dense) {
    initOpenVdb();
    openvdb::GridPtrVec grids{denseToOpenVdb(dense, gridName)};
    try {
        openvdb::io::File(path).write(grids);
    } catch (const std::exception& e) {
        throw InputError(path, std::string("cannot write the VDB file (") + e.what() + ")");
    }
}

}  // namespace ub
