/* The BVH of the beam estimators (src/estimators/bvh.h builds it): its flat node
 * record and the node tests of a traversal, shared by the host walk and the OpenCL
 * kernels so both visit the same leaves in the same order.
 *
 * Four children per node, their boxes stored as a structure of arrays in the node itself,
 * so that one node fetch tests all four (the walk is bound by the latency of its node
 * loads: measured, docs/performance.md). Walk order (UB_BVH_WALK_BEGIN in kernels/beams.cl,
 * Bvh::traverse on the host): pop a node; test its four children; visit the primitives of
 * the leaf children that pass, child 0 first; push the inner children that pass, child 3
 * first, so that child 0 is walked next. */
#ifndef UB_BVH_H
#define UB_BVH_H

#include "ub_upbp_records.h"
#include "ub_vec3.h"

/* count[c] == UB_BVH_NONE: no child c; count[c] == 0: child c is the inner node child[c];
 * else child c is a leaf holding prims[child[c] .. child[c] + count[c]). 128 bytes. */
#define UB_BVH_NONE 0xFFFFFFFFu
typedef struct UB_CACHE_ALIGNED {
    float loX[4], loY[4], loZ[4];
    float hiX[4], hiY[4], hiZ[4];
    ub_uint child[4];
    ub_uint count[4];
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

/* The part [t0, t1] of photon beam b, whose index is `beam` (the BVH's parts; a whole beam,
 * t0 = 0 and t1 = b.length, in the screen tiles). */
UB_INLINE ub_beam_part ub_beam_part_of(ub_beam b, ub_uint beam, float t0, float t1) {
    ub_beam_part p;
    UB_UNROLL
    for (int c = 0; c < 3; ++c) {
        p.origin[c] = b.origin[c];
        p.dir[c] = b.dir[c];
    }
    p.length = b.length;
    p.mediumId = b.mediumId;
    p.beam = beam;
    p.t0 = t0;
    p.t1 = t1;
    p.pathLength = b.pathLength;
    return p;
}

/* What a bb1d walk tests first of four consecutive beam parts (in leaf order: parts 4 j ..
 * 4 j + 3 are block j, the last block padded with zeros): their lines and parameter ranges,
 * as a structure of arrays, so one load tests four candidates (ub_beam_lines_near4). The
 * ranges are widened by 1e-5 of their ends, and t1 is +infinity for a beam's last part, which
 * also holds parameters past its end (as ub_beam_part_holds decides): the filter compares
 * products where the pair test divides, OpenCL C lets a float division be off by 2.5 ulp, and
 * a device may round the filter's vector operations and the pair test's scalar ones
 * differently (seen on PoCL when the filter divided too: without the margin the kernel lost
 * pairs at parts' ends, and its bunny bb1d image moved from 5.3e-7 to 1.3e-6 of the host
 * twin's; with it, back to 5.3e-7). 128 bytes. */
typedef struct UB_CACHE_ALIGNED {
    float ox[4], oy[4], oz[4];
    float dx[4], dy[4], dz[4];
    float t0[4], t1[4];
} ub_beam_keys4;

/* Lane j of a block: part p's line and range. */
UB_INLINE void ub_beam_keys4_set(UB_PRIVATE ub_beam_keys4* k, int j, ub_beam_part p) {
    k->ox[j] = p.origin[0];
    k->oy[j] = p.origin[1];
    k->oz[j] = p.origin[2];
    k->dx[j] = p.dir[0];
    k->dy[j] = p.dir[1];
    k->dz[j] = p.dir[2];
    k->t0[j] = p.t0 - 1e-5f * ub_fabs(p.t0);
    k->t1[j] = p.t1 < p.length ? p.t1 + 1e-5f * ub_fabs(p.t1) : INFINITY;
}

/* Bit j set when line j of the block passes within sqrt(radiusSqr) of the line o + t d, the
 * closest point of line j lies in part j's (widened) range, and the query's closest point in
 * [0, queryLength] (widened by 1e-5 of the terms it is the difference of), by the first tests of
 * ub_beam_beam_near (not parallel; separation along d x d_j) and ub_beam_part_holds on its
 * parameter tB = num / sin2, the range compared against num without the division (sin2 >
 * 1e-7 wherever a bit is set; a division is the costliest operation of the test on GPUs, and
 * the margin above covers the different rounding): a candidate it rejects, ub_bb1d_pair
 * rejects. A
 * filter ahead of the pair test, which still decides; the lanes are the caller's to mask.
 * The range test drops the parts next to the one that holds a pair, which share its line:
 * 45% of the candidates the lines alone passed on mirrorballs, 29% on the bunny. The query's
 * range (its numerator the pair test's nA, the same operations) drops the lines that meet the
 * query's line off the query beam: 23% of the candidates left on the bunny, 13% on mirrorballs,
 * each a part record read (docs/performance.md, session 49). */
UB_INLINE ub_uint ub_beam_lines_near4(UB_PRIVATE const ub_beam_keys4* k, ub_float3 o, ub_float3 d,
                                      float queryLength, float radiusSqr) {
    ub_uint mask = 0u;
    UB_UNROLL
    for (int j = 0; j < 4; ++j) {
        ub_float3 oB = ub_make_float3(k->ox[j], k->oy[j], k->oz[j]);
        ub_float3 dB = ub_make_float3(k->dx[j], k->dy[j], k->dz[j]);
        ub_float3 w0 = ub_f3_sub(o, oB);
        float b = ub_f3_dot(d, dB);
        float sin2 = 1.0f - b * b;
        float sep = ub_f3_dot(w0, ub_f3_cross(d, dB));
        float e = ub_f3_dot(dB, w0), dw = ub_f3_dot(d, w0);
        float num = e - b * dw;
        int held = !(num < k->t0[j] * sin2 || num >= k->t1[j] * sin2);
        /* the query's side: its closest point's parameter (times sin2) in [0, queryLength] */
        float qNum = b * e - dw, slack = 1e-5f * (ub_fabs(b * e) + ub_fabs(dw));
        int onQuery = !(qNum < -slack || qNum > queryLength * sin2 * 1.0001f + slack);
        mask |=
            (sin2 > 1e-7f && !(sep * sep > radiusSqr * sin2) && held && onQuery) ? (1u << j) : 0u;
    }
    return mask;
}

/* The lanes of block `block` that hold parts first .. end - 1. */
UB_INLINE ub_uint ub_block_lanes(ub_uint block, ub_uint first, ub_uint end) {
    ub_uint base = block * 4u;
    ub_uint lo = first > base ? first - base : 0u;
    ub_uint hi = end - base < 4u ? end - base : 4u;
    return ((1u << hi) - 1u) & ~((1u << lo) - 1u);
}

/* Bit c set when child c exists and its box contains p. */
UB_INLINE ub_uint ub_bvh_contains(UB_PRIVATE const ub_bvh_node* n, ub_float3 p) {
    ub_uint mask = 0u;
    UB_UNROLL
    for (int c = 0; c < 4; ++c) {
        int in = p.x >= n->loX[c] && p.x <= n->hiX[c] && p.y >= n->loY[c] && p.y <= n->hiY[c] &&
                 p.z >= n->loZ[c] && p.z <= n->hiZ[c] && n->count[c] != UB_BVH_NONE;
        mask |= in ? (1u << c) : 0u;
    }
    return mask;
}

/* One axis of the slab test of a segment against a box, for float or float4 operands (T):
 * narrows [t0, t1] by the parameters where the segment (origin o, 1 / d = inv on this axis)
 * crosses the planes lo and hi. NaN (0 * inf, an origin on a slab plane of a flat box) keeps
 * the interval: the selects pick the other operand when a comparison with NaN is false, and
 * compile to min/max instructions, so the test has no branches. Vector selects are
 * component-wise with the same comparisons, so the float4 form gives the scalar result per
 * lane. */
#define UB_BVH_SLAB(T, lo, hi, o, inv, t0, t1)                                   \
    {                                                                            \
        T ubTa = ((lo) - (o)) * (inv), ubTb = ((hi) - (o)) * (inv);              \
        T ubNear = ubTa > ubTb ? ubTb : ubTa, ubFar = ubTa > ubTb ? ubTa : ubTb; \
        t0 = ubNear > t0 ? ubNear : t0;                                          \
        t1 = ubFar < t1 ? ubFar : t1;                                            \
    }

/* Slab test of the segment o + t d, t in [0, len], against one box (invD = 1 / d per axis):
 * every axis narrows [t0, t1] and one comparison decides. */
UB_INLINE int ub_bvh_box_meets(float loX, float loY, float loZ, float hiX, float hiY, float hiZ,
                               ub_float3 o, ub_float3 invD, float len) {
    float t0 = 0.0f, t1 = len;
    UB_BVH_SLAB(float, loX, hiX, o.x, invD.x, t0, t1)
    UB_BVH_SLAB(float, loY, hiY, o.y, invD.y, t0, t1)
    UB_BVH_SLAB(float, loZ, hiZ, o.z, invD.z, t0, t1)
    return t0 <= t1;
}

/* Bit c set when child c exists and its box meets the segment o + t d, t in [0, len]. */
UB_INLINE ub_uint ub_bvh_meets(UB_PRIVATE const ub_bvh_node* n, ub_float3 o, ub_float3 invD,
                               float len) {
    ub_uint mask = 0u;
    UB_UNROLL
    for (int c = 0; c < 4; ++c) {
        int in = ub_bvh_box_meets(n->loX[c], n->loY[c], n->loZ[c], n->hiX[c], n->hiY[c], n->hiZ[c],
                                  o, invD, len) &&
                 n->count[c] != UB_BVH_NONE;
        mask |= in ? (1u << c) : 0u;
    }
    return mask;
}

#ifdef __OPENCL_C_VERSION__
/* The kernels' ub_bvh_meets: the four children as float4 lanes (UB_BVH_SLAB), read in place
 * from global memory, so the mask equals ub_bvh_meets' bit for bit; written so because PoCL runs a
 * work-item's walk as scalar code and does not vectorise the loop over the children
 * (measured, docs/performance.md). */
UB_INLINE ub_uint ub_bvh_meets_global(__global const ub_bvh_node* n, ub_float3 o, ub_float3 invD,
                                      float len) {
    float4 t0 = (float4)(0.0f), t1 = (float4)(len);
    UB_BVH_SLAB(float4, vload4(0, n->loX), vload4(0, n->hiX), o.x, invD.x, t0, t1)
    UB_BVH_SLAB(float4, vload4(0, n->loY), vload4(0, n->hiY), o.y, invD.y, t0, t1)
    UB_BVH_SLAB(float4, vload4(0, n->loZ), vload4(0, n->hiZ), o.z, invD.z, t0, t1)
    int4 hit = (t0 <= t1) & (vload4(0, n->count) != (uint4)(UB_BVH_NONE));
    return ub_lane_mask4(hit);
}

/* The line filter of ub_beam_lines_near4 on T lanes (float4: one block; float8: two), its
 * comparisons as IT; LOAD(field) gives the lanes of a field of ub_beam_keys4. Sets `near`. */
#define UB_BEAM_LINES_NEAR(T, IT, LOAD, o, d, queryLength, radiusSqr, near)                       \
    {                                                                                             \
        T ubOx = LOAD(ox), ubOy = LOAD(oy), ubOz = LOAD(oz);                                      \
        T ubDx = LOAD(dx), ubDy = LOAD(dy), ubDz = LOAD(dz);                                      \
        T ubB = d.x * ubDx + d.y * ubDy + d.z * ubDz;                                             \
        T ubSin2 = 1.0f - ubB * ubB;                                                              \
        T ubWx = o.x - ubOx, ubWy = o.y - ubOy, ubWz = o.z - ubOz;                                \
        T ubCx = d.y * ubDz - d.z * ubDy, ubCy = d.z * ubDx - d.x * ubDz,                         \
          ubCz = d.x * ubDy - d.y * ubDx;                                                         \
        T ubSep = ubWx * ubCx + ubWy * ubCy + ubWz * ubCz;                                        \
        T ubE = ubDx * ubWx + ubDy * ubWy + ubDz * ubWz;                                          \
        T ubDw = d.x * ubWx + d.y * ubWy + d.z * ubWz;                                            \
        T ubNum = ubE - ubB * ubDw;                                                               \
        IT ubHeld = !(ubNum < LOAD(t0) * ubSin2 || ubNum >= LOAD(t1) * ubSin2);                   \
        T ubQNum = ubB * ubE - ubDw, ubSlack = 1e-5f * (fabs(ubB * ubE) + fabs(ubDw));            \
        IT ubOnQuery = !(ubQNum < -ubSlack || ubQNum > (queryLength)*ubSin2 * 1.0001f + ubSlack); \
        near = (ubSin2 > 1e-7f) & !(ubSep * ubSep > radiusSqr * ubSin2) & ubHeld & ubOnQuery;     \
    }
#define UB_KEYS_LOAD4(field) vload4(0, k->field)
#define UB_KEYS_LOAD8(field) ((float8)(vload4(0, k[0].field), vload4(0, k[1].field)))

/* The kernels' ub_beam_lines_near4: the four lines as float4 lanes, the same operations. */
UB_INLINE ub_uint ub_beam_lines_near4_global(__global const ub_beam_keys4* k, ub_float3 o,
                                             ub_float3 d, float queryLength, float radiusSqr) {
    int4 near;
    UB_BEAM_LINES_NEAR(float4, int4, UB_KEYS_LOAD4, o, d, queryLength, radiusSqr, near)
    return ub_lane_mask4(near);
}

/* Two consecutive blocks k[0], k[1] as float8 lanes, the same operations: bits 0-3 are block
 * k[0]'s mask, bits 4-7 block k[1]'s. On PoCL's AVX2 CPU target a float8 is one register, so two
 * blocks cost about what one did (the host's beamLinesNear8, src/estimators/bb1d_walk.inc). */
UB_INLINE ub_uint ub_beam_lines_near8_global(__global const ub_beam_keys4* k, ub_float3 o,
                                             ub_float3 d, float queryLength, float radiusSqr) {
    int8 near;
    UB_BEAM_LINES_NEAR(float8, int8, UB_KEYS_LOAD8, o, d, queryLength, radiusSqr, near)
    return ub_lane_mask8(near);
}

/* The kernels' ub_bvh_contains, the same way. */
UB_INLINE ub_uint ub_bvh_contains_global(__global const ub_bvh_node* n, ub_float3 p) {
    int4 in = (vload4(0, n->loX) <= p.x) & (vload4(0, n->hiX) >= p.x) & (vload4(0, n->loY) <= p.y) &
              (vload4(0, n->hiY) >= p.y) & (vload4(0, n->loZ) <= p.z) & (vload4(0, n->hiZ) >= p.z) &
              (vload4(0, n->count) != (uint4)(UB_BVH_NONE));
    return ub_lane_mask4(in);
}
#endif

/* The photon beam part that counts a pair whose beam parameter is t (each pair once). */
UB_INLINE int ub_beam_part_holds(ub_beam_part p, float t, float beamLength) {
    return !(t < p.t0 || (t >= p.t1 && p.t1 < beamLength));
}

#ifndef __OPENCL_C_VERSION__
#include <cstddef>
static_assert(sizeof(ub_bvh_node) == 128, "ub_bvh_node layout");
static_assert(offsetof(ub_bvh_node, child) == 96, "ub_bvh_node layout");
static_assert(sizeof(ub_beam_part) == 48, "ub_beam_part layout");
static_assert(sizeof(ub_beam_keys4) == 128, "ub_beam_keys4 layout");
static_assert(offsetof(ub_beam_keys4, dx) == 48, "ub_beam_keys4 layout");
static_assert(offsetof(ub_beam_part, dir) == 16, "ub_beam_part layout");
static_assert(offsetof(ub_beam_part, beam) == 32, "ub_beam_part layout");
static_assert(offsetof(ub_beam_part, pathLength) == 44, "ub_beam_part layout");
#endif

#endif /* UB_BVH_H */
