// bp2d host twin: photon beams x query points, 2D kernel (Jarosz et al. 2011).
//
// Estimates, for each query point z, the radiance scattered towards the camera
// from the photon beams passing within r_bp2d of z (UPBP Table 1, "B-P2D";
// per-pair value, MIS weight and normalisation 1 / (N_B pi r^2) in
// kernels/shared/ub_bp2d.h). Lookup: BVH over the diced beam parts; a beam counts
// in the part whose parameter range holds z's projection (volume_estimate.h).

#include "estimators/beam_medium.h"
#include "estimators/bvh.h"
#include "estimators/volume_estimate.h"
#include "kernels/shared/ub_bp2d.h"
#include "scene/scene.h"

namespace ub {

void estimateBP2D(const VolumeEstimateInput& in, const Bvh& beamParts,
                  const std::vector<BeamPart>& parts, const std::vector<BeamMedium>& photonMedia,
                  std::vector<Rgb>* out, size_t* pairs) {
    const std::vector<ub_beam>& beams = *in.photonBeams;
    const std::vector<ub_query_point>& queries = *in.queryPoints;
    if (beams.empty() || queries.empty()) return;
    const float r = in.radius[UB_TECH_BP2D];
    const float normalization = ub_bp2d_normalization(in.beamPathCount, r);
    forEachQuery(queries.size(), 64, out, pairs, [&](size_t i, size_t* found) {
        const ub_query_point& q = queries[i];
        const float g = in.scene->media[q.mediumId].g;
        const ub_float3 p = ub_f3_from(q.pos);
        Rgb sum(0.0f);
        beamParts.queryPoint(Vec3(p.x, p.y, p.z), q.mediumId, [&](uint32_t k) {
            const BeamPart& part = parts[k];
            float t = 0.0f;
            if (!ub_bp2d_pair(q, part, r * r, ub_uint(in.minLength), ub_uint(in.maxLength), &t))
                return;
            const ub_beam& pb = beams[part.beam];
            const ub_segment_eval s = photonMedia[part.beam].eval(t);
            const ub_float3 c = ub_bp2d_contribution(in.mis, pb, q, s, t, g, normalization);
            sum += Rgb(c.x, c.y, c.z);
            ++*found;
        });
        return sum;
    });
}

}  // namespace ub
