/* The hashed uniform grid of the point estimators (pp3d, surface merging): cell
 * hashing and the buckets a range query visits, shared by the host build and
 * query (src/estimators/hash_grid.h) and the OpenCL kernels, so that both visit
 * the same photons in the same order. After Teschner et al. 2003, "Optimized
 * Spatial Hashing for Collision Detection of Deformable Objects", as in SmallVCM.
 *
 * Cells have edge 2r; the ball of radius r around a query point lies in the
 * 2x2x2 block of cells nearest to it. Cells hash into cellCount buckets; the
 * points' indices are laid out bucket by bucket (cellEnds[b] is the end of bucket
 * b, its start cellEnds[b-1] or 0).
 */
#ifndef UB_HASH_GRID_H
#define UB_HASH_GRID_H

#include "ub_vec3.h"

typedef struct {
    float lo[3];       /* corner of the points' bounding box */
    float invCellSize; /* 1 / (2 r) */
    float radiusSqr;
    ub_uint cellCount; /* buckets, a power of two (HashGrid::build) */
    ub_uint pad0, pad1;
} ub_hash_grid;

/* Bucket of integer cell (x, y, z) (Teschner et al. 2003), of a power-of-two count. */
UB_INLINE ub_uint ub_hash_cell(ub_hash_grid g, int x, int y, int z) {
    ub_uint h = ((ub_uint)(x)*73856093u) ^ ((ub_uint)(y)*19349663u) ^ ((ub_uint)(z)*83492791u);
    return h & (g.cellCount - 1u);
}

/* Bucket of a point. */
UB_INLINE ub_uint ub_hash_point(ub_hash_grid g, ub_float3 p) {
    return ub_hash_cell(g, (int)ub_floor((p.x - g.lo[0]) * g.invCellSize),
                        (int)ub_floor((p.y - g.lo[1]) * g.invCellSize),
                        (int)ub_floor((p.z - g.lo[2]) * g.invCellSize));
}

/* The distinct buckets of the 2x2x2 block of cells nearest to q (two cells may hash to the
 * same bucket: each is visited once); returns how many (<= 8). */
/* The lowest cell of the 2x2x2 block of cells nearest to q. */
UB_INLINE void ub_hash_block_base(ub_hash_grid g, ub_float3 q, UB_PRIVATE int* base) {
    float d[3];
    d[0] = (q.x - g.lo[0]) * g.invCellSize;
    d[1] = (q.y - g.lo[1]) * g.invCellSize;
    d[2] = (q.z - g.lo[2]) * g.invCellSize;
    UB_UNROLL
    for (int a = 0; a < 3; ++a) {
        float f = ub_floor(d[a]);
        base[a] = (int)f - (d[a] - f < 0.5f ? 1 : 0);
    }
}

UB_INLINE int ub_hash_buckets(ub_hash_grid g, ub_float3 q, UB_PRIVATE ub_uint* buckets) {
    int base[3];
    ub_hash_block_base(g, q, base);
    int nb = 0;
    UB_UNROLL
    for (int k = 0; k < 8; ++k) {
        ub_uint b =
            ub_hash_cell(g, base[0] + (k & 1), base[1] + ((k >> 1) & 1), base[2] + (k >> 2));
        int seen = 0;
        for (int j = 0; j < nb; ++j) seen |= buckets[j] == b;
        if (!seen) buckets[nb++] = b;
    }
    return nb;
}

/* The index ranges [begins[k], ends[k]) of the buckets buckets[0 .. nb - 1] (from
 * ub_hash_buckets) that hold points, in that order; returns how many (<= 8). cellEnds: the
 * end of each bucket in bucket order. Every bucket's bounds are read before any candidate,
 * so that their cache misses overlap rather than each waiting for the previous bucket's
 * candidates (surf kernel about 5% faster on cornell-fog). The kernels call it for a whole
 * work-group at once (ub_hash_ranges_group). */
UB_INLINE int ub_hash_bucket_ranges(UB_PRIVATE const ub_uint* buckets, int nb,
                                    UB_GLOBAL const ub_uint* cellEnds, UB_PRIVATE ub_uint* begins,
                                    UB_PRIVATE ub_uint* ends) {
    int n = 0;
    for (int k = 0; k < nb; ++k) {
        ub_uint b = buckets[k];
        ub_uint begin = b == 0 ? 0u : cellEnds[b - 1], end = cellEnds[b];
        begins[n] = begin;
        ends[n] = end;
        n += begin < end ? 1 : 0;
    }
    return n;
}

/* The candidates of a query at q: the ranges of the distinct buckets of its 2x2x2 block
 * (ub_hash_buckets, then ub_hash_bucket_ranges); returns how many (<= 8). */
UB_INLINE int ub_hash_ranges(ub_hash_grid g, ub_float3 q, UB_GLOBAL const ub_uint* cellEnds,
                             UB_PRIVATE ub_uint* begins, UB_PRIVATE ub_uint* ends) {
    ub_uint buckets[8];
    int nb = ub_hash_buckets(g, q, buckets);
    return ub_hash_bucket_ranges(buckets, nb, cellEnds, begins, ends);
}

#ifdef __OPENCL_C_VERSION__
/* ub_hash_buckets with the eight hashes as one uint8 and each bucket's test against the earlier
 * ones as one comparison and lane mask, without branches: the same buckets in the same order.
 * PoCL ran ub_hash_buckets' loop of up to 28 scalar comparisons, with its data-dependent trip
 * counts, at about a tenth of the surf kernel's time (docs/performance.md, session 34). */
UB_INLINE int ub_hash_buckets8(ub_hash_grid g, ub_float3 q, UB_PRIVATE ub_uint* buckets) {
    int base[3];
    ub_hash_block_base(g, q, base);
    /* ub_hash_cell of cell k = base + (k & 1, k >> 1 & 1, k >> 2), lane k */
    uint8 x = (uint8)((uint)base[0]) + (uint8)(0u, 1u, 0u, 1u, 0u, 1u, 0u, 1u);
    uint8 y = (uint8)((uint)base[1]) + (uint8)(0u, 0u, 1u, 1u, 0u, 0u, 1u, 1u);
    uint8 z = (uint8)((uint)base[2]) + (uint8)(0u, 0u, 0u, 0u, 1u, 1u, 1u, 1u);
    uint8 h = ((x * 73856093u) ^ (y * 19349663u) ^ (z * 83492791u)) & (uint8)(g.cellCount - 1u);
    ub_uint hs[8];
    vstore8(h, 0, hs);
    int nb = 0;
    UB_UNROLL
    for (int k = 0; k < 8; ++k) {
        ub_uint seen = ub_lane_mask8(h == (uint8)(hs[k])) & ((1u << k) - 1u);
        buckets[nb] = hs[k];
        nb += seen == 0u ? 1 : 0;
    }
    return nb;
}

/* ub_hash_ranges for a work-group, every work-item of which must call it (`live` false for
 * one past the queries: it gets no ranges): the buckets of every query, a barrier, the bounds
 * of every bucket, a barrier. No local memory is shared; the barriers make PoCL run each phase
 * for the whole work-group before the next, so the bounds' loads of 64 queries follow each
 * other and their cache misses overlap, where one query at a time waited on its own
 * (kernels/surf.cl; the host twins' HashGrid::blockRanges does the same over blocks). */
UB_INLINE int ub_hash_ranges_group(ub_hash_grid g, ub_float3 q, int live,
                                   UB_GLOBAL const ub_uint* cellEnds, UB_PRIVATE ub_uint* begins,
                                   UB_PRIVATE ub_uint* ends) {
    ub_uint buckets[8];
    int nb = live ? ub_hash_buckets8(g, q, buckets) : 0;
    barrier(CLK_LOCAL_MEM_FENCE);
    int nr = ub_hash_bucket_ranges(buckets, nb, cellEnds, begins, ends);
    barrier(CLK_LOCAL_MEM_FENCE);
    return nr;
}
#endif

/* Whether point p lies within the grid's radius of q: the range test of a query, the host's
 * (HashGrid::query) and the kernels' before they read a candidate's record. */
UB_INLINE int ub_hash_within(ub_hash_grid g, ub_float3 p, ub_float3 q) {
    ub_float3 d = ub_f3_sub(p, q);
    return ub_f3_dot(d, d) <= g.radiusSqr;
}

#endif /* UB_HASH_GRID_H */
