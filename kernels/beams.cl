/* Estimate kernels of the beam estimators: one work-item per query, walking the BVH
 * (kernels/shared/ub_bvh.h) depth first, left child first, as the host twin does
 * (src/estimators/bvh.h), and evaluating each pair with the shared per-estimator math
 * (ub_pb2d.h, ub_bp2d.h, ub_bb1d.h) and the medium along the beam: the closed form in
 * homogeneous media (ub_medium_homogeneous.h), regular tracking through the NanoVDB grid
 * in grid media (ub_grid_medium.h; grids[m] describes medium m's grid in gridData), read from
 * tables (ub_beam_table.h): each photon beam's, built by the host (beamPieces from
 * beamRanges[2 b], beamRanges[2 b + 1] of them; none: walk per pair), and each query beam's,
 * built by its work-item at its first pair in UB_QUERY_PIECES private pieces (a longer beam
 * walks per pair). Grid media with an albedo grid or trilinear filtering run these
 * estimators on the host. out: 3 floats per query. */
/* No contraction of a * b + c into fma: the host twins compute without it (x86-64 baseline), and
 * the candidate tests (ub_pb2d_near4_global, ub_beam_lines_near4_global) then give the host's
 * answers at the radius, where one contracted rounding moved a pair in or out (mirrorballs pb2d:
 * image means 8e-5 apart, docs/performance.md). The runtime puts the pragma on the first line
 * of the program (src/cl/cl_runtime.cpp), ahead of pp3d.cl, which defines the shared headers'
 * functions first; it stays here for a program built from this file alone. */
#pragma OPENCL FP_CONTRACT OFF
#include "ub_bb1d.h"
#include "ub_bp2d.h"
#include "ub_bvh.h"
#include "ub_grid_medium.h"
#include "ub_medium_homogeneous.h"
#include "ub_pb2d.h"
#include "ub_screen_tiles.h"

/* = Bvh::kStackSize (src/estimators/bvh.h), whose build checks that no walk needs more */
#define UB_BVH_STACK 64
/* Pieces of a query beam's private table: long query beams through the bundled VDB smoke
 * cross up to ~100 non-empty pieces (docs/performance.md). A build option may change it. */
#ifndef UB_QUERY_PIECES
#define UB_QUERY_PIECES 128
#endif
/* bb1d's candidates gathered before they are tested (ub_bb1d_flush); kPending of
 * src/estimators/bb1d_estimator.cpp. */
#define UB_BB1D_PENDING 32
/* pb2d's pairs gathered before they are evaluated (ub_pb2d_flush); kPending of
 * src/estimators/pb2d_estimator.cpp. */
#define UB_PB2D_PENDING 32

/* The walk of kernels/shared/ub_bvh.h, in the host twin's order (src/estimators/bvh.h), from
 * ROOT (the query's medium's tree, Bvh::build's groups; none when UB_BVH_NONE): pop a node; MASK
 * (an expression of `n`, the node in global memory) gives the children that pass; the statements
 * between UB_BVH_LEAVES_BEGIN and UB_BVH_LEAVES_END run for those that are leaves, child 0 first,
 * with the leaf's entries leafFirst .. leafEnd - 1 (the items are in the BVH's leaf order,
 * Bvh::permuteToLeafOrder, so a leaf's entries are items, read without an index array), and those
 * between UB_BVH_WALK_BEGIN and UB_BVH_WALK_END for each entry `k` of them (`continue` skips a
 * primitive); then the walk pushes those that are inner nodes, child 3 first. The children come
 * from bit masks, leaves lowest bit first and pushes highest bit first, rather than from a loop
 * over the four with two branches each: 10% off the pb2d walk on cornell-fog, host and kernel alike
 * (docs/performance.md). A begin/end pair rather than one macro taking the block: a block with
 * commas needs a variadic macro, which OpenCL C 1.2 does not have (NVIDIA's compiler rejects it:
 * "variadic macros not supported in OpenCL", seen on an H200, docs/opencl.md). */
#define UB_BVH_LEAVES_BEGIN(nodes, ROOT, MASK)                               \
    {                                                                        \
        uint ubStack[UB_BVH_STACK];                                          \
        int ubTop = 0;                                                       \
        uint ubRoot = (ROOT);                                                \
        if (ubRoot != UB_BVH_NONE) ubStack[ubTop++] = ubRoot;                \
        while (ubTop > 0) {                                                  \
            __global const ub_bvh_node* n = nodes + ubStack[--ubTop];        \
            uint ubMask = (MASK);                                            \
            if (ubMask == 0u) continue;                                      \
            uint ubLeaf = ub_lane_mask4(vload4(0, n->count) != (uint4)(0u)); \
            uint ubInner = ubMask & ~ubLeaf;                                 \
            ubLeaf &= ubMask;                                                \
            while (ubLeaf) {                                                 \
                uint ubC = 31u - clz(ubLeaf & (0u - ubLeaf));                \
                ubLeaf &= ubLeaf - 1u;                                       \
                uint leafFirst = n->child[ubC], leafEnd = leafFirst + n->count[ubC];
#define UB_BVH_LEAVES_END                 \
    }                                     \
    while (ubInner) {                     \
        uint ubC = 31u - clz(ubInner);    \
        ubInner &= ~(1u << ubC);          \
        ubStack[ubTop++] = n->child[ubC]; \
    }                                     \
    }                                     \
    }
/* The walk item by item (`k`) within UB_BVH_LEAVES_BEGIN/END's leaves. */
#define UB_BVH_WALK_BEGIN(nodes, ROOT, MASK) \
    UB_BVH_LEAVES_BEGIN(nodes, ROOT, MASK)   \
    for (uint k = leafFirst; k < leafEnd; ++k) {
#define UB_BVH_WALK_END \
    }                   \
    UB_BVH_LEAVES_END

/* A query's medium, read when its first candidates are evaluated rather than when its
 * work-item starts: most queries of a pass find no pair (the candle's bp2d: 644 pairs for 28,573
 * query points), and the medium record, the 112-byte grid record and the continuation
 * probability cost a walk that finds nothing about as much as its node tests (docs/performance.md,
 * session 36). The host twins read a query's medium lazily too (BeamMedium). */
typedef struct {
    ub_medium_info m;
    ub_grid_info gi;
    ub_grid_accessor acc;
    float mCont;
    int ready;
} ub_query_medium;

static void ub_query_medium_load(ub_query_medium* qm, __global const ub_medium_info* media,
                                 __global const ub_grid_info* grids, __global const uchar* gridData,
                                 uint mediumId) {
    if (qm->ready) return;
    qm->m = media[mediumId];
    qm->mCont = ub_homogeneous_cont_prob(qm->m);
    qm->gi = grids[mediumId];
    if (!qm->m.homogeneous) ub_grid_accessor_init(&qm->acc, gridData, qm->gi);
    qm->ready = 1;
}

/* pb2d's pairs, pending[0 .. np - 1] at beam parameters t[0 .. np - 1] in walk order: the
 * photons' records prefetched (UB_PREFETCH: PoCL's CPU devices; a hint or nothing elsewhere) and
 * their path lengths read, whose loads then overlap their cache misses, then the pairs'
 * contributions in the same order, as the host twin does. */
static void ub_pb2d_flush(__global const ub_photon_point* photons, ub_query_medium* qm,
                          __global const ub_beam* qb, ub_beam_piece* table, ub_uint* tableState,
                          ub_mis_constants mis, float normalization, uint minLength, uint maxLength,
                          const uint* pending, const float* t, int np, float* sum) {
    uint lengths[UB_PB2D_PENDING];
    for (int j = 0; j < np; ++j) UB_PREFETCH(photons + pending[j]);
    for (int j = 0; j < np; ++j) lengths[j] = photons[pending[j]].pathLength;
    /* In a homogeneous medium, the pairs' exponentials in one loop (as bb1d's flush). */
    float T[3 * UB_PB2D_PENDING];
    if (qm->m.homogeneous) ub_homogeneous_transmittances(qm->m, t, np, T);
    for (int j = 0; j < np; ++j) {
        if (!ub_pb2d_length_ok(lengths[j], *qb, minLength, maxLength)) continue;
        ub_photon_point ph = photons[pending[j]];
        ub_segment_eval s = qm->m.homogeneous
                                ? ub_homogeneous_segment_of(qm->m, T + 3 * j, qm->mCont)
                                : ub_query_beam_segment(qm->m, qm->mCont, qm->gi, &qm->acc, *qb,
                                                        t[j], table, UB_QUERY_PIECES, tableState);
        ub_float3 c = ub_pb2d_contribution(mis, ph, *qb, s, t[j], qm->m.g, normalization);
        sum[0] += c.x;
        sum[1] += c.y;
        sum[2] += c.z;
    }
}

/* pb2d: query beams x photon points (BVH over the photons' kernel spheres). */
__kernel void ub_pb2d_estimate(
    __global const ub_photon_point* photons, __global const ub_photon_keys4* keys,
    __global const ub_bvh_node* nodes, __global const uint* roots, __global const uint* tileStart,
    __global const ub_photon_keys4* tileKeys, __global const uint* tileItems, ub_screen_tiles tiles,
    __global const ub_grid_info* grids, __global const uchar* gridData,
    __global const ub_beam* queries, uint queryCount, __global const ub_medium_info* media,
    ub_mis_constants mis, float radius, float normalization, uint minLength, uint maxLength,
    __global float* out) {
    uint i = get_global_id(0);
    if (i >= queryCount) return;
    /* The query beam is read in place (its flush reads the record from global memory), as
     * bb1d's and bp2d's queries are: copied into private memory it stayed on the stack through
     * the walk (docs/performance.md, session 46). */
    __global const ub_beam* qg = queries + i;
    ub_query_medium qm;
    qm.ready = 0;
    ub_float3 o = ub_f3_from_global(qg->origin), d = ub_f3_from_global(qg->dir);
    ub_float3 invD = ub_make_float3(1.0f / d.x, 1.0f / d.y, 1.0f / d.z);
    const float qLength = qg->length, r2 = radius * radius;
    const uint qMedium = qg->mediumId;
    ub_beam_piece table[UB_QUERY_PIECES];
    ub_uint tableState = UB_TABLE_UNBUILT;
    /* A leaf's photons four at a time by their keys, as the host twin does
     * (src/estimators/pb2d_estimator.cpp), the pairs gathered UB_PB2D_PENDING at a time and
     * evaluated in walk order (ub_pb2d_flush). */
    uint pending[UB_PB2D_PENDING];
    float pendingT[UB_PB2D_PENDING];
    float sum[3] = {0.0f, 0.0f, 0.0f};
    int np = 0;
    /* A query on a line through the eye reads its screen tile's photons and the common list
     * (ub_screen_tiles.h) in place of the walk, in the same order as the host twin. */
    int tile = ub_screen_tile_of(tiles, o, d);
    if (tile >= 0) {
        uint lists[2] = {(uint)tile, tiles.tilesX * tiles.tilesY};
        for (int l = 0; l < 2; ++l) {
            uint end = tileStart[lists[l] + 1u];
            for (uint b = tileStart[lists[l]]; b < end; ++b) {
                float t[8];
                uint near = b + 1u < end
                                ? ub_pb2d_near8_global(tileKeys + b, o, d, qLength, qMedium, r2, t)
                                : ub_pb2d_near4_global(tileKeys + b, o, d, qLength, qMedium, r2, t);
                for (; near != 0u; near &= near - 1u) {
                    uint lane = 31u - clz(near & (0u - near));
                    pending[np] = tileItems[b * 4u + lane];
                    pendingT[np++] = t[lane];
                    if (np == UB_PB2D_PENDING) {
                        ub_query_medium_load(&qm, media, grids, gridData, qMedium);
                        ub_pb2d_flush(photons, &qm, qg, table, &tableState, mis, normalization,
                                      minLength, maxLength, pending, pendingT, np, sum);
                        np = 0;
                    }
                }
                if (b + 1u < end) ++b; /* the pair's second block is done */
            }
        }
    } else {
        UB_BVH_LEAVES_BEGIN(nodes, roots[qMedium], ub_bvh_meets_global(n, o, invD, qLength))
        for (uint b = leafFirst / 4u; b * 4u < leafEnd; ++b) {
            /* two blocks at once where the leaf has both (ub_pb2d_near8_global) */
            float t[8];
            uint near;
            if ((b + 1u) * 4u < leafEnd) {
                uint m8 = ub_pb2d_near8_global(keys + b, o, d, qLength, qMedium, r2, t);
                near = (m8 & ub_block_lanes(b, leafFirst, leafEnd)) |
                       ((m8 >> 4) & ub_block_lanes(b + 1u, leafFirst, leafEnd)) << 4;
            } else {
                near = ub_pb2d_near4_global(keys + b, o, d, qLength, qMedium, r2, t) &
                       ub_block_lanes(b, leafFirst, leafEnd);
            }
            for (; near != 0u; near &= near - 1u) {
                uint lane = 31u - clz(near & (0u - near));
                pending[np] = b * 4u + lane;
                pendingT[np++] = t[lane];
                if (np == UB_PB2D_PENDING) {
                    ub_query_medium_load(&qm, media, grids, gridData, qMedium);
                    ub_pb2d_flush(photons, &qm, qg, table, &tableState, mis, normalization,
                                  minLength, maxLength, pending, pendingT, np, sum);
                    np = 0;
                }
            }
            if ((b + 1u) * 4u < leafEnd) ++b; /* the pair's second block is done */
        }
        UB_BVH_LEAVES_END
    }
    if (np > 0) {
        ub_query_medium_load(&qm, media, grids, gridData, qMedium);
        ub_pb2d_flush(photons, &qm, qg, table, &tableState, mis, normalization, minLength,
                      maxLength, pending, pendingT, np, sum);
    }
    ub_store_f3(out, i, sum[0], sum[1], sum[2]);
}

/* bp2d: query points x photon beams (BVH over the diced beam parts). */
__kernel void ub_bp2d_estimate(__global const ub_beam* beams, __global const ub_beam_part* parts,
                               __global const ub_beam_piece* beamPieces,
                               __global const uint* beamRanges, __global const ub_bvh_node* nodes,
                               __global const uint* roots, __global const ub_grid_info* grids,
                               __global const uchar* gridData,
                               __global const ub_query_point* queries, uint queryCount,
                               __global const ub_medium_info* media, ub_mis_constants mis,
                               float radius, float normalization, uint minLength, uint maxLength,
                               __global float* out) {
    uint i = get_global_id(0);
    if (i >= queryCount) return;
    /* The walk reads the query's position and medium only; the record is read where a part is
     * tested. Copying the 64-byte record first kept it in private memory through the walk, whose
     * node tests PoCL then compiled with spills: the candle's bp2d kernel, whose walks visit a
     * few nodes and test about four parts each, ran 415-440 us a pass against 380-400 us now
     * (queue profiling, docs/performance.md, session 45). */
    __global const ub_query_point* qg = queries + i;
    ub_query_medium qm;
    qm.ready = 0;
    ub_float3 p = ub_f3_from_global(qg->pos);
    float sx = 0.0f, sy = 0.0f, sz = 0.0f;
    UB_BVH_WALK_BEGIN(nodes, roots[qg->mediumId], ub_bvh_contains_global(n, p)) {
        ub_beam_part part = parts[k];
        float t = 0.0f;
        ub_query_point q = *qg;
        if (!ub_bp2d_pair(q, part, radius * radius, minLength, maxLength, &t)) continue;
        ub_query_medium_load(&qm, media, grids, gridData, q.mediumId);
        ub_beam pb = beams[part.beam];
        ub_segment_eval s = ub_photon_beam_segment(qm.m, qm.mCont, qm.gi, &qm.acc, pb, t,
                                                   beamPieces, beamRanges, part.beam);
        ub_float3 c = ub_bp2d_contribution(mis, pb, q, s, t, qm.m.g, normalization);
        sx += c.x;
        sy += c.y;
        sz += c.z;
    }
    UB_BVH_WALK_END
    ub_store_f3(out, i, sx, sy, sz);
}

/* bb1d's candidates that passed the four-lane filter, pending[0 .. np - 1] in walk order, in
 * two stages as the host twin handles them (src/estimators/bb1d_estimator.cpp): their parts
 * prefetched (UB_PREFETCH), the pair test of each, whose part reads no longer wait on each other's
 * cache misses, prefetching the photon beam of each pair it accepts, then the contributions of
 * the pairs it accepted, in the same order (the sum is the walk order's). */
static void ub_bb1d_flush(__global const ub_beam* beams, __global const ub_beam_part* parts,
                          __global const ub_beam_piece* beamPieces, __global const uint* beamRanges,
                          ub_query_medium* qm, __global const ub_beam* qb, ub_beam_piece* table,
                          ub_uint* tableState, ub_mis_constants mis, float radius,
                          float normalization, uint minLength, uint maxLength, const uint* pending,
                          int np, float* sum) {
    uint accepted[UB_BB1D_PENDING], beamOf[UB_BB1D_PENDING];
    float tcs[UB_BB1D_PENDING], tls[UB_BB1D_PENDING], sins[UB_BB1D_PENDING];
    for (int j = 0; j < np; ++j) {
        __global const char* part = (__global const char*)(parts + pending[j]);
        UB_PREFETCH(part);
        UB_PREFETCH(part + sizeof(ub_beam_part) - 1); /* a part may straddle two lines */
    }
    for (int j = 0; j < np; ++j) beamOf[j] = parts[pending[j]].beam;
    int nf = 0;
    for (int j = 0; j < np; ++j) {
        float tc = 0.0f, tl = 0.0f, sinTheta = 0.0f;
        if (!ub_bb1d_pair(*qb, parts[pending[j]], radius * radius, minLength, maxLength, &tc, &tl,
                          &sinTheta))
            continue;
        accepted[nf] = beamOf[j];
        UB_PREFETCH(beams + beamOf[j]);
        tcs[nf] = tc;
        tls[nf] = tl;
        sins[nf] = sinTheta;
        ++nf;
    }
    /* Both beams of each pair are in the query's medium: in a homogeneous one, the
     * exponentials of all the pairs in one loop. */
    float Tl[3 * UB_BB1D_PENDING], Tc[3 * UB_BB1D_PENDING];
    if (qm->m.homogeneous) {
        ub_homogeneous_transmittances(qm->m, tls, nf, Tl);
        ub_homogeneous_transmittances(qm->m, tcs, nf, Tc);
    }
    for (int j = 0; j < nf; ++j) {
        uint beam = accepted[j];
        ub_beam pb = beams[beam];
        ub_segment_eval sl, sc;
        if (qm->m.homogeneous) {
            sl = ub_homogeneous_segment_of(qm->m, Tl + 3 * j, qm->mCont);
            sc = ub_homogeneous_segment_of(qm->m, Tc + 3 * j, qm->mCont);
        } else {
            sl = ub_photon_beam_segment(qm->m, qm->mCont, qm->gi, &qm->acc, pb, tls[j], beamPieces,
                                        beamRanges, beam);
            sc = ub_query_beam_segment(qm->m, qm->mCont, qm->gi, &qm->acc, *qb, tcs[j], table,
                                       UB_QUERY_PIECES, tableState);
        }
        ub_float3 c = ub_bb1d_contribution(mis, pb, *qb, sl, sc, tls[j], tcs[j], sins[j], qm->m.g,
                                           normalization);
        sum[0] += c.x;
        sum[1] += c.y;
        sum[2] += c.z;
    }
}

/* bb1d: query beams x photon beams (BVH over the diced beam parts). */
__kernel void ub_bb1d_estimate(
    __global const ub_beam* beams, __global const ub_beam_part* parts,
    __global const ub_beam_keys4* lines, __global const ub_beam_piece* beamPieces,
    __global const uint* beamRanges, __global const ub_bvh_node* nodes, __global const uint* roots,
    __global const uint* tileStart, __global const ub_beam_keys4* tileLines,
    __global const uint* tileParts, __global const ub_beam_part* tileItemParts,
    ub_screen_tiles tiles, __global const ub_grid_info* grids, __global const uchar* gridData,
    __global const ub_beam* queries, uint queryCount, __global const ub_medium_info* media,
    ub_mis_constants mis, float radius, float normalization, uint minLength, uint maxLength,
    __global float* out) {
    uint i = get_global_id(0);
    if (i >= queryCount) return;
    /* The query beam is read in place (its flush reads the record from global memory):
     * copying the 96-byte record into private memory first kept it on the stack through the
     * walk, as bp2d's query did (docs/performance.md, session 45): the bunny's bb1d replay
     * 0.963-0.970 -> 0.988-1.011 of the host twin, three alternating rounds. */
    __global const ub_beam* qg = queries + i;
    ub_query_medium qm;
    qm.ready = 0;
    ub_float3 o = ub_f3_from_global(qg->origin), d = ub_f3_from_global(qg->dir);
    const float qLength = qg->length;
    const uint qMedium = qg->mediumId;
    ub_float3 invD = ub_make_float3(1.0f / d.x, 1.0f / d.y, 1.0f / d.z);
    ub_beam_piece table[UB_QUERY_PIECES];
    ub_uint tableState = UB_TABLE_UNBUILT;
    float sum[3] = {0.0f, 0.0f, 0.0f};
    uint pending[UB_BB1D_PENDING];
    int np = 0;
    /* A query on a line through the eye reads its screen tile's items (whole photon beams, or
     * parts, tileItemParts) and the common list (ub_screen_tiles.h) in place of the walk, in
     * the same order as the host twin. */
    int tile = ub_screen_tile_of(tiles, o, d);
    if (tile >= 0) {
        uint lists[2] = {(uint)tile, tiles.tilesX * tiles.tilesY};
        for (int l = 0; l < 2; ++l) {
            uint end = tileStart[lists[l] + 1u];
            for (uint b = tileStart[lists[l]]; b < end; ++b) {
                uint near =
                    b + 1u < end
                        ? ub_beam_lines_near8_global(tileLines + b, o, d, qLength, radius * radius)
                        : ub_beam_lines_near4_global(tileLines + b, o, d, qLength, radius * radius);
                for (; near != 0u; near &= near - 1u) {
                    pending[np++] = tileParts[b * 4u + (31u - clz(near & (0u - near)))];
                    if (np == UB_BB1D_PENDING) {
                        ub_query_medium_load(&qm, media, grids, gridData, qMedium);
                        ub_bb1d_flush(beams, tileItemParts, beamPieces, beamRanges, &qm, qg, table,
                                      &tableState, mis, radius, normalization, minLength, maxLength,
                                      pending, np, sum);
                        np = 0;
                    }
                }
                if (b + 1u < end) ++b; /* the pair's second block is done */
            }
        }
        if (np > 0) {
            ub_query_medium_load(&qm, media, grids, gridData, qMedium);
            ub_bb1d_flush(beams, tileItemParts, beamPieces, beamRanges, &qm, qg, table, &tableState,
                          mis, radius, normalization, minLength, maxLength, pending, np, sum);
            np = 0;
        }
    } else {
        /* A leaf's candidates four at a time by their lines first, as the host twin does
         * (src/estimators/bb1d_estimator.cpp), gathered and handled UB_BB1D_PENDING at a time. */
        UB_BVH_LEAVES_BEGIN(nodes, roots[qMedium], ub_bvh_meets_global(n, o, invD, qLength))
        for (uint b = leafFirst / 4u; b * 4u < leafEnd; ++b) {
            /* two blocks at once where the leaf has both (ub_beam_lines_near8_global) */
            uint near;
            if ((b + 1u) * 4u < leafEnd) {
                uint m8 = ub_beam_lines_near8_global(lines + b, o, d, qLength, radius * radius);
                near = (m8 & ub_block_lanes(b, leafFirst, leafEnd)) |
                       ((m8 >> 4) & ub_block_lanes(b + 1u, leafFirst, leafEnd)) << 4;
            } else {
                near = ub_beam_lines_near4_global(lines + b, o, d, qLength, radius * radius) &
                       ub_block_lanes(b, leafFirst, leafEnd);
            }
            for (; near != 0u; near &= near - 1u) {
                pending[np++] = b * 4u + (31u - clz(near & (0u - near)));
                if (np == UB_BB1D_PENDING) {
                    ub_query_medium_load(&qm, media, grids, gridData, qMedium);
                    ub_bb1d_flush(beams, parts, beamPieces, beamRanges, &qm, qg, table, &tableState,
                                  mis, radius, normalization, minLength, maxLength, pending, np,
                                  sum);
                    np = 0;
                }
            }
            if ((b + 1u) * 4u < leafEnd) ++b; /* the pair's second block is done */
        }
        UB_BVH_LEAVES_END
    }
    if (np > 0) {
        ub_query_medium_load(&qm, media, grids, gridData, qMedium);
        ub_bb1d_flush(beams, parts, beamPieces, beamRanges, &qm, qg, table, &tableState, mis,
                      radius, normalization, minLength, maxLength, pending, np, sum);
    }
    ub_store_f3(out, i, sum[0], sum[1], sum[2]);
}
