/* Mitsuba 3's `principledthin` BSDF (host C++ and OpenCL C): the thin-surface variant of the
 * principled BSDF (Burley 2015, "Extending the Disney BRDF to a BSDF with Integrated
 * Subsurface Scattering", Sec. 4: thin surfaces), written from Mitsuba 3.9's documentation and
 * src/bsdfs/principledthin.cpp. A sheet of no thickness, the same from both sides: wi and wo
 * are mirrored so that wi.z > 0 (the caller flips the frame to dirFix's side, as for a
 * two-sided material); rays pass without bending.
 *
 * Value ub_principled_thin_value() is Mitsuba's eval() = f_s |cos wo| (no transport-mode
 * factor: nothing bends). Lobes, with st = spec_trans and dt = diff_trans / 2:
 *   specular reflection    st F_thin D G / (4 cos i), GGX of roughness (alpha_x, alpha_y) as
 *                          ub_principled_alphas; F_thin = lerp(F(i.h, eta), Schlick(c_tint R0),
 *                          spec_tint);
 *   specular transmission  st base (1 - F) D_s G_s / (4 cos i): wo mirrored to the front is the
 *                          reflection about h (no bending), with the roughness scaled by
 *                          (0.65 eta - 0.35) (Burley 2015, Fig. 15);
 *   diffuse and retro      (1 - st)(1 - dt) base / pi (Burley's diffuse + retro, blended with
 *                          the fake subsurface term by flatness) |cos o|, and the sheen;
 *   diffuse transmission   (1 - st) dt base / pi |cos o|.
 * Sampling picks a lobe with constant probabilities (st r_sr / 2, st r_st / 2, r_dr (1 - st)
 * (1 - dt), r_dt (1 - st) dt, normalised): visible GGX normals for the two specular lobes
 * (Heitz 2018), cosine-weighted hemispheres for the diffuse ones. The pdf is that mixture,
 * exact. Measures: solid angle (pdfW). */
#ifndef UB_PRINCIPLED_THIN_H
#define UB_PRINCIPLED_THIN_H

#include "ub_principled.h"

typedef struct {
    float base[3];
    float roughness, anisotropic;
    float specTrans, specTint, sheen, sheenTint, flatness;
    float diffTrans; /* Mitsuba's diff_trans, in [0, 2] */
    float eta;
    float rateSpecRefl, rateSpecTrans, rateDiffRefl, rateDiffTrans;
} ub_principled_thin;

/* The four lobe probabilities (specular reflection, specular transmission, diffuse
 * reflection, diffuse transmission), normalised; returns 0 if all vanish. */
UB_INLINE int ub_principled_thin_probs(UB_PRIVATE const ub_principled_thin* p,
                                       UB_PRIVATE float pr[4]) {
    float st = p->specTrans, dt = 0.5f * p->diffTrans;
    pr[0] = st * p->rateSpecRefl * 0.5f;
    pr[1] = st * p->rateSpecTrans * 0.5f;
    pr[2] = p->rateDiffRefl * (1.0f - st) * (1.0f - dt);
    pr[3] = p->rateDiffTrans * (1.0f - st) * dt;
    float total = pr[0] + pr[1] + pr[2] + pr[3];
    if (!(total > 0.0f)) return 0;
    UB_UNROLL
    for (int k = 0; k < 4; ++k) pr[k] /= total;
    return 1;
}

/* Roughness of the transmission lobe (Burley 2015, Fig. 15). */
UB_INLINE void ub_principled_thin_alphas(UB_PRIVATE const ub_principled_thin* p, int transmission,
                                         UB_PRIVATE float* ax, UB_PRIVATE float* ay) {
    float r = transmission ? (0.65f * p->eta - 0.35f) * p->roughness : p->roughness;
    ub_principled_alphas(r, p->anisotropic, ax, ay);
}

/* Mitsuba's pdf(wi -> wo) for wi.z > 0 (the caller's frame is on wi's side). */
UB_INLINE float ub_principled_thin_pdf(UB_PRIVATE const ub_principled_thin* p, ub_float3 wi,
                                       ub_float3 wo) {
    if (!(wi.z > 0.0f)) return 0.0f;
    float pr[4];
    if (!ub_principled_thin_probs(p, pr)) return 0.0f;
    int reflect = wo.z > 0.0f, refract = wo.z < 0.0f;
    float pdf = 0.0f;
    if (p->specTrans > 0.0f) {
        ub_float3 woR = ub_make_float3(wo.x, wo.y, ub_fabs(wo.z));
        ub_float3 h = ub_f3_normalize(ub_f3_add(wi, woR));
        float jac = ub_fabs(1.0f / (4.0f * ub_f3_dot(woR, h)));
        float ax, ay;
        if (reflect && ub_principled_compatible(h, wi, wo, 1)) {
            ub_principled_thin_alphas(p, 0, &ax, &ay);
            pdf += pr[0] * ub_principled_visible_pdf(wi, h, ax, ay) * jac;
        }
        if (refract && ub_principled_compatible(h, wi, wo, 0)) {
            ub_principled_thin_alphas(p, 1, &ax, &ay);
            pdf += pr[1] * ub_principled_visible_pdf(wi, h, ax, ay) * jac;
        }
    }
    if (reflect) pdf += pr[2] * UB_INV_PI * wo.z;
    if (refract) pdf += pr[3] * UB_INV_PI * (-wo.z);
    return pdf;
}

/* Mitsuba's eval(wi -> wo) = f_s |cos wo| for wi.z > 0. */
UB_INLINE ub_float3 ub_principled_thin_value(UB_PRIVATE const ub_principled_thin* p, ub_float3 wi,
                                             ub_float3 wo) {
    ub_float3 v = ub_make_float3(0.0f, 0.0f, 0.0f);
    if (!(wi.z > 0.0f)) return v;
    float st = p->specTrans, dt = 0.5f * p->diffTrans;
    int reflect = wo.z > 0.0f, refract = wo.z < 0.0f;
    float ci = wi.z, co = ub_fabs(wo.z);
    ub_float3 woR = ub_make_float3(wo.x, wo.y, co);
    ub_float3 h = ub_f3_normalize(ub_f3_add(wi, woR));
    float lum = 0.212671f * p->base[0] + 0.715160f * p->base[1] + 0.072169f * p->base[2];
    if (st > 0.0f) {
        float ih = ub_f3_dot(wi, h);
        float f = ub_principled_fresnel(ih, p->eta);
        float ax, ay;
        if (reflect && ub_principled_compatible(h, wi, wo, 1)) {
            ub_principled_thin_alphas(p, 0, &ax, &ay);
            float d = ub_mf_d_aniso(UB_MF_GGX, h.x, h.y, h.z, ax, ay);
            float g = ub_principled_g1(wi, h, ax, ay) * ub_principled_g1(wo, h, ax, ay);
            float etaIT = ih >= 0.0f ? p->eta : 1.0f / p->eta;
            float r0 = (etaIT - 1.0f) / (etaIT + 1.0f);
            r0 *= r0;
            float spec[3];
            UB_UNROLL
            for (int c = 0; c < 3; ++c) {
                float tint = lum > 0.0f ? p->base[c] / lum : 1.0f;
                float fs = ub_principled_schlick(tint * r0, ih, p->eta);
                float ft = f + (fs - f) * p->specTint;
                spec[c] = st * ft * d * g / (4.0f * ci);
            }
            v = ub_f3_add(v, ub_make_float3(spec[0], spec[1], spec[2]));
        }
        if (refract && ub_principled_compatible(h, wi, wo, 0)) {
            ub_principled_thin_alphas(p, 1, &ax, &ay);
            float d = ub_mf_d_aniso(UB_MF_GGX, h.x, h.y, h.z, ax, ay);
            float g = ub_principled_g1(wi, h, ax, ay) * ub_principled_g1(wo, h, ax, ay);
            float t = st * (1.0f - f) * d * g / (4.0f * ci);
            v = ub_f3_add(v, ub_make_float3(t * p->base[0], t * p->base[1], t * p->base[2]));
        }
    }
    if (reflect && st < 1.0f && dt < 1.0f) {
        float cd = ub_f3_dot(h, wo);
        float k = (1.0f - st) * co * UB_INV_PI * (1.0f - dt) *
                  ub_principled_diffuse_lobe(ci, co, cd, p->roughness, p->flatness);
        v = ub_f3_add(v, ub_make_float3(k * p->base[0], k * p->base[1], k * p->base[2]));
        if (p->sheen > 0.0f) {
            float s = p->sheen * (1.0f - st) * ub_principled_schlick_weight(ub_fabs(cd)) *
                      (1.0f - dt) * co;
            float tint[3];
            ub_principled_sheen_colour(p->base, lum, p->sheenTint, tint);
            v = ub_f3_add(v, ub_make_float3(s * tint[0], s * tint[1], s * tint[2]));
        }
    }
    if (refract && st < 1.0f && dt > 0.0f) {
        float k = (1.0f - st) * dt * UB_INV_PI * co;
        v = ub_f3_add(v, ub_make_float3(k * p->base[0], k * p->base[1], k * p->base[2]));
    }
    return v;
}

/* Samples wo from wi (wi.z > 0) with (u1, u2, u3) in [0,1)^3 (banner); returns 0 where the
 * sample fails. */
UB_INLINE int ub_principled_thin_sample(UB_PRIVATE const ub_principled_thin* p, ub_float3 wi,
                                        float u1, float u2, float u3, UB_PRIVATE ub_float3* wo) {
    if (!(wi.z > 0.0f)) return 0;
    float pr[4];
    if (!ub_principled_thin_probs(p, pr)) return 0;
    if (u3 < pr[0] + pr[1]) {
        int transmission = u3 >= pr[0];
        float ax, ay, mx, my, mz;
        ub_principled_thin_alphas(p, transmission, &ax, &ay);
        ub_ggx_sample_visible(wi.x, wi.y, wi.z, ax, ay, u1, u2, &mx, &my, &mz);
        ub_float3 m = ub_make_float3(mx, my, mz);
        *wo = ub_f3_sub(ub_f3_scale(m, 2.0f * ub_f3_dot(wi, m)), wi);
        if (transmission) wo->z = -wo->z; /* through the sheet, unbent */
        return transmission ? (wo->z < 0.0f && ub_principled_compatible(m, wi, *wo, 0))
                            : (wo->z > 0.0f && ub_principled_compatible(m, wi, *wo, 1));
    }
    float r = ub_sqrt(u1), phi = 2.0f * UB_PI * u2;
    float z = ub_sqrt(ub_fmax(0.0f, 1.0f - u1));
    *wo = ub_make_float3(r * ub_cos(phi), r * ub_sin(phi), u3 < pr[0] + pr[1] + pr[2] ? z : -z);
    return wo->z != 0.0f;
}

#endif /* UB_PRINCIPLED_THIN_H */
