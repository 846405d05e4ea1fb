/* bb1d: photon beams x query beams, 1D kernel (Jarosz et al. 2011, "beam x beam
 * 1D"; UPBP Table 1: "B-B1D").
 *
 * Estimates the radiance arriving at the origin of a query beam (origin o_c,
 * direction d_c) from the photon beams (o_l, d_l) whose lines pass within distance r
 * of it, at the parameters t_c, t_l of their closest approach:
 *   L ~= sum Theta_c T_c(t_c) / cover_c * Phi_l T_l(t_l) / cover_l
 *            * sigma_s(v) rho(v; -d_c, -d_l) * K1 / (sin(theta) N_B),
 *   K1 = 1 / (2 r)                               (box kernel, UPBP Table 1)
 * theta the angle between the beams; v = o_c + t_c d_c. Neither beam samples a vertex,
 * so sigma_s(v) is multiplied here.
 * pdfs for MIS: the phase at v, each side's continuation probability at its point; both
 * sides' partials completed at their beam points (ub_beam_at).
 */
#ifndef UB_BB1D_H
#define UB_BB1D_H

#include "ub_beam_geometry.h"
#include "ub_bvh.h"
#include "ub_phase.h"
#include "ub_upbp_records.h"

/* 1 / (N_B 2 r): the box kernel K1 over the N_B beam-emitting light subpaths (the 1 / sin
 * of UPBP Table 1 is applied per pair). */
UB_INLINE float ub_bb1d_normalization(float beamPaths, float radius) {
    return 1.0f / (beamPaths * 2.0f * radius);
}

/* Whether query beam qb and part `part` of a photon beam make a bb1d pair (same medium, path
 * length in range, lines within radius, closest approach on both beams and in this part);
 * writes the parameters and sin(theta). Reads the beam's copy in the part. */
UB_INLINE int ub_bb1d_pair(ub_beam qb, ub_beam_part part, float radiusSqr, ub_uint minLength,
                           ub_uint maxLength, UB_PRIVATE float* tc, UB_PRIVATE float* tl,
                           UB_PRIVATE float* sinTheta) {
    if (part.mediumId != qb.mediumId) return 0;
    ub_uint length = part.pathLength + qb.pathLength;
    if (length > maxLength || length < minLength) return 0;
    if (!ub_beam_beam_near(ub_f3_from(qb.origin), ub_f3_from(qb.dir), qb.length,
                           ub_f3_from(part.origin), ub_f3_from(part.dir), part.length, radiusSqr,
                           tc, tl, sinTheta))
        return 0;
    return ub_beam_part_holds(part, *tl, part.length);
}

UB_INLINE_HOT ub_float3 ub_bb1d_contribution(ub_mis_constants c, ub_beam pb, ub_beam qb,
                                             ub_segment_eval sl, ub_segment_eval sc, float tl,
                                             float tc, float sinTheta, float g,
                                             float normalization) {
    ub_beam_point lp = ub_beam_at(c, pb, sl, tl, 1u);
    ub_beam_point cp = ub_beam_at(c, qb, sc, tc, 0u);
    if (!lp.valid || !cp.valid) return ub_make_float3(0.0f, 0.0f, 0.0f);
    ub_float3 wz = ub_f3_neg(ub_f3_from(qb.dir)), wy = ub_f3_neg(ub_f3_from(pb.dir));
    float phase = ub_hg_eval_dirs(wz, wy, g);
    ub_mis_etas etas = ub_mis_volume_etas(c, lp.rInL, cp.rInL, sinTheta);
    float w = ub_mis_weight_volume(c, lp.mis, cp.mis, phase * sc.contProb, phase * sl.contProb,
                                   etas, UB_TECH_BB1D);
    ub_float3 f = ub_f3_mul(ub_f3_mul(cp.throughput, lp.throughput), ub_f3_from(sc.sigmaS));
    return ub_f3_scale(f, phase * w * normalization / sinTheta);
}

#endif /* UB_BB1D_H */
