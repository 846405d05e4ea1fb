// OpenVDB reading/writing and the conversion to NanoVDB. The only translation
// unit of the library that includes OpenVDB (its headers are slow to compile).
#include "scene/vdb_grid.h"

#include <cmath>
#include <filesystem>
#include <mutex>
#include <sstream>

#include <openvdb/openvdb.h>
#include <openvdb/io/File.h>
#include <nanovdb/util/OpenToNanoVDB.h>

#include "core/error.h"

namespace ub {

namespace {

void initOpenVdb() {
    static std::once_flag once;
    std::call_once(once, [] { openvdb::initialize(); });
}

std::string quoted(const std::string& s) { return "'" + s + "'"; }

}  // namespace

/// Validates an OpenVDB float grid and converts it (friend of VdbGrid).
struct VdbGridBuilder {
    static std::shared_ptr<const VdbGrid> build(const openvdb::FloatGrid& grid,
                                                const std::string& label,
                                                const std::string& gridName) {
        auto fail = [&](const std::string& what) {
            throw InputError(label, "grid " + quoted(gridName) + " " + what);
        };
        const openvdb::math::Transform& xform = grid.transform();
        if (!xform.isLinear())
            fail("has a non-linear (" + xform.mapType() +
                 ") transform; only linear (affine) grid transforms are supported");
        if (grid.activeVoxelCount() == 0) fail("is empty (no active voxels)");

        // Every stored value (active or not, voxels and tiles) and the background are
        // densities: they must be finite and >= 0.
        float maxValue = grid.background();
        auto checkValue = [&](float v, const openvdb::Coord& ijk, bool background) {
            if (!std::isfinite(v) || v < 0) {
                std::ostringstream os;
                os << "has a " << (std::isfinite(v) ? "negative" : "non-finite") << " density "
                   << v;
                if (background)
                    os << " as its background value";
                else
                    os << " at voxel (" << ijk.x() << ", " << ijk.y() << ", " << ijk.z() << ")";
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

std::shared_ptr<const VdbGrid> VdbGrid::load(const std::string& path,
                                             const std::string& gridName) {
    initOpenVdb();
    auto fail = [&](const std::string& what) {
        throw InputError(path, "cannot load grid " + quoted(gridName) + ": " + what);
    };
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) fail("file not found");
    if (std::filesystem::is_directory(path, ec)) fail("is a directory, expected a .vdb file");

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
        present += (present.empty() ? "" : ", ") + quoted(g->getName()) + " (" +
                   g->valueType() + ")";
        if (g->getName() == gridName && !meta) meta = g;
    }
    if (!meta)
        fail("no grid of that name in the file; grids present: " +
             (present.empty() ? std::string("none") : present));
    if (!meta->isType<openvdb::FloatGrid>())
        fail("grid holds values of type " + quoted(meta->valueType()) + " (grid type " +
             meta->type() + "), expected a float (density) grid");

    openvdb::GridBase::Ptr base;
    try {
        base = file.readGrid(gridName);
        file.close();
    } catch (const std::exception& e) {
        fail(std::string("reading the grid failed (") + e.what() + ")");
    }
    openvdb::FloatGrid::Ptr grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
    if (!grid)
        fail("grid holds values of type " + quoted(base->valueType()) + " (grid type " +
             base->type() + "), expected a float (density) grid");
    return VdbGridBuilder::build(*grid, path, gridName);
}

namespace {

openvdb::FloatGrid::Ptr denseToOpenVdb(const DenseFloatGrid& dense, const std::string& name) {
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
    grid->setName(name);
    grid->setGridClass(openvdb::GRID_FOG_VOLUME);
    openvdb::math::Transform::Ptr xform =
        openvdb::math::Transform::createLinearTransform(double(dense.voxelSize));
    xform->postTranslate(openvdb::Vec3d(dense.origin.x, dense.origin.y, dense.origin.z));
    grid->setTransform(xform);
    openvdb::FloatGrid::Accessor acc = grid->getAccessor();
    for (int k = 0; k < dense.nz; ++k)
        for (int j = 0; j < dense.ny; ++j)
            for (int i = 0; i < dense.nx; ++i) {
                float v = dense.at(i, j, k);
                if (v != 0.0f) acc.setValue(openvdb::Coord(i, j, k), v);
            }
    grid->pruneGrid(0.0f);  // exact: only blocks of identical values become tiles
    return grid;
}

}  // namespace

std::shared_ptr<const VdbGrid> VdbGrid::fromDense(const DenseFloatGrid& dense,
                                                  const std::string& gridName,
                                                  const std::string& label) {
    initOpenVdb();
    if (dense.values.size() != size_t(dense.nx) * dense.ny * dense.nz)
        throw InputError(label, "grid " + quoted(gridName) + ": dense value count does not "
                                "match its dimensions");
    return VdbGridBuilder::build(*denseToOpenVdb(dense, gridName), label, gridName);
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
