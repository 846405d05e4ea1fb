// pb2d host twin: photon points x query beams, 2D kernel (the beam radiance
// estimate, Jarosz et al. 2008).
//
// Estimates, for each query beam, the radiance arriving at its origin from the
// photon points within r_pb2d of the beam (UPBP Table 1, "P-B2D"; per-pair value,
// MIS weight and normalisation 1 / (N_L pi r^2) in kernels/shared/ub_pb2d.h).
// Lookup: BVH over the photon points as boxes of their kernel sphere, traversed by
// the beam's segment (estimators/bvh.h); query beams on lines through a pinhole camera's eye
// read the photons their screen tile lists instead (estimators/screen_tiles.h; the same
// pairs). The medium along the query beam up to the photon's projection is evaluated exactly
// (regular tracking).

#include "estimators/beam_medium.h"
#include "estimators/bvh.h"
#include "estimators/screen_tiles.h"
#include "estimators/volume_estimate.h"
#include "kernels/shared/ub_pb2d.h"
#include "scene/scene.h"

namespace ub {

namespace {

/// Pairs gathered before they are evaluated (see estimatePB2D).
constexpr int kPending = 32;

/// ub_pb2d_near4 (kernels/shared/ub_pb2d.h) in SSE: the same operations in the same order per
/// lane, so the same mask and parameters (tests/bvh_test.cpp).
uint32_t pb2dNear4(const ub_photon_keys4& k, const ub_float3& o, const ub_float3& d, float length,
                   uint32_t mediumId, float radiusSqr, float* t) {
#if defined(__SSE2__)
    const __m128 dx = _mm_set1_ps(d.x), dy = _mm_set1_ps(d.y), dz = _mm_set1_ps(d.z);
    const __m128 opx = _mm_sub_ps(_mm_loadu_ps(k.px), _mm_set1_ps(o.x));
    const __m128 opy = _mm_sub_ps(_mm_loadu_ps(k.py), _mm_set1_ps(o.y));
    const __m128 opz = _mm_sub_ps(_mm_loadu_ps(k.pz), _mm_set1_ps(o.z));
    const __m128 tp =
        _mm_add_ps(_mm_add_ps(_mm_mul_ps(opx, dx), _mm_mul_ps(opy, dy)), _mm_mul_ps(opz, dz));
    const __m128 qx = _mm_sub_ps(opx, _mm_mul_ps(dx, tp));
    const __m128 qy = _mm_sub_ps(opy, _mm_mul_ps(dy, tp));
    const __m128 qz = _mm_sub_ps(opz, _mm_mul_ps(dz, tp));
    const __m128 d2 =
        _mm_add_ps(_mm_add_ps(_mm_mul_ps(qx, qx), _mm_mul_ps(qy, qy)), _mm_mul_ps(qz, qz));
    const __m128 inRange =
        _mm_and_ps(_mm_cmpge_ps(tp, _mm_setzero_ps()), _mm_cmple_ps(tp, _mm_set1_ps(length)));
    const __m128 near = _mm_and_ps(inRange, _mm_cmple_ps(d2, _mm_set1_ps(radiusSqr)));
    const __m128i sameMedium =
        _mm_cmpeq_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(k.mediumId)),
                        _mm_set1_epi32(int(mediumId)));
    _mm_storeu_ps(t, tp);
    return uint32_t(_mm_movemask_ps(_mm_and_ps(near, _mm_castsi128_ps(sameMedium))));
#else
    return ub_pb2d_near4(&k, o, d, length, mediumId, radiusSqr, t);
#endif
}

}  // namespace

uint32_t pb2dNear4ForTests(const ub_photon_keys4& k, const ub_float3& o, const ub_float3& d,
                           float length, uint32_t mediumId, float radiusSqr, float* t) {
    return pb2dNear4(k, o, d, length, mediumId, radiusSqr, t);
}

void estimatePB2D(const VolumeEstimateInput& in, const Bvh& photonSpheres,
                  const std::vector<ub_photon_point>& photons,
                  const std::vector<ub_photon_keys4>& keys, const ScreenTiles& tiles,
                  std::vector<Rgb>* out, size_t* pairs) {
    const std::vector<ub_beam>& queries = *in.queryBeams;
    if (photons.empty() || queries.empty()) return;
    const float r = in.radius[UB_TECH_PB2D];
    const float normalization = ub_pb2d_normalization(in.lightPathCount, r);
    const std::vector<BeamMediumPrep> queryMedia = prepareBeamMedia(*in.scene);
    forEachQuery(queries.size(), 16, out, pairs, [&](size_t i, size_t* found) {
        const ub_beam& qb = queries[i];
        const BeamMediumPrep& prep = queryMedia[qb.mediumId];
        const float g = prep.info.g;
        const ub_float3 o = ub_f3_from(qb.origin), d = ub_f3_from(qb.dir);
        BeamMedium queryMedium;  // tabulated when the first pair is found
        queryMedium.reset(prep, qb);
        Rgb sum(0.0f);
        // A leaf's photons four at a time (their keys as a structure of arrays); the pairs are
        // gathered in walk order, kPending at a time, their 80-byte records prefetched, then
        // evaluated in that order (as bb1d does, estimators/bb1d_estimator.cpp), so that the
        // records' cache misses overlap.
        uint32_t pending[kPending];
        float pendingT[kPending];
        int np = 0;
        auto flush = [&] {
            for (int k = 0; k < np; ++k) __builtin_prefetch(&photons[pending[k]]);
            for (int k = 0; k < np; ++k) {
                const ub_photon_point& ph = photons[pending[k]];
                if (!ub_pb2d_length_ok(ph.pathLength, qb, ub_uint(in.minLength),
                                       ub_uint(in.maxLength)))
                    continue;
                if (!queryMedium.built()) queryMedium.build();
                const ub_segment_eval s = queryMedium.eval(pendingT[k]);
                const ub_float3 c =
                    ub_pb2d_contribution(in.mis, ph, qb, s, pendingT[k], g, normalization);
                sum += Rgb(c.x, c.y, c.z);
                ++*found;
            }
            np = 0;
        };
        // A query on a line through the eye reads its screen tile's photons and the common
        // list (kernels/shared/ub_screen_tiles.h) instead of walking the BVH.
        const int tile = ub_screen_tile_of(tiles.params, o, d);
        if (tile >= 0) {
            const uint32_t common = tiles.params.tilesX * tiles.params.tilesY;
            for (uint32_t list : {uint32_t(tile), common})
                for (uint32_t b = tiles.start[list]; b < tiles.start[list + 1]; ++b) {
                    float t[4];
                    uint32_t near =
                        pb2dNear4(tiles.photonKeys[b], o, d, qb.length, qb.mediumId, r * r, t);
                    for (; near != 0; near &= near - 1) {
                        const int lane = __builtin_ctz(near);
                        pending[np] = tiles.items[b * 4 + uint32_t(lane)];
                        pendingT[np++] = t[lane];
                        if (np == kPending) flush();
                    }
                }
            flush();
            return sum;
        }
        photonSpheres.querySegmentLeaves(Vec3(o.x, o.y, o.z), Vec3(d.x, d.y, d.z), qb.length,
                                         qb.mediumId, [&](uint32_t first, uint32_t end) {
                                             for (uint32_t b = first / 4; b * 4 < end; ++b) {
                                                 float t[4];
                                                 uint32_t near = pb2dNear4(keys[b], o, d, qb.length,
                                                                           qb.mediumId, r * r, t) &
                                                                 ub_block_lanes(b, first, end);
                                                 for (; near != 0; near &= near - 1) {
                                                     const int lane = __builtin_ctz(near);
                                                     pending[np] = b * 4 + uint32_t(lane);
                                                     pendingT[np++] = t[lane];
                                                     if (np == kPending) flush();
                                                 }
                                             }
                                         });
        flush();
        return sum;
    });
}

}  // namespace ub
