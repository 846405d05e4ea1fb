/* Records of the UPBP estimate pass, shared by the host (which writes them in
 * the light and camera passes) and the estimators (host twins in
 * src/estimators/, OpenCL kernels later), with the medium evaluation of a
 * beam point and the completion of a beam's MIS partials there.
 *
 * Fixed-size scalars only (float, ub_uint), float[3] instead of float3 (whose
 * OpenCL size is 16), explicit padding; sizes and offsets are checked by
 * static_asserts on the host (below) and are the same in OpenCL C.
 *
 * Measures in names: pdfs per unit length (free-flight densities) end in L,
 * probabilities (pass) have no suffix; ratios R = cover / pdf (ub_mis_volume.h)
 * are lengths.
 */
#ifndef UB_UPBP_RECORDS_H
#define UB_UPBP_RECORDS_H

#include "ub_mis_volume.h"
#include "ub_vec3.h"

/* A photon point: a light-subpath vertex in a medium (pp3d, pb2d). 80 bytes. */
typedef struct {
    float pos[3];
    ub_uint pathLength;  /* segments from the light to this vertex */
    float throughput[3]; /* light throughput at the vertex; includes sigma_s there */
    ub_uint mediumId;
    float sigmaS[3]; /* sigma_s at the vertex (pp3d divides the throughput by it) */
    float contProb;  /* the light subpath's continuation probability here */
    float dirFix[3]; /* unit direction towards the previous light vertex */
    float rPhotonL;  /* R of the photon beam that reached the vertex (ub_mis_volume.h) */
    float dVCM;      /* MIS partials after the hit update here (ub_mis.h) */
    float dVM;
    float pad0, pad1;
} ub_photon_point;

/* What the pb2d walk reads of a photon point before it is a pair (ub_pb2d_near): its position and
 * medium, 16 bytes (the 80-byte records are read for the pairs only). The walks read them four
 * photons to a block (ub_photon_keys4, below), in the BVH's leaf order beside the photons. */
typedef struct {
    float pos[3];
    ub_uint mediumId;
} ub_photon_key;

/* The keys of four consecutive photons in the BVH's leaf order (photons 4 j .. 4 j + 3 are
 * block j; the last block's missing lanes hold medium UB_NO_MEDIUM, which no query is in), as a
 * structure of arrays, so one load tests four candidates (ub_pb2d_near4). 64 bytes. */
#define UB_NO_MEDIUM 0xFFFFFFFFu
typedef struct UB_CACHE_ALIGNED {
    float px[4], py[4], pz[4];
    ub_uint mediumId[4];
} ub_photon_keys4;

/* Lane j of a block: photon ph's key. */
UB_INLINE void ub_photon_keys4_set(UB_PRIVATE ub_photon_keys4* k, int j, ub_photon_point ph) {
    k->px[j] = ph.pos[0];
    k->py[j] = ph.pos[1];
    k->pz[j] = ph.pos[2];
    k->mediumId[j] = ph.mediumId;
}

UB_INLINE ub_photon_key ub_photon_key_of(ub_photon_point ph) {
    ub_photon_key k;
    k.pos[0] = ph.pos[0];
    k.pos[1] = ph.pos[1];
    k.pos[2] = ph.pos[2];
    k.mediumId = ph.mediumId;
    return k;
}

/* A query point: a camera-subpath vertex in a medium (pp3d, bp2d). 64 bytes. */
typedef struct {
    float pos[3];
    ub_uint pathLength;  /* segments from the camera to this vertex */
    float throughput[3]; /* camera throughput at the vertex; includes sigma_s there */
    ub_uint mediumId;
    float dirFix[3]; /* unit direction towards the previous camera vertex */
    float rQueryL;   /* R of the query beam that reached the vertex */
    float dVCM;      /* MIS partials after the hit update here */
    float dVM;
    float contProb; /* the camera subpath's continuation probability here */
    ub_uint pixel;  /* y * width + x */
} ub_query_point;

#define UB_BEAM_ORIGIN_IN_PIECE 1u /* the piece starts at the medium vertex that emits it */
#define UB_BEAM_APPLY_DIST2 2u     /* not the first segment of a light at infinity */

/* A beam piece: the part of a photon beam (light subpath segment) or query beam (camera
 * subpath segment) inside one medium segment of its chain (scene/medium_trace.h), from
 * `origin` (the piece start) for `length` along `dir`. 96 bytes.
 * MIS: the partials of the subpath after scattering at the vertex x that emits the beam
 * (dVCM, dVM, dOut as ub_mis_scatter_volume left them), the distance from x to the piece
 * start, and the free-flight probabilities of the chain between x and the piece start:
 * fwdPassBefore (passing it from x), revPdfBeforeL (from the piece start back to x,
 * stopping at x if x is a medium vertex) and revPassBefore (passing it back to x). */
typedef struct {
    float origin[3];
    float length;
    float dir[3];
    ub_uint mediumId;
    float throughput[3]; /* at the piece start: after scattering at x, times the chain's
                            weight up to here (T / P per segment for short beams, T long) */
    ub_uint pathLength;  /* segments from the subpath start to a point of this beam */
    float dVCM;
    float dVM;
    float dOut;
    float distBefore; /* |piece start - x| */
    float fwdPassBefore;
    float revPdfBeforeL;
    float revPassBefore;
    ub_uint flags; /* UB_BEAM_* */
    ub_uint pixel; /* query beams: y * width + x; photon beams: the light subpath index */
    ub_uint pad0, pad1, pad2;
} ub_beam;

/* The medium along a beam piece from its start to distance t (regular tracking on the host,
 * scene/medium.h evalMediumSegment): everything an estimator needs at the point. */
typedef struct {
    float transmittance[3];
    float sigmaS[3];     /* sigma_s at the point */
    float stopFwdL;      /* density of free-flight sampling from the start stopping at t */
    float stopRevStartL; /* density of sampling from t back to the start stopping there */
    float passProb;      /* probability of passing [0, t] (either direction) */
    float contProb;      /* continuation probability of a vertex at the point */
} ub_segment_eval;

/* A subpath at a point of one of its beams, as if it had sampled a vertex there. */
typedef struct {
    ub_uint valid;        /* 0: the point's free-flight densities underflow (T below ~1e-18);
                             it contributes nothing measurable and its MIS is not evaluated */
    ub_mis_partials mis;  /* completed at the point (ub_mis_at_hit_volume) */
    float rInL;           /* R of this beam at the point (its kind) */
    ub_float3 throughput; /* at the point: T / P of the piece for short beams, T for long */
} ub_beam_point;

/* Completes beam b at distance t of its piece. photonBeam: 1 for photon beams (light
 * subpath), 0 for query beams. UPBP Sec. 5.1: the point is a virtual vertex; its partials
 * are those a vertex sampled there would have (distance pdfs of the whole chain from x). */
UB_INLINE ub_beam_point ub_beam_at(ub_mis_constants c, ub_beam b, ub_segment_eval s, float t,
                                   ub_uint photonBeam) {
    ub_beam_point out;
    ub_uint shortThis = photonBeam ? c.shortPhotonBeams : c.shortQueryBeams;
    ub_uint shortOther = photonBeam ? c.shortQueryBeams : c.shortPhotonBeams;
    float stopFwd = b.fwdPassBefore * s.stopFwdL;
    float passFwd = b.fwdPassBefore * s.passProb;
    float stopRev, passRev;
    if (b.flags & UB_BEAM_ORIGIN_IN_PIECE) {
        stopRev = s.stopRevStartL;
        passRev = s.passProb;
    } else {
        stopRev = s.passProb * b.revPdfBeforeL;
        passRev = s.passProb * b.revPassBefore;
    }
    /* Below this density the squares of the power heuristic underflow float (pdf^2 < 1e-36)
     * and 0 * inf would poison the weight; such points carry T < 1e-18. */
    out.valid = stopFwd > 1e-18f && stopRev > 1e-18f && s.passProb > 0.0f;
    if (!out.valid) {
        out.mis.dVCM = out.mis.dVC = out.mis.dVM = out.mis.dOut = 0.0f;
        out.rInL = 0.0f;
        out.throughput = ub_make_float3(0.0f, 0.0f, 0.0f);
        return out;
    }
    ub_mis_partials p = ub_mis_merge_partials(b.dVCM, b.dVM);
    p.dOut = b.dOut;
    /* R_out of x is the other kind of beam over the same chain, seen from the point */
    out.mis =
        ub_mis_at_hit_volume(c, p, b.distBefore + t, 1.0f, (b.flags & UB_BEAM_APPLY_DIST2) ? 1 : 0,
                             stopFwd, stopRev, ub_mis_beam_ratio(shortOther, passRev, stopRev));
    out.rInL = ub_mis_beam_ratio(shortThis, passFwd, stopFwd);
    /* short beams cover t with probability passProb (of this piece; earlier pieces are in
     * b.throughput), long ones always */
    float cover = shortThis ? s.passProb : 1.0f;
    float scale = cover > 0.0f ? 1.0f / cover : 0.0f;
    out.throughput = ub_make_float3(b.throughput[0] * s.transmittance[0] * scale,
                                    b.throughput[1] * s.transmittance[1] * scale,
                                    b.throughput[2] * s.transmittance[2] * scale);
    return out;
}

/* Continuation probability of a medium vertex: the largest single-scattering albedo over
 * the channels (render/vertex_scatter.h). */
UB_INLINE float ub_medium_cont_prob(float sigmaS0, float sigmaS1, float sigmaS2, float sigmaT0,
                                    float sigmaT1, float sigmaT2) {
    float a = 0.0f;
    if (sigmaT0 > 0.0f) a = ub_fmax(a, sigmaS0 / sigmaT0);
    if (sigmaT1 > 0.0f) a = ub_fmax(a, sigmaS1 / sigmaT1);
    if (sigmaT2 > 0.0f) a = ub_fmax(a, sigmaS2 / sigmaT2);
    return ub_fmin(a, 1.0f);
}

#ifndef __OPENCL_C_VERSION__
#include <cstddef>
static_assert(sizeof(ub_photon_point) == 80, "ub_photon_point layout");
static_assert(offsetof(ub_photon_point, throughput) == 16, "ub_photon_point layout");
static_assert(offsetof(ub_photon_point, sigmaS) == 32, "ub_photon_point layout");
static_assert(offsetof(ub_photon_point, dirFix) == 48, "ub_photon_point layout");
static_assert(offsetof(ub_photon_point, dVCM) == 64, "ub_photon_point layout");
static_assert(sizeof(ub_photon_key) == 16, "ub_photon_key layout");
static_assert(sizeof(ub_photon_keys4) == 64, "ub_photon_keys4 layout");
static_assert(offsetof(ub_photon_keys4, mediumId) == 48, "ub_photon_keys4 layout");
static_assert(offsetof(ub_photon_key, mediumId) == 12, "ub_photon_key layout");
static_assert(sizeof(ub_query_point) == 64, "ub_query_point layout");
static_assert(offsetof(ub_query_point, throughput) == 16, "ub_query_point layout");
static_assert(offsetof(ub_query_point, dirFix) == 32, "ub_query_point layout");
static_assert(offsetof(ub_query_point, pixel) == 60, "ub_query_point layout");
static_assert(sizeof(ub_beam) == 96, "ub_beam layout");
static_assert(offsetof(ub_beam, dir) == 16, "ub_beam layout");
static_assert(offsetof(ub_beam, throughput) == 32, "ub_beam layout");
static_assert(offsetof(ub_beam, dVCM) == 48, "ub_beam layout");
static_assert(offsetof(ub_beam, fwdPassBefore) == 64, "ub_beam layout");
static_assert(offsetof(ub_beam, pixel) == 80, "ub_beam layout");
#endif

#endif /* UB_UPBP_RECORDS_H */
