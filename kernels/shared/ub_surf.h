/* surf: surface photon merging (VCM's vertex merging; Georgiev et al. 2012, "Light
 * transport simulation with vertex connection and merging", and its technical report
 * [TR]), per pair of a surface photon (a stored light-subpath vertex on a surface,
 * ub_light_vertex.h) and a surface query (a camera-subpath vertex on a non-specular
 * surface, recorded by the camera pass), shared by the host twin
 * (src/estimators/surface_merging.cpp) and the OpenCL kernel (kernels/surf.cl).
 *
 * Estimate at the camera vertex z with the photons y within r (disk kernel, [TR (19)]):
 *   L(z) = sum_y f_s(z; w_z, w_y) Phi_y / (N_L pi r^2)
 * pdfs: the camera BSDF sampling w_y (directPdfW, times the camera's continuation
 * probability) and the reverse one (reversePdfW, times the light's), per unit solid angle.
 * MIS: ub_mis_weight_merge [TR (37)-(39)] from the partials stored at the two ends.
 */
#ifndef UB_SURF_H
#define UB_SURF_H

#include "ub_bsdf.h"
#include "ub_light_vertex.h"
#include "ub_mis.h"

/* A surface query: a camera-subpath vertex on a surface with a non-delta lobe, with the BSDF
 * set up there. 240 bytes. */
typedef struct {
    ub_bsdf bsdf; /* set up with dirFix towards the previous camera vertex */
    float pos[3];
    ub_uint pathLength;  /* segments from the camera to this vertex */
    float throughput[3]; /* camera throughput up to the vertex (before its BSDF) */
    ub_uint pixel;       /* y * width + x */
    float dVCM;          /* camera MIS partials after the hit update here [TR (31)-(33)] */
    float dVM;
    float contProb; /* the camera subpath's continuation probability here */
    ub_uint pad0;
} ub_surface_query;

/* 1 / (N_L pi r^2): the disk kernel over N_L light subpaths [TR (19)]. */
UB_INLINE float ub_surf_normalization(float lightPathCount, float radius) {
    return 1.0f / (UB_PI * radius * radius * lightPathCount);
}

/* Whether photon lv and a camera vertex at pos (pathLength segments) make a surf pair:
 * a surface photon inside the disk of radius^2 radiusSqr, the merged path length in
 * [minLength, maxLength]. */
UB_INLINE int ub_surf_pair(UB_PRIVATE const ub_light_vertex* lv, const float* pos,
                           ub_uint pathLength, float radiusSqr, ub_uint minLength,
                           ub_uint maxLength) {
    if (lv->flags & UB_LIGHT_VERTEX_IN_MEDIUM) return 0; /* merged by pp3d and pb2d */
    float dx = lv->position[0] - pos[0], dy = lv->position[1] - pos[1],
          dz = lv->position[2] - pos[2];
    if (dx * dx + dy * dy + dz * dz > radiusSqr) return 0;
    ub_uint length = lv->pathLength + pathLength;
    return length <= maxLength && length >= minLength;
}

/* f Phi_y w of a pair, from the camera BSDF value f towards the photon's incoming direction
 * and its pdfs (forward cameraDirPdfW, reverse cameraRevPdfW), the camera partials
 * (dVCM, dVM) and continuation probability. noMis: PPM, every weight 1. */
UB_INLINE ub_float3 ub_surf_weighted(ub_mis_constants c, UB_PRIVATE const ub_light_vertex* lv,
                                     ub_float3 f, float cameraDirPdfW, float cameraRevPdfW,
                                     float cameraDVCM, float cameraDVM, float cameraContProb,
                                     ub_uint noMis) {
    float weight = 1.0f;
    if (!noMis) {
        ub_mis_partials light, camera;
        light.dVCM = lv->dVCM;
        light.dVC = lv->dVC;
        light.dVM = lv->dVM;
        light.dOut = 0.0f;
        camera = ub_mis_merge_partials(cameraDVCM, cameraDVM);
        /* the reverse direction would be sampled by the light subpath: its roulette */
        weight = ub_mis_weight_merge(c, light, camera, cameraDirPdfW * cameraContProb,
                                     cameraRevPdfW * lv->contProb); /* [TR (37)-(39)] */
    }
    return ub_make_float3(f.x * lv->throughput[0] * weight, f.y * lv->throughput[1] * weight,
                          f.z * lv->throughput[2] * weight);
}

/* f_s Phi_y w for one photon (no camera throughput, no normalisation); zero outside the
 * disk, for medium vertices and for path lengths outside [minLength, maxLength].
 * coating: the query material's rough-plastic coating table (else unused). noMis: PPM, every
 * weight 1. */
UB_INLINE ub_float3 ub_surf_contribution(ub_mis_constants c, UB_PRIVATE const ub_light_vertex* lv,
                                         UB_PRIVATE const ub_surface_query* q,
                                         UB_GLOBAL const float* coating, float radiusSqr,
                                         ub_uint minLength, ub_uint maxLength, ub_uint noMis) {
    ub_float3 zero = ub_make_float3(0.0f, 0.0f, 0.0f);
    float pos[3] = {q->pos[0], q->pos[1], q->pos[2]};
    if (!ub_surf_pair(lv, pos, q->pathLength, radiusSqr, minLength, maxLength)) return zero;
    float cosGen, cameraDirPdfW, cameraRevPdfW;
    /* the camera BSDF towards the photon's incoming direction */
    ub_float3 f = ub_bsdf_evaluate(&q->bsdf, coating, ub_f3_from(lv->dirFix), &cosGen,
                                   &cameraDirPdfW, &cameraRevPdfW);
    if (f.x == 0.0f && f.y == 0.0f && f.z == 0.0f) return zero;
    return ub_surf_weighted(c, lv, f, cameraDirPdfW, cameraRevPdfW, q->dVCM, q->dVM, q->contProb,
                            noMis);
}

#ifndef __OPENCL_C_VERSION__
#include <cstddef>
static_assert(sizeof(ub_surface_query) == 240, "ub_surface_query layout");
static_assert(offsetof(ub_surface_query, pos) == 192, "ub_surface_query layout");
static_assert(offsetof(ub_surface_query, pixel) == 220, "ub_surface_query layout");
static_assert(offsetof(ub_surface_query, contProb) == 232, "ub_surface_query layout");
#endif

#endif /* UB_SURF_H */
