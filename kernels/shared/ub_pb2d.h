/* pb2d: photon points x query beams, the beam radiance estimate with a 2D
 * kernel (Jarosz et al. 2008, "The beam radiance estimate for volumetric photon
 * mapping"; UPBP Table 1: "P-B2D").
 *
 * Estimates the radiance arriving at the origin of a query beam (a camera-subpath
 * segment through a medium, origin o, direction d) from the photon points y within
 * distance r of the beam, each at the beam parameter t of its projection:
 *   L ~= sum_y Theta_o T(o, t) / cover(t) * rho(v; -d, w_y) * Phi_y * K2 / N_L,
 *   K2 = 1 / (pi r^2)                             (box kernel, UPBP Table 1)
 * cover(t) = probability that a short query beam reaches t (1 for long beams).
 * Phi_y carries sigma_s(y), the one scattering coefficient of the merged path; the
 * query beam carries none (it samples no vertex).
 * pdfs for MIS: the phase at v = o + t d in both directions, the camera's continuation
 * probability at v; the camera partials completed at v (ub_beam_at), the light partials
 * of the photon.
 */
#ifndef UB_PB2D_H
#define UB_PB2D_H

#include "ub_beam_geometry.h"
#include "ub_phase.h"
#include "ub_upbp_records.h"

/* 1 / (N_L pi r^2): the box kernel K2 over N_L light subpaths (UPBP Table 1). */
UB_INLINE float ub_pb2d_normalization(float lightPaths, float radius) {
    return 1.0f / (lightPaths * UB_PI * radius * radius);
}

/* Whether a photon and query beam qb make a pb2d pair: same medium, the photon within radius
 * of the beam (ub_pb2d_near, on the photon's key, which is where most candidates of a walk
 * end; writes its beam parameter), and the path length in [minLength, maxLength]
 * (ub_pb2d_length_ok, on the photon record, read for the near ones only). */
UB_INLINE int ub_pb2d_near(ub_photon_key k, ub_float3 origin, ub_float3 dir, float length,
                           ub_uint mediumId, float radiusSqr, UB_PRIVATE float* t) {
    if (k.mediumId != mediumId) return 0;
    float d2 = ub_point_beam_dist2(ub_f3_from(k.pos), origin, dir, length, t);
    return d2 >= 0.0f && d2 <= radiusSqr;
}
/* ub_pb2d_near for the four photons of a block: bit j set for a pair candidate, t[j] its beam
 * parameter. The walks test a leaf block by block (the host in SSE, estimators/pb2d_estimator.cpp;
 * the kernel in float4, ub_pb2d_near4_global), with these operations per lane. */
UB_INLINE ub_uint ub_pb2d_near4(UB_PRIVATE const ub_photon_keys4* k, ub_float3 origin,
                                ub_float3 dir, float length, ub_uint mediumId, float radiusSqr,
                                UB_PRIVATE float* t) {
    ub_uint mask = 0u;
    UB_UNROLL
    for (int j = 0; j < 4; ++j) {
        ub_photon_key key;
        key.pos[0] = k->px[j];
        key.pos[1] = k->py[j];
        key.pos[2] = k->pz[j];
        key.mediumId = k->mediumId[j];
        t[j] = 0.0f;
        mask |= ub_pb2d_near(key, origin, dir, length, mediumId, radiusSqr, &t[j]) ? (1u << j) : 0u;
    }
    return mask;
}

#ifdef __OPENCL_C_VERSION__
/* The kernel's ub_pb2d_near4: the four photons as float4 lanes, read in place. */
UB_INLINE ub_uint ub_pb2d_near4_global(__global const ub_photon_keys4* k, ub_float3 o, ub_float3 d,
                                       float length, ub_uint mediumId, float radiusSqr,
                                       UB_PRIVATE float* t) {
    float4 opx = vload4(0, k->px) - o.x, opy = vload4(0, k->py) - o.y, opz = vload4(0, k->pz) - o.z;
    float4 tp = opx * d.x + opy * d.y + opz * d.z;
    float4 qx = opx - d.x * tp, qy = opy - d.y * tp, qz = opz - d.z * tp;
    float4 d2 = qx * qx + qy * qy + qz * qz;
    int4 near = (tp >= 0.0f) & (tp <= length) & (d2 <= radiusSqr) &
                (vload4(0, k->mediumId) == (uint4)(mediumId));
    vstore4(tp, 0, t);
    return ub_lane_mask4(near);
}
/* Two consecutive blocks k[0], k[1] as float8 lanes, the same operations per lane: bits 0-3
 * are block k[0]'s mask and t[0..3] its parameters, bits 4-7 and t[4..7] block k[1]'s. On
 * PoCL's AVX2 CPU target a float8 is one register (as ub_beam_lines_near8_global). */
UB_INLINE ub_uint ub_pb2d_near8_global(__global const ub_photon_keys4* k, ub_float3 o, ub_float3 d,
                                       float length, ub_uint mediumId, float radiusSqr,
                                       UB_PRIVATE float* t) {
    float8 opx = (float8)(vload4(0, k[0].px), vload4(0, k[1].px)) - o.x;
    float8 opy = (float8)(vload4(0, k[0].py), vload4(0, k[1].py)) - o.y;
    float8 opz = (float8)(vload4(0, k[0].pz), vload4(0, k[1].pz)) - o.z;
    float8 tp = opx * d.x + opy * d.y + opz * d.z;
    float8 qx = opx - d.x * tp, qy = opy - d.y * tp, qz = opz - d.z * tp;
    float8 d2 = qx * qx + qy * qy + qz * qz;
    int8 near = (tp >= 0.0f) & (tp <= length) & (d2 <= radiusSqr) &
                ((uint8)(vload4(0, k[0].mediumId), vload4(0, k[1].mediumId)) == (uint8)(mediumId));
    vstore8(tp, 0, t);
    return ub_lane_mask8(near);
}
#endif

UB_INLINE int ub_pb2d_length_ok(ub_uint photonLength, ub_beam qb, ub_uint minLength,
                                ub_uint maxLength) {
    ub_uint length = photonLength + qb.pathLength;
    return length <= maxLength && length >= minLength;
}

/* Contribution of photon ph to query beam qb at parameter t (from
 * ub_point_beam_dist2), with the medium of qb evaluated over [0, t] in s.
 * normalization = 1 / (N_L pi r^2). */
UB_INLINE ub_float3 ub_pb2d_contribution(ub_mis_constants c, ub_photon_point ph, ub_beam qb,
                                         ub_segment_eval s, float t, float g, float normalization) {
    ub_beam_point cp = ub_beam_at(c, qb, s, t, 0u);
    if (!cp.valid) return ub_make_float3(0.0f, 0.0f, 0.0f);
    ub_float3 wz = ub_f3_neg(ub_f3_from(qb.dir)), wy = ub_f3_from(ph.dirFix);
    float phase = ub_hg_eval_dirs(wz, wy, g);
    ub_mis_partials l = ub_mis_merge_partials(ph.dVCM, ph.dVM);
    float sinTheta = ub_f3_length(ub_f3_cross(wz, wy));
    ub_mis_etas etas = ub_mis_volume_etas(c, ph.rPhotonL, cp.rInL, sinTheta);
    float w = ub_mis_weight_volume(c, l, cp.mis, phase * s.contProb, phase * ph.contProb, etas,
                                   UB_TECH_PB2D);
    return ub_f3_scale(ub_f3_mul(cp.throughput, ub_f3_from(ph.throughput)),
                       phase * w * normalization);
}

#endif /* UB_PB2D_H */
