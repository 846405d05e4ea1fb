/* A stored light-subpath vertex: everything vertex connection (bpt) and surface
 * merging (surf) need from the light side, shared by the host (which writes it in
 * the light pass) and device code. 112 bytes.
 *
 * Fixed-size scalars only (float, ub_uint), float[3] instead of float3 (whose
 * OpenCL size is 16), explicit padding; the host checks size and offsets below.
 *
 * The light BSDF is not stored: the host rebuilds it from (materialId, dirFix,
 * geoNormal, shadingNormal, uv, attribute, tangent) when a connection needs it. Merging only needs
 * dirFix and contProb.
 *
 * dVCM, dVC, dVM are the MIS partials of the light subpath after the hit update
 * at this vertex (ub_mis.h; VCM tech. rep. (31)-(36)).
 *
 * Medium vertices (vlt, vbpt, upbp): flags has UB_LIGHT_VERTEX_IN_MEDIUM,
 * materialId holds the medium's index, geoNormal, shadingNormal, uv, attribute and tangent
 * are zero,
 * and the scattering function is sigma_s times the medium's phase function
 * (sigma_s is already part of the throughput). contProb is then the medium's
 * roulette probability at the vertex, and rInL the R (a length, ub_mis_volume.h)
 * of the photon beam that reached it.
 */
#ifndef UB_LIGHT_VERTEX_H
#define UB_LIGHT_VERTEX_H

#include "ub_defs.h"

#define UB_LIGHT_VERTEX_IN_MEDIUM 1u /* a medium (not surface) vertex */

typedef struct {
    float position[3];      /* world-space vertex */
    ub_uint pathLength;     /* segments from the light source to this vertex (>= 1) */
    float throughput[3];    /* Le cos / p_emit * prod f cos / p, before this vertex's BSDF */
    ub_uint materialId;     /* index of the material (medium vertex: of the medium) */
    float dirFix[3];        /* unit direction to the previous vertex (towards the light) */
    float contProb;         /* continuation probability of the light subpath here */
    float geoNormal[3];     /* geometric normal as stored on the surface */
    float dVCM;             /* MIS partial [TR (31)/(36)] */
    float shadingNormal[3]; /* shading normal as stored on the surface */
    float dVC;              /* MIS partial [TR (32)/(34)] */
    float dVM;              /* MIS partial [TR (33)/(35)] */
    ub_uint flags;          /* UB_LIGHT_VERTEX_* bits */
    float uv[2];            /* surface uv, where the textures are looked up */
    float rInL;             /* medium vertex: R of the photon beam that reached it */
    float attribute[3];     /* the surface's mesh attribute value (Hit::attribute), or 0 */
    float tangent[3];       /* shading tangent (Hit::tangent): orients anisotropic BSDFs, or 0 */
    ub_uint pad;
} ub_light_vertex;

#ifndef __OPENCL_C_VERSION__
#include <cstddef>
static_assert(sizeof(ub_light_vertex) == 128, "ub_light_vertex layout");
static_assert(offsetof(ub_light_vertex, throughput) == 16, "ub_light_vertex layout");
static_assert(offsetof(ub_light_vertex, dirFix) == 32, "ub_light_vertex layout");
static_assert(offsetof(ub_light_vertex, geoNormal) == 48, "ub_light_vertex layout");
static_assert(offsetof(ub_light_vertex, shadingNormal) == 64, "ub_light_vertex layout");
static_assert(offsetof(ub_light_vertex, dVM) == 80, "ub_light_vertex layout");
static_assert(offsetof(ub_light_vertex, flags) == 84, "ub_light_vertex layout");
static_assert(offsetof(ub_light_vertex, uv) == 88, "ub_light_vertex layout");
static_assert(offsetof(ub_light_vertex, rInL) == 96, "ub_light_vertex layout");
static_assert(offsetof(ub_light_vertex, attribute) == 100, "ub_light_vertex layout");
static_assert(offsetof(ub_light_vertex, tangent) == 112, "ub_light_vertex layout");
#endif

#endif /* UB_LIGHT_VERTEX_H */
