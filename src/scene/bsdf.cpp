// BSDFs of unibeam's materials (conventions: top of bsdf.h).
//
// Lobes (formulas in kernels/shared/, shared with the OpenCL kernels):
//  Diffuse          Lambert rho/pi, cosine-weighted sampling.
//  Phong            SmallVCM's model: Lambert `diffuse` + modified Phong `glossy`
//                   (n+2)/(2 pi) cos^n around the mirror direction of dirFix
//                   (Lafortune & Willems 1994). One lobe is picked with probability
//                   proportional to the luminance of its reflectance; the pdf is the
//                   mixture of both lobe pdfs (one-sample MIS, as SmallVCM).
//  Mirror           delta reflection, weight `specular`, times the conductor Fresnel
//                   reflectance F(cos_fix) of eta + i k per channel when the material has
//                   conductorFresnel (Mitsuba's smooth conductor; cos_fix = cos_gen, so the
//                   weight is the same in both transport directions).
//  Dielectric       smooth interface, exact unpolarised Fresnel F; reflection picked
//                   with probability F, refraction with 1 - F; weights `specular`
//                   times 1 (reflection) or (eta_fix/eta_gen)^2 for radiance and 1 for
//                   importance (refraction; Veach 1997, Sec. 5.2). On a camera path
//                   going from IOR n1 into n2, f cos / pdf = (n1/n2)^2 (pbrt-v4).
//  RoughConductor   GGX, height-correlated Smith G2, conductor Fresnel per channel;
//                   sampling of visible normals (Heitz 2018), exact pdf
//                   G1(fix) D(h) / (4 cos_fix).
//  RoughDielectric  Walter et al. 2007: GGX reflection (eq. 20, height-correlated G2)
//                   and transmission (eq. 21, separable G2 = G1 G1), visible-normal
//                   sampling on dirFix's side, Fresnel selection F(fix.h), Jacobians
//                   eq. 14 / eq. 17. Radiance transport uses eq. 21 as written
//                   (eta_o^2 with o = dirFix, the camera side); importance transport
//                   uses its adjoint, eta_gen^2 in place of eta_fix^2, so
//                   f_radiance(a, b) = f_importance(b, a).
//  Plastic, RoughPlastic, ThinDielectric: Mitsuba 3's coated-diffuse and thin-sheet
//                   models, in bsdf_plastic.cpp (banner there).
//  Blend            Mitsuba 3's `blendbsdf` (its documentation: "linear combination of two
//                   BSDFs", f = (1 - w) f_a + w f_b): evaluate() and both pdfs are the
//                   weighted sums of the parts' non-delta values, so the pdf of a direction
//                   is the mixture pdf (1 - w) p_a + w p_b in both transport directions and
//                   MIS stays exact. sample() picks part a with probability 1 - w (b with w),
//                   samples it, and for a non-delta direction returns the full mixture
//                   evaluate() there; a delta lobe of the picked part keeps its weight and
//                   gets pdf (selection probability) x (its discrete probability), so
//                   f cos / pdf is the part's throughput (coinciding delta lobes of both
//                   parts are then counted once each, which is unbiased: the expected weight
//                   is (1 - w) W_a + w W_b). A `mask` is a Blend of a null part (ThinDielectric
//                   of ior 1: straight transmission, tint 1) and the masked BSDF, w = opacity.
// RGB parameters come from SurfaceColors (colors_): the Material's constants, or its
// textures looked up at the hit by Scene::setupBsdf.
//
// Sidedness: opaque two-sided materials flip both normals to dirFix's side of the
// shading normal; one-sided ones are black from the back (valid, contProb 0).
// Dielectrics never flip: dirFix on the back of the shading normal means inside
// (IOR `ior`), the front is outside (IOR 1).
//
// Shading normals (Veach 1997, Sec. 5.3): f_s is defined with the shading normal.
// Guard: a reflected dirGen must lie on dirFix's side of the geometric surface and a
// transmitted one on the other side, otherwise f = 0, pdf = 0, and sampling fails
// (this removes light leaks through the surface and black-side reflections; the
// rule is symmetric in dirFix/dirGen, so reciprocity and reverse pdfs survive it).
// Switched off (ShadingNormals::kShadingOnly, Mitsuba scenes) every lobe direction is kept,
// as Mitsuba 3 does; pdfs stay symmetric, light may leak through smooth-shaded surfaces.
// For light subpaths f_s is multiplied by the adjoint factor
//   |dirFix.Ns| |dirGen.Ng| / (|dirFix.Ng| |dirGen.Ns|)
// so that f_s cos_s(dirGen) is the correct importance throughput; it is exactly 1
// when Ns == Ng.
//
// Perturbed shading normals (Mitsuba 3's normalmap / bumpmap; scene/normal_perturbation.h):
// the shading normal given to setup() is already the perturbed one (Scene::intersect), so the
// lobes and the adjoint factor above use it. Like Mitsuba's wrappers, f(camera side, light
// side) is also zero unless the light-side direction lies on the same side of the
// unperturbed surface as of the perturbed one, and is scaled by the shadow-terminator factor
// of Estevez et al. 2019 for the light-side direction (Mitsuba's use_shadowing_function).
// Mitsuba measures both against the unperturbed shading normal; unibeam uses the geometric
// normal, which is the same on spheres and on meshes without vertex normals. On a camera
// subpath the light side is dirGen (a per-direction factor), on a light subpath it is dirFix
// (one factor for the vertex; black when its side rule fails), so all algorithms use the
// same f. Pdfs are zero where the rule fails (no sample lands there).
//
// Russian roulette (continuationProb): max over RGB of the albedo estimate,
// clamped to [0,1] as SmallVCM: diffuse (+ glossy); mirror `specular`; dielectrics
// `specular` (1 for clear glass; refraction weights may exceed 1 for radiance, RR
// uses the tint only); rough conductor and mirror `specular` * F_conductor(cos_fix) (the
// mirror's F is 1 without conductorFresnel).
#include "scene/bsdf.h"

#include <stdexcept>

#include "core/sampling.h"
#include "kernels/shared/ub_fresnel.h"
#include "kernels/shared/ub_microfacet.h"
#include "kernels/shared/ub_phong.h"
#include "scene/microfacet_sampling.h"
#include "scene/normal_perturbation.h"

namespace ub {

namespace {

constexpr float kEpsCosine = 1e-6f;

float clamp01(float x) {
    return std::min(1.0f, std::max(0.0f, x));
}

Rgb fresnelConductor(float cosThetaI, const Rgb& eta, const Rgb& k) {
    return {ub_fresnel_conductor(cosThetaI, eta.x, k.x),
            ub_fresnel_conductor(cosThetaI, eta.y, k.y),
            ub_fresnel_conductor(cosThetaI, eta.z, k.z)};
}

bool isDielectric(MaterialType t) {
    return t == MaterialType::Dielectric || t == MaterialType::RoughDielectric;
}

/// Materials whose normals are never flipped to dirFix's side: the normal tells inside from
/// outside, or (a one-sided MultiLobe, SmallUPBP's) the lobes themselves decide what reflects
/// behind it (Lambert and Phong nothing, the mirror as in front).
bool keepsNormalSide(const Material& m) {
    return isDielectric(m.type) || m.type == MaterialType::ThinDielectric ||
           (m.type == MaterialType::MultiLobe && (m.refract || !m.twoSided)) ||
           (m.type == MaterialType::Principled && !m.twoSided);
}

}  // namespace

bool Bsdf::setup(const Material& mat, const Vec3& dirFix, const Vec3& geoNormal,
                 const Vec3& shadingNormal, bool fromLight) {
    return setup(mat, SurfaceColors::of(mat), dirFix, geoNormal, shadingNormal, fromLight);
}

bool Bsdf::setup(const Material& mat, const SurfaceColors& colors, const Vec3& dirFix,
                 const Vec3& geoNormal, const Vec3& shadingNormal, bool fromLight,
                 const Vec3& tangent) {
    mat_ = &mat;
    colors_ = colors;
    fromLight_ = fromLight;
    valid_ = false;
    black_ = false;
    contProb_ = 0.0f;
    probDiffuse_ = probGlossy_ = 0.0f;
    etaFix_ = etaOther_ = 1.0f;
    fresnelFix_ = 0.0f;
    specularWeight_ = 0.0f;
    probReflect_ = 0.0f;
    plasticBase_ = Rgb(0.0f);
    blend_.reset();
    blendWeight_ = 0.0f;
    isDelta_ = mat.type == MaterialType::Mirror || mat.type == MaterialType::Dielectric ||
               mat.type == MaterialType::ThinDielectric;

    Vec3 ns = shadingNormal, ng = geoNormal;
    perturbed_ = mat.perturbation != NormalPerturbation::kNone;
    terminatorAlpha2_ = perturbed_ && mat.shadowTerminator ? shadowTerminatorAlpha2(ns, ng) : 0.0f;
    if (!keepsNormalSide(mat) && dot(dirFix, ns) < 0.0f) {
        if (mat.twoSided || mat.type == MaterialType::PrincipledThin) {  // a sheet: both sides
            ns = -ns;
            ng = -ng;
        } else {
            black_ = true;
        }
    }
    frame_ = Frame(ns);
    if ((colors_.alphaU != colors_.alphaV ||
         ((mat.type == MaterialType::Principled || mat.type == MaterialType::PrincipledThin) &&
          colors_.principled.anisotropic != 0.0f)) &&
        lengthSqr(tangent) > 0.0f) {
        // Anisotropic roughness: alpha_u along Mitsuba's shading tangent s, the tangent made
        // orthogonal to the (perturbed, possibly flipped) shading normal; t = n x s. The
        // distribution is even in s and t, so the frame's handedness does not matter.
        frame_.s = shadingTangent(ns, tangent);
        frame_.t = cross(ns, frame_.s);
    }
    geoNormal_ = ng;
    localDirFix_ = frame_.toLocal(dirFix);
    cosGeoFix_ = dot(dirFix, ng);
    if (std::fabs(localDirFix_.z) < kEpsCosine || std::fabs(cosGeoFix_) < kEpsCosine) {
        packShared();  // not evaluable
        return false;
    }

    switch (mat.type) {
        case MaterialType::Diffuse:
            probDiffuse_ = 1.0f;
            contProb_ = maxComponent(colors_.diffuse);
            break;
        case MaterialType::Phong: {
            // Lobe selection proportional to the albedo estimates (SmallVCM).
            float albedoDiffuse = luminance(colors_.diffuse),
                  albedoGlossy = luminance(colors_.glossy);
            float total = albedoDiffuse + albedoGlossy;
            if (total > 1e-9f) {
                probDiffuse_ = albedoDiffuse / total;
                probGlossy_ = albedoGlossy / total;
            } else {
                black_ = true;
            }
            contProb_ = maxComponent(colors_.diffuse + colors_.glossy);
            break;
        }
        case MaterialType::Mirror:
            contProb_ = maxComponent(colors_.specular * mirrorReflectance());
            break;
        case MaterialType::Dielectric:
        case MaterialType::RoughDielectric:
            if (localDirFix_.z > 0.0f) {
                etaFix_ = 1.0f;
                etaOther_ = mat.ior;
            } else {
                etaFix_ = mat.ior;
                etaOther_ = 1.0f;
            }
            fresnelFix_ = ub_fresnel_dielectric(std::fabs(localDirFix_.z), etaOther_ / etaFix_);
            contProb_ = maxComponent(colors_.specular);
            break;
        case MaterialType::RoughConductor:
            contProb_ =
                maxComponent(colors_.specular * fresnelConductor(localDirFix_.z, mat.eta, mat.k));
            break;
        case MaterialType::Plastic:
        case MaterialType::RoughPlastic:
        case MaterialType::ThinDielectric:
            setupPlastic();
            break;
        case MaterialType::MultiLobe:
            setupMultiLobe();
            break;
        case MaterialType::PrincipledThin:
            contProb_ = std::max(0.5f, maxComponent(colors_.diffuse));  // as Principled
            break;
        case MaterialType::Principled:
            // Russian roulette: any probability in (0, 1] is unbiased; the largest base
            // colour channel, at least 1/2 (a black base still has its specular lobes).
            contProb_ = std::max(0.5f, maxComponent(colors_.diffuse));
            // From the back without transmission nothing scatters (Mitsuba's sample() fails).
            if (localDirFix_.z < 0.0f &&
                !((1.0f - colors_.principled.metallic) * colors_.principled.specTrans > 0.0f))
                black_ = true;
            break;
        case MaterialType::Blend:
            // The parts come from Scene::setupBsdf (setupBlend); alone it is not evaluable.
            packShared();
            return false;
    }
    // Perturbed normal (normal/bump map): on a light subpath dirFix is the light-side
    // direction, which must lie on the same side of the geometric and the shading surface.
    if (perturbed_ && fromLight && !(localDirFix_.z * cosGeoFix_ > 0.0f)) black_ = true;
    if (black_) contProb_ = 0.0f;
    contProb_ = clamp01(contProb_);
    valid_ = true;
    packShared();
    return true;
}

void Bsdf::packShared() {
    static_assert(uint32_t(MaterialType::Diffuse) == UB_MATERIAL_DIFFUSE &&
                      uint32_t(MaterialType::Phong) == UB_MATERIAL_PHONG &&
                      uint32_t(MaterialType::Mirror) == UB_MATERIAL_MIRROR &&
                      uint32_t(MaterialType::Dielectric) == UB_MATERIAL_DIELECTRIC &&
                      uint32_t(MaterialType::RoughConductor) == UB_MATERIAL_ROUGH_CONDUCTOR &&
                      uint32_t(MaterialType::RoughDielectric) == UB_MATERIAL_ROUGH_DIELECTRIC &&
                      uint32_t(MaterialType::Plastic) == UB_MATERIAL_PLASTIC &&
                      uint32_t(MaterialType::RoughPlastic) == UB_MATERIAL_ROUGH_PLASTIC &&
                      uint32_t(MaterialType::ThinDielectric) == UB_MATERIAL_THIN_DIELECTRIC &&
                      uint32_t(MaterialType::MultiLobe) == UB_MATERIAL_MULTI_LOBE &&
                      uint32_t(MaterialType::Principled) == UB_MATERIAL_PRINCIPLED &&
                      uint32_t(MaterialType::PrincipledThin) == UB_MATERIAL_PRINCIPLED_THIN,
                  "MaterialType values are the UB_MATERIAL_* of kernels/shared/ub_bsdf.h");
    ub_bsdf& b = shared_;
    const Material& m = *mat_;
    auto put = [](float dst[3], const Vec3& v) {
        dst[0] = v.x;
        dst[1] = v.y;
        dst[2] = v.z;
    };
    put(b.frameS, frame_.s);
    put(b.frameT, frame_.t);
    put(b.frameN, frame_.n);
    put(b.geoNormal, geoNormal_);
    put(b.localFix, localDirFix_);
    put(b.diffuse, colors_.diffuse);
    put(b.glossy, colors_.glossy);
    put(b.specular, colors_.specular);
    put(b.eta, m.eta);
    put(b.k, m.k);
    put(b.plasticBase, plasticBase_);
    b.type = uint32_t(m.type);
    b.flags = (valid_ && !isDelta_ && !black_ ? UB_BSDF_EVALUABLE : 0u) |
              (m.type == MaterialType::MultiLobe && m.refract ? UB_BSDF_REFRACT : 0u) |
              (fromLight_ ? UB_BSDF_FROM_LIGHT : 0u) |
              (geometricGuard_ ? UB_BSDF_GEOMETRIC_GUARD : 0u) |
              (m.separableMasking ? UB_BSDF_SEPARABLE : 0u) |
              (m.distribution == MicrofacetDistribution::kBeckmann ? UB_BSDF_BECKMANN : 0u) |
              (perturbed_ ? UB_BSDF_PERTURBED : 0u);
    b.cosGeoFix = cosGeoFix_;
    b.exponent = m.exponent;
    b.alpha = colors_.alphaU;
    b.alphaV = colors_.alphaV;
    b.ior = m.ior;
    b.etaFix = etaFix_;
    b.etaOther = etaOther_;
    b.probDiffuse = probDiffuse_;
    b.probGlossy = probGlossy_;
    b.fresnelFix = fresnelFix_;
    b.specularWeight = specularWeight_;
    b.tableIndex = 0;  // the surface-merging pass sets the material's index
    b.terminatorAlpha2 = terminatorAlpha2_;
    coating_ = m.type == MaterialType::RoughPlastic ? m.coatingTransmittance.data() : nullptr;
    if (m.type == MaterialType::PrincipledThin) {
        // The parameters in the fields ub_bsdf_principled_thin reads (kernels/shared/ub_bsdf.h).
        const PrincipledParams& q = colors_.principled;
        b.exponent = q.anisotropic;
        put(b.glossy, Vec3(0.0f, q.specTrans, q.specTint));
        put(b.specular, Vec3(q.sheen, q.sheenTint, q.flatness));
        put(b.eta, Vec3(0.0f, 0.0f, colors_.alphaU));
        put(b.k, Vec3(q.rateDiffuse, q.rateSpecular, 0.0f));
        put(b.plasticBase, Vec3(q.diffTrans, q.rateSpecTrans, q.rateDiffTrans));
    }
    if (m.type == MaterialType::Principled) {
        // The parameters in the fields ub_bsdf_principled reads (kernels/shared/ub_bsdf.h).
        const PrincipledParams& q = colors_.principled;
        const float roughness = colors_.alphaU;
        ub_principled_alphas(roughness, q.anisotropic, &b.alpha, &b.alphaV);
        put(b.glossy, Vec3(q.metallic, q.specTrans, q.specTint));
        put(b.specular, Vec3(q.sheen, q.sheenTint, q.flatness));
        put(b.eta, Vec3(q.clearcoat, q.clearcoatGloss, roughness));
        put(b.k, Vec3(q.rateDiffuse, q.rateSpecular, q.rateClearcoat));
    }
}

struct Bsdf::BlendParts {
    Bsdf part[2];
};

bool Bsdf::setupBlend(const Material& mat, float weight, const Bsdf& a, const Bsdf& b) {
    // Frame, dirFix and flags from part b (the masked BSDF of a mask): both parts share the
    // hit, so |cos| values agree; which side a part flips its normal to is its own business.
    *this = b;
    mat_ = &mat;
    blend_ = std::make_shared<const BlendParts>(BlendParts{{a, b}});
    blendWeight_ = clamp01(weight);
    valid_ = a.valid_ && b.valid_;
    isDelta_ = a.isDelta_ && b.isDelta_;
    black_ = false;
    const float wa = 1.0f - blendWeight_, wb = blendWeight_;
    contProb_ = valid_ ? clamp01(wa * a.contProb_ + wb * b.contProb_) : 0.0f;
    probDiffuse_ = probGlossy_ = probReflect_ = 0.0f;
    shared_ = ub_bsdf{};  // not evaluable by the kernels' ub_bsdf_evaluate
    shared_.flags =
        (fromLight_ ? UB_BSDF_FROM_LIGHT : 0u) | (geometricGuard_ ? UB_BSDF_GEOMETRIC_GUARD : 0u);
    shared_.type = UB_MATERIAL_DIFFUSE;
    coating_ = nullptr;
    return valid_;
}

const Bsdf& Bsdf::blendPart(int i) const {
    if (!blend_) throw std::logic_error("Bsdf::blendPart: not a blend");
    return blend_->part[i == 0 ? 0 : 1];
}

Rgb Bsdf::evaluate(const Vec3& dirGen, float* cosThetaGen, float* directPdfW,
                   float* reversePdfW) const {
    if (blend_) {
        // Mixture of the parts' non-delta lobes (banner: Blend).
        const float w[2] = {1.0f - blendWeight_, blendWeight_};
        Rgb f(0.0f);
        float cosGen = 0.0f, pd = 0.0f, pr = 0.0f;
        for (int i = 0; i < 2; ++i) {
            if (!(w[i] > 0.0f)) continue;
            float c = 0.0f, d = 0.0f, r = 0.0f;
            const Rgb fi = blend_->part[i].evaluate(dirGen, &c, &d, &r);
            f += fi * w[i];
            pd += w[i] * d;
            pr += w[i] * r;
            cosGen = std::max(cosGen, c);
        }
        if (cosThetaGen) *cosThetaGen = cosGen > 0.0f ? cosGen : std::fabs(dot(dirGen, frame_.n));
        if (directPdfW) *directPdfW = pd;
        if (reversePdfW) *reversePdfW = pr;
        return f;
    }
    float cosGen = 0.0f, pd = 0.0f, pr = 0.0f;
    const ub_float3 f = ub_bsdf_evaluate(
        &shared_, coating_, ub_make_float3(dirGen.x, dirGen.y, dirGen.z), &cosGen, &pd, &pr);
    if (cosThetaGen) *cosThetaGen = cosGen;
    if (directPdfW) *directPdfW = pd;
    if (reversePdfW) *reversePdfW = pr;
    return Rgb(f.x, f.y, f.z);
}

float Bsdf::pdf(const Vec3& dirGen, bool reverse) const {
    float pd = 0.0f, pr = 0.0f;
    evaluate(dirGen, nullptr, &pd, &pr);
    return reverse ? pr : pd;
}

Rgb Bsdf::sample(const Vec3& rnd, Vec3* dirGen, float* pdfW, float* cosThetaGen,
                 uint32_t* sampledEvent, float* reversePdfW) const {
    *pdfW = 0.0f;
    if (reversePdfW) *reversePdfW = 0.0f;
    if (cosThetaGen) *cosThetaGen = 0.0f;
    if (sampledEvent) *sampledEvent = kEventNone;
    if (!valid_ || black_) return Rgb(0.0f);
    if (blend_) return sampleBlend(rnd, dirGen, pdfW, cosThetaGen, sampledEvent, reversePdfW);
    if (isDelta_) return sampleDelta(rnd, dirGen, pdfW, cosThetaGen, sampledEvent);

    const Vec3& fix = localDirFix_;
    Vec3 gen;
    uint32_t event = kEventGlossy;
    switch (mat_->type) {
        case MaterialType::Diffuse:
        case MaterialType::Phong:
            if (rnd.z < probDiffuse_) {
                gen = sampleCosineHemisphere(Vec2(rnd.x, rnd.y));
                event = kEventDiffuse;
            } else {
                Vec3 lobe;
                ub_power_cos_sample(rnd.x, rnd.y, mat_->exponent, &lobe.x, &lobe.y, &lobe.z);
                gen = Frame(Vec3(-fix.x, -fix.y, fix.z)).toWorld(lobe);
            }
            break;
        case MaterialType::RoughConductor: {
            const Vec3 m = sampleVisibleNormal(uint32_t(mat_->distribution), fix, alphaU(),
                                               alphaV(), rnd.x, rnd.y);
            gen = 2.0f * dot(fix, m) * m - fix;
            break;
        }
        case MaterialType::MultiLobe:
            // One lobe by its probability: Lambert, Phong, then the delta mirror / refraction.
            if (rnd.z < probDiffuse_) {
                gen = sampleCosineHemisphere(Vec2(rnd.x, rnd.y));
                event = kEventDiffuse;
            } else if (rnd.z < probDiffuse_ + probGlossy_) {
                Vec3 lobe;
                ub_power_cos_sample(rnd.x, rnd.y, mat_->exponent, &lobe.x, &lobe.y, &lobe.z);
                gen = Frame(Vec3(-fix.x, -fix.y, fix.z)).toWorld(lobe);
            } else {
                return sampleDelta(rnd, dirGen, pdfW, cosThetaGen, sampledEvent);
            }
            break;
        case MaterialType::Plastic:
            // Delta coating reflection with probability plasticSpecularProb, else the base.
            if (rnd.z < plasticSpecularProb(fix.z))
                return sampleDelta(rnd, dirGen, pdfW, cosThetaGen, sampledEvent);
            gen = sampleCosineHemisphere(Vec2(rnd.x, rnd.y));
            event = kEventDiffuse;
            break;
        case MaterialType::RoughPlastic:
            if (rnd.z < plasticSpecularProb(fix.z)) {
                const Vec3 m =
                    sampleVisibleNormal(uint32_t(mat_->distribution), fix, alphaU(), rnd.x, rnd.y);
                gen = 2.0f * dot(fix, m) * m - fix;
            } else {
                gen = sampleCosineHemisphere(Vec2(rnd.x, rnd.y));
                event = kEventDiffuse;
            }
            break;
        case MaterialType::Principled: {
            // Mitsuba's lobe selection and sampling (kernels/shared/ub_principled.h).
            const ub_principled p = ub_bsdf_principled(&shared_);
            ub_float3 wo;
            if (!ub_principled_sample(&p, ub_make_float3(fix.x, fix.y, fix.z), rnd.x, rnd.y, rnd.z,
                                      &wo))
                return Rgb(0.0f);
            gen = Vec3(wo.x, wo.y, wo.z);
            break;
        }
        case MaterialType::PrincipledThin: {
            const ub_principled_thin p = ub_bsdf_principled_thin(&shared_);
            ub_float3 wo;
            if (!ub_principled_thin_sample(&p, ub_make_float3(fix.x, fix.y, fix.z), rnd.x, rnd.y,
                                           rnd.z, &wo))
                return Rgb(0.0f);
            gen = Vec3(wo.x, wo.y, wo.z);
            break;
        }
        case MaterialType::RoughDielectric: {
            // Work mirrored to dirFix's side (GGX is symmetric under z -> -z).
            const float side = fix.z < 0.0f ? -1.0f : 1.0f;
            const Vec3 fixUp(fix.x, fix.y, side * fix.z);
            const Vec3 m = sampleVisibleNormal(uint32_t(mat_->distribution), fixUp, alphaU(),
                                               alphaV(), rnd.x, rnd.y);
            const float cosI = dot(fixUp, m);
            float cosT;
            const float fresnel = ub_fresnel_dielectric_ct(cosI, etaOther_ / etaFix_, &cosT);
            const bool reflect = rnd.z < fresnel;
            if (reflect) {
                gen = 2.0f * cosI * m - fixUp;
            } else {
                const float eta = etaFix_ / etaOther_;  // Snell: t = -eta i + (eta cos_i - cos_t) m
                gen = -eta * fixUp + (eta * cosI - cosT) * m;
            }
            // A microfacet reflection that leaves below the macro-surface, or a refraction
            // that leaves above it, fails: evaluate() would read it as the other lobe, whose
            // pdf this sample does not follow.
            if ((gen.z > 0.0f) != reflect) return Rgb(0.0f);
            gen.z *= side;
            break;
        }
        default:
            return Rgb(0.0f);
    }
    if (!(lengthSqr(gen) > 0.0f)) return Rgb(0.0f);
    const Vec3 world = frame_.toWorld(normalize(gen));
    // Evaluate exactly as evaluate() does, so sample() and evaluate()/pdf() agree.
    float pd, pr, cosGen;
    Rgb f = evaluate(world, &cosGen, &pd, &pr);
    if (!(pd > 0.0f)) return Rgb(0.0f);
    *dirGen = world;
    *pdfW = pd;
    if (reversePdfW) *reversePdfW = pr;
    if (cosThetaGen) *cosThetaGen = cosGen;
    if (sampledEvent) *sampledEvent = event;
    return f;
}

void Bsdf::setupMultiLobe() {
    const Material& mat = *mat_;
    if (mat.refract) {
        // As Dielectric: the front of the (unflipped) normal is outside, IOR 1.
        etaFix_ = localDirFix_.z > 0.0f ? 1.0f : mat.ior;
        etaOther_ = localDirFix_.z > 0.0f ? mat.ior : 1.0f;
        fresnelFix_ = ub_fresnel_dielectric(std::fabs(localDirFix_.z), etaOther_ / etaFix_);
    } else {
        fresnelFix_ = 1.0f;  // SmallUPBP: without refraction the mirror has weight 1
    }
    packShared();  // the lobe probabilities come from the shared function
    if (!ub_bsdf_multilobe_probs(&shared_, localDirFix_.z, &probDiffuse_, &probGlossy_,
                                 &probReflect_)) {
        black_ = true;
        return;
    }
    isDelta_ = probDiffuse_ == 0.0f && probGlossy_ == 0.0f;
    // Russian roulette: a bound that does not depend on dirFix (the MIS partials assume both
    // subpaths through a vertex continue with the same probability): with refraction the
    // transmitted albedo may be 1, so 1; else the largest channel of the summed lobes.
    contProb_ =
        mat.refract ? 1.0f : maxComponent(colors_.diffuse + colors_.glossy + colors_.specular);
}

Rgb Bsdf::mirrorReflectance() const {
    if (!mat_->conductorFresnel) return Rgb(1.0f);
    return fresnelConductor(std::fabs(localDirFix_.z), mat_->eta, mat_->k);
}

Rgb Bsdf::sampleBlend(const Vec3& rnd, Vec3* dirGen, float* pdfW, float* cosThetaGen,
                      uint32_t* sampledEvent, float* reversePdfW) const {
    // Part a with probability 1 - w, b with w; rnd.z rescaled to [0, 1) for the part.
    const float wa = 1.0f - blendWeight_, wb = blendWeight_;
    const int i = (rnd.z < wa || !(wb > 0.0f)) ? 0 : 1;
    const float select = i == 0 ? wa : wb;
    if (!(select > 0.0f)) return Rgb(0.0f);
    const float z = std::min(i == 0 ? rnd.z / wa : (rnd.z - wa) / wb, 0x1.fffffep-1f);
    const Bsdf& part = blend_->part[i];
    Vec3 dir;
    float pdf = 0.0f, cosGen = 0.0f;
    uint32_t event = kEventNone;
    const Rgb fPart = part.sample(Vec3(rnd.x, rnd.y, z), &dir, &pdf, &cosGen, &event);
    if (!(pdf > 0.0f) || isBlack(fPart)) return Rgb(0.0f);
    if (event & kEventSpecular) {
        // A delta lobe of the picked part: the other part has no density there.
        *dirGen = dir;
        *pdfW = select * pdf;
        if (cosThetaGen) *cosThetaGen = cosGen;
        if (sampledEvent) *sampledEvent = event | (part.isNullEvent(event) ? kEventNull : 0u);
        return fPart * select;
    }
    // A non-delta direction: the mixture's value and pdf there (as evaluate()).
    float pd = 0.0f, pr = 0.0f, cosMix = 0.0f;
    const Rgb f = evaluate(dir, &cosMix, &pd, &pr);
    if (!(pd > 0.0f)) return Rgb(0.0f);
    *dirGen = dir;
    *pdfW = pd;
    if (reversePdfW) *reversePdfW = pr;
    if (cosThetaGen) *cosThetaGen = cosMix;
    if (sampledEvent) *sampledEvent = event;
    return f;
}

bool Bsdf::hasNullLobe() const {
    if (blend_) return blend_->part[0].hasNullLobe() || blend_->part[1].hasNullLobe();
    return mat_ && mat_->type == MaterialType::ThinDielectric;
}

Rgb Bsdf::sampleDelta(const Vec3& rnd, Vec3* dirGen, float* pdfW, float* cosThetaGen,
                      uint32_t* sampledEvent) const {
    const Vec3& fix = localDirFix_;
    Vec3 gen(-fix.x, -fix.y, fix.z);  // mirror direction
    float prob = 1.0f;
    Rgb weight = colors_.specular;
    uint32_t event = kEventReflect;
    if (mat_->type == MaterialType::Mirror) {
        weight = colors_.specular * mirrorReflectance();
    } else if (mat_->type == MaterialType::Plastic) {
        // Coating reflection: f cos / pdf = specular F(fix) / P(specular) (Mitsuba 3).
        prob = plasticSpecularProb(fix.z);
        weight = colors_.specular * fresnelFix_;
    } else if (mat_->type == MaterialType::ThinDielectric) {
        // Reflection 2r/(1+r) (ub_plastic.h), else straight through: the two refractions
        // of the sheet cancel, so no eta^2 factor in either transport mode.
        const float reflectance = fresnelFix_;
        if (rnd.z < reflectance) {
            prob = reflectance;
            weight = colors_.specular * reflectance;
        } else {
            gen = -fix;
            prob = 1.0f - reflectance;
            weight = colors_.transmittance * (1.0f - reflectance);
            event = kEventRefract;
        }
    } else if (mat_->type == MaterialType::MultiLobe) {
        // rnd.z in [probDiffuse + probGlossy, 1): the mirror with probReflect_, else the
        // refraction (SmallUPBP's Bsdf.hxx): weights F mirror and (1 - F) (eta^2 for radiance).
        const float probRefract = 1.0f - probDiffuse_ - probGlossy_ - probReflect_;
        if (rnd.z < probDiffuse_ + probGlossy_ + probReflect_ || !(probRefract > 0.0f)) {
            prob = probReflect_;
            weight = colors_.specular * fresnelFix_;
        } else {
            const float eta = etaFix_ / etaOther_;
            float cosT;
            ub_fresnel_dielectric_ct(std::fabs(fix.z), etaOther_ / etaFix_, &cosT);
            gen = Vec3(-eta * fix.x, -eta * fix.y, fix.z > 0.0f ? -cosT : cosT);
            prob = probRefract;
            weight = Rgb((1.0f - fresnelFix_) * (fromLight_ ? 1.0f : eta * eta));
            event = kEventRefract;
        }
    } else if (mat_->type == MaterialType::Dielectric) {
        const float fresnel = fresnelFix_;
        if (rnd.z < fresnel) {
            prob = fresnel;
            weight = colors_.specular * fresnel;
        } else {
            const float eta = etaFix_ / etaOther_;  // n_fix / n_gen
            float cosT;
            ub_fresnel_dielectric_ct(std::fabs(fix.z), etaOther_ / etaFix_, &cosT);
            gen = Vec3(-eta * fix.x, -eta * fix.y, fix.z > 0.0f ? -cosT : cosT);
            prob = 1.0f - fresnel;
            // Radiance is scaled by (n_fix/n_gen)^2 across the interface; importance is not.
            weight = colors_.specular * ((1.0f - fresnel) * (fromLight_ ? 1.0f : eta * eta));
            event = kEventRefract;
        }
    }
    const Vec3 world = frame_.toWorld(gen);
    const float cosGen = std::fabs(gen.z);
    const float cosGeoGen = dot(world, geoNormal_);
    const float perturbed = ub_bsdf_perturbed_factor(&shared_, gen.z, cosGeoGen);
    if (!(prob > 0.0f) || cosGen < kEpsCosine ||
        !ub_bsdf_geometric_side_ok(&shared_, gen.z, cosGeoGen) || !(perturbed > 0.0f))
        return Rgb(0.0f);
    *dirGen = world;
    *pdfW = prob;
    if (cosThetaGen) *cosThetaGen = cosGen;
    if (sampledEvent) *sampledEvent = event;
    // Pre-divided by the cosine the caller multiplies with (SmallVCM convention).
    return weight * (ub_bsdf_shading_factor(&shared_, cosGen, cosGeoGen) * perturbed / cosGen);
}

}  // namespace ub
