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

namespace {
/// Candidates gathered before a flush (see estimateBB1D): a query beam of mirrorballs finds
/// 4.5 pairs on average, and a flush of a full buffer costs nothing more than several.
constexpr int kPending = 32;
}  // namespace

void estimateBB1D(const VolumeEstimateInput& in, const Bvh& beamParts,
                  const std::vector<BeamPart>& parts, const std::vector<ub_beam_keys4>& lines,
                  const std::vector<BeamMedium>& photonMedia, std::vector<Rgb>* out,
                  size_t* pairs) {
    const std::vector<ub_beam>& beams = *in.photonBeams;
    const std::vector<ub_beam>& queries = *in.queryBeams;
    if (beams.empty() || queries.empty()) return;
    const float r = in.radius[UB_TECH_BB1D];
    const float normalization = ub_bb1d_normalization(in.beamPathCount, r);
    forEachQuery(queries.size(), 16, out, pairs, [&](size_t i, size_t* pairsFound) {
        const ub_beam& qb = queries[i];
        const float g = in.scene->media[qb.mediumId].g;
        const ub_float3 o = ub_f3_from(qb.origin), d = ub_f3_from(qb.dir);
        BeamMedium queryMedium;  // tabulated when the first pair is found
        queryMedium.reset(*in.scene, qb);
        Rgb sum(0.0f);
        // The candidates the four-lane filter passes are gathered in walk order and handled
        // in three stages, so that the cache misses of several candidates overlap where each
        // waited on its own: their parts are prefetched; the pair test reads each part, and
        // prefetches the photon beam and its medium of each pair it accepts; then the pairs'
        // contributions, in the order the walk found them (the sum is as before, bit for bit).
        // The first read of a candidate's part was 18% of the pass (perf, mirrorballs).
        struct Accepted {
            uint32_t part;
            float tc, tl, sinTheta;
        };
        uint32_t pending[kPending];
        Accepted accepted[kPending];
        int np = 0;
        auto flush = [&] {
            for (int k = 0; k < np; ++k) {
                const char* p = reinterpret_cast<const char*>(&parts[pending[k]]);
                __builtin_prefetch(p);
                __builtin_prefetch(p + sizeof(BeamPart) - 1);  // a part may straddle two lines
            }
            int nf = 0;
            for (int k = 0; k < np; ++k) {
                const BeamPart& part = parts[pending[k]];
                Accepted& f = accepted[nf];
                if (!ub_bb1d_pair(qb, part, r * r, ub_uint(in.minLength), ub_uint(in.maxLength),
                                  &f.tc, &f.tl, &f.sinTheta))
                    continue;
                f.part = pending[k];
                __builtin_prefetch(&beams[part.beam]);
                __builtin_prefetch(&photonMedia[part.beam]);
                ++nf;
            }
            for (int k = 0; k < nf; ++k) {
                const Accepted& f = accepted[k];
                const uint32_t beam = parts[f.part].beam;
                if (!queryMedium.built()) queryMedium.build();
                const ub_segment_eval sl = photonMedia[beam].eval(f.tl);
                const ub_segment_eval sc = queryMedium.eval(f.tc);
                const ub_float3 c = ub_bb1d_contribution(in.mis, beams[beam], qb, sl, sc, f.tl,
                                                         f.tc, f.sinTheta, g, normalization);
                sum += Rgb(c.x, c.y, c.z);
            }
            *pairsFound += size_t(nf);
            np = 0;
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
                    for (; near != 0; near &= near - 1) {
                        pending[np++] = b * 4 + uint32_t(__builtin_ctz(near));
                        if (np == kPending) flush();
                    }
                }
            });
        flush();
        return sum;
    });
}

}  // namespace ub
