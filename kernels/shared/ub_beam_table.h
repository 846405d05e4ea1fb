/* The medium along one beam in a nearest-filtered grid medium, tabulated once and then
 * evaluated at many distances t: what the beam estimators need at each photon-query pair.
 *
 * Regular tracking (Novak et al. 2018, Sec. 4.1) visits pieces of constant extinction, so
 * the optical depth along the beam is piecewise linear in t: tau(t) = tau0_k +
 * sigmaT_k (t - t0_k) on piece k. One walk over the whole beam (ub_grid_walk in
 * ub_grid_medium.h) gives the table of pieces (start t0, extinction sigmaT, optical depth
 * tau0 at the start); a later evaluation is a binary search plus an exponential: the value
 * of a walk from the beam start to t up to the rounding of the sum, at O(log pieces)
 * instead of O(voxels).
 *
 * Users: the host twins (src/estimators/beam_medium.cpp: photon beams and query beams,
 * unbounded tables), and the beam kernels (kernels/beams.cl): photon beams' tables built by
 * the host and read from a global buffer, each query beam's table built by its own
 * work-item in private memory (UB_QUERY_PIECES pieces; a longer beam walks per pair). */
#ifndef UB_BEAM_TABLE_H
#define UB_BEAM_TABLE_H

#include "ub_medium_homogeneous.h"

/* One piece of constant extinction starting at t0. 12 bytes. */
typedef struct {
    float t0;
    float sigmaT;
    float tau0; /* optical depth of [0, t0] */
} ub_beam_piece;

/* A table that was not built yet / did not fit its buffer (query beams in the kernels). */
#define UB_TABLE_UNBUILT 0xffffffffu
#define UB_TABLE_OVERFLOW 0xfffffffeu

/* The ub_segment_eval of [0, t] from the optical depth tau of [0, t] and the extinction of
 * the first piece (sFirst) and of the piece the walk to t ends in (sLast), in a medium grey in
 * sigma_t with albedo (ar, ag, ab) at the end: T = exp(-tau), sigma_s = albedo sigma_t, the
 * stopping densities sigma_t T at either end, passing T (Novak et al. 2018, Eq. 9 and 13). */
UB_INLINE ub_segment_eval ub_grey_segment(float tau, float sFirst, float sLast, float ar, float ag,
                                          float ab) {
    const float T = ub_exp(-tau);
    ub_segment_eval e;
    e.transmittance[0] = T;
    e.transmittance[1] = T;
    e.transmittance[2] = T;
    e.sigmaS[0] = ar * sLast;
    e.sigmaS[1] = ag * sLast;
    e.sigmaS[2] = ab * sLast;
    e.stopFwdL = sLast * T;
    e.stopRevStartL = sFirst * T;
    e.passProb = T;
    e.contProb = ub_medium_cont_prob(e.sigmaS[0], e.sigmaS[1], e.sigmaS[2], sLast, sLast, sLast);
    return e;
}

/* The optical depth of [0, t] from a table of count >= 1 pieces, and the extinction of its
 * first piece and of the piece a walk to t ends in: the last piece starting at or before t,
 * except that a walk ending exactly on a boundary t ends in the piece before it. Written once
 * per address space (OpenCL C 1.2 has no generic one): _g reads a global table, _p a private
 * one; on the host both are the same function. */
#define UB_DEFINE_TABLE_TAU(NAME, SPACE)                                             \
    UB_INLINE float NAME(SPACE const ub_beam_piece* p, ub_uint count, float t,       \
                         UB_PRIVATE float* sFirst, UB_PRIVATE float* sLast) {        \
        ub_uint lo = 0u, hi = count; /* the first piece with t0 > t (upper bound) */ \
        while (lo < hi) {                                                            \
            const ub_uint mid = (lo + hi) / 2u;                                      \
            if (t < p[mid].t0)                                                       \
                hi = mid;                                                            \
            else                                                                     \
                lo = mid + 1u;                                                       \
        }                                                                            \
        ub_uint k = lo == 0u ? 0u : lo - 1u;                                         \
        if (lo > 1u && p[k].t0 == t) k -= 1u;                                        \
        *sFirst = p[0].sigmaT;                                                       \
        *sLast = p[k].sigmaT;                                                        \
        return p[k].tau0 + p[k].sigmaT * (t - p[k].t0);                              \
    }
UB_DEFINE_TABLE_TAU(ub_beam_table_tau_g, UB_GLOBAL)
#ifdef __OPENCL_C_VERSION__
UB_DEFINE_TABLE_TAU(ub_beam_table_tau_p, UB_PRIVATE)
#else
#define ub_beam_table_tau_p ub_beam_table_tau_g
#endif
#undef UB_DEFINE_TABLE_TAU

#ifndef __OPENCL_C_VERSION__
#include <cstddef>
static_assert(sizeof(ub_beam_piece) == 12, "ub_beam_piece layout");
static_assert(offsetof(ub_beam_piece, tau0) == 8, "ub_beam_piece layout");
#endif

#endif /* UB_BEAM_TABLE_H */
