/* Plain 3-vector for code shared by host C++ and OpenCL C (see ub_defs.h).
 *
 * ub_float3 is a struct of three floats, 12 bytes with 4-byte alignment on
 * host and device alike. It is deliberately NOT OpenCL's float3, which is
 * 16 bytes and 16-byte aligned, so that it can sit inside shared structs
 * without hidden padding. Host code keeps using ub::Vec3 (same layout) and
 * converts at the boundary.
 */
#ifndef UB_VEC3_H
#define UB_VEC3_H

#include "ub_defs.h"

typedef struct {
    float x, y, z;
} ub_float3;

/* Writes v to out[3i .. 3i+2] (the per-query results of the estimate kernels). */
UB_INLINE void ub_store_f3(UB_GLOBAL float* out, unsigned int i, float x, float y, float z) {
    out[3 * i + 0] = x;
    out[3 * i + 1] = y;
    out[3 * i + 2] = z;
}

UB_INLINE ub_float3 ub_make_float3(float x, float y, float z) {
    ub_float3 r;
    r.x = x;
    r.y = y;
    r.z = z;
    return r;
}
/* The float[3] field of a (private) record as a ub_float3. */
UB_INLINE ub_float3 ub_f3_from(const float v[3]) {
    return ub_make_float3(v[0], v[1], v[2]);
}
/* The same for a record read in place from global memory (the beam kernels' queries). */
UB_INLINE ub_float3 ub_f3_from_global(UB_GLOBAL const float v[3]) {
    return ub_make_float3(v[0], v[1], v[2]);
}
UB_INLINE ub_float3 ub_f3_add(ub_float3 a, ub_float3 b) {
    return ub_make_float3(a.x + b.x, a.y + b.y, a.z + b.z);
}
UB_INLINE ub_float3 ub_f3_sub(ub_float3 a, ub_float3 b) {
    return ub_make_float3(a.x - b.x, a.y - b.y, a.z - b.z);
}
UB_INLINE ub_float3 ub_f3_mul(ub_float3 a, ub_float3 b) {
    return ub_make_float3(a.x * b.x, a.y * b.y, a.z * b.z);
}
UB_INLINE ub_float3 ub_f3_scale(ub_float3 a, float s) {
    return ub_make_float3(a.x * s, a.y * s, a.z * s);
}
UB_INLINE ub_float3 ub_f3_neg(ub_float3 a) {
    return ub_make_float3(-a.x, -a.y, -a.z);
}
UB_INLINE float ub_f3_dot(ub_float3 a, ub_float3 b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
UB_INLINE ub_float3 ub_f3_cross(ub_float3 a, ub_float3 b) {
    return ub_make_float3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
UB_INLINE float ub_f3_length(ub_float3 a) {
    return ub_sqrt(ub_f3_dot(a, a));
}
UB_INLINE ub_float3 ub_f3_normalize(ub_float3 a) {
    return ub_f3_scale(a, 1.0f / ub_f3_length(a));
}

/* Orthonormal basis (s, t) completing the unit vector n to a right-handed
 * frame (s, t, n); Duff et al. 2017, "Building an Orthonormal Basis,
 * Revisited", Listing 3. */
UB_INLINE void ub_f3_basis(ub_float3 n, UB_PRIVATE ub_float3* s, UB_PRIVATE ub_float3* t) {
    float sign = n.z >= 0.0f ? 1.0f : -1.0f;
    float a = -1.0f / (sign + n.z);
    float b = n.x * n.y * a;
    *s = ub_make_float3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
    *t = ub_make_float3(b, sign + n.y * n.y * a, -n.y);
}

#endif /* UB_VEC3_H */
