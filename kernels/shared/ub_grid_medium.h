/* A NanoVDB grid medium along a beam: regular tracking (Novak et al. 2018, Sec. 4.1) by a
 * 3D-DDA through the voxels (Amanatides and Woo 1987), skipping 8^3 blocks without a leaf,
 * in the cell space of scene/medium.h (index space + 1/2: voxel v covers [v, v + 1)), so the
 * pieces are those of the host walk (scene/medium.cpp forEachPiece) and the optical depth
 * is exact: piecewise linear in t. Used by the beam kernels (kernels/beams.cl) through
 * CNanoVDB.h, and by the host (src/estimators/grid_access.h) through NanoVDB's C++
 * accessor; only the voxel fetch differs.
 *
 * The voxel fetch: a type ub_grid_accessor and
 *   float ub_grid_probe(UB_PRIVATE ub_grid_accessor* acc, int i, int j, int k,
 *                       UB_PRIVATE int* inLeaf);
 * returning the density of voxel (i, j, k) and whether a leaf node holds it, and
 *   float ub_grid_leaf_value(UB_PRIVATE const ub_grid_accessor* acc, ub_uint offset);
 * returning voxel `offset` (x * 64 + y * 8 + z within the leaf) of the leaf that the last probe
 * found (only called after a probe that set *inLeaf). OpenCL C: defined
 * below over CNanoVDB.h's read accessor (libnanovdb-dev; embedded with the kernels). Host:
 * src/estimators/grid_access.h defines them over NanoVDB's C++ accessor and then includes
 * this header.
 *
 * The medium is grey in sigma_t (sigma_t = densityScale * density) with a constant RGB
 * albedo; media with an albedo grid or trilinear filtering stay on the host. */
#ifndef UB_GRID_MEDIUM_H
#define UB_GRID_MEDIUM_H

#include "ub_beam_table.h"
#include "ub_grid_dda.h"
#include "ub_medium_homogeneous.h"

#ifdef __OPENCL_C_VERSION__
#include "CNanoVDB.h"
typedef cnanovdb_readaccessor ub_grid_accessor;
/* After a lookup the accessor caches the leaf it descended to (mNode[0]), and clears that
 * slot when the voxel lies outside the cached leaf: so mNode[0] != 0 says "in a leaf". */
UB_INLINE float ub_grid_probe(UB_PRIVATE ub_grid_accessor* acc, int i, int j, int k,
                              UB_PRIVATE int* inLeaf) {
    cnanovdb_coord c;
    c.mVec[0] = i;
    c.mVec[1] = j;
    c.mVec[2] = k;
    const float v = cnanovdb_readaccessor_getValueF(acc, &c);
    *inLeaf = acc->mNode[0] != 0;
    return v;
}
UB_INLINE float ub_grid_leaf_value(UB_PRIVATE const ub_grid_accessor* acc, ub_uint offset) {
    return ((const __global cnanovdb_node0F*)acc->mNode[0])->mVoxels[offset];
}
#elif !defined(UB_HOST_GRID_ACCESSOR)
#error "include src/estimators/grid_access.h, which defines the host's grid accessor"
#endif

/* A grid medium as the kernels see it. 112 bytes. */
typedef struct {
    float worldToCell[12]; /* rows 0-2 of the 4x4 world -> cell-space matrix */
    float densityScale;
    float background; /* density outside the grid's index bounds */
    float albedo[3];
    float g;
    int lo[3]; /* cell-space box [lo, hi) of the grid's index bounds */
    int hi[3];
    ub_uint gridOffset; /* byte offset of the NanoVDB grid in the grid buffer */
    ub_uint pad[3];
} ub_grid_info;

/* The optical depth of [0, tMax] along o + t d (world space, t in world units) and the
 * extinction of its first and last non-empty pieces (at t = 0 and where the walk ends).
 * tMax = 0: no piece; *sigmaTFirst and *sigmaTLast are then the extinction of the piece a
 * walk starting at o would visit first (over [0, firstLength]).
 * pieces (cap entries; 0 with cap 0): the walk's pieces as a table (ub_beam_table.h), as far
 * as they fit; *count: how many pieces the walk visited (more than cap: the table is
 * incomplete). */
UB_INLINE float ub_grid_walk(ub_grid_info g, UB_PRIVATE ub_grid_accessor* acc, ub_float3 o,
                             ub_float3 d, float tMax, float firstLength,
                             UB_PRIVATE float* sigmaTFirst, UB_PRIVATE float* sigmaTLast,
                             UB_PRIVATE ub_beam_piece* pieces, ub_uint cap,
                             UB_PRIVATE ub_uint* count) {
    *count = 0u;
    const int onlyFirst = !(tMax > 0.0f);
    if (onlyFirst) tMax = firstLength;
    float tau = 0.0f;
    int visited = 0;
    const float bgT = g.densityScale * g.background;
    *sigmaTFirst = bgT;
    *sigmaTLast = bgT;
    if (!(tMax > 0.0f)) return 0.0f;
    float P[3], D[3];
    UB_UNROLL
    for (int r = 0; r < 3; ++r) {
        P[r] = g.worldToCell[4 * r] * o.x + g.worldToCell[4 * r + 1] * o.y +
               g.worldToCell[4 * r + 2] * o.z + g.worldToCell[4 * r + 3];
        D[r] = g.worldToCell[4 * r] * d.x + g.worldToCell[4 * r + 1] * d.y +
               g.worldToCell[4 * r + 2] * d.z;
    }
    /* Slab test against the cell box [lo, hi). */
    float tEnter = 0.0f, tExit = tMax, invD[3];
    int step[3];
    UB_UNROLL
    for (int a = 0; a < 3; ++a) {
        step[a] = D[a] > 0.0f ? 1 : (D[a] < 0.0f ? -1 : 0);
        if (step[a] == 0) {
            invD[a] = 0.0f;
            if (P[a] < (float)g.lo[a] || P[a] >= (float)g.hi[a]) tExit = -1.0f;
            continue;
        }
        invD[a] = 1.0f / D[a];
        float t0 = ((float)g.lo[a] - P[a]) * invD[a], t1 = ((float)g.hi[a] - P[a]) * invD[a];
        if (t0 > t1) {
            float s = t0;
            t0 = t1;
            t1 = s;
        }
        tEnter = ub_fmax(tEnter, t0);
        tExit = ub_fmin(tExit, t1);
    }
/* One piece [ta, tb) of extinction st. */
#define UB_GRID_PIECE(ta, tb, st)          \
    {                                      \
        if (!visited) *sigmaTFirst = (st); \
        *sigmaTLast = (st);                \
        visited = 1;                       \
        if (*count < cap) {                \
            pieces[*count].t0 = (ta);      \
            pieces[*count].sigmaT = (st);  \
            pieces[*count].tau0 = tau;     \
        }                                  \
        *count += 1u;                      \
        tau += (st) * ((tb) - (ta));       \
        if (onlyFirst) return 0.0f;        \
    }
    if (!(tEnter < tExit)) {
        UB_GRID_PIECE(0.0f, tMax, bgT)
        return tau;
    }
    if (tEnter > 0.0f) UB_GRID_PIECE(0.0f, tEnter, bgT)
    int v[3];
    UB_UNROLL
    for (int a = 0; a < 3; ++a) {
        int c = (int)ub_floor(P[a] + D[a] * tEnter);
        v[a] = c < g.lo[a] ? g.lo[a] : (c > g.hi[a] - 1 ? g.hi[a] - 1 : c);
    }
    float t = tEnter;
    for (;;) {
        int inLeaf = 0;
        const float density = ub_grid_probe(acc, v[0], v[1], v[2], &inLeaf);
        if (inLeaf) {
            /* In a leaf every step of the loop below is one voxel, and the other axes' voxel
             * indices are clamped to themselves: only the crossed axis changes. So the walk
             * stays here until it leaves the leaf, reads the leaf's values by offset instead
             * of probing, and recomputes only the crossed axis's boundary parameter, with the
             * same operations: the same pieces, bit for bit (tests/medium_test.cpp). */
            int leafLo[3], ended = 0;
            float tb[3], dens = density;
            UB_UNROLL
            for (int a = 0; a < 3; ++a) {
                leafLo[a] = v[a] & ~7;
                tb[a] = step[a] == 0 ? INFINITY : ub_dda_exit(v[a], step[a], P[a], invD[a]);
            }
            for (;;) {
                float tNext;
                const int axis = ub_dda_nearest(tb, tExit, &tNext);
                tNext = ub_fmax(tNext, t);
                if (tNext > t) UB_GRID_PIECE(t, tNext, g.densityScale * dens)
                if (axis < 0) {
                    ended = 1; /* reached tExit inside this voxel */
                    break;
                }
                t = tNext;
                v[axis] += step[axis];
                if (v[axis] < g.lo[axis] || v[axis] >= g.hi[axis]) {
                    ended = 1;
                    break;
                }
                if ((v[axis] & ~7) != leafLo[axis]) break; /* the next voxel is past the leaf */
                tb[axis] = ub_dda_exit(v[axis], step[axis], P[axis], invD[axis]);
                dens = ub_grid_leaf_value(
                    acc, (ub_uint)((v[0] & 7) << 6 | (v[1] & 7) << 3 | (v[2] & 7)));
            }
            if (ended) break;
            continue;
        }
        const int dim = inLeaf ? 1 : 8;
        int blockLo[3];
        UB_UNROLL
        for (int a = 0; a < 3; ++a) blockLo[a] = inLeaf ? v[a] : (v[a] & ~7);
        float tNext = tExit;
        int axis = -1;
        UB_UNROLL
        for (int a = 0; a < 3; ++a) {
            if (step[a] == 0) continue;
            const int boundary = step[a] > 0 ? blockLo[a] + dim : blockLo[a];
            const float tb = ((float)boundary - P[a]) * invD[a];
            if (tb < tNext) {
                tNext = tb;
                axis = a;
            }
        }
        tNext = ub_fmax(tNext, t);
        if (tNext > t) UB_GRID_PIECE(t, tNext, g.densityScale * density)
        if (axis < 0) break; /* reached tExit inside this block */
        t = tNext;
        UB_UNROLL
        for (int b = 0; b < 3; ++b) {
            if (b == axis) continue;
            int c = (int)ub_floor(P[b] + D[b] * t);
            v[b] =
                c < blockLo[b] ? blockLo[b] : (c > blockLo[b] + dim - 1 ? blockLo[b] + dim - 1 : c);
        }
        v[axis] = step[axis] > 0 ? blockLo[axis] + dim : blockLo[axis] - 1;
        if (v[axis] < g.lo[axis] || v[axis] >= g.hi[axis]) break;
    }
    if (tExit < tMax) UB_GRID_PIECE(tExit, tMax, bgT)
#undef UB_GRID_PIECE
    return tau;
}

/* ub_grid_walk without a table. */
UB_INLINE float ub_grid_optical_depth(ub_grid_info g, UB_PRIVATE ub_grid_accessor* acc, ub_float3 o,
                                      ub_float3 d, float tMax, float firstLength,
                                      UB_PRIVATE float* sigmaTFirst, UB_PRIVATE float* sigmaTLast) {
    ub_uint n = 0u;
    return ub_grid_walk(g, acc, o, d, tMax, firstLength, sigmaTFirst, sigmaTLast,
                        (UB_PRIVATE ub_beam_piece*)0, 0u, &n);
}

/* The ub_segment_eval of [0, t] along beam b in grid medium g by a walk from the beam start
 * (as the host's tabulated BeamMedium::eval gives it, ub_grey_segment). */
UB_INLINE ub_segment_eval ub_grid_segment(ub_grid_info g, UB_PRIVATE ub_grid_accessor* acc,
                                          ub_beam b, float t) {
    float sFirst = 0.0f, sLast = 0.0f;
    const float tau = ub_grid_optical_depth(g, acc, ub_f3_from(b.origin), ub_f3_from(b.dir), t,
                                            b.length, &sFirst, &sLast);
    return ub_grey_segment(tau, sFirst, sLast, g.albedo[0], g.albedo[1], g.albedo[2]);
}

/* The medium along beam b from its piece start to t, whatever kind medium m is: the closed
 * form in a homogeneous medium, regular tracking through grid g otherwise (the kernels).
 * mCont: ub_homogeneous_cont_prob(m), computed once per query by the callers. */
UB_INLINE ub_segment_eval ub_beam_segment(ub_medium_info m, float mCont, ub_grid_info g,
                                          UB_PRIVATE ub_grid_accessor* acc, ub_beam b, float t) {
    return m.homogeneous ? ub_homogeneous_segment_cp(m, t, mCont) : ub_grid_segment(g, acc, b, t);
}

/* Photon beam `beam`'s medium at t: the closed form in a homogeneous medium, else from its
 * table in a global buffer (ranges[2 beam], ranges[2 beam + 1]: its first piece in `pieces`
 * and their count; count 0: no table, walk). The range is read only for a grid medium: beams
 * in homogeneous media have no table, and the load per pair cost bb1d's kernel 1-2%
 * (docs/performance.md, session 38). */
UB_INLINE ub_segment_eval ub_photon_beam_segment(ub_medium_info m, float mCont, ub_grid_info g,
                                                 UB_PRIVATE ub_grid_accessor* acc, ub_beam b,
                                                 float t, UB_GLOBAL const ub_beam_piece* pieces,
                                                 UB_GLOBAL const ub_uint* ranges, ub_uint beam) {
    if (m.homogeneous) return ub_homogeneous_segment_cp(m, t, mCont);
    const ub_uint count = ranges[2u * beam + 1u];
    if (count == 0u) return ub_grid_segment(g, acc, b, t);
    float sFirst = 0.0f, sLast = 0.0f;
    const float tau = ub_beam_table_tau_g(pieces + ranges[2u * beam], count, t, &sFirst, &sLast);
    return ub_grey_segment(tau, sFirst, sLast, g.albedo[0], g.albedo[1], g.albedo[2]);
}

/* A query beam's medium at t, its table built in `table` (cap pieces) at the first call:
 * *state is UB_TABLE_UNBUILT before it, then the table's piece count, or UB_TABLE_OVERFLOW
 * when the beam has more than cap pieces (then every call walks from the start). */
UB_INLINE ub_segment_eval ub_query_beam_segment(ub_medium_info m, float mCont, ub_grid_info g,
                                                UB_PRIVATE ub_grid_accessor* acc, ub_beam b,
                                                float t, UB_PRIVATE ub_beam_piece* table,
                                                ub_uint cap, UB_PRIVATE ub_uint* state) {
    if (m.homogeneous) return ub_homogeneous_segment_cp(m, t, mCont);
    if (*state == UB_TABLE_UNBUILT) {
        float sFirst = 0.0f, sLast = 0.0f;
        ub_uint n = 0u;
        ub_grid_walk(g, acc, ub_f3_from(b.origin), ub_f3_from(b.dir), b.length, b.length, &sFirst,
                     &sLast, table, cap, &n);
        *state = n <= cap ? n : UB_TABLE_OVERFLOW;
    }
    if (*state == UB_TABLE_OVERFLOW || *state == 0u) return ub_grid_segment(g, acc, b, t);
    float sFirst = 0.0f, sLast = 0.0f;
    const float tau = ub_beam_table_tau_p(table, *state, t, &sFirst, &sLast);
    return ub_grey_segment(tau, sFirst, sLast, g.albedo[0], g.albedo[1], g.albedo[2]);
}

#ifdef __OPENCL_C_VERSION__
/* The accessor of medium g's grid in the concatenated grid buffer. */
UB_INLINE void ub_grid_accessor_init(UB_PRIVATE ub_grid_accessor* acc,
                                     __global const uchar* gridData, ub_grid_info g) {
    const __global cnanovdb_griddata* grid =
        (const __global cnanovdb_griddata*)(gridData + g.gridOffset);
    cnanovdb_readaccessor_init(acc, cnanovdb_treedata_rootF(cnanovdb_griddata_tree(grid)));
}
#else
#include <cstddef>
static_assert(sizeof(ub_grid_info) == 112, "ub_grid_info layout");
static_assert(offsetof(ub_grid_info, densityScale) == 48, "ub_grid_info layout");
static_assert(offsetof(ub_grid_info, lo) == 72, "ub_grid_info layout");
static_assert(offsetof(ub_grid_info, gridOffset) == 96, "ub_grid_info layout");
#endif

#endif /* UB_GRID_MEDIUM_H */
