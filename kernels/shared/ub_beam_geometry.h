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

/* Closest approach of the lines oA + tA dA and oB + tB dB (Jarosz et al. 2011, "A
 * comprehensive theory of volumetric radiance estimation using photon points and beams",
 * Sec. 5.2, beam x beam): writes tA, tB and sin(theta) of the angle between them, returns the
 * squared distance between the lines, or -1 if they are (nearly) parallel. */
UB_INLINE float ub_beam_beam_dist2(ub_float3 oA, ub_float3 dA, ub_float3 oB, ub_float3 dB,
                                   UB_PRIVATE float* tA, UB_PRIVATE float* tB,
                                   UB_PRIVATE float* sinTheta) {
    ub_float3 w0 = ub_f3_sub(oA, oB);
    float b = ub_f3_dot(dA, dB);
    float sin2 = 1.0f - b * b;
    if (!(sin2 > 1e-7f)) return -1.0f;
    float d = ub_f3_dot(dA, w0), e = ub_f3_dot(dB, w0);
    *tA = (b * e - d) / sin2;
    *tB = (e - b * d) / sin2;
    *sinTheta = ub_sqrt(sin2);
    /* the separation is along dA x dB: its length is |w0 . (dA x dB)| / sin */
    float sep = ub_f3_dot(w0, ub_f3_cross(dA, dB));
    return sep * sep / sin2;
}

#endif /* UB_BEAM_GEOMETRY_H */
