// Materials as flat data with a type tag (no virtual calls per sample).
// The BSDF built from a material at a hit is in scene/bsdf.h.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "core/vec.h"

namespace ub {

enum class MaterialType : uint32_t {
    Diffuse = 0,  ///< Lambertian, reflectance `diffuse`
    Phong = 1,    ///< SmallVCM model: Lambert `diffuse` + modified Phong lobe `glossy`, `exponent`
    Mirror = 2,   ///< specular reflection scaled by `specular` (x the conductor Fresnel term
                  ///< of `eta`, `k` when `conductorFresnel`)
    Dielectric = 3,  ///< smooth glass: Fresnel reflection + refraction, `ior`, tint `specular`
    RoughConductor =
        4,  ///< GGX microfacet conductor: `eta`, `k` (RGB), roughness `alpha`, tint `specular`
    RoughDielectric =
        5,  ///< GGX microfacet dielectric (Walter et al. 2007): `ior`, `alpha`, tint `specular`
    Plastic = 6,  ///< Mitsuba 3 `plastic`: smooth coating (`ior` = int/ext) over Lambert `diffuse`
    RoughPlastic = 7,    ///< Mitsuba 3 `roughplastic`: GGX coating (`alpha`) over Lambert `diffuse`
    ThinDielectric = 8,  ///< Mitsuba 3 `thindielectric`: delta reflection `specular` + straight
                         ///< transmission `transmittance`; `ior` of the sheet
    MultiLobe = 9,    ///< SmallUPBP's sum of lobes: Lambert `diffuse` + Phong `glossy`/`exponent` +
                      ///< mirror `specular` (Fresnel-weighted with `refract`) + smooth untinted
                      ///< refraction with `ior` when `refract` (scene/bsdf.cpp)
    Blend = 10,       ///< Mitsuba 3 `blendbsdf` (and `mask`): (1 - w) f_a + w f_b of the materials
                      ///< `blendParts`, w = `blendWeight` or the texture `textures.weight`
                      ///< (scene/bsdf.cpp; not on the OpenCL device nor in upbp's batch pass)
    Principled = 11,  ///< Mitsuba 3 `principled` (kernels/shared/ub_principled.h): base colour
                      ///< `diffuse`, roughness `alpha` (both texturable), `ior` = eta, the
                      ///< other weights in `principled`
    PrincipledThin = 12,  ///< Mitsuba 3 `principledthin` (kernels/shared/ub_principled_thin.h):
                          ///< as Principled; a sheet of no thickness, the same from both sides
};

/// Mitsuba 3's `principled` parameters other than base colour (Material::diffuse), roughness
/// (Material::alpha, not squared: the BSDF maps it) and eta (Material::ior); its defaults.
struct PrincipledParams {
    float anisotropic = 0.0f, metallic = 0.0f, specTrans = 0.0f, specTint = 0.0f;
    float sheen = 0.0f, sheenTint = 0.0f, flatness = 0.0f;
    float clearcoat = 0.0f, clearcoatGloss = 0.0f;
    /// PrincipledThin: the diffuse transmission, in [0, 2] as Mitsuba's diff_trans.
    float diffTrans = 0.0f;
    /// diffuse_reflectance_sampling_rate, main_specular_sampling_rate (PrincipledThin:
    /// specular_reflectance_sampling_rate), clearcoat_sampling_rate; PrincipledThin's
    /// specular_transmittance_sampling_rate and diffuse_transmittance_sampling_rate.
    float rateDiffuse = 1.0f, rateSpecular = 1.0f, rateClearcoat = 1.0f;
    float rateSpecTrans = 1.0f, rateDiffTrans = 1.0f;
    /// The ten weights above in order (anisotropic ... diffTrans), for textures.
    static constexpr int kWeights = 10;
    float& weight(int i) {
        float* w[kWeights] = {&anisotropic, &metallic, &specTrans, &specTint,       &sheen,
                              &sheenTint,   &flatness, &clearcoat, &clearcoatGloss, &diffTrans};
        return *w[i];
    }
    float weight(int i) const { return const_cast<PrincipledParams*>(this)->weight(i); }
    /// Mitsuba's names of the weights, in weight() order.
    static const char* weightName(int i) {
        static const char* names[kWeights] = {
            "anisotropic", "metallic", "spec_trans", "spec_tint",       "sheen",
            "sheen_tint",  "flatness", "clearcoat",  "clearcoat_gloss", "diff_trans"};
        return names[i];
    }
};

/// Textured RGB parameters of a material, in Scene::textures (-1: the constant is used).
struct MaterialTextures {
    int diffuse = -1;        ///< replaces Material::diffuse
    int glossy = -1;         ///< replaces Material::glossy
    int specular = -1;       ///< replaces Material::specular
    int transmittance = -1;  ///< replaces Material::transmittance
    int weight = -1;         ///< Blend: replaces Material::blendWeight (the texture's luminance)
    /// RoughConductor, RoughDielectric: replace Material::alpha and Material::alphaV (the
    /// texture's luminance, Mitsuba's float textures). alphaV -1 with alpha >= 0: isotropic.
    int alpha = -1;
    int alphaV = -1;
    /// Principled: textures of its weights, in PrincipledParams::weight order (the
    /// texture's luminance, Mitsuba's float textures).
    std::array<int, PrincipledParams::kWeights> principled{-1, -1, -1, -1, -1, -1, -1, -1, -1, -1};
};

/// Mitsuba 3's `normalmap` and `bumpmap` wrappers: the shading normal of a hit perturbed by a
/// texture (scene/normal_perturbation.h; Scene::intersect applies it).
enum class NormalPerturbation : uint32_t {
    kNone = 0,
    kNormalMap = 1,  ///< RGB texel c -> tangent-space normal 2 c - 1 in the frame (dpdu, n)
    kBumpMap = 2,    ///< height field: `bumpScale` x the uv gradient of the texel luminance
};

/// Microfacet normal distribution of the rough materials (kernels/shared/ub_microfacet.h).
enum class MicrofacetDistribution : uint32_t {
    kGgx = 0,       ///< GGX / Trowbridge-Reitz (unibeam's default)
    kBeckmann = 1,  ///< Beckmann (Mitsuba 3's default)
};

struct Material {
    MaterialType type = MaterialType::Diffuse;
    std::string name;
    Rgb diffuse{0.5f, 0.5f, 0.5f};  ///< Diffuse, Phong
    Rgb glossy{0, 0, 0};            ///< Phong lobe reflectance
    float exponent = 1.0f;          ///< Phong exponent (> 0)
    Rgb specular{1, 1, 1};          ///< Mirror / Dielectric / Rough* tint
    float ior = 1.5f;               ///< Dielectric, RoughDielectric: interior / exterior IOR
    Rgb eta{0.2f, 0.92f, 1.1f};  ///< RoughConductor, Mirror with conductorFresnel: real part of the
                                 ///< complex IOR (default: copper)
    Rgb k{3.9f, 2.45f, 2.14f};   ///< RoughConductor: imaginary part
    /// Mirror: multiply the reflection by the conductor Fresnel reflectance of eta + i k at
    /// the angle of incidence (Mitsuba's smooth `conductor`); false: a perfect mirror.
    bool conductorFresnel = false;
    /// Microfacet roughness (alpha = roughness^2 convention NOT used: alpha as given); for an
    /// anisotropic RoughConductor or RoughDielectric the roughness along the shading tangent s
    /// (Mitsuba's alpha_u: s is dp/du made orthogonal to the shading normal, Hit::tangent).
    float alpha = 0.1f;
    /// RoughConductor, RoughDielectric: the roughness along t = n x s (Mitsuba's alpha_v);
    /// negative: isotropic (alpha in every direction). RoughPlastic is always isotropic.
    float alphaV = -1.0f;
    /// RoughConductor, RoughDielectric reflection: Smith masking-shadowing G2 separable,
    /// G1(i) G1(o) (Mitsuba 3's choice; Walter 2007 eq. 23), instead of the default
    /// height-correlated 1 / (1 + Lambda(i) + Lambda(o)) (Heitz 2014 eq. 99). Refraction
    /// and RoughPlastic always use the separable form.
    bool separableMasking = false;
    /// RoughConductor, RoughDielectric, RoughPlastic: the microfacet distribution (`alpha` is
    /// its roughness: the RMS slope for Beckmann, as in Mitsuba).
    MicrofacetDistribution distribution = MicrofacetDistribution::kGgx;
    /// Two-sided: if true (default for opaque materials), the back side of a surface
    /// behaves like the front. Dielectrics ignore it: their inside is defined by the normal.
    /// Principled: false (its back side is the inside of its transmission lobe, as in
    /// Mitsuba) unless wrapped in Mitsuba's `twosided`.
    /// ThinDielectric ignores it too: the sheet is the same from both sides.
    bool twoSided = true;
    Rgb transmittance{1, 1, 1};   ///< ThinDielectric: tint of the transmitted light
    PrincipledParams principled;  ///< Principled
    /// MultiLobe: a refraction lobe with `ior` (SmallUPBP's ior >= 0); without it the mirror
    /// lobe has Fresnel weight 1 (SmallUPBP's ior < 0).
    bool refract = false;
    /// Plastic, RoughPlastic: Mitsuba's `nonlinear` (base albedo inside the internal
    /// scattering sum, darker and more saturated colours); false keeps texture colours.
    bool nonlinear = false;
    /// Blend: the material ids of the two components (f = (1 - w) f_a + w f_b), and the
    /// weight w in [0, 1] of the second one. A mask is a blend of a null (pass-through)
    /// material and the masked one, with w = opacity.
    int blendParts[2] = {-1, -1};
    float blendWeight = 0.5f;
    MaterialTextures textures;  ///< textured parameters (Scene::setupBsdf looks them up)
    /// Shading-normal perturbation (Mitsuba's normalmap / bumpmap wrapping this material) and
    /// its texture in Scene::textures; `bumpScale` multiplies the height gradient.
    NormalPerturbation perturbation = NormalPerturbation::kNone;
    int perturbationTexture = -1;
    float bumpScale = 1.0f;
    /// Perturbed normals: Mitsuba's `use_shadowing_function`, the shadow-terminator factor of
    /// Estevez et al. 2019 on the light-side direction (scene/normal_perturbation.h).
    bool shadowTerminator = true;

    // ---- derived data, filled by prepareMaterial() (scene/bsdf.h) ----
    /// Plastic: Fdr of the coating seen from inside (fit); RoughPlastic: Mitsuba 3's
    /// discretised hemispherical reflectance of the rough coating seen from inside.
    float internalReflectance = 0.0f;
    /// RoughPlastic: transmittance of the rough coating from outside at
    /// mu = k / (size - 1) (kernels/shared/ub_plastic.h).
    std::array<float, 64> coatingTransmittance{};
    /// `ior` and `alpha` that prepareMaterial() used (-1: not prepared). Bsdf::setup throws
    /// std::logic_error for a plastic whose current ior/alpha differ from these.
    float preparedIor = -1.0f, preparedAlpha = -1.0f;
    MicrofacetDistribution preparedDistribution = MicrofacetDistribution::kGgx;

    /// Anisotropic roughness (alphaV or its texture given): the BSDF needs the shading
    /// tangent of the hit (Hit::tangent).
    bool anisotropic() const {
        if (type == MaterialType::Principled || type == MaterialType::PrincipledThin)
            return principled.anisotropic != 0.0f || textures.principled[0] >= 0;
        return (type == MaterialType::RoughConductor || type == MaterialType::RoughDielectric) &&
               ((alphaV >= 0.0f && (alphaV != alpha || textures.alpha >= 0)) ||
                textures.alphaV >= 0);
    }
};

}  // namespace ub
