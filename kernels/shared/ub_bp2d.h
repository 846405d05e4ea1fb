/* bp2d: photon beams x query points, 2D kernel (Jarosz et al. 2011, "A
 * comprehensive theory of volumetric radiance estimation using photon points and
 * beams", the "beam x point" estimator; UPBP Table 1: "B-P2D").
 *
 * Estimates the radiance scattered towards the camera at a query point z from the
 * photon beams (light-subpath segments through media: origin o, direction d) that
 * pass within distance r of z, each at the parameter t of z's projection:
 *   L(z) ~= sum_beams Theta_z * rho(z; w_z, -d) * Phi_o T(o, t) / cover(t) * K2 / N_B,
 *   K2 = 1 / (pi r^2)                             (box kernel, UPBP Table 1)
 * N_B: the light subpaths that emit beams; cover(t): as in pb2d, for short photon beams.
 * Theta_z carries sigma_s(z); the beam none.
 * pdfs for MIS: the phase at z, the camera's continuation probability at z and the light's
 * at the beam point; the light partials completed at o + t d (ub_beam_at).
 */
#ifndef UB_BP2D_H
#define UB_BP2D_H

#include "ub_beam_geometry.h"
#include "ub_bvh.h"
#include "ub_phase.h"
#include "ub_upbp_records.h"

/* 1 / (N_B pi r^2): the box kernel K2 over the N_B beam-emitting light subpaths. */
UB_INLINE float ub_bp2d_normalization(float beamPaths, float radius) {
    return 1.0f / (beamPaths * UB_PI * radius * radius);
}

/* Whether query point q and part `part` of a photon beam make a bp2d pair (same medium,
 * path length in range, q within radius of the beam, and its projection in this part, so
 * each beam counts once); writes the beam parameter. Reads the beam's copy in the part. */
UB_INLINE int ub_bp2d_pair(ub_query_point q, ub_beam_part part, float radiusSqr, ub_uint minLength,
                           ub_uint maxLength, UB_PRIVATE float* t) {
    if (part.mediumId != q.mediumId) return 0;
    ub_uint length = part.pathLength + q.pathLength;
    if (length > maxLength || length < minLength) return 0;
    float d2 = ub_point_beam_dist2(ub_f3_from(q.pos), ub_f3_from(part.origin), ub_f3_from(part.dir),
                                   part.length, t);
    if (d2 < 0.0f || d2 > radiusSqr) return 0;
    return ub_beam_part_holds(part, *t, part.length);
}

/* Contribution of photon beam pb at parameter t to query point q, the beam's medium over
 * [0, t] in s. normalization = 1 / (N_B pi r^2). */
UB_INLINE ub_float3 ub_bp2d_contribution(ub_mis_constants c, ub_beam pb, ub_query_point q,
                                         ub_segment_eval s, float t, float g, float normalization) {
    ub_beam_point lp = ub_beam_at(c, pb, s, t, 1u);
    if (!lp.valid) return ub_make_float3(0.0f, 0.0f, 0.0f);
    ub_float3 wz = ub_f3_from(q.dirFix), wy = ub_f3_neg(ub_f3_from(pb.dir));
    float phase = ub_hg_eval_dirs(wz, wy, g);
    ub_mis_partials e = ub_mis_merge_partials(q.dVCM, q.dVM);
    float sinTheta = ub_f3_length(ub_f3_cross(wz, wy));
    ub_mis_etas etas = ub_mis_volume_etas(c, lp.rInL, q.rQueryL, sinTheta);
    float w = ub_mis_weight_volume(c, lp.mis, e, phase * q.contProb, phase * s.contProb, etas,
                                   UB_TECH_BP2D);
    return ub_f3_scale(ub_f3_mul(ub_f3_from(q.throughput), lp.throughput),
                       phase * w * normalization);
}

#endif /* UB_BP2D_H */
