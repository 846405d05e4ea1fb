// bb1d host twin: photon beams x query beams, 1D kernel (Jarosz et al. 2011).
//
// Estimates, for each query beam, the radiance arriving at its origin from the
// photon beams whose lines pass within r_bb1d of it, at their closest approach
// (UPBP Table 1, "B-B1D"; per-pair value, MIS weight and normalisation
// 1 / (N_B 2 r sin(theta)) in kernels/shared/ub_bb1d.h). Lookup: BVH over the
// diced beam parts, traversed by the query beam's segment; a photon beam counts
// in the part whose parameter range holds its closest-approach parameter.
// Both beams' media up to the closest approach are evaluated exactly.

#include "estimators/beam_medium.h"
#include "estimators/bvh.h"
#include "estimators/volume_estimate.h"
#include "kernels/shared/ub_bb1d.h"
#include "scene/scene.h"

namespace ub {

void estimateBB1D(const VolumeEstimateInput& in, const Bvh& beamParts,
                  const std::vector<BeamPart>& parts, const std::vector<ub_beam_keys4>& lines,
                  const std::vector<BeamMedium>& photonMedia, std::vector<Rgb>* out,
                  size_t* pairs) {
    const std::vector<ub_beam>& beams = *in.photonBeams;
    const std::vector<ub_beam>& queries = *in.queryBeams;
    if (beams.empty() || queries.empty()) return;
    const float r = in.radius[UB_TECH_BB1D];
    const float normalization = ub_bb1d_normalization(in.beamPathCount, r);
    forEachQuery(queries.size(), 16, out, pairs, [&](size_t i, size_t* found) {
        const ub_beam& qb = queries[i];
        const float g = in.scene->media[qb.mediumId].g;
        const ub_float3 o = ub_f3_from(qb.origin), d = ub_f3_from(qb.dir);
        BeamMedium queryMedium;  // tabulated when the first pair is found
        queryMedium.reset(*in.scene, qb);
        Rgb sum(0.0f);
        auto pair = [&](uint32_t k) {
            const BeamPart& part = parts[k];
            float tc = 0.0f, tl = 0.0f, sinTheta = 0.0f;
            if (!ub_bb1d_pair(qb, part, r * r, ub_uint(in.minLength), ub_uint(in.maxLength), &tc,
                              &tl, &sinTheta))
                return;
            const ub_beam& pb = beams[part.beam];
            if (!queryMedium.built()) queryMedium.build();
            const ub_segment_eval sl = photonMedia[part.beam].eval(tl);
            const ub_segment_eval sc = queryMedium.eval(tc);
            const ub_float3 c =
                ub_bb1d_contribution(in.mis, pb, qb, sl, sc, tl, tc, sinTheta, g, normalization);
            sum += Rgb(c.x, c.y, c.z);
            ++*found;
        };
        // A leaf's candidates four at a time by their lines and ranges (the pair test's first
        // two rejections and its range test), then the pair test for those left: most
        // candidates of a long query beam are far from it (on mirrorballs, 45 candidates a
        // pair), and the keys of four parts are one 128-byte block against 192 bytes of parts,
        // whose first read is a cache miss (27% of the pass before the range test).
        beamParts.querySegmentLeaves(
            Vec3(o.x, o.y, o.z), Vec3(d.x, d.y, d.z), qb.length, [&](uint32_t first, uint32_t end) {
                for (uint32_t b = first / 4; b * 4 < end; ++b) {
                    uint32_t near =
                        beamLinesNear4(lines[b], o, d, r * r) & ub_block_lanes(b, first, end);
                    for (; near != 0; near &= near - 1) pair(b * 4 + uint32_t(__builtin_ctz(near)));
                }
            });
        return sum;
    });
}

}  // namespace ub
