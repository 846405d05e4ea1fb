/* surf estimate kernel: one work-item per surface query, gathering the surface photons of
 * the hashed grid's buckets around it. All math is kernels/shared/ub_surf.h (the host twin
 * src/estimators/surface_merging.cpp runs the same per-pair function over the same buffers
 * in the same order). out: 3 floats per query, throughput * normalisation * sum. */
#include "ub_hash_grid.h"
#include "ub_medium_homogeneous.h"
#include "ub_surf.h"

/* Arguments: the lookup (photons, grid with its keys, coating tables), then the tail every estimate
 * kernel shares (queries, their count, media (unused here), MIS constants, radius, normalisation,
 * path lengths, results). */
__kernel void ub_surf_estimate(__global const ub_light_vertex* photons,
                               __global const uint* cellEnds, __global const uint* indices,
                               __global const float* keys, ub_hash_grid grid,
                               __global const float* tables,
                               __global const ub_surface_query* queries, uint queryCount,
                               __global const ub_medium_info* media, ub_mis_constants mis,
                               float radius, float normalization, uint minLength, uint maxLength,
                               __global float* out) {
    /* The buckets and their bounds for the whole work-group first (ub_hash_ranges_group, which
     * every work-item joins), then the candidates (cornell-fog, replayed: 0.017-0.019 ->
     * 0.014-0.017 s, docs/performance.md). */
    uint i = get_global_id(0);
    int live = i < queryCount;
    /* The query (240 bytes) and a photon (112 bytes) are copied to private memory only for a
     * photon within the radius: most candidates of a bucket are farther. ub_surf_contribution
     * tests the distance again, the same test as the host twin's grid query. */
    __global const ub_surface_query* gq = queries + (live ? i : 0u);
    ub_float3 qp = ub_make_float3(gq->pos[0], gq->pos[1], gq->pos[2]);
    float r2 = radius * radius;
    ub_surface_query q;
    int loaded = 0;
    ub_uint begins[8], ends[8];
    int nr = ub_hash_ranges_group(grid, qp, live, cellEnds, begins, ends);
    if (!live) return;
    float sx = 0.0f, sy = 0.0f, sz = 0.0f;
    for (int k = 0; k < nr; ++k) {
        for (uint j = begins[k]; j < ends[k]; ++j) {
            float4 key = vload4(j, keys); /* the position, in bucket order (HashGrid::keys) */
            if (!ub_hash_within(grid, ub_make_float3(key.x, key.y, key.z), qp)) continue;
            __global const ub_light_vertex* gp = photons + indices[j];
            if (!loaded) {
                q = *gq;
                loaded = 1;
            }
            ub_light_vertex lv = *gp;
            __global const float* coating =
                tables + UB_ROUGH_PLASTIC_TABLE_SIZE * q.bsdf.tableIndex;
            ub_float3 c = ub_surf_contribution(mis, &lv, &q, coating, r2, minLength, maxLength, 0u);
            sx += c.x;
            sy += c.y;
            sz += c.z;
        }
    }
    float tx = loaded ? q.throughput[0] : 0.0f, ty = loaded ? q.throughput[1] : 0.0f,
          tz = loaded ? q.throughput[2] : 0.0f;
    ub_store_f3(out, i, sx * tx * normalization, sy * ty * normalization, sz * tz * normalization);
}
