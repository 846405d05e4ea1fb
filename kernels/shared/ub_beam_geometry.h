/* Geometry of the beam estimators: a point against a beam, and two beams
 * against each other (closest approach of two lines). Shared by host C++ and
 * OpenCL C; all directions unit length. */
#ifndef UB_BEAM_GEOMETRY_H
#define UB_BEAM_GEOMETRY_H

#include "ub_vec3.h"

/* Projection of point p on the beam (origin o, direction dir, length len): writes the beam
 * parameter t in [0, len] and returns the squared distance from p to o + t dir, or -1 if the
 * projection falls outside [0, len]. */
UB_INLINE float ub_point_beam_dist2(ub_float3 p, ub_float3 o, ub_float3 dir, float len,
                                    UB_PRIVATE float* t) {
    ub_float3 op = ub_f3_sub(p, o);
    float tp = ub_f3_dot(op, dir);
    if (tp < 0.0f || tp > len) return -1.0f;
    ub_float3 perp = ub_f3_sub(op, ub_f3_scale(dir, tp));
    *t = tp;
    return ub_f3_dot(perp, perp);
}

/* Closest approach of the segments oA + tA dA, tA in [0, lenA], and oB + tB dB, tB in
 * [0, lenB], when their lines pass within sqrt(radiusSqr) (Jarosz et al. 2011, "A
 * comprehensive theory of volumetric radiance estimation using photon points and beams",
 * Sec. 5.2, beam x beam): returns 1 and writes tA, tB and sin(theta) of the angle between
 * them, or returns 0 (also when the lines are nearly parallel). With sin^2 = 1 - (dA.dB)^2
 * and w0 = oA - oB, the separation along dA x dB is |w0 . (dA x dB)| / sin and the
 * parameters are tA = (b e - d) / sin^2, tB = (e - b d) / sin^2 (b = dA.dB, d = dA.w0,
 * e = dB.w0). Most candidates of a BVH walk fail, so the tests run on the numerators first,
 * without the two divisions and the square root (measured, docs/performance.md); the
 * parameters are checked again after the division, so an accepted pair satisfies
 * 0 <= tA <= lenA and 0 <= tB <= lenB exactly as computed. */
UB_INLINE int ub_beam_beam_near(ub_float3 oA, ub_float3 dA, float lenA, ub_float3 oB, ub_float3 dB,
                                float lenB, float radiusSqr, UB_PRIVATE float* tA,
                                UB_PRIVATE float* tB, UB_PRIVATE float* sinTheta) {
    ub_float3 w0 = ub_f3_sub(oA, oB);
    float b = ub_f3_dot(dA, dB);
    float sin2 = 1.0f - b * b;
    if (!(sin2 > 1e-7f)) return 0;
    float sep = ub_f3_dot(w0, ub_f3_cross(dA, dB));
    if (sep * sep > radiusSqr * sin2) return 0;
    float d = ub_f3_dot(dA, w0), e = ub_f3_dot(dB, w0);
    float nA = b * e - d, nB = e - b * d;
    if (nA < 0.0f || nB < 0.0f || nA > lenA * sin2 * 1.0001f || nB > lenB * sin2 * 1.0001f)
        return 0;
    *tA = nA / sin2;
    *tB = nB / sin2;
    if (*tA > lenA || *tB > lenB) return 0;
    *sinTheta = ub_sqrt(sin2);
    return 1;
}

#endif /* UB_BEAM_GEOMETRY_H */
