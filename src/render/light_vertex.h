// A stored light-subpath vertex: everything vertex connection (BPT, VCM) and
// vertex merging (PPM, BPM, VCM) need from the light side, as flat data
// (fixed-size scalars, no pointers) so that the same array can later be
// uploaded to OpenCL devices (the surface estimator of UPBP).
//
// The light BSDF is not stored: it is rebuilt from (materialId, dirFix,
// geoNormal, shadingNormal) with Bsdf::setup(..., fromLight = true) when a
// connection needs it. Merging only needs dirFix and continuationProb.
//
// dVCM, dVC, dVM are the MIS partials of the light subpath after the hit
// update at this vertex (kernels/shared/ub_mis.h, tech. rep. (31)-(36)).
//
// Medium vertices (vlt, vbpt): flags has kLightVertexInMedium, materialId holds
// the medium's index into Scene::media (mediumId()), geoNormal, shadingNormal
// and uv are zero, and the scattering function is sigma_s times the
// medium's Henyey-Greenstein phase function (sigma_s is already part of the
// throughput: free-flight sampling weight T sigma_s / pdf, scene/medium.h).
// continuationProb is then the medium's roulette probability at the vertex.
#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "core/vec.h"

namespace ub {

struct LightVertex {
    Vec3 position;           ///< world-space hit point
    uint32_t pathLength;     ///< segments from the light source to this vertex (>= 1)
    Vec3 throughput;         ///< Le cos / p_emit * prod f cos / p, before this vertex's BSDF
    uint32_t materialId;     ///< index into Scene::materials (medium vertex: Scene::media)
    Vec3 dirFix;             ///< unit direction to the previous vertex (towards the light)
    float continuationProb;  ///< Bsdf::continuationProb() of the light BSDF here
    Vec3 geoNormal;          ///< geometric normal as stored on the surface
    float dVCM;              ///< MIS partial [TR (31)/(36)]
    Vec3 shadingNormal;      ///< shading normal as stored on the surface
    float dVC;               ///< MIS partial [TR (32)/(34)]
    float dVM;               ///< MIS partial [TR (33)/(35)]
    uint32_t flags;          ///< kLightVertex* bits
    Vec2 uv;                 ///< surface uv: Scene::setupBsdf looks the textures up here
    float rInL;              ///< medium vertex: R of the photon beam that reached it (UPBP MIS)
    uint32_t pad[3];

    bool inMedium() const { return (flags & kLightVertexInMedium) != 0; }
    /// Medium of a medium vertex (index into Scene::media).
    int mediumId() const { return int(materialId); }
    static constexpr uint32_t kLightVertexInMedium = 1u;  ///< a medium (not surface) vertex
};

// Layout check: the struct is read as raw memory by device code later.
static_assert(std::is_standard_layout<LightVertex>::value, "LightVertex must be flat");
static_assert(std::is_trivially_copyable<LightVertex>::value, "LightVertex must be flat");
static_assert(sizeof(Vec3) == 12, "Vec3 must be three packed floats");
static_assert(sizeof(LightVertex) == 112, "LightVertex layout changed");
static_assert(offsetof(LightVertex, rInL) == 96, "LightVertex layout changed");
static_assert(offsetof(LightVertex, throughput) == 16, "LightVertex layout changed");
static_assert(offsetof(LightVertex, dirFix) == 32, "LightVertex layout changed");
static_assert(offsetof(LightVertex, geoNormal) == 48, "LightVertex layout changed");
static_assert(offsetof(LightVertex, shadingNormal) == 64, "LightVertex layout changed");
static_assert(offsetof(LightVertex, dVM) == 80, "LightVertex layout changed");
static_assert(offsetof(LightVertex, flags) == 84, "LightVertex layout changed");
static_assert(offsetof(LightVertex, uv) == 88, "LightVertex layout changed");

}  // namespace ub
