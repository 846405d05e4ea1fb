/* Mitsuba 3's `principled` BSDF (host C++ and OpenCL C): the Disney BRDF of Burley 2012,
 * "Physically Based Shading at Disney", extended with a microfacet transmission lobe as in
 * Burley 2015, "Extending the Disney BRDF to a BSDF with Integrated Subsurface Scattering".
 * Written from Mitsuba 3.9's documentation and src/bsdfs/principled.cpp (its lobes, weights,
 * sampling probabilities and pdf), so that unibeam renders scenes made for Mitsuba the same.
 *
 * Local frame: z is the shading normal as stored (never flipped: the back side is the inside
 * of the transmission lobe), x the tangent of anisotropy. wi = dirFix, wo = dirGen. Value
 * ub_principled_value() is Mitsuba's eval(), i.e. f_s |cos wo|; unibeam's f_s is that over
 * |wo.z|. Lobes (brdf = (1 - metallic)(1 - spec_trans), bsdf = (1 - metallic) spec_trans):
 *   specular reflection  F_p D G / (4 |cos i|), GGX with alpha_x, alpha_y from roughness and
 *                        anisotropic (Burley 2012, Addendum B.2: aspect = sqrt(1 - 0.9 an),
 *                        alpha = max(0.001, r^2 / aspect), r^2 aspect), separable Smith G; F_p
 *                        mixes the dielectric Fresnel term with Schlick terms for metallic
 *                        and spec_tint (front side), bsdf F on the back side;
 *   transmission         sqrt(base) bsdf (1 - F) D G eta^2 |(i.h)(o.h)| / (|cos i| (i.h +
 *                        eta o.h)^2) (Walter et al. 2007, eq. 21), times 1 / eta^2 for
 *                        radiance transport (the adjoint for importance: Veach 1997, 5.2);
 *   clearcoat            0.25 clearcoat F_schlick(0.04) D_GTR1 G_ggx(0.25) |cos o| (Burley
 *                        2012, B.2; alpha = lerp(0.1, 0.001, clearcoat_gloss)), front only;
 *   diffuse and retro    brdf base / pi (1 - F_i / 2)(1 - F_o / 2) + R_r (F_o + F_i + F_o F_i
 *                        (R_r - 1)), R_r = 2 roughness cos^2 theta_d, blended with the
 *                        Hanrahan-Krueger fake subsurface term by flatness (Burley 2015, eq. 4);
 *   sheen                sheen (1 - metallic) F_d c_sheen |cos o| (Burley 2012, B.2), only where
 *                        the diffuse lobe is on (brdf > 0), as Mitsuba's scalar variants do.
 * F_schlick weights are (1 - cos)^5 (Schlick 1994). Sampling (ub_principled_sample, host
 * only): from the front, diffuse (cosine) with probability ~ brdf rate_diffuse, clearcoat
 * (GTR1 normals) ~ 0.25 clearcoat rate_clearcoat and the main lobe ~ rate_specular, whose
 * visible GGX normal m (Heitz 2018) then reflects with probability 1 - bsdf (1 - F(i.m)) and
 * refracts otherwise; from the back, reflection with F and refraction with 1 - F. The pdf is
 * that mixture; since the mixture weights are constant per wi and the split of the main lobe
 * uses the sampled normal, ub_principled_pdf is the exact density of successful samples.
 * Measures: solid angle (pdfW). */
#ifndef UB_PRINCIPLED_H
#define UB_PRINCIPLED_H

#include "ub_fresnel.h"
#include "ub_microfacet.h"
#include "ub_vec3.h"

typedef struct {
    float base[3];
    float alphaX, alphaY; /* GGX roughness along x and y (ub_principled_alphas) */
    float roughness;      /* as given: the retro-reflection term uses it */
    float metallic, specTrans, specTint;
    float sheen, sheenTint, flatness;
    float clearcoat, clearcoatGloss;
    float eta; /* interior / exterior */
    float rateDiffuse, rateSpecular, rateClearcoat;
} ub_principled;

/* Burley 2012, Addendum B.2 (with Mitsuba's floor of 0.001). */
UB_INLINE void ub_principled_alphas(float roughness, float anisotropic, UB_PRIVATE float* alphaX,
                                    UB_PRIVATE float* alphaY) {
    float r2 = roughness * roughness;
    float aspect = ub_sqrt(1.0f - 0.9f * anisotropic);
    *alphaX = ub_fmax(0.001f, r2 / aspect);
    *alphaY = ub_fmax(0.001f, r2 * aspect);
}

UB_INLINE float ub_principled_schlick_weight(float c) {
    float m = ub_clampf(1.0f - c, 0.0f, 1.0f);
    return m * m * m * m * m;
}

/* Dielectric Fresnel term for a signed cosine with the microfacet normal (negative: from
 * inside, relative IOR 1 / eta). */
UB_INLINE float ub_principled_fresnel(float cosI, float eta) {
    return cosI >= 0.0f ? ub_fresnel_dielectric(cosI, eta)
                        : ub_fresnel_dielectric(-cosI, 1.0f / eta);
}

/* Schlick's approximation R0 + (1 - R0) w, with w at the transmitted angle when the ray
 * leaves the denser side (Mitsuba's calc_schlick). */
UB_INLINE float ub_principled_schlick(float r0, float cosI, float eta) {
    float etaIT = cosI >= 0.0f ? eta : 1.0f / eta;
    float etaTI = 1.0f / etaIT;
    float cosT = ub_sqrt(ub_fmax(0.0f, 1.0f - (1.0f - cosI * cosI) * etaTI * etaTI));
    float w = ub_principled_schlick_weight(etaIT > 1.0f ? ub_fabs(cosI) : cosT);
    return r0 + (1.0f - r0) * w;
}

UB_INLINE float ub_principled_luminance(UB_PRIVATE const ub_principled* p) {
    return 0.212671f * p->base[0] + 0.715160f * p->base[1] + 0.072169f * p->base[2];
}

/* Smith G1 of the anisotropic GGX, zero where v sees the back of m. */
UB_INLINE float ub_principled_g1(ub_float3 v, ub_float3 m, float ax, float ay) {
    if (ub_f3_dot(v, m) * v.z <= 0.0f) return 0.0f;
    float xy = ax * ax * v.x * v.x + ay * ay * v.y * v.y;
    if (xy == 0.0f) return 1.0f;
    return 2.0f / (1.0f + ub_sqrt(1.0f + xy / (v.z * v.z)));
}

/* Density of visible normals m from v (v.z > 0; Heitz 2014, eq. 38). */
UB_INLINE float ub_principled_visible_pdf(ub_float3 v, ub_float3 m, float ax, float ay) {
    float d = ub_mf_d_aniso(UB_MF_GGX, m.x, m.y, m.z, ax, ay);
    float r = d * ub_principled_g1(v, m, ax, ay) * ub_fabs(ub_f3_dot(v, m)) / v.z;
    return r > 1e-20f ? r : 0.0f;
}

/* GTR1 (Burley 2012, B.2, "gamma = 1") for the clearcoat, alpha < 1. */
UB_INLINE float ub_principled_gtr1(float cosM, float alpha) {
    float a2 = alpha * alpha;
    float r = (a2 - 1.0f) / (UB_PI * ub_log(a2) * (1.0f + (a2 - 1.0f) * cosM * cosM));
    return r * cosM > 1e-20f ? r : 0.0f;
}

/* Separable Smith G1 of an isotropic GGX with roughness alpha (the clearcoat's 0.25). */
UB_INLINE float ub_principled_g1_clearcoat(ub_float3 v, ub_float3 m, float alpha) {
    float c = ub_fabs(v.z);
    float c2 = c * c;
    float r = 2.0f / (1.0f + ub_sqrt(1.0f + alpha * alpha * (1.0f - c2) / c2));
    if (v.z == 1.0f) r = 1.0f;
    if (ub_f3_dot(v, m) * v.z <= 0.0f) r = 0.0f;
    return r;
}

/* Both directions see m from wi's side (reflection) or wo from the other side (refraction). */
UB_INLINE int ub_principled_compatible(ub_float3 m, ub_float3 wi, ub_float3 wo, int reflection) {
    float s = wi.z >= 0.0f ? 1.0f : -1.0f;
    ub_float3 ms = ub_f3_scale(m, s);
    if (!(ub_f3_dot(wi, ms) > 0.0f)) return 0;
    return reflection ? ub_f3_dot(wo, ms) > 0.0f : ub_f3_dot(wo, ms) < 0.0f;
}

/* The half vector of (wi, wo), turned to +z. */
UB_INLINE ub_float3 ub_principled_half(ub_float3 wi, ub_float3 wo, float etaPath, int reflect) {
    ub_float3 h = ub_f3_normalize(ub_f3_add(wi, ub_f3_scale(wo, reflect ? 1.0f : etaPath)));
    return h.z < 0.0f ? ub_f3_neg(h) : h;
}

/* Burley's diffuse and retro-reflection (|cos i| = ci, |cos o| = co, cd = h.o), blended with
 * the Hanrahan-Krueger fake subsurface term by flatness (Burley 2015, eq. 4); times base / pi
 * and |cos o| by the caller. Shared by principled and principledthin. */
UB_INLINE float ub_principled_diffuse_lobe(float ci, float co, float cd, float roughness,
                                           float flatness) {
    float fo = ub_principled_schlick_weight(co), fi = ub_principled_schlick_weight(ci);
    float diff = (1.0f - 0.5f * fi) * (1.0f - 0.5f * fo);
    float rr = 2.0f * roughness * cd * cd;
    float lobe = diff + rr * (fo + fi + fo * fi * (rr - 1.0f));
    if (flatness > 0.0f) {
        float fss90 = 0.5f * rr;
        float fss = (1.0f + (fss90 - 1.0f) * fo) * (1.0f + (fss90 - 1.0f) * fi);
        float ss = 1.25f * (fss * (1.0f / (co + ci) - 0.5f) + 0.5f);
        lobe = lobe + (ss - lobe) * flatness;
    }
    return lobe;
}

/* The sheen's colour: 1 blended towards base / luminance by sheenTint (Burley 2012, B.2). */
UB_INLINE void ub_principled_sheen_colour(const float base[3], float lum, float sheenTint,
                                          UB_PRIVATE float tint[3]) {
    UB_UNROLL
    for (int c = 0; c < 3; ++c) {
        float ct = lum > 0.0f ? base[c] / lum : 1.0f;
        tint[c] = 1.0f + (ct - 1.0f) * sheenTint;
    }
}

/* Lobe probabilities for wi (before the main lobe's reflection/refraction split); return
 * their sum (0: nothing to sample). */
UB_INLINE float ub_principled_lobe_weights(UB_PRIVATE const ub_principled* p, int front,
                                           UB_PRIVATE float* wDiffuse, UB_PRIVATE float* wClearcoat,
                                           UB_PRIVATE float* wMain) {
    float brdf = (1.0f - p->metallic) * (1.0f - p->specTrans);
    *wDiffuse = front ? brdf * p->rateDiffuse : 0.0f;
    *wClearcoat = front ? 0.25f * p->clearcoat * p->rateClearcoat : 0.0f;
    *wMain = front ? p->rateSpecular : 1.0f;
    return *wDiffuse + *wClearcoat + *wMain;
}

/* The main lobe's probability of reflecting (the rest refracts) at a normal with dielectric
 * Fresnel term f. */
UB_INLINE float ub_principled_reflect_prob(UB_PRIVATE const ub_principled* p, int front, float f) {
    float bsdf = (1.0f - p->metallic) * p->specTrans;
    return front ? 1.0f - bsdf * (1.0f - f) : f;
}

/* Mitsuba's pdf(wi -> wo), solid angle. */
UB_INLINE float ub_principled_pdf(UB_PRIVATE const ub_principled* p, ub_float3 wi, ub_float3 wo) {
    if (wi.z == 0.0f) return 0.0f;
    int front = wi.z > 0.0f;
    float bsdf = (1.0f - p->metallic) * p->specTrans;
    if (!front && !(bsdf > 0.0f)) return 0.0f;
    float etaPath = front ? p->eta : 1.0f / p->eta;
    int reflect = wi.z * wo.z > 0.0f, refract = wi.z * wo.z < 0.0f;
    ub_float3 h = ub_principled_half(wi, wo, etaPath, reflect);
    float f = ub_principled_fresnel(ub_f3_dot(wi, h), p->eta);
    float wD, wC, wM;
    float total = ub_principled_lobe_weights(p, front, &wD, &wC, &wM);
    if (!(total > 0.0f)) return 0.0f;
    float pr = ub_principled_reflect_prob(p, front, f);
    float oh = ub_f3_dot(wo, h), ih = ub_f3_dot(wi, h);
    float jac = reflect ? 1.0f / (4.0f * oh)
                        : etaPath * etaPath * oh / ((ih + etaPath * oh) * (ih + etaPath * oh));
    jac = ub_fabs(jac);
    ub_float3 wiUp = front ? wi : ub_f3_neg(wi);
    float pdf = 0.0f;
    if (reflect) {
        if (ub_principled_compatible(h, wi, wo, 1)) {
            pdf += wM * pr * ub_principled_visible_pdf(wiUp, h, p->alphaX, p->alphaY) * jac;
            if (wC > 0.0f) {
                float alpha = 0.1f + (0.001f - 0.1f) * p->clearcoatGloss;
                float ccPdf = h.z < 0.0f ? 0.0f : h.z * ub_principled_gtr1(h.z, alpha);
                pdf += wC * ccPdf * jac;
            }
        }
        pdf += wD * UB_INV_PI * wo.z;
    } else if (refract && ub_principled_compatible(h, wi, wo, 0)) {
        pdf += wM * (1.0f - pr) * ub_principled_visible_pdf(wiUp, h, p->alphaX, p->alphaY) * jac;
    }
    return pdf / total;
}

/* Mitsuba's eval(wi -> wo) = f_s |cos wo| for channel values; fromLight: importance
 * transport (no 1 / eta^2 on the transmission). */
UB_INLINE ub_float3 ub_principled_value(UB_PRIVATE const ub_principled* p, ub_float3 wi,
                                        ub_float3 wo, int fromLight) {
    ub_float3 v = ub_make_float3(0.0f, 0.0f, 0.0f);
    if (wi.z == 0.0f) return v;
    float brdf = (1.0f - p->metallic) * (1.0f - p->specTrans);
    float bsdf = (1.0f - p->metallic) * p->specTrans;
    int front = wi.z > 0.0f;
    int reflect = wi.z * wo.z > 0.0f, refract = wi.z * wo.z < 0.0f;
    float etaPath = front ? p->eta : 1.0f / p->eta;
    ub_float3 h = ub_principled_half(wi, wo, etaPath, reflect);
    float ih = ub_f3_dot(wi, h), oh = ub_f3_dot(wo, h);
    float f = ub_principled_fresnel(ih, p->eta);
    int compatR = ub_principled_compatible(h, wi, wo, 1);
    int compatT = ub_principled_compatible(h, wi, wo, 0);
    float d = ub_mf_d_aniso(UB_MF_GGX, h.x, h.y, h.z, p->alphaX, p->alphaY);
    float g = ub_principled_g1(wi, h, p->alphaX, p->alphaY) *
              ub_principled_g1(wo, h, p->alphaX, p->alphaY);
    float ci = ub_fabs(wi.z), co = ub_fabs(wo.z);
    float lum = ub_principled_luminance(p);
    if (reflect && compatR && f > 0.0f) {
        /* Mitsuba's principled_fresnel */
        float etaIT = ih >= 0.0f ? p->eta : 1.0f / p->eta;
        float r0 = (etaIT - 1.0f) / (etaIT + 1.0f);
        r0 *= r0;
        float spec[3];
        UB_UNROLL
        for (int c = 0; c < 3; ++c) {
            float fp;
            if (front) {
                float tint = lum > 0.0f ? p->base[c] / lum : 1.0f;
                float schlick = p->metallic * ub_principled_schlick(p->base[c], ih, p->eta) +
                                (1.0f - p->metallic) * p->specTint *
                                    ub_principled_schlick(tint * r0, ih, p->eta);
                fp = (1.0f - p->metallic) * (1.0f - p->specTint) * f + schlick;
            } else {
                fp = bsdf * f;
            }
            spec[c] = fp * d * g / (4.0f * ci);
        }
        v = ub_f3_add(v, ub_make_float3(spec[0], spec[1], spec[2]));
    }
    if (bsdf > 0.0f && refract && compatT && f < 1.0f) {
        float scale = fromLight ? 1.0f : 1.0f / (etaPath * etaPath);
        float den = ih + etaPath * oh;
        float t = bsdf * ub_fabs(scale * (1.0f - f) * d * g * etaPath * etaPath * ih * oh /
                                 (wi.z * den * den));
        v = ub_f3_add(v, ub_make_float3(ub_sqrt(p->base[0]) * t, ub_sqrt(p->base[1]) * t,
                                        ub_sqrt(p->base[2]) * t));
    }
    if (p->clearcoat > 0.0f && reflect && compatR && front) {
        float alpha = 0.1f + (0.001f - 0.1f) * p->clearcoatGloss;
        float fcc = ub_principled_schlick(0.04f, ih, p->eta);
        float gcc =
            ub_principled_g1_clearcoat(wi, h, 0.25f) * ub_principled_g1_clearcoat(wo, h, 0.25f);
        float cc = 0.25f * p->clearcoat * fcc * ub_principled_gtr1(h.z, alpha) * gcc * co;
        v = ub_f3_add(v, ub_make_float3(cc, cc, cc));
    }
    if (brdf > 0.0f && reflect && front) {
        float cd = ub_f3_dot(h, wo);
        float k = brdf * co * UB_INV_PI *
                  ub_principled_diffuse_lobe(ci, co, cd, p->roughness, p->flatness);
        v = ub_f3_add(v, ub_make_float3(k * p->base[0], k * p->base[1], k * p->base[2]));
        if (p->sheen > 0.0f && 1.0f - p->metallic > 0.0f) {
            float s =
                p->sheen * (1.0f - p->metallic) * ub_principled_schlick_weight(ub_fabs(cd)) * co;
            float tint[3];
            ub_principled_sheen_colour(p->base, lum, p->sheenTint, tint);
            v = ub_f3_add(v, ub_make_float3(s * tint[0], s * tint[1], s * tint[2]));
        }
    }
    return v;
}

/* Samples wo from wi with (u1, u2, u3) in [0,1)^3 as Mitsuba does (banner); returns 0 where
 * the sample fails (the lobe's direction leaves on the wrong side of the macro- or
 * microsurface). The caller evaluates the value and pdf of *wo. */
UB_INLINE int ub_principled_sample(UB_PRIVATE const ub_principled* p, ub_float3 wi, float u1,
                                   float u2, float u3, UB_PRIVATE ub_float3* wo) {
    if (wi.z == 0.0f) return 0;
    int front = wi.z > 0.0f;
    float bsdf = (1.0f - p->metallic) * p->specTrans;
    if (!front && !(bsdf > 0.0f)) return 0;
    float wD, wC, wM;
    float total = ub_principled_lobe_weights(p, front, &wD, &wC, &wM);
    if (!(total > 0.0f)) return 0;
    float u = u3 * total;
    if (u < wD) { /* cosine-weighted hemisphere (Malley's method) */
        float r = ub_sqrt(u1), phi = 2.0f * UB_PI * u2;
        *wo = ub_make_float3(r * ub_cos(phi), r * ub_sin(phi), ub_sqrt(ub_fmax(0.0f, 1.0f - u1)));
        return wo->z > 0.0f;
    }
    if (u < wD + wC) { /* GTR1 normal, reflected */
        float alpha = 0.1f + (0.001f - 0.1f) * p->clearcoatGloss;
        float a2 = alpha * alpha;
        float cos2 = (1.0f - ub_pow(a2, 1.0f - u2)) / (1.0f - a2);
        float sinT = ub_sqrt(ub_fmax(0.0f, 1.0f - cos2)), cosT = ub_sqrt(ub_fmax(0.0f, cos2));
        float phi = 2.0f * UB_PI * u1;
        ub_float3 m = ub_make_float3(ub_cos(phi) * sinT, ub_sin(phi) * sinT, cosT);
        *wo = ub_f3_sub(ub_f3_scale(m, 2.0f * ub_f3_dot(wi, m)), wi);
        return wo->z > 0.0f && ub_principled_compatible(m, wi, *wo, 1);
    }
    /* main lobe: a visible GGX normal seen from wi mirrored to +z */
    float s = front ? 1.0f : -1.0f;
    float mx, my, mz;
    ub_ggx_sample_visible(s * wi.x, s * wi.y, s * wi.z, p->alphaX, p->alphaY, u1, u2, &mx, &my,
                          &mz);
    ub_float3 m = ub_make_float3(mx, my, mz);
    float c = ub_f3_dot(wi, m);
    float f = ub_principled_fresnel(c, p->eta);
    float uMain = (u - wD - wC) / wM;
    if (uMain < ub_principled_reflect_prob(p, front, f)) {
        *wo = ub_f3_sub(ub_f3_scale(m, 2.0f * c), wi);
        return wi.z * wo->z > 0.0f && ub_principled_compatible(m, wi, *wo, 1);
    }
    /* refraction through m: Snell's law with eta_ti = 1 / eta from outside */
    float etaTI = c >= 0.0f ? 1.0f / p->eta : p->eta;
    float cos2T = 1.0f - etaTI * etaTI * (1.0f - c * c);
    if (!(cos2T > 0.0f)) return 0;
    float cosT = c >= 0.0f ? -ub_sqrt(cos2T) : ub_sqrt(cos2T);
    *wo = ub_f3_sub(ub_f3_scale(m, c * etaTI + cosT), ub_f3_scale(wi, etaTI));
    return wi.z * wo->z < 0.0f && ub_principled_compatible(m, wi, *wo, 0);
}

#endif /* UB_PRINCIPLED_H */
