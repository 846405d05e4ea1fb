/* pp3d: photon points x query points, the volumetric photon map with a 3D
 * kernel (Jensen & Christensen 1998; UPBP, Krivanek et al. 2014, Sec. 4 and
 * Table 1: "P-P3D").
 *
 * Estimates the radiance scattered towards the camera at a query point z (a
 * camera-subpath vertex in a medium) from the photon points y (light-subpath
 * vertices in the same medium) within distance r:
 *   L(z) ~= sum_y  Theta_z * rho(z; w_z, w_y) * Phi_y / sigma_s(y) * K3 / N_L,
 *   K3 = 1 / ((4/3) pi r^3)                      (box kernel, UPBP Table 1)
 * Theta_z (camera throughput) and Phi_y (light throughput) each carry the sigma_s
 * of their own free-flight vertex, but the merged path has one scattering vertex:
 * one sigma_s is divided out (that of y).
 * pdfs for MIS: the phase function (its own adjoint) in both directions, times the
 * continuation probability of the subpath that would have sampled it.
 * MIS: ub_mis_weight_volume with the partials stored at y and z, the etas at the
 * merge vertex from R_photon(y), R_query(z) and the angle between w_y and w_z
 * (ub_mis_volume.h, UPBP eq. (8)).
 */
#ifndef UB_PP3D_H
#define UB_PP3D_H

#include "ub_phase.h"
#include "ub_upbp_records.h"

/* 1 / (N_L (4/3) pi r^3): the box kernel K3 over N_L light subpaths (UPBP Table 1). */
UB_INLINE float ub_pp3d_normalization(float lightPaths, float radius) {
    return 1.0f / (lightPaths * (4.0f / 3.0f) * UB_PI * radius * radius * radius);
}

/* Contribution of photon ph to query q (0 if out of range or in another medium).
 * g: the medium's HG asymmetry; normalization = 1 / (N_L (4/3) pi r^3). */
UB_INLINE ub_float3 ub_pp3d_contribution(ub_mis_constants c, ub_photon_point ph, ub_query_point q,
                                         float g, float radiusSqr, float normalization,
                                         ub_uint minLength, ub_uint maxLength) {
    ub_float3 zero = ub_make_float3(0.0f, 0.0f, 0.0f);
    if (ph.mediumId != q.mediumId) return zero;
    ub_uint length = ph.pathLength + q.pathLength;
    if (length > maxLength || length < minLength) return zero;
    ub_float3 d = ub_f3_sub(ub_f3_from(ph.pos), ub_f3_from(q.pos));
    if (ub_f3_dot(d, d) > radiusSqr) return zero;
    ub_float3 wz = ub_f3_from(q.dirFix), wy = ub_f3_from(ph.dirFix);
    float phase = ub_hg_eval_dirs(wz, wy, g); /* = pdf in both directions */
    ub_mis_partials l = ub_mis_merge_partials(ph.dVCM, ph.dVM);
    ub_mis_partials e = ub_mis_merge_partials(q.dVCM, q.dVM);
    float sinTheta = ub_f3_length(ub_f3_cross(wz, wy));
    ub_mis_etas etas = ub_mis_volume_etas(c, ph.rPhotonL, q.rQueryL, sinTheta);
    float w =
        ub_mis_weight_volume(c, l, e, phase * q.contProb, phase * ph.contProb, etas, UB_TECH_PP3D);
    float s = phase * w * normalization;
    ub_float3 out;
    out.x = ph.sigmaS[0] > 0.0f ? q.throughput[0] * ph.throughput[0] / ph.sigmaS[0] * s : 0.0f;
    out.y = ph.sigmaS[1] > 0.0f ? q.throughput[1] * ph.throughput[1] / ph.sigmaS[1] * s : 0.0f;
    out.z = ph.sigmaS[2] > 0.0f ? q.throughput[2] * ph.throughput[2] / ph.sigmaS[2] * s : 0.0f;
    return out;
}

#endif /* UB_PP3D_H */
