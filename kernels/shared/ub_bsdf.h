/* Evaluation of unibeam's BSDFs at a surface point (host C++ and OpenCL C): the non-delta
 * lobes of every material type, their value f_s and both solid-angle pdfs. The host's
 * Bsdf (src/scene/bsdf.h, conventions there) sets a ub_bsdf up at a hit and evaluates it
 * with these functions; the surface-merging kernel (kernels/surf.cl) evaluates the same
 * record, recorded by the camera pass, for each photon it gathers.
 *
 * Lobes and references (details in src/scene/bsdf.cpp and bsdf_plastic.cpp):
 *   Diffuse, Phong   Lambert rho/pi plus the modified Phong lobe (Lafortune & Willems
 *                    1994), mixture pdf by lobe-selection probabilities (SmallVCM);
 *   RoughConductor   GGX or Beckmann (ub_microfacet.h), Walter et al. 2007 eq. 20, visible-normal
 * pdf (Heitz 2018) times the reflection Jacobian (Walter eq. 14); RoughDielectric  Walter et al.
 * 2007 eq. 20 (reflection) and eq. 21 (refraction, Jacobian eq. 17), Fresnel lobe selection;
 *   Plastic, RoughPlastic  Mitsuba 3's coated diffuse (kernels/shared/ub_plastic.h);
 *   Principled       Mitsuba 3's principled BSDF (ub_principled.h); the record's fields hold
 *                    its parameters as ub_bsdf_principled() reads them;
 *   PrincipledThin   Mitsuba 3's principledthin (ub_principled_thin.h), likewise;
 *   MultiLobe        SmallUPBP's sum of lobes: its Lambert and Phong lobes here, picked
 *                    with probabilities proportional to the lobes' albedos, which depend on
 *                    the Fresnel weight of the delta lobes seen from the fixed direction
 *                    (ub_bsdf_multilobe_probs): the reverse pdf uses those of dirGen.
 * Delta lobes (Mirror, Dielectric, ThinDielectric, the plastic coating) have no density:
 * they are sampled on the host only and evaluate to zero here.
 *
 * Measures: pdfs per unit solid angle (suffix W). directPdfW = p(dirGen | dirFix),
 * reversePdfW = p(dirFix | dirGen); neither includes Russian roulette.
 *
 * Fixed-size scalars only; 192 bytes, checked below and by the layout probe.
 */
#ifndef UB_BSDF_H
#define UB_BSDF_H

#include "ub_fresnel.h"
#include "ub_microfacet.h"
#include "ub_phong.h"
#include "ub_plastic.h"
#include "ub_principled.h"
#include "ub_principled_thin.h"
#include "ub_vec3.h"

/* Material types (the values of ub::MaterialType, src/scene/material.h). */
#define UB_MATERIAL_DIFFUSE 0u
#define UB_MATERIAL_PHONG 1u
#define UB_MATERIAL_MIRROR 2u
#define UB_MATERIAL_DIELECTRIC 3u
#define UB_MATERIAL_ROUGH_CONDUCTOR 4u
#define UB_MATERIAL_ROUGH_DIELECTRIC 5u
#define UB_MATERIAL_PLASTIC 6u
#define UB_MATERIAL_ROUGH_PLASTIC 7u
#define UB_MATERIAL_THIN_DIELECTRIC 8u
#define UB_MATERIAL_MULTI_LOBE 9u
#define UB_MATERIAL_PRINCIPLED 11u
#define UB_MATERIAL_PRINCIPLED_THIN 12u

/* The material types ub_bsdf_eval_local evaluates, a mask of 1 << UB_MATERIAL_*: every type,
 * unless a program is built for the types of one scene (-DUB_BSDF_TYPES=..., clBsdfTypesOption
 * in src/estimators/surface_merging.cpp). The switch then holds only those types: the surf
 * kernel of a scene without the principled BSDFs compiles without their code, which PoCL runs
 * faster (docs/performance.md, session 27). The mask must hold the type of every record the
 * program evaluates; the others evaluate to zero. */
#ifndef UB_BSDF_TYPES
#define UB_BSDF_TYPES 0xFFFFFFFFu
#endif
#define UB_BSDF_HAS(t) ((((ub_uint)(UB_BSDF_TYPES)) >> (t)) & 1u)

#define UB_BSDF_EVALUABLE 1u       /* valid, not all-delta, not black: evaluation can be > 0 */
#define UB_BSDF_FROM_LIGHT 2u      /* light subpath: importance transport (bsdf.h) */
#define UB_BSDF_GEOMETRIC_GUARD 4u /* the geometric-normal guard is on (bsdf.h) */
#define UB_BSDF_SEPARABLE 8u       /* separable Smith G2 for GGX reflection (Material) */
#define UB_BSDF_BECKMANN 16u       /* Beckmann microfacets instead of GGX */
#define UB_BSDF_REFRACT 32u        /* multi-lobe: has the refraction lobe */
#define UB_BSDF_PERTURBED 64u      /* normal- or bump-mapped shading normal: light-side rule */

/* Smallest microfacet roughness used (alpha -> 0 is a delta lobe floats cannot represent). */
#define UB_MIN_GGX_ALPHA 1e-4f
/* |cos| below which a direction counts as grazing (no evaluation). */
#define UB_EPS_COSINE 1e-6f

typedef struct {
    float frameS[3]; /* shading frame (s, t, n); n possibly flipped to dirFix's side */
    ub_uint type;    /* UB_MATERIAL_* */
    float frameT[3];
    ub_uint flags; /* UB_BSDF_* */
    float frameN[3];
    float cosGeoFix;    /* dot(dirFix, geoNormal) */
    float geoNormal[3]; /* same side convention as frameN */
    float exponent;     /* Phong exponent */
    float localFix[3];  /* dirFix in the shading frame */
    float alpha; /* microfacet roughness as given (clamped to UB_MIN_GGX_ALPHA when used); rough
                    conductor and dielectric: along frameS (alpha_u) */
    float diffuse[3]; /* RGB parameters at the point (textures resolved) */
    float ior;        /* interior / exterior IOR (dielectrics, plastics) */
    float glossy[3];
    float etaFix; /* dielectrics: IOR on dirFix's side */
    float specular[3];
    float etaOther; /* dielectrics: IOR on the other side */
    float eta[3];   /* conductor: complex IOR */
    float probDiffuse;
    float k[3];
    float probGlossy;
    float plasticBase[3];   /* plastics: rho / (1 - Fint) per channel (ub_plastic.h) */
    float fresnelFix;       /* smooth interface's Fresnel reflectance seen from dirFix */
    float specularWeight;   /* plastics: mean(specular) / (mean(diffuse) + mean(specular)) */
    ub_uint tableIndex;     /* rough plastic: the material whose coating table applies */
    float terminatorAlpha2; /* perturbed normals: a^2 of the shadow-terminator factor (0: off) */
    float alphaV; /* rough conductor and dielectric: roughness along frameT (= alpha: isotropic) */
} ub_bsdf;

/* The microfacet distribution of b (UB_MF_*). */
UB_INLINE ub_uint ub_bsdf_distribution(UB_PRIVATE const ub_bsdf* b) {
    return (b->flags & UB_BSDF_BECKMANN) ? UB_MF_BECKMANN : UB_MF_GGX;
}

UB_INLINE ub_float3 ub_bsdf_to_local(UB_PRIVATE const ub_bsdf* b, ub_float3 v) {
    return ub_make_float3(v.x * b->frameS[0] + v.y * b->frameS[1] + v.z * b->frameS[2],
                          v.x * b->frameT[0] + v.y * b->frameT[1] + v.z * b->frameT[2],
                          v.x * b->frameN[0] + v.y * b->frameN[1] + v.z * b->frameN[2]);
}

/* Veach 1997, Sec. 5.3: the adjoint factor |dirFix.Ns| |dirGen.Ng| / (|dirFix.Ng| |dirGen.Ns|)
 * for importance transport, 1 for radiance. */
UB_INLINE float ub_bsdf_shading_factor(UB_PRIVATE const ub_bsdf* b, float cosShadingGen,
                                       float cosGeoGen) {
    if (!(b->flags & UB_BSDF_FROM_LIGHT)) return 1.0f;
    return ub_fabs(b->localFix[2]) * ub_fabs(cosGeoGen) / (ub_fabs(b->cosGeoFix) * cosShadingGen);
}

/* The geometric-normal guard: a reflected dirGen on dirFix's side of the geometric surface,
 * a transmitted one on the other side (bsdf.cpp's banner). */
UB_INLINE int ub_bsdf_geometric_side_ok(UB_PRIVATE const ub_bsdf* b, float localGenZ,
                                        float cosGeoGen) {
    if (cosGeoGen == 0.0f) return 0;
    if (!(b->flags & UB_BSDF_GEOMETRIC_GUARD)) return 1; /* Mitsuba 3: shading frame decides */
    int shadingReflect = localGenZ * b->localFix[2] > 0.0f;
    int geometricReflect = cosGeoGen * b->cosGeoFix > 0.0f;
    return shadingReflect == geometricReflect;
}

/* Perturbed shading normals (Mitsuba 3's normalmap and bumpmap wrappers, bsdf.h): the
 * light-side direction (dirGen on a camera subpath, dirFix on a light subpath) must lie on the
 * same side of the geometric surface as of the shading normal, and f is scaled by the
 * shadow-terminator factor of Estevez et al., "A Microfacet-Based Shadowing Function to Solve
 * the Bump Terminator Problem" (Ray Tracing Gems, 2019): G = 2 / (1 + sqrt(1 + a^2 tan^2)),
 * with tan the tangent of the light-side direction's angle to the geometric normal and a^2 =
 * terminatorAlpha2. Returns G, 0 where the side rule fails, 1 without a perturbation. */
UB_INLINE float ub_bsdf_perturbed_factor(UB_PRIVATE const ub_bsdf* b, float localGenZ,
                                         float cosGeoGen) {
    if (!(b->flags & UB_BSDF_PERTURBED)) return 1.0f;
    int fromLight = (b->flags & UB_BSDF_FROM_LIGHT) != 0u;
    float shadingCos = fromLight ? b->localFix[2] : localGenZ;
    float geoCos = fromLight ? b->cosGeoFix : cosGeoGen;
    if (!(shadingCos * geoCos > 0.0f)) return 0.0f;
    float cos2 = geoCos * geoCos;
    float tan2 = ub_fmax(0.0f, 1.0f - cos2) / cos2;
    return 2.0f / (1.0f + ub_sqrt(1.0f + b->terminatorAlpha2 * tan2));
}

/* Probability of picking a plastic's specular lobe seen from a direction with |cos| =
 * cosTheta (Mitsuba 3: R w / (R w + (1 - R)(1 - w)), bsdf_plastic.cpp). coating: the rough
 * plastic's transmittance table (unused for the smooth one). */
UB_INLINE float ub_bsdf_plastic_specular_prob(UB_PRIVATE const ub_bsdf* b,
                                              UB_GLOBAL const float* coating, float cosTheta) {
    float reflectance = b->type == UB_MATERIAL_PLASTIC
                            ? ub_fresnel_dielectric(cosTheta, b->ior)
                            : 1.0f - ub_plastic_table_lookup(coating, cosTheta);
    float ps = reflectance * b->specularWeight;
    float pd = (1.0f - reflectance) * (1.0f - b->specularWeight);
    return ps + pd > 0.0f ? ps / (ps + pd) : 0.0f;
}

/* Multi-lobe: the probabilities of picking the Lambert, the Phong and the mirror lobe (the
 * refraction has the rest) when sampling from
 * a direction on the front with cos cosTheta: albedo estimates lum(Kd), lum(Ks),
 * F lum(mirror) and, with refraction, (1 - F), normalised (SmallUPBP's Bsdf.hxx); F is the
 * Fresnel reflectance of the interface seen from there (1 without refraction). Returns 0 if
 * no lobe has albedo (every probability 0). */
UB_INLINE int ub_bsdf_multilobe_probs(UB_PRIVATE const ub_bsdf* b, float cosTheta,
                                      UB_PRIVATE float* probDiffuse, UB_PRIVATE float* probGlossy,
                                      UB_PRIVATE float* probReflect) {
    float fresnel = (b->flags & UB_BSDF_REFRACT)
                        ? ub_fresnel_dielectric(ub_fabs(cosTheta), b->etaOther / b->etaFix)
                        : 1.0f;
    float d = 0.212671f * b->diffuse[0] + 0.715160f * b->diffuse[1] + 0.072169f * b->diffuse[2];
    float p = 0.212671f * b->glossy[0] + 0.715160f * b->glossy[1] + 0.072169f * b->glossy[2];
    float m = 0.212671f * b->specular[0] + 0.715160f * b->specular[1] + 0.072169f * b->specular[2];
    float total = d + p + fresnel * m + ((b->flags & UB_BSDF_REFRACT) ? 1.0f - fresnel : 0.0f);
    if (!(total >= 1e-9f)) {
        *probDiffuse = 0.0f;
        *probGlossy = 0.0f;
        *probReflect = 0.0f;
        return 0;
    }
    *probDiffuse = d / total;
    *probGlossy = p / total;
    *probReflect = fresnel * m / total;
    return 1;
}

/* Diffuse + Phong, reflection above the surface only. */
UB_INLINE ub_float3 ub_bsdf_eval_phong(UB_PRIVATE const ub_bsdf* b, ub_float3 gen,
                                       UB_PRIVATE float* directPdfW,
                                       UB_PRIVATE float* reversePdfW) {
    ub_float3 fix = ub_f3_from(b->localFix);
    ub_float3 f = ub_make_float3(0.0f, 0.0f, 0.0f);
    if (fix.z <= 0.0f || gen.z <= 0.0f) return f;
    if (b->probDiffuse > 0.0f) {
        f = ub_f3_scale(ub_f3_from(b->diffuse), UB_INV_PI);
        *directPdfW += b->probDiffuse * ub_lambert_pdf(gen.z);
        *reversePdfW += b->probDiffuse * ub_lambert_pdf(fix.z);
    }
    if (b->probGlossy > 0.0f) {
        /* cos between dirGen and the mirror direction of dirFix: symmetric in the two
         * directions, so the reverse pdf is the same value */
        float cosAlpha = -fix.x * gen.x - fix.y * gen.y + fix.z * gen.z;
        float lobePdf = b->probGlossy * ub_power_cos_pdf(cosAlpha, b->exponent);
        f = ub_f3_add(f, ub_f3_scale(ub_f3_from(b->glossy), ub_phong_lobe(cosAlpha, b->exponent)));
        *directPdfW += lobePdf;
        *reversePdfW += lobePdf;
    }
    return f;
}

UB_INLINE ub_float3 ub_bsdf_eval_rough_conductor(UB_PRIVATE const ub_bsdf* b, ub_float3 gen,
                                                 UB_PRIVATE float* directPdfW,
                                                 UB_PRIVATE float* reversePdfW) {
    ub_uint dist = ub_bsdf_distribution(b);
    ub_float3 fix = ub_f3_from(b->localFix);
    if (fix.z <= 0.0f || gen.z <= 0.0f) return ub_make_float3(0.0f, 0.0f, 0.0f);
    float au = ub_fmax(b->alpha, UB_MIN_GGX_ALPHA), av = ub_fmax(b->alphaV, UB_MIN_GGX_ALPHA);
    ub_float3 h = ub_f3_normalize(ub_f3_add(fix, gen)); /* h.z > 0, fix.h = gen.h > 0 */
    float cosFixH = ub_f3_dot(fix, h), cosGenH = ub_f3_dot(gen, h);
    float d = ub_mf_d_aniso(dist, h.x, h.y, h.z, au, av);
    float lFix = ub_mf_lambda_aniso(dist, fix.x, fix.y, fix.z, au, av);
    float lGen = ub_mf_lambda_aniso(dist, gen.x, gen.y, gen.z, au, av);
    float g2 = (b->flags & UB_BSDF_SEPARABLE) ? 1.0f / ((1.0f + lFix) * (1.0f + lGen))
                                              : 1.0f / (1.0f + lFix + lGen);
    /* visible-normal density D_v = G1(v) (v.m) D / v.z (Heitz 2014, eq. 38) times the
     * reflection Jacobian (Walter et al. 2007, eq. 14) */
    *directPdfW = cosFixH * d / ((1.0f + lFix) * fix.z) * ub_jacobian_reflect(cosGenH);
    *reversePdfW = cosGenH * d / ((1.0f + lGen) * gen.z) * ub_jacobian_reflect(cosFixH);
    /* Walter et al. 2007, eq. 20: F D G / (4 |i.n| |o.n|) */
    float s = d * g2 / (4.0f * fix.z * gen.z);
    return ub_make_float3(b->specular[0] * ub_fresnel_conductor(cosFixH, b->eta[0], b->k[0]) * s,
                          b->specular[1] * ub_fresnel_conductor(cosFixH, b->eta[1], b->k[1]) * s,
                          b->specular[2] * ub_fresnel_conductor(cosFixH, b->eta[2], b->k[2]) * s);
}

UB_INLINE ub_float3 ub_bsdf_eval_rough_dielectric(UB_PRIVATE const ub_bsdf* b, ub_float3 gen,
                                                  UB_PRIVATE float* directPdfW,
                                                  UB_PRIVATE float* reversePdfW) {
    ub_uint dist = ub_bsdf_distribution(b);
    ub_float3 fix = ub_f3_from(b->localFix);
    ub_float3 zero = ub_make_float3(0.0f, 0.0f, 0.0f);
    float au = ub_fmax(b->alpha, UB_MIN_GGX_ALPHA), av = ub_fmax(b->alphaV, UB_MIN_GGX_ALPHA);
    int reflect = fix.z * gen.z > 0.0f;
    float etaGen = reflect ? b->etaFix : b->etaOther;
    /* half vector: Walter et al. 2007 eq. 13 (reflection), eq. 16 (refraction), to +z */
    ub_float3 h = reflect ? ub_f3_add(fix, gen)
                          : ub_f3_add(ub_f3_scale(fix, b->etaFix), ub_f3_scale(gen, etaGen));
    float len2 = ub_f3_dot(h, h);
    if (!(len2 > 1e-12f)) return zero;
    h = ub_f3_scale(h, 1.0f / ub_sqrt(len2));
    if (h.z < 0.0f) h = ub_f3_neg(h);
    float cosFixH = ub_f3_dot(fix, h), cosGenH = ub_f3_dot(gen, h);
    /* both directions see the microfacet from their side (chi+ of Walter eq. 20/21) */
    if (cosFixH * fix.z <= 0.0f || cosGenH * gen.z <= 0.0f) return zero;
    float cFix = ub_fabs(fix.z), cGen = ub_fabs(gen.z);
    float aFix = ub_fabs(cosFixH), aGen = ub_fabs(cosGenH);
    float d = ub_mf_d_aniso(dist, h.x, h.y, h.z, au, av);
    /* Lambda depends on |v.z| and v's azimuth only: the mirrored direction has the same */
    float lFix = ub_mf_lambda_aniso(dist, fix.x, fix.y, cFix, au, av);
    float lGen = ub_mf_lambda_aniso(dist, gen.x, gen.y, cGen, au, av);
    float visFix = aFix * d / ((1.0f + lFix) * cFix); /* Heitz 2014, eq. 38 */
    float visGen = aGen * d / ((1.0f + lGen) * cGen);
    float etaRel = b->etaOther / b->etaFix;
    if (reflect) {
        float fresnelFix = ub_fresnel_dielectric(aFix, etaRel);
        float fresnelGen = ub_fresnel_dielectric(aGen, etaRel);
        *directPdfW = fresnelFix * visFix * ub_jacobian_reflect(aGen);
        *reversePdfW = fresnelGen * visGen * ub_jacobian_reflect(aFix);
        float g2 = (b->flags & UB_BSDF_SEPARABLE) ? 1.0f / ((1.0f + lFix) * (1.0f + lGen))
                                                  : 1.0f / (1.0f + lFix + lGen);
        /* F at the mean of fix.h and gen.h (equal in exact arithmetic) keeps f(fix, gen) =
         * f(gen, fix) bit for bit; the pdfs keep F(fix.h), what the sampler used */
        float fresnelSym = ub_fresnel_dielectric(0.5f * (aFix + aGen), etaRel);
        return ub_f3_scale(ub_f3_from(b->specular), fresnelSym * d * g2 / (4.0f * cFix * cGen));
    }
    /* refraction: F computed from the outside direction whichever is dirFix, so f and the
     * pdfs are symmetric under swapping the two */
    float transmit = 1.0f - (fix.z > 0.0f ? ub_fresnel_dielectric(aFix, etaGen / b->etaFix)
                                          : ub_fresnel_dielectric(aGen, b->etaFix / etaGen));
    *directPdfW = transmit * visFix * ub_jacobian_refract(b->etaFix, cosFixH, etaGen, cosGenH);
    *reversePdfW = transmit * visGen * ub_jacobian_refract(etaGen, cosGenH, b->etaFix, cosFixH);
    float denom = ub_sqr(b->etaFix * cosFixH + etaGen * cosGenH);
    /* Walter eq. 21 with o the camera side: eta_o = etaFix for radiance, etaGen for
     * importance (the adjoint BTDF) */
    float etaO = (b->flags & UB_BSDF_FROM_LIGHT) ? etaGen : b->etaFix;
    float g2 = 1.0f / ((1.0f + lFix) * (1.0f + lGen)); /* separable (Walter et al. eq. 23) */
    return ub_f3_scale(ub_f3_from(b->specular),
                       transmit * d * g2 * aFix * aGen * etaO * etaO / (cFix * cGen * denom));
}

/* Multi-lobe: the Lambert and Phong lobes above the surface; the forward pdf mixes them with
 * dirFix's lobe probabilities (b->probDiffuse, b->probGlossy), the reverse one with dirGen's. */
UB_INLINE ub_float3 ub_bsdf_eval_multilobe(UB_PRIVATE const ub_bsdf* b, ub_float3 gen,
                                           UB_PRIVATE float* directPdfW,
                                           UB_PRIVATE float* reversePdfW) {
    ub_float3 fix = ub_f3_from(b->localFix);
    ub_float3 f = ub_make_float3(0.0f, 0.0f, 0.0f);
    if (fix.z <= 0.0f || gen.z <= 0.0f) return f;
    float revDiffuse, revGlossy, revReflect;
    ub_bsdf_multilobe_probs(b, gen.z, &revDiffuse, &revGlossy, &revReflect);
    f = ub_f3_scale(ub_f3_from(b->diffuse), UB_INV_PI);
    *directPdfW = b->probDiffuse * ub_lambert_pdf(gen.z);
    *reversePdfW = revDiffuse * ub_lambert_pdf(fix.z);
    if (b->probGlossy > 0.0f) {
        float cosAlpha = -fix.x * gen.x - fix.y * gen.y + fix.z * gen.z;
        float lobePdf = ub_power_cos_pdf(cosAlpha, b->exponent); /* symmetric */
        f = ub_f3_add(f, ub_f3_scale(ub_f3_from(b->glossy), ub_phong_lobe(cosAlpha, b->exponent)));
        *directPdfW += b->probGlossy * lobePdf;
        *reversePdfW += revGlossy * lobePdf;
    }
    return f;
}

/* Plastic: the diffuse base under the smooth coating (the coating itself is a delta). */
UB_INLINE ub_float3 ub_bsdf_eval_plastic(UB_PRIVATE const ub_bsdf* b, ub_float3 gen,
                                         UB_PRIVATE float* directPdfW,
                                         UB_PRIVATE float* reversePdfW) {
    ub_float3 fix = ub_f3_from(b->localFix);
    if (fix.z <= 0.0f || gen.z <= 0.0f) return ub_make_float3(0.0f, 0.0f, 0.0f);
    float eta = b->ior;
    float fresnelGen = ub_fresnel_dielectric(gen.z, eta);
    *directPdfW = (1.0f - ub_bsdf_plastic_specular_prob(b, 0, fix.z)) * ub_lambert_pdf(gen.z);
    *reversePdfW = (1.0f - ub_bsdf_plastic_specular_prob(b, 0, gen.z)) * ub_lambert_pdf(fix.z);
    return ub_f3_scale(ub_f3_from(b->plasticBase),
                       (1.0f - b->fresnelFix) * (1.0f - fresnelGen) * UB_INV_PI / (eta * eta));
}

/* RoughPlastic: GGX coating reflection plus the diffuse base, mixed by the selection
 * probabilities of each direction. */
UB_INLINE ub_float3 ub_bsdf_eval_rough_plastic(UB_PRIVATE const ub_bsdf* b,
                                               UB_GLOBAL const float* coating, ub_float3 gen,
                                               UB_PRIVATE float* directPdfW,
                                               UB_PRIVATE float* reversePdfW) {
    ub_uint dist = ub_bsdf_distribution(b);
    ub_float3 fix = ub_f3_from(b->localFix);
    if (fix.z <= 0.0f || gen.z <= 0.0f) return ub_make_float3(0.0f, 0.0f, 0.0f);
    float eta = b->ior, alpha = ub_fmax(b->alpha, UB_MIN_GGX_ALPHA);
    ub_float3 h = ub_f3_normalize(ub_f3_add(fix, gen));
    float cosFixH = ub_f3_dot(fix, h), cosGenH = ub_f3_dot(gen, h);
    float d = ub_mf_d(dist, h.z, alpha);
    float g = ub_mf_g2_separable(dist, fix.z, gen.z, alpha);
    float fresnel = ub_fresnel_dielectric(cosFixH, eta);
    float probSpecFix = ub_bsdf_plastic_specular_prob(b, coating, fix.z);
    float probSpecGen = ub_bsdf_plastic_specular_prob(b, coating, gen.z);
    /* Walter et al. 2007 eq. 14 for the coating, mixed with the cosine lobe */
    *directPdfW = probSpecFix * ub_mf_visible_pdf(dist, fix.z, cosFixH, h.z, alpha) *
                      ub_jacobian_reflect(cosGenH) +
                  (1.0f - probSpecFix) * ub_lambert_pdf(gen.z);
    *reversePdfW = probSpecGen * ub_mf_visible_pdf(dist, gen.z, cosGenH, h.z, alpha) *
                       ub_jacobian_reflect(cosFixH) +
                   (1.0f - probSpecGen) * ub_lambert_pdf(fix.z);
    float glossy = fresnel * d * g / (4.0f * fix.z * gen.z);
    float transmit =
        ub_plastic_table_lookup(coating, fix.z) * ub_plastic_table_lookup(coating, gen.z);
    float base = transmit * UB_INV_PI / (eta * eta);
    return ub_make_float3(b->specular[0] * glossy + b->plasticBase[0] * base,
                          b->specular[1] * glossy + b->plasticBase[1] * base,
                          b->specular[2] * glossy + b->plasticBase[2] * base);
}

/* Principled: its parameters, stored in the fields its lobes do not otherwise use
 * (Bsdf::packShared): diffuse = base colour, alpha/alphaV = GGX alpha_x/alpha_y, ior = eta, glossy
 * = (metallic, spec_trans, spec_tint), specular = (sheen, sheen_tint, flatness), eta = (clearcoat,
 * clearcoat_gloss, roughness), k = sampling rates (diffuse, main specular, clearcoat). */
UB_INLINE ub_principled ub_bsdf_principled(UB_PRIVATE const ub_bsdf* b) {
    ub_principled p;
    UB_UNROLL
    for (int c = 0; c < 3; ++c) p.base[c] = b->diffuse[c];
    p.alphaX = b->alpha;
    p.alphaY = b->alphaV;
    p.roughness = b->eta[2];
    p.metallic = b->glossy[0];
    p.specTrans = b->glossy[1];
    p.specTint = b->glossy[2];
    p.sheen = b->specular[0];
    p.sheenTint = b->specular[1];
    p.flatness = b->specular[2];
    p.clearcoat = b->eta[0];
    p.clearcoatGloss = b->eta[1];
    p.eta = b->ior;
    p.rateDiffuse = b->k[0];
    p.rateSpecular = b->k[1];
    p.rateClearcoat = b->k[2];
    return p;
}

/* Principled: f_s = Mitsuba's eval / |cos dirGen|; the pdfs are its pdf both ways. */
UB_INLINE ub_float3 ub_bsdf_eval_principled(UB_PRIVATE const ub_bsdf* b, ub_float3 gen,
                                            UB_PRIVATE float* directPdfW,
                                            UB_PRIVATE float* reversePdfW) {
    ub_principled p = ub_bsdf_principled(b);
    ub_float3 fix = ub_f3_from(b->localFix);
    *directPdfW = ub_principled_pdf(&p, fix, gen);
    *reversePdfW = ub_principled_pdf(&p, gen, fix);
    ub_float3 v = ub_principled_value(&p, fix, gen, (b->flags & UB_BSDF_FROM_LIGHT) != 0u);
    return ub_f3_scale(v, 1.0f / ub_fabs(gen.z));
}

/* PrincipledThin: as ub_bsdf_principled, with anisotropic in exponent, diff_trans and the
 * transmission sampling rates in plasticBase (Bsdf::packShared). */
UB_INLINE ub_principled_thin ub_bsdf_principled_thin(UB_PRIVATE const ub_bsdf* b) {
    ub_principled_thin p;
    UB_UNROLL
    for (int c = 0; c < 3; ++c) p.base[c] = b->diffuse[c];
    p.roughness = b->eta[2];
    p.anisotropic = b->exponent;
    p.specTrans = b->glossy[1];
    p.specTint = b->glossy[2];
    p.sheen = b->specular[0];
    p.sheenTint = b->specular[1];
    p.flatness = b->specular[2];
    p.diffTrans = b->plasticBase[0];
    p.eta = b->ior;
    p.rateDiffRefl = b->k[0];
    p.rateSpecRefl = b->k[1];
    p.rateSpecTrans = b->plasticBase[1];
    p.rateDiffTrans = b->plasticBase[2];
    return p;
}

/* PrincipledThin: the frame is on dirFix's side (two-sided); the reverse pdf mirrors both
 * directions to dirGen's side, as Mitsuba does for a wi below the sheet. Mitsuba's thin model
 * is not reciprocal (its microsurface side tests differ when the two directions swap roles),
 * so a light subpath evaluates the adjoint of the radiance BSDF, f(dirGen -> dirFix): every
 * estimator then converges to what Mitsuba's path tracer renders. */
UB_INLINE ub_float3 ub_bsdf_eval_principled_thin(UB_PRIVATE const ub_bsdf* b, ub_float3 gen,
                                                 UB_PRIVATE float* directPdfW,
                                                 UB_PRIVATE float* reversePdfW) {
    ub_principled_thin p = ub_bsdf_principled_thin(b);
    ub_float3 fix = ub_f3_from(b->localFix);
    *directPdfW = ub_principled_thin_pdf(&p, fix, gen);
    float s = gen.z < 0.0f ? -1.0f : 1.0f;
    *reversePdfW = ub_principled_thin_pdf(&p, ub_f3_scale(gen, s), ub_f3_scale(fix, s));
    if (b->flags & UB_BSDF_FROM_LIGHT)
        return ub_f3_scale(ub_principled_thin_value(&p, ub_f3_scale(gen, s), ub_f3_scale(fix, s)),
                           1.0f / ub_fabs(fix.z));
    return ub_f3_scale(ub_principled_thin_value(&p, fix, gen), 1.0f / ub_fabs(gen.z));
}

/* f_s(dirFix, dirGen) and both pdfs for dirGen given in the shading frame; cosGeoGen =
 * dot(dirGen, geoNormal). Applies the geometric guard, the perturbed-normal rule and factor,
 * and, for light subpaths, the shading-normal factor. coating: the rough plastic's coating table
 * (else unused). */
UB_INLINE ub_float3 ub_bsdf_eval_local(UB_PRIVATE const ub_bsdf* b, UB_GLOBAL const float* coating,
                                       ub_float3 gen, float cosGeoGen, UB_PRIVATE float* directPdfW,
                                       UB_PRIVATE float* reversePdfW) {
    ub_float3 f = ub_make_float3(0.0f, 0.0f, 0.0f);
    *directPdfW = 0.0f;
    *reversePdfW = 0.0f;
    if (ub_fabs(gen.z) < UB_EPS_COSINE || !ub_bsdf_geometric_side_ok(b, gen.z, cosGeoGen)) return f;
    float perturbed = ub_bsdf_perturbed_factor(b, gen.z, cosGeoGen);
    if (!(perturbed > 0.0f)) return f;
    switch (b->type) {
        case UB_MATERIAL_DIFFUSE:
        case UB_MATERIAL_PHONG:
            if (UB_BSDF_HAS(UB_MATERIAL_DIFFUSE) || UB_BSDF_HAS(UB_MATERIAL_PHONG))
                f = ub_bsdf_eval_phong(b, gen, directPdfW, reversePdfW);
            break;
        case UB_MATERIAL_ROUGH_CONDUCTOR:
            if (UB_BSDF_HAS(UB_MATERIAL_ROUGH_CONDUCTOR))
                f = ub_bsdf_eval_rough_conductor(b, gen, directPdfW, reversePdfW);
            break;
        case UB_MATERIAL_ROUGH_DIELECTRIC:
            if (UB_BSDF_HAS(UB_MATERIAL_ROUGH_DIELECTRIC))
                f = ub_bsdf_eval_rough_dielectric(b, gen, directPdfW, reversePdfW);
            break;
        case UB_MATERIAL_PLASTIC:
            if (UB_BSDF_HAS(UB_MATERIAL_PLASTIC))
                f = ub_bsdf_eval_plastic(b, gen, directPdfW, reversePdfW);
            break;
        case UB_MATERIAL_ROUGH_PLASTIC:
            if (UB_BSDF_HAS(UB_MATERIAL_ROUGH_PLASTIC))
                f = ub_bsdf_eval_rough_plastic(b, coating, gen, directPdfW, reversePdfW);
            break;
        case UB_MATERIAL_MULTI_LOBE:
            if (UB_BSDF_HAS(UB_MATERIAL_MULTI_LOBE))
                f = ub_bsdf_eval_multilobe(b, gen, directPdfW, reversePdfW);
            break;
        case UB_MATERIAL_PRINCIPLED:
            if (UB_BSDF_HAS(UB_MATERIAL_PRINCIPLED))
                f = ub_bsdf_eval_principled(b, gen, directPdfW, reversePdfW);
            break;
        case UB_MATERIAL_PRINCIPLED_THIN:
            if (UB_BSDF_HAS(UB_MATERIAL_PRINCIPLED_THIN))
                f = ub_bsdf_eval_principled_thin(b, gen, directPdfW, reversePdfW);
            break;
        default:
            break;
    }
    return ub_f3_scale(f, ub_bsdf_shading_factor(b, ub_fabs(gen.z), cosGeoGen) * perturbed);
}

/* The same for a world-space unit dirGen; *cosThetaGen = |cos| to the shading normal. */
UB_INLINE ub_float3 ub_bsdf_evaluate(UB_PRIVATE const ub_bsdf* b, UB_GLOBAL const float* coating,
                                     ub_float3 dirGen, UB_PRIVATE float* cosThetaGen,
                                     UB_PRIVATE float* directPdfW, UB_PRIVATE float* reversePdfW) {
    ub_float3 gen = ub_bsdf_to_local(b, dirGen);
    *cosThetaGen = ub_fabs(gen.z);
    if (!(b->flags & UB_BSDF_EVALUABLE)) {
        *directPdfW = 0.0f;
        *reversePdfW = 0.0f;
        return ub_make_float3(0.0f, 0.0f, 0.0f);
    }
    float cosGeoGen =
        dirGen.x * b->geoNormal[0] + dirGen.y * b->geoNormal[1] + dirGen.z * b->geoNormal[2];
    return ub_bsdf_eval_local(b, coating, gen, cosGeoGen, directPdfW, reversePdfW);
}

#ifndef __OPENCL_C_VERSION__
#include <cstddef>
static_assert(sizeof(ub_bsdf) == 192, "ub_bsdf layout");
static_assert(offsetof(ub_bsdf, flags) == 28, "ub_bsdf layout");
static_assert(offsetof(ub_bsdf, localFix) == 64, "ub_bsdf layout");
static_assert(offsetof(ub_bsdf, plasticBase) == 160, "ub_bsdf layout");
static_assert(offsetof(ub_bsdf, tableIndex) == 180, "ub_bsdf layout");
#endif

#endif /* UB_BSDF_H */
