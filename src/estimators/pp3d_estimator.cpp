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
    forEachQuery(queries.size(), 64, out, pairs, [&](size_t i, size_t* found) {
        const ub_query_point& q = queries[i];
        const float g = in.scene->media[q.mediumId].g;
        Rgb sum(0.0f);
        grid.query(
            Vec3(q.pos[0], q.pos[1], q.pos[2]), reinterpret_cast<const Vec3*>(photons[0].pos),
            sizeof(ub_photon_point), [&](uint32_t j) {
                ub_float3 c = ub_pp3d_contribution(in.mis, photons[j], q, g, r * r, normalization,
                                                   ub_uint(in.minLength), ub_uint(in.maxLength));
                sum += Rgb(c.x, c.y, c.z);
                ++*found;
            });
        return sum;
    });
}

}  // namespace ub
