// The scattering function at a vertex of a bidirectional subpath: a surface BSDF
// (scene/bsdf.h) or, at a medium vertex, the Henyey-Greenstein phase function of
// the medium (kernels/shared/ub_phase.h). One type with a tag, so that the
// connection, NEE and light-tracing code of render/vcm*.cpp is written once for
// both kinds of vertex (no virtual calls per sample).
//
// At a medium vertex the "BSDF" of the path integral is sigma_s * phase; sigma_s
// is carried by the free-flight throughput weight T sigma_s / pdf (scene/medium.h),
// so evaluate() and sample() return the phase value alone, cosines are 1 (no
// surface), the phase is its own adjoint (reverse pdf = forward pdf) and never a
// delta. The Russian-roulette probability of a medium vertex is the single-
// scattering albedo max_c sigma_s,c / sigma_t,c at the vertex (as `vpt`), the same
// for light and camera subpaths, as the MIS partials assume.
//
// Directions follow scene/bsdf.h: dirFix towards the previous vertex of the subpath
// being traced, dirGen towards the next one, both pointing away from the vertex.
#pragma once

#include <algorithm>
#include <cstdint>
#include <new>

#include "kernels/shared/ub_phase.h"
#include "render/vcm.h"
#include "scene/bsdf.h"
#include "scene/medium.h"
#include "scene/scene.h"

namespace ub {

/// Single-scattering albedo max_c sigma_s,c / sigma_t,c, clamped to [0, 1] (0 where
/// sigma_t = 0): the Russian-roulette continuation probability at a medium vertex.
inline float mediumContinuationProb(const MediumCoefficients& c) {
    float a = 0.0f;
    for (int i = 0; i < 3; ++i)
        if (c.sigmaT[i] > 0.0f) a = std::max(a, c.sigmaS[i] / c.sigmaT[i]);
    return std::min(a, 1.0f);
}

class VertexScatter {
  public:
    /// Surface vertex at a hit: sets up the BSDF with its textures (Scene::setupBsdf; false
    /// if degenerate or the hit has no material).
    bool setupSurface(const Scene& scene, const Hit& hit, const Vec3& dirFix, bool fromLight) {
        inMedium_ = false;
        if (!scene.setupBsdf(&bsdf_, hit, dirFix, fromLight)) return false;
        contProb_ = vcmContinuationProb(bsdf_);
        return true;
    }
    /// The same from stored vertex data (a light vertex).
    bool setupSurface(const Scene& scene, int materialId, const Vec2& uv, const Rgb& attribute,
                      const Vec3& dirFix, const Vec3& geoNormal, const Vec3& shadingNormal,
                      const Vec3& tangent, bool fromLight) {
        inMedium_ = false;
        if (!scene.setupBsdf(&bsdf_, materialId, uv, attribute, dirFix, geoNormal, shadingNormal,
                             tangent, fromLight))
            return false;
        contProb_ = vcmContinuationProb(bsdf_);
        return true;
    }
    /// Medium vertex with HG parameter g and roulette probability contProb.
    void setupMedium(float g, const Vec3& dirFix, float contProb) {
        inMedium_ = true;
        g_ = g;
        dirFix_ = dirFix;
        contProb_ = contProb;
    }

    bool inMedium() const { return inMedium_; }
    bool isDelta() const { return !inMedium_ && bsdf_.isDelta(); }
    /// A lobe that continues the ray unchanged (Bsdf::hasNullLobe; never in a medium).
    bool hasNullLobe() const { return !inMedium_ && bsdf_.hasNullLobe(); }
    bool isNullEvent(uint32_t event) const { return !inMedium_ && bsdf_.isNullEvent(event); }
    /// |cos| at the vertex of the segment to the previous vertex (1 in a medium).
    float cosThetaFix() const { return inMedium_ ? 1.0f : bsdf_.cosThetaFix(); }
    /// Russian-roulette continuation probability of the bidirectional engine here.
    float continuationProb() const { return contProb_; }
    const Bsdf& bsdf() const { return bsdf_; }

    /// f (BSDF value, or phase value) for dirGen; pdfs without roulette, as Bsdf::evaluate.
    Rgb evaluate(const Vec3& dirGen, float* cosThetaGen, float* directPdfW,
                 float* reversePdfW) const {
        if (!inMedium_) return bsdf_.evaluate(dirGen, cosThetaGen, directPdfW, reversePdfW);
        const float p = ub_hg_pdf(f3(dirFix_), f3(dirGen), g_);
        if (cosThetaGen) *cosThetaGen = 1.0f;
        if (directPdfW) *directPdfW = p;
        if (reversePdfW) *reversePdfW = p;
        return Rgb(p);
    }
    /// Samples dirGen; as Bsdf::sample (value * cos / pdf is the throughput factor, and
    /// *reversePdfW is pdf(*dirGen, true) for a non-delta event).
    Rgb sample(const Vec3& rnd, Vec3* dirGen, float* pdfW, float* cosThetaGen,
               uint32_t* sampledEvent, float* reversePdfW) const {
        if (!inMedium_)
            return bsdf_.sample(rnd, dirGen, pdfW, cosThetaGen, sampledEvent, reversePdfW);
        ub_float3 w = ub_hg_sample(f3(dirFix_), g_, rnd.x, rnd.y, pdfW);
        *dirGen = normalize(Vec3(w.x, w.y, w.z));
        // pdf(*dirGen, true) recomputes the pdf from the normalised direction; so does this.
        *reversePdfW = ub_hg_pdf(f3(dirFix_), f3(*dirGen), g_);
        *cosThetaGen = 1.0f;
        *sampledEvent = kEventDiffuse;  // any non-specular event
        return Rgb(*pdfW);
    }
    /// Pdf of dirGen (or, reverse, of dirFix given dirGen), without roulette.
    float pdf(const Vec3& dirGen, bool reverse = false) const {
        if (!inMedium_) return bsdf_.pdf(dirGen, reverse);
        return ub_hg_pdf(f3(dirFix_), f3(dirGen), g_);
    }

  private:
    static ub_float3 f3(const Vec3& v) { return ub_make_float3(v.x, v.y, v.z); }

    bool inMedium_ = false;
    Bsdf bsdf_;
    float g_ = 0.0f;
    Vec3 dirFix_;
    float contProb_ = 0.0f;
};

/// The scattering functions of one light subpath's vertices, each set up at its first
/// connection and reused by the camera subpath's later vertices. A camera vertex connects to
/// every vertex of the light subpath with the same index, so without this each surface light
/// vertex's BSDF, with its texture lookups, was set up again for every camera vertex. One per
/// camera subpath; vertices past kSlots share one more slot, set up for each connection.
class LightScatterCache {
  public:
    static constexpr uint32_t kSlots = 16;
    LightScatterCache() {}
    LightScatterCache(const LightScatterCache&) = delete;
    LightScatterCache& operator=(const LightScatterCache&) = delete;
    ~LightScatterCache() {
        for (uint32_t k = 0; k <= kSlots; ++k)
            if (state_[k] != kUnset) slot(k)->~VertexScatter();
    }
    /// The scattering function of lv, the k-th stored vertex of its light subpath, or null
    /// where it has none (a degenerate surface configuration, as setupSurface decides).
    const VertexScatter* get(const Scene& scene, const LightVertex& lv, uint32_t k) {
        if (k >= kSlots) {
            k = kSlots;
            if (state_[k] != kUnset) slot(k)->~VertexScatter();
            state_[k] = kUnset;
        }
        if (state_[k] == kUnset)
            state_[k] = setup(scene, lv, new (storage_[k]) VertexScatter()) ? kReady : kNone;
        return state_[k] == kReady ? slot(k) : nullptr;
    }

  private:
    enum : uint8_t { kUnset, kReady, kNone };
    static bool setup(const Scene& scene, const LightVertex& lv, VertexScatter* s) {
        if (lv.inMedium()) {
            s->setupMedium(scene.media[size_t(lv.mediumId())].g, lv.dirFix3(), lv.contProb);
            return true;
        }
        return s->setupSurface(scene, int(lv.materialId), lv.uv2(), lv.attribute3(), lv.dirFix3(),
                               lv.geoNormal3(), lv.shadingNormal3(), lv.tangent3(),
                               /*fromLight=*/true);
    }
    VertexScatter* slot(uint32_t k) {
        return std::launder(reinterpret_cast<VertexScatter*>(storage_[k]));
    }
    alignas(VertexScatter) unsigned char storage_[kSlots + 1][sizeof(VertexScatter)];
    uint8_t state_[kSlots + 1] = {};
};

}  // namespace ub
