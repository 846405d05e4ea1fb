// BSDF at a surface point, built from a Material (SmallVCM-style interface,
// extended with GGX microfacet models).
//
// Direction conventions (used everywhere in unibeam):
//  * All directions point AWAY from the surface point.
//  * `dirFix` is the direction towards the previous vertex of the subpath being
//    traced (i.e. -ray.dir of the incoming ray). It is fixed when the BSDF is set up.
//  * `dirGen` is a direction being generated (sampled) or evaluated: towards
//    the next vertex.
//  * On a camera subpath, dirFix points to the camera side, dirGen to the light side;
//    on a light subpath the reverse. `fromLight` records which: it selects the
//    adjoint BSDF for refraction (radiance vs importance; Veach 1997, Sec. 5.2,
//    the (eta_i/eta_t)^2 factor applies only to radiance transport).
//  * Pdfs in solid angle measure (suffix W). directPdfW = p(dirGen | dirFix),
//    reversePdfW = p(dirFix | dirGen). Neither includes Russian roulette.
//  * evaluate() returns f_s (without any cosine); cosThetaGen is |cos| between
//    dirGen and the shading normal.
//  * Shading normals: the shading normal is flipped to the side of dirFix for
//    two-sided opaque materials. For dielectrics the normal's side defines inside
//    (the normal points outside).
//  * Geometric normal guard (details in bsdf.cpp): a reflected dirGen must lie on the
//    same side of the geometric surface as dirFix and a transmitted one on the other
//    side; otherwise evaluate() and pdf() give 0 and sample() fails. It can be switched
//    off (setGeometricGuard(false), ShadingNormals::kShadingOnly: Mitsuba 3, whose BSDFs
//    look at the shading frame only); Scene::setupBsdf does so by the scene's settings.
//    With fromLight,
//    the returned f_s includes Veach's shading-normal adjoint factor (1997, Sec. 5.3)
//    |dirFix.Ns| |dirGen.Ng| / (|dirFix.Ng| |dirGen.Ns|), so callers always use
//    f_s * cosThetaGen (shading cosine) and never apply the correction themselves.
//  * sample() may fail (black, *pdfW = 0) for directions that the lobe proposes but the
//    BSDF does not allow (below the surface, wrong side of the microfacet); pdf() is the
//    density of the successful samples only, and is zero exactly where they cannot land.
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>

#include "core/vec.h"
#include "kernels/shared/ub_bsdf.h"
#include "scene/material.h"

namespace ub {

/// A material's RGB parameters at one surface point: the constants of the Material, or
/// its textures looked up at the hit's uv (Scene::setupBsdf).
struct SurfaceColors {
    Rgb diffuse, glossy, specular, transmittance;
    /// RoughConductor, RoughDielectric: the microfacet roughness along the shading tangent s
    /// and along t (equal: isotropic), textures resolved.
    float alphaU = 0.1f, alphaV = 0.1f;
    /// Principled: its weights at the point (textures resolved).
    PrincipledParams principled;
    /// The material's constants (no textures).
    static SurfaceColors of(const Material& m) {
        return {m.diffuse,       m.glossy, m.specular,
                m.transmittance, m.alpha,  m.alphaV >= 0.0f ? m.alphaV : m.alpha,
                m.principled};
    }
};

/// Precomputes a material's derived data (Plastic: Fdr of the coating; RoughPlastic: the
/// coating transmittance table and internal reflectance). Scene::addMaterial calls it;
/// code that builds a Bsdf from a Material of its own must call it after changing ior or
/// alpha. Cheap for the other types (nothing to do).
void prepareMaterial(Material& m);

/// Which lobe sample() picked (for MIS bookkeeping and debugging).
enum BsdfEvent : uint32_t {
    kEventNone = 0,
    kEventDiffuse = 1,
    kEventGlossy = 2,   ///< Phong lobe, GGX reflection or GGX transmission (rough dielectric:
                        ///< the side of dirGen w.r.t. the geometric normal tells which)
    kEventReflect = 4,  ///< specular (delta) reflection
    kEventRefract = 8,  ///< specular (delta) refraction
    kEventSpecular = kEventReflect | kEventRefract,
    /// Set with kEventRefract by a Blend whose part sampled its null lobe (a thin sheet's or a
    /// mask's straight transmission): Bsdf::isNullEvent then tells it from a refraction.
    kEventNull = 16,
};

class Bsdf {
  public:
    Bsdf() = default;
    /// Sets up the BSDF at a hit. dirFix = -incoming ray direction (unit).
    /// geoNormal/shadingNormal: unit normals as stored on the surface (not flipped).
    /// Returns false (isValid() false) if the configuration is degenerate, e.g. dirFix
    /// grazing the shading hemisphere (|cos| < 1e-6); callers then stop the path.
    bool setup(const Material& mat, const Vec3& dirFix, const Vec3& geoNormal,
               const Vec3& shadingNormal, bool fromLight);
    /// Same, with the RGB parameters and roughness given (textures resolved at the hit); the
    /// Material supplies the type and the other scalar parameters. tangent: the hit's shading
    /// tangent (Hit::tangent), which orients the frame of an anisotropic material (its s axis
    /// is tangent made orthogonal to the shading normal); zero or unused: an arbitrary frame.
    bool setup(const Material& mat, const SurfaceColors& colors, const Vec3& dirFix,
               const Vec3& geoNormal, const Vec3& shadingNormal, bool fromLight,
               const Vec3& tangent = Vec3(0.0f));

    /// f_s(dirFix, dirGen) for the non-delta lobes; 0 for pure delta materials.
    /// Any of the out pointers may be null.
    Rgb evaluate(const Vec3& dirGen, float* cosThetaGen, float* directPdfW,
                 float* reversePdfW) const;
    /// Blend (MaterialType::Blend): this BSDF becomes (1 - w) a + w b of two BSDFs set up at
    /// the same hit with the same dirFix, normals and fromLight (Scene::setupBsdf builds the
    /// parts). Valid if both parts are. Definitions in bsdf.cpp ("Blend").
    bool setupBlend(const Material& mat, float weight, const Bsdf& a, const Bsdf& b);
    bool isBlend() const { return blend_ != nullptr; }
    /// Blend: part i (0: weight 1 - w, 1: weight w) and w.
    const Bsdf& blendPart(int i) const;
    float blendWeight() const { return blendWeight_; }

    /// Samples dirGen from rnd in [0,1)^3 and returns f_s for it. *pdfW is the solid-angle
    /// pdf including lobe selection. For a delta lobe *pdfW is the discrete lobe probability
    /// and the returned value is the lobe weight / |cos|, so f_s * cosThetaGen / pdfW is the
    /// throughput factor in every case. Returns black and *pdfW = 0 if sampling failed.
    /// For a non-delta event, *reversePdfW (if given) is pdf(*dirGen, true), computed by the
    /// same evaluation that gave *pdfW (the bidirectional engine's MIS needs both, and used
    /// to evaluate the BSDF a second time for it). For a delta event it is 0:
    /// the reverse pdf of a delta lobe is the forward one, which the caller knows.
    Rgb sample(const Vec3& rnd, Vec3* dirGen, float* pdfW, float* cosThetaGen,
               uint32_t* sampledEvent, float* reversePdfW = nullptr) const;
    /// Pdf of dirGen given dirFix (reverse=false) or of dirFix given dirGen (reverse=true),
    /// for the non-delta lobes.
    float pdf(const Vec3& dirGen, bool reverse = false) const;

    bool isValid() const { return valid_; }
    /// True if every lobe is a delta (mirror, smooth dielectric, thin dielectric). Plastic
    /// mixes a delta reflection with a diffuse lobe: isDelta() is false, evaluate() and pdf()
    /// cover the diffuse lobe and sample() reports kEventReflect for the delta one.
    bool isDelta() const { return isDelta_; }
    /// True if a lobe continues the ray unchanged, dirGen = -dirFix (Mitsuba 3's Null flag:
    /// the transmission of a ThinDielectric sheet), which DepthCounting::kNonNullVertices
    /// does not count as a vertex.
    bool hasNullLobe() const;
    /// True if sample() reported `event` for that lobe.
    bool isNullEvent(uint32_t event) const {
        if (event & kEventNull) return true;
        return !blend_ && hasNullLobe() && (event & kEventRefract);
    }
    /// Russian-roulette continuation probability: max over RGB of the albedo
    /// estimate, clamped to [0,1] (SmallVCM's mContinuationProb).
    float continuationProb() const { return contProb_; }
    /// |cos| between dirFix and the shading normal.
    float cosThetaFix() const { return std::fabs(localDirFix_.z); }
    const Vec3& shadingNormal() const { return frame_.n; }
    const Material* material() const { return mat_; }
    /// Geometric-normal guard on (default) or off (Mitsuba 3); kept across setup() calls.
    void setGeometricGuard(bool on) {
        geometricGuard_ = on;
        shared_.flags = on ? (shared_.flags | UB_BSDF_GEOMETRIC_GUARD)
                           : (shared_.flags & ~UB_BSDF_GEOMETRIC_GUARD);
    }
    bool geometricGuard() const { return geometricGuard_; }

    /// The evaluation state shared with the kernels (kernels/shared/ub_bsdf.h), filled by
    /// setup(); the surface-merging pass records it. A Blend has none (not evaluable there:
    /// VertexCM::mergeVertices evaluates it through evaluate(), upbp refuses it). coatingTable():
    /// the rough plastic's coating transmittance table that evaluation reads (null for other
    /// materials).
    const ub_bsdf& shared() const { return shared_; }
    const float* coatingTable() const { return coating_; }

  private:
    void setupPlastic();
    void setupMultiLobe();
    /// Fills shared_ from the members (end of setup()).
    void packShared();
    /// Probability of picking the specular lobe of a (rough) plastic seen from a
    /// direction with |cos| = cosTheta (Mitsuba 3's weighting, see bsdf_plastic.cpp).
    float plasticSpecularProb(float cosTheta) const;
    /// Coating transmittance of a (rough) plastic for |cos| = cosTheta.
    float plasticTransmittance(float cosTheta) const;
    Rgb sampleBlend(const Vec3& rnd, Vec3* dirGen, float* pdfW, float* cosThetaGen,
                    uint32_t* sampledEvent, float* reversePdfW) const;
    Rgb sampleDelta(const Vec3& rnd, Vec3* dirGen, float* pdfW, float* cosThetaGen,
                    uint32_t* sampledEvent) const;
    /// Mirror: the conductor Fresnel reflectance at dirFix's angle (1 without
    /// Material::conductorFresnel).
    Rgb mirrorReflectance() const;
    /// The microfacet roughness at this point along frame_.s and frame_.t, clamped to
    /// UB_MIN_GGX_ALPHA as the evaluation clamps it.
    float alphaU() const { return std::max(colors_.alphaU, UB_MIN_GGX_ALPHA); }
    float alphaV() const { return std::max(colors_.alphaV, UB_MIN_GGX_ALPHA); }

    const Material* mat_ = nullptr;
    SurfaceColors colors_;    ///< RGB parameters at this point (textures resolved)
    Frame frame_;             ///< shading frame (normal possibly flipped, see above)
    Vec3 localDirFix_;        ///< dirFix in frame_
    Vec3 geoNormal_;          ///< geometric normal, same side convention as frame_.n
    float cosGeoFix_ = 0.0f;  ///< dot(dirFix, geoNormal_)
    bool fromLight_ = false;
    bool geometricGuard_ = true;     ///< see the banner
    bool perturbed_ = false;         ///< normal- or bump-mapped material (bsdf.cpp's banner)
    float terminatorAlpha2_ = 0.0f;  ///< its shadow-terminator a^2 (0: no factor)
    bool valid_ = false;
    bool isDelta_ = false;
    bool black_ = false;  ///< back side of a one-sided material, or all-black lobes
    float contProb_ = 0.0f;
    // Lobe selection probabilities (Phong: diffuse vs glossy).
    float probDiffuse_ = 0.0f, probGlossy_ = 0.0f;
    float probReflect_ = 0.0f;  ///< MultiLobe: the mirror lobe (the refraction has the rest)
    // Dielectrics: IOR on dirFix's side and on the other side of the interface, and the
    // Fresnel reflectance of the smooth interface seen from dirFix.
    float etaFix_ = 1.0f, etaOther_ = 1.0f;
    float fresnelFix_ = 0.0f;
    // Plastics: weight of the specular lobe in the selection (Mitsuba: s_mean / (d_mean +
    // s_mean)), and the diffuse-base factor rho / (1 - Fint) per channel.
    float specularWeight_ = 0.0f;
    Rgb plasticBase_{0.0f};
    // What evaluate() reads (ub_bsdf_evaluate): the fields above in the shared layout.
    ub_bsdf shared_{};
    const float* coating_ = nullptr;
    // Blend: the two parts (shared: copying a Bsdf stays cheap) and the weight of part 1.
    struct BlendParts;
    std::shared_ptr<const BlendParts> blend_;
    float blendWeight_ = 0.0f;
};

}  // namespace ub
