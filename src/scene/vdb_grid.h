// A scalar density grid read from an OpenVDB file (.vdb) and converted once to
// NanoVDB (Museth 2021, "NanoVDB: A GPU-Friendly and Portable VDB Data
// Structure For Real-Time Rendering And Simulation").
//
// The NanoVDB buffer is one contiguous block: host code samples it through
// nanovdb/NanoVDB.h and OpenCL kernels will read the very same bytes through
// nanovdb/CNanoVDB.h. OpenVDB itself (slow to compile) is included only by
// vdb_grid.cpp.
//
// Voxel convention: the value of voxel (i, j, k) is the density of the cell
// centred at index-space point (i, j, k), i.e. [i-1/2, i+1/2) x ... (OpenVDB's
// cell-centred interpretation, the one nearest-neighbour sampling uses).
// Outside the index bounding box of the grid the density is the background
// value (0 for fog volumes).
#pragma once

#include <nanovdb/NanoVDB.h>
#include <nanovdb/util/GridHandle.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/vec.h"

namespace ub {

/// A dense block of float voxels: value(i, j, k) = values[(k * ny + j) * nx + i] for voxel
/// (i, j, k), 0 <= i < nx etc. Voxel (i, j, k) is centred at origin + voxelSize * (i, j, k)
/// in the grid's local space. Used to build grids procedurally (tools, tests).
struct DenseFloatGrid {
    int nx = 0, ny = 0, nz = 0;
    float voxelSize = 1.0f;
    Vec3 origin{0, 0, 0};
    std::vector<float> values;

    DenseFloatGrid() = default;
    DenseFloatGrid(int x, int y, int z, float fill = 0.0f)
        : nx(x), ny(y), nz(z), values(size_t(x) * y * z, fill) {}
    float& at(int i, int j, int k) { return values[(size_t(k) * ny + j) * nx + i]; }
    float at(int i, int j, int k) const { return values[(size_t(k) * ny + j) * nx + i]; }
};

/// A float density grid in NanoVDB form (immutable after construction).
class VdbGrid {
  public:
    /// Reads grid `gridName` from the OpenVDB file `path`. Throws ub::InputError naming the
    /// file and the grid if the file is missing, is not a VDB file, has no grid of that name
    /// (the message lists the grids present), holds a grid of another value type than float,
    /// has a non-linear (frustum) transform, is empty, or holds negative or non-finite values.
    static std::shared_ptr<const VdbGrid> load(const std::string& path,
                                               const std::string& gridName);
    /// Builds a grid from dense voxels (zeros stay inactive background; constant blocks are
    /// pruned into tiles, as a VDB writer would). Same validation as load(), with `label`
    /// standing for the file name in messages.
    static std::shared_ptr<const VdbGrid> fromDense(const DenseFloatGrid& dense,
                                                    const std::string& gridName,
                                                    const std::string& label = "<dense>");
    /// Reads grid `gridName` of a VDB file as channels: a float grid gives one, a vec3 float
    /// grid (openvdb::Vec3SGrid) three float grids (x, y, z) with its transform. Values (of
    /// voxels, tiles, and the background) must be finite and lie in [0, maxAllowed]; messages
    /// call them `quantity` ("albedo"). Same errors as load() otherwise.
    static std::vector<std::shared_ptr<const VdbGrid>> loadChannels(const std::string& path,
                                                                    const std::string& gridName,
                                                                    const std::string& quantity,
                                                                    float maxAllowed);
    /// A grid whose value is `value` everywhere (one active voxel at the origin holding it,
    /// and `value` as the background): a constant extinction as a grid medium.
    static std::shared_ptr<const VdbGrid> constant(float value, const std::string& label);
    /// fromDense() with the value check of loadChannels().
    static std::shared_ptr<const VdbGrid> fromDenseChecked(const DenseFloatGrid& dense,
                                                           const std::string& gridName,
                                                           const std::string& label,
                                                           const std::string& quantity,
                                                           float maxAllowed);

    const nanovdb::FloatGrid& grid() const { return *grid_; }
    /// The NanoVDB buffer (for upload to OpenCL devices).
    const uint8_t* data() const { return handle_.data(); }
    uint64_t byteSize() const { return handle_.size(); }
    const std::string& name() const { return name_; }
    const std::string& path() const { return path_; }
    /// Index-space voxel bounds [lo, hi] (inclusive) of the active values.
    const nanovdb::CoordBBox& indexBounds() const { return grid_->indexBBox(); }
    /// Index space -> grid-local space (the VDB's own linear transform).
    const Transform& indexToLocal() const { return indexToLocal_; }
    /// Largest value stored anywhere in the grid (voxels, tiles, background).
    float maxValue() const { return maxValue_; }
    float background() const { return background_; }
    uint64_t activeVoxelCount() const { return activeVoxels_; }

    VdbGrid(const VdbGrid&) = delete;
    VdbGrid& operator=(const VdbGrid&) = delete;

  private:
    VdbGrid() = default;
    friend struct VdbGridBuilder;

    nanovdb::GridHandle<nanovdb::HostBuffer> handle_;
    const nanovdb::FloatGrid* grid_ = nullptr;
    std::string name_, path_;
    Transform indexToLocal_;
    float maxValue_ = 0, background_ = 0;
    uint64_t activeVoxels_ = 0;
};

/// Writes `dense` as a float grid named `gridName` to the OpenVDB file `path` (zeros are
/// inactive background). Used by tools/make_smoke_vdb and tests. Throws ub::InputError if
/// the file cannot be written.
void writeDenseFloatVdb(const std::string& path, const std::string& gridName,
                        const DenseFloatGrid& dense);

/// One grid of writeDenseVdb(): 1 channel makes a float grid, 3 a vec3 float grid (the
/// channels must have equal dimensions; the first gives voxel size and origin).
struct DenseVdbGrid {
    std::string name;
    std::vector<DenseFloatGrid> channels;
};
/// Writes several grids to one OpenVDB file (voxels where every channel is 0 stay inactive
/// background). Throws ub::InputError if the file cannot be written or a grid is malformed.
void writeDenseVdb(const std::string& path, const std::vector<DenseVdbGrid>& grids);

}  // namespace ub
