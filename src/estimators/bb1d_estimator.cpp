// bb1d host twin: photon beams x query beams, 1D kernel (Jarosz et al. 2011).
//
// Estimates, for each query beam, the radiance arriving at its origin from the
// photon beams whose lines pass within r_bb1d of it, at their closest approach
// (UPBP Table 1, "B-B1D"; per-pair value, MIS weight and normalisation
// 1 / (N_B 2 r sin(theta)) in kernels/shared/ub_bb1d.h). Lookup: BVH over the
// diced beam parts, traversed by the query beam's segment; a photon beam counts
// in the part whose parameter range holds its closest-approach parameter.
// Both beams' media up to the closest approach are evaluated exactly.
//
// Query beams on lines through a pinhole camera's eye (the camera rays' pieces) read the parts
// their screen tile lists instead of walking the BVH (estimators/screen_tiles.h, the proof of
// completeness in kernels/shared/ub_screen_tiles.h): the same pairs, tested the same way.
//
// The walk (estimators/bb1d_walk.inc):
// - A leaf's candidates are tested four at a time by their lines and ranges
//   (ub_beam_keys4: the pair test's first two rejections and its range test), then the pair
//   test runs for those left. Most candidates of a long query beam are far from it (on
//   mirrorballs, 45 candidates a pair). The keys of four parts are one 128-byte block
//   against 192 bytes of parts, whose first read is a cache miss (27% of the pass before
//   the range test).
// - Where the CPU has AVX, the lines are tested eight at a time (two blocks). The walk is
//   bound by the filter's arithmetic, not by its loads (docs/performance.md, session 33).
// - The candidates the filter passes are gathered in walk order, 32 at a time, and handled in
//   three stages, so that the cache misses of several candidates overlap where each waited on
//   its own. First their parts are prefetched. Then the pair test reads each part, and
//   prefetches the photon beam and medium of each pair it accepts. Last come the pairs'
//   contributions, in the order the walk found them, so the sum is as before, bit for bit.
//   The first read of a candidate's part was 18% of the pass (perf, mirrorballs).

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include <atomic>
#include <stdexcept>

#include "estimators/beam_medium.h"
#include "estimators/bvh.h"
#include "estimators/screen_tiles.h"
#include "estimators/volume_estimate.h"
#include "kernels/shared/ub_bb1d.h"
#include "scene/scene.h"

namespace ub {

namespace {
/// Candidates gathered before a flush: a query beam of mirrorballs finds 4.5 pairs on average,
/// and a flush of a full buffer costs nothing more than several.
constexpr int kPending = 32;

/// What every query of a pass reads.
struct Bb1dPass {
    const VolumeEstimateInput& in;
    const Bvh& bvh;  ///< walked from the query's medium's root (Bvh::build's groups)
    const std::vector<BvhNode>& nodes;
    const std::vector<BeamPart>& parts;
    const std::vector<ub_beam_keys4>& lines;
    const std::vector<BeamMedium>& photonMedia;
    const std::vector<BeamMediumPrep>& queryMedia;  ///< by medium id
    const std::vector<ub_beam>& beams;
    const std::vector<ub_beam>& queries;
    const ScreenTiles& tiles;
    float r, normalization;
    std::vector<Rgb>* out;
};

/// One query beam's state during its walk.
struct Bb1dQuery {
    struct Accepted {
        uint32_t part;
        float tc, tl, sinTheta;
    };
    ub_beam qb;
    float g = 0.0f;
    BeamMedium medium;
    Rgb sum{0.0f};
    uint32_t pending[kPending];
    Accepted accepted[kPending];
    int np = 0;
};

/// Whether the AVX walk may run (tests turn it off to compare the two).
std::atomic<bool> wideAllowed{true};

namespace baseline {
#define UB_BB1D_WIDE 0
#include "estimators/bb1d_walk.inc"
#undef UB_BB1D_WIDE
}  // namespace baseline

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define UB_BB1D_HAS_WIDE 1
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx")
#endif
namespace wide {
#define UB_BB1D_WIDE 1
#include "estimators/bb1d_walk.inc"
#undef UB_BB1D_WIDE
}  // namespace wide
#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif
#else
#define UB_BB1D_HAS_WIDE 0
#endif

bool cpuHasAvx() {
#if UB_BB1D_HAS_WIDE
    static const bool avx = __builtin_cpu_supports("avx");
    return avx;
#else
    return false;
#endif
}
}  // namespace

bool bb1dWideWalk() {
    return wideAllowed && cpuHasAvx();
}

bool bb1dWideWalkAvailable() {
    return cpuHasAvx();
}

void setBb1dWideWalkForTests(bool allowed) {
    wideAllowed = allowed;
}

uint32_t bb1dLinesNear8ForTests(const ub_beam_keys4* k, const ub_float3& o, const ub_float3& d,
                                float queryLength, float radiusSqr) {
#if UB_BB1D_HAS_WIDE
    if (cpuHasAvx()) return wide::beamLinesNear8(k, o, d, queryLength, radiusSqr);
#endif
    throw std::logic_error("bb1dLinesNear8ForTests: this CPU or build has no AVX walk");
}

void estimateBB1D(const VolumeEstimateInput& in, const Bvh& beamParts,
                  const std::vector<BeamPart>& parts, const std::vector<ub_beam_keys4>& lines,
                  const std::vector<BeamMedium>& photonMedia, const ScreenTiles& tiles,
                  std::vector<Rgb>* out, size_t* pairs) {
    const std::vector<ub_beam>& beams = *in.photonBeams;
    const std::vector<ub_beam>& queries = *in.queryBeams;
    if (beams.empty() || queries.empty() || beamParts.empty()) return;
    if (!beamParts.leafOrdered())
        throw std::logic_error("bb1d given a BVH whose parts are not in leaf order");
    const float r = in.radius[UB_TECH_BB1D];
    const std::vector<BeamMediumPrep> queryMedia = prepareBeamMedia(*in.scene);
    const Bb1dPass pass{in,         beamParts, beamParts.nodes(),
                        parts,      lines,     photonMedia,
                        queryMedia, beams,     queries,
                        tiles,      r,         ub_bb1d_normalization(in.beamPathCount, r),
                        out};
    const bool useWide = bb1dWideWalk();
    forEachQueryBlock(queries.size(), 16, out, pairs, [&](size_t begin, size_t end, size_t* found) {
#if UB_BB1D_HAS_WIDE
        if (useWide) return wide::estimateQueries(pass, begin, end, found);
#endif
        baseline::estimateQueries(pass, begin, end, found);
    });
}

}  // namespace ub
