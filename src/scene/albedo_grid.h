// A spatially varying single-scattering albedo for grid media (Mitsuba 3's
// `heterogeneous` medium with `albedo` given as a volume): sigma_s(x) =
// albedo(x) * sigma_t(x), per RGB channel. Extinction, and therefore tracking,
// transmittance and every distance pdf, does not depend on it: the albedo
// only enters where a collision is made (the free-flight throughput weight
// T sigma_s / pdf, Russian roulette at medium vertices), so it is looked up
// once per collision, never per voxel step (scene/medium.h).
//
// Data: 1 (grey) or 3 (RGB) float NanoVDB grids, one per channel, all with the
// same index -> local transform (scene/vdb_grid.h), so kernels can read them
// like the density grid. Cell convention as the density grid: in cell space
// (index + 1/2) voxel v covers [v, v + 1).
//  * kNearest: the value of the voxel containing the point.
//  * kTrilinear: trilinear interpolation between voxel centres (dual space =
//    cell space - 1/2, voxel v's centre at the integer point v).
// Both clamp the lookup to the domain [domainLo, domainHi] (Mitsuba's
// gridvolume default wrap_mode="clamp", which Mitsuba applies to any
// evaluation point: outside the grid's box the albedo is that of the nearest
// edge voxel, never 0), or wrap it (wrap_mode "repeat": the domain tiles space,
// index modulo its size; "mirror": tiles mirrored at each face), voxel indices
// wrapped after the filter picks them, as a texture's address mode does (the
// interpolation across a face reaches the voxel on the opposite side). Inside the
// domain a voxel that is not stored in a sparse .vdb grid has the grid's background
// value.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/vec.h"
#include "scene/medium.h"
#include "scene/vdb_grid.h"

namespace ub {

/// How a lookup outside the domain finds its voxel (Mitsuba's gridvolume `wrap_mode`).
enum class GridWrap : uint32_t { kClamp = 0, kRepeat = 1, kMirror = 2 };

struct AlbedoGrid {
    int channelCount = 1;                        ///< 1 (grey) or 3 (RGB)
    std::shared_ptr<const VdbGrid> channels[3];  ///< [0] only when grey
    GridFilter filter = GridFilter::kNearest;
    GridWrap wrap = GridWrap::kClamp;
    int domainLo[3] = {0, 0, 0}, domainHi[3] = {0, 0, 0};  ///< inclusive voxel range
    Transform localToWorld;  ///< grid-local space -> world (then the VDB's index -> local)
    Transform worldToCell;   ///< world -> cell space (index + 1/2)
    std::string label;       ///< file and grid, for messages and `unibeam info`

    /// Validates and builds: 1 or 3 channel grids with equal index -> local transforms and
    /// values in [0, 1]; domainLo > domainHi on an axis (the default of `domain`) means the
    /// union of the channels' active index bounds. Throws ub::InputError naming `label`.
    static std::shared_ptr<const AlbedoGrid> make(
        std::vector<std::shared_ptr<const VdbGrid>> channels, GridFilter filter,
        const Transform& localToWorld, const int domainLo[3] = nullptr,
        const int domainHi[3] = nullptr, const std::string& label = "<albedo grid>",
        GridWrap wrap = GridWrap::kClamp);
};

/// Reads an albedo from grid `gridName` of the OpenVDB file `path`: a float grid (grey) or a
/// vec3 float grid (RGB), split into one float grid per channel. Throws ub::InputError naming
/// the file and the grid (missing file or grid, with the grids present; another value type;
/// values outside [0, 1]).
std::vector<std::shared_ptr<const VdbGrid>> loadVdbAlbedoChannels(const std::string& path,
                                                                  const std::string& gridName);

}  // namespace ub
