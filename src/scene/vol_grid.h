// Mitsuba's binary volume files (.vol, "VOL" version 3, dense float32 voxels),
// read with full header validation, and their conversion to the NanoVDB grids
// unibeam's media use (scene/vdb_grid.h).
//
// Layout (little endian): 'V' 'O' 'L' <uint8 version = 3>, int32 encoding
// (1 = float32; Mitsuba 3 reads no other), int32 xres, yres, zres, int32
// channels, float32 bbox min (x, y, z) and max (x, y, z), then
// xres * yres * zres * channels float32 values, x fastest:
//   value(x, y, z, c) = data[((z * yres + y) * xres + x) * channels + c].
// Voxel (x, y, z) covers [x, x+1]/xres x ... of the unit cube (Mitsuba's
// gridvolume places the grid in [0, 1]^3 unless use_grid_bbox is set).
#pragma once

#include <string>
#include <vector>

#include "core/vec.h"
#include "scene/vdb_grid.h"

namespace ub {

struct VolGrid {
    int nx = 0, ny = 0, nz = 0, channels = 0;
    Vec3 bboxMin, bboxMax;      ///< from the header (used only with use_grid_bbox)
    std::vector<float> values;  ///< nx * ny * nz * channels
    float at(int x, int y, int z, int c) const {
        return values[((size_t(z) * ny + y) * nx + x) * channels + c];
    }
};

/// Reads a .vol file. Throws InputError naming the file and the problem: missing file, bad
/// magic, version other than 3, encoding other than 1 (float32), non-positive resolution,
/// channel count other than 1 or 3, a file size that does not match the header, non-finite
/// voxel values, an empty or inverted bounding box.
VolGrid readVolFile(const std::string& path);

/// One channel as a dense grid (voxel size 1, origin 0: voxel (i, j, k) is centred at index
/// (i, j, k), so it covers cell [i, i+1) x ... in unibeam's cell space).
DenseFloatGrid volChannelToDense(const VolGrid& vol, int channel);

/// Transform from cell space [0, n)^3 of a .vol grid to Mitsuba's unit cube [0, 1]^3.
Transform volCellToUnitCube(const VolGrid& vol);

}  // namespace ub
