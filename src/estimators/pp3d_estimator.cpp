// pp3d host twin: photon points x query points, 3D kernel.
//
// Estimates, for each query point z, the radiance scattered towards the camera
// from the photon points within r_pp3d of it (UPBP Table 1, "P-P3D"; the per-pair
// value, its MIS weight and normalisation 1 / (N_L (4/3) pi r^3) are
// kernels/shared/ub_pp3d.h). Lookup: hashed grid of cell 2 r over the photon
// points, 8 cells per query (estimators/hash_grid.h).

#include "estimators/hash_grid.h"
#include "estimators/volume_estimate.h"
#include "kernels/shared/ub_pp3d.h"
#include "scene/scene.h"

namespace ub {

void estimatePP3D(const VolumeEstimateInput& in, const HashGrid& grid, std::vector<Rgb>* out,
                  size_t* pairs) {
    const std::vector<ub_photon_point>& photons = *in.photonPoints;
    const std::vector<ub_query_point>& queries = *in.queryPoints;
    if (photons.empty() || queries.empty()) return;
    const float r = in.radius[UB_TECH_PP3D];
    // UPBP Table 1: K3 = 1 / ((4/3) pi r^3), over N_L light subpaths.
    const float normalization = ub_pp3d_normalization(in.lightPathCount, r);
    forEachQueryBlock(
        queries.size(), HashGrid::kBlock, out, pairs, [&](size_t begin, size_t end, size_t* found) {
            HashGrid::BlockRanges ranges;
            grid.blockRanges(
                end - begin,
                [&](size_t k) {
                    const float* p = queries[begin + k].pos;
                    return Vec3(p[0], p[1], p[2]);
                },
                &ranges);
            for (size_t i = begin; i < end; ++i) {
                const ub_query_point& q = queries[i];
                const float g = in.scene->media[q.mediumId].g;
                Rgb sum(0.0f);
                grid.candidates(ranges, i - begin, [&](uint32_t j) {
                    ub_float3 c =
                        ub_pp3d_contribution(in.mis, photons[j], q, g, r * r, normalization,
                                             ub_uint(in.minLength), ub_uint(in.maxLength));
                    sum += Rgb(c.x, c.y, c.z);
                    ++*found;
                });
                (*out)[i] = sum;
            }
        });
}

}  // namespace ub
