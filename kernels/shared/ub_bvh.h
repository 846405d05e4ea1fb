/* The BVH of the beam estimators (src/estimators/bvh.h builds it): its flat node
 * record and the two node tests of a traversal, shared by the host walk and the
 * OpenCL kernels so both visit the same leaves in the same order (depth first,
 * left child first). */
#ifndef UB_BVH_H
#define UB_BVH_H

#include "ub_vec3.h"

/* count > 0: a leaf holding prims[first .. first + count); count == 0: an inner node whose
 * left child is the next node and right child node `first`. 32 bytes. */
typedef struct {
    float lo[3];
    ub_uint first;
    float hi[3];
    ub_uint count;
} ub_bvh_node;

/* A piece of a photon beam diced for the BVH: parameters [t0, t1] of beam `beam`, with a
 * copy of what the pair tests read of the beam (ub_bp2d_pair, ub_bb1d_pair), so that a walk
 * reads its candidates from the parts alone, stored in leaf order (prims is the identity):
 * the full beam is fetched only for the pairs. 48 bytes. */
typedef struct {
    float origin[3];
    float length; /* the beam's */
    float dir[3];
    ub_uint mediumId;
    ub_uint beam;
    float t0, t1;
    ub_uint pathLength;
} ub_beam_part;

UB_INLINE int ub_bvh_contains(ub_bvh_node n, ub_float3 p) {
    return p.x >= n.lo[0] && p.x <= n.hi[0] && p.y >= n.lo[1] && p.y <= n.hi[1] && p.z >= n.lo[2] &&
           p.z <= n.hi[2];
}

/* Slab test of the segment o + t d, t in [0, len], against the node's box (invD = 1 / d per
 * axis). NaN (0 * inf, an origin on a slab plane of a flat box) keeps the interval. */
UB_INLINE int ub_bvh_meets(ub_bvh_node n, ub_float3 o, ub_float3 invD, float len) {
    float t0 = 0.0f, t1 = len;
    float oa[3], ia[3];
    oa[0] = o.x;
    oa[1] = o.y;
    oa[2] = o.z;
    ia[0] = invD.x;
    ia[1] = invD.y;
    ia[2] = invD.z;
    for (int a = 0; a < 3; ++a) {
        float ta = (n.lo[a] - oa[a]) * ia[a], tb = (n.hi[a] - oa[a]) * ia[a];
        if (ta > tb) {
            float s = ta;
            ta = tb;
            tb = s;
        }
        if (ta > t0) t0 = ta;
        if (tb < t1) t1 = tb;
        if (t0 > t1) return 0;
    }
    return 1;
}

/* The photon beam part that counts a pair whose beam parameter is t (each pair once). */
UB_INLINE int ub_beam_part_holds(ub_beam_part p, float t, float beamLength) {
    return !(t < p.t0 || (t >= p.t1 && p.t1 < beamLength));
}

#ifndef __OPENCL_C_VERSION__
#include <cstddef>
static_assert(sizeof(ub_beam_part) == 48, "ub_beam_part layout");
static_assert(offsetof(ub_beam_part, dir) == 16, "ub_beam_part layout");
static_assert(offsetof(ub_beam_part, beam) == 32, "ub_beam_part layout");
static_assert(offsetof(ub_beam_part, pathLength) == 44, "ub_beam_part layout");
#endif

#endif /* UB_BVH_H */
