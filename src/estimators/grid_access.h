// The host's voxel fetch for kernels/shared/ub_grid_medium.h: ub_grid_accessor over
// NanoVDB's C++ read accessor, so the host runs the same DDA as the kernels (which fetch
// through CNanoVDB.h), and the ub_grid_info of a grid medium.
#pragma once

#include <nanovdb/NanoVDB.h>

#include <utility>

#include "kernels/shared/ub_medium_homogeneous.h"
#include "scene/medium.h"

struct ub_grid_accessor {
    decltype(std::declval<const nanovdb::FloatGrid&>().getAccessor()) acc;
    const nanovdb::NanoLeaf<float>* leaf = nullptr;  ///< what the last probe found
};

static inline float ub_grid_probe(ub_grid_accessor* a, int i, int j, int k, int* inLeaf) {
    const nanovdb::Coord ijk(i, j, k);
    a->leaf = a->acc.probeLeaf(ijk);
    *inLeaf = a->leaf != nullptr;
    return a->leaf ? a->leaf->getValue(ijk) : a->acc.getValue(ijk);
}

static inline float ub_grid_leaf_value(const ub_grid_accessor* a, uint32_t offset) {
    return a->leaf->getValue(offset);
}

#define UB_HOST_GRID_ACCESSOR 1
#include "kernels/shared/ub_grid_medium.h"

namespace ub {

/// Whether the kernels can evaluate grid medium m (nearest filtering, grey extinction, no
/// albedo grid).
inline bool gridMediumOnDevice(const Medium& m) {
    return m.type != MediumType::kHomogeneous && m.grid && m.filter == GridFilter::kNearest &&
           !m.albedoGrid && !m.chromatic();
}

/// The kernels' description of grid medium m, its grid at byte gridOffset of the buffer.
ub_grid_info gridInfo(const Medium& m, uint32_t gridOffset);

}  // namespace ub
