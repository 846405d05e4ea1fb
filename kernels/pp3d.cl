/* pp3d estimate kernel: one work-item per query point, gathering the photon points of
 * the hashed grid's buckets around it. All math is kernels/shared/ub_pp3d.h (the host twin
 * src/estimators/pp3d_estimator.cpp runs the same per-pair function over the same buffers
 * in the same order). out: 3 floats per query. */
#include "ub_bvh.h"
#include "ub_hash_grid.h"
#include "ub_medium_homogeneous.h"
#include "ub_pp3d.h"
#include "ub_surf.h"

/* Arguments: the lookup (photons, grid with its keys), then the tail every estimate kernel shares
 * (queries, their count, media, MIS constants, radius, normalisation, path lengths, results). */
__kernel void ub_pp3d_estimate(__global const ub_photon_point* photons,
                               __global const uint* cellEnds, __global const uint* indices,
                               __global const float* keys, ub_hash_grid grid,
                               __global const ub_query_point* queries, uint queryCount,
                               __global const ub_medium_info* media, ub_mis_constants mis,
                               float radius, float normalization, uint minLength, uint maxLength,
                               __global float* out) {
    /* The buckets and their bounds for the whole work-group first, as kernels/surf.cl does
     * (cornell-fog, replayed: 0.0054-0.0065 -> 0.0049 s). */
    uint i = get_global_id(0);
    int live = i < queryCount;
    __global const ub_query_point* gq = queries + (live ? i : 0u);
    ub_float3 qp = ub_make_float3(gq->pos[0], gq->pos[1], gq->pos[2]);
    ub_uint begins[8], ends[8];
    int nr = ub_hash_ranges_group(grid, qp, live, cellEnds, begins, ends);
    if (!live) return;
    ub_query_point q = *gq;
    float g = media[q.mediumId].g;
    float sx = 0.0f, sy = 0.0f, sz = 0.0f;
    for (int k = 0; k < nr; ++k) {
        for (uint j = begins[k]; j < ends[k]; ++j) {
            /* The distance first, from the position in bucket order (HashGrid::keys), as the
             * host's HashGrid::query does: most candidates end there, and the 80-byte record
             * is read only for the others (ub_pp3d_contribution tests it again). */
            float4 key = vload4(j, keys);
            if (!ub_hash_within(grid, ub_make_float3(key.x, key.y, key.z), qp)) continue;
            ub_photon_point ph = photons[indices[j]];
            ub_float3 c = ub_pp3d_contribution(mis, ph, q, g, radius * radius, normalization,
                                               minLength, maxLength);
            sx += c.x;
            sy += c.y;
            sz += c.z;
        }
    }
    ub_store_f3(out, i, sx, sy, sz);
}

/* Layout probe: the device's sizes and offsets of the shared records, compared with the
 * host's at start-up (src/cl/cl_runtime.cpp): a mismatch is an error, never garbage. */
__kernel void ub_layout_probe(__global uint* out) {
    ub_photon_point ph;
    ub_query_point q;
    ub_beam b;
    out[0] = (uint)sizeof(ub_photon_point);
    out[1] = (uint)sizeof(ub_query_point);
    out[2] = (uint)sizeof(ub_beam);
    out[3] = (uint)sizeof(ub_hash_grid);
    out[4] = (uint)sizeof(ub_mis_constants);
    out[5] = (uint)((__private char*)&ph.dVCM - (__private char*)&ph);
    out[6] = (uint)((__private char*)&q.pixel - (__private char*)&q);
    out[7] = (uint)((__private char*)&b.fwdPassBefore - (__private char*)&b);
    ub_surface_query s;
    out[8] = (uint)sizeof(ub_light_vertex);
    out[9] = (uint)sizeof(ub_surface_query);
    out[10] = (uint)((__private char*)&s.bsdf.tableIndex - (__private char*)&s);
    out[11] = (uint)((__private char*)&s.pixel - (__private char*)&s);
    ub_beam_part part;
    out[12] = (uint)sizeof(ub_beam_part);
    out[13] = (uint)((__private char*)&part.pathLength - (__private char*)&part);
    ub_bvh_node node;
    out[14] = (uint)sizeof(ub_bvh_node);
    out[15] = (uint)((__private char*)&node.child - (__private char*)&node);
    ub_photon_keys4 keys;
    out[16] = (uint)sizeof(ub_photon_keys4);
    out[17] = (uint)((__private char*)&keys.mediumId - (__private char*)&keys);
    ub_beam_keys4 lines;
    out[18] = (uint)sizeof(ub_beam_keys4);
    out[19] = (uint)((__private char*)&lines.dx - (__private char*)&lines);
}

#ifdef UB_FORCE_BUILD_ERROR
#error "build failure forced by -DUB_FORCE_BUILD_ERROR (tests/opencl_estimate_test.cpp)"
#endif
