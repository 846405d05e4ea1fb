/* GGX (Trowbridge-Reitz) and Beckmann microfacet distributions, isotropic roughness
 * alpha or anisotropic (alphaU along the frame's x = s axis, alphaV along y = t; the
 * ub_mf_*_aniso functions) (host C++ and OpenCL C). Local frame: z is the macro-surface normal, and
 * every function here assumes the directions were mirrored to z >= 0 by the
 * caller (GGX is symmetric under z -> -z).
 *
 *  D      Walter et al. 2007, eq. 33 (Trowbridge & Reitz 1975).
 *  Lambda Smith's auxiliary function for GGX (Heitz 2014, "Understanding the
 *         masking-shadowing function in microfacet-based BRDFs", eq. 72).
 *  G1     Smith masking 1 / (1 + Lambda) (Heitz 2014, eq. 43).
 *  G2     height-correlated masking-shadowing 1 / (1 + Lambda(i) + Lambda(o))
 *         for reflection (Heitz 2014, eq. 99); separable G1(i) G1(o) for
 *         transmission (Walter et al. 2007, eq. 23; Heitz 2014, eq. 98).
 *  Sampling of visible normals: Heitz 2018, "Sampling the GGX distribution of
 *         visible normals" (JCGT 7(4)), whose density is
 *         D_v(m) = G1(v) max(0, v.m) D(m) / v.z   (Heitz 2014, eq. 38).
 *  Beckmann: D = exp(-tan^2 / alpha^2) / (pi alpha^2 cos^4) (Walter et al. 2007, eq. 25;
 *         Beckmann & Spizzichino 1963); Lambda(v) = (erf(a) - 1) / 2 + exp(-a^2) /
 *         (2 a sqrt(pi)), a = 1 / (alpha tan theta_v) (Walter et al. 2007, eq. 27 as
 *         Lambda; Heitz 2014, eq. 80). Its visible normals are sampled on the host
 *         (src/scene/microfacet_sampling.cpp); the density is D_v above with Beckmann D, G1.
 *  ub_mf_*: the same quantities for either distribution (UB_MF_GGX, UB_MF_BECKMANN).
 *  Anisotropy (Heitz 2014, Sec. 5.4): D(m) with tan^2 theta_m / alpha^2 replaced by
 *         (m.x^2 / alphaU^2 + m.y^2 / alphaV^2) / m.z^2 and the normalisation 1 / alpha^2 by
 *         1 / (alphaU alphaV); Lambda(v) is the isotropic one with the roughness seen along
 *         v's azimuth, alpha_v = sqrt(cos^2 phi_v alphaU^2 + sin^2 phi_v alphaV^2). Visible
 *         normals: the stretch to alpha = 1 scales x by alphaU and y by alphaV (Heitz 2018,
 *         Sec. 3; Heitz & d'Eon 2014, Sec. 4). Equal roughnesses take the isotropic code.
 *  Jacobians from the microfacet normal to the generated direction:
 *         reflection 1 / (4 |o.m|) (Walter et al. 2007, eq. 14),
 *         refraction eta_o^2 |o.m| / (eta_i (i.m) + eta_o (o.m))^2 (eq. 17).
 */
#ifndef UB_MICROFACET_H
#define UB_MICROFACET_H

#include "ub_defs.h"

/* D(m) for a microfacet normal with m.z = cosThetaM; zero below the surface. */
UB_INLINE float ub_ggx_d(float cosThetaM, float alpha) {
    if (cosThetaM <= 0.0f) return 0.0f;
    float a2 = alpha * alpha;
    /* cos^4 (alpha^2 + tan^2)^2 written as (cos^2 (alpha^2 - 1) + 1)^2 */
    float t = cosThetaM * cosThetaM * (a2 - 1.0f) + 1.0f;
    return a2 / (UB_PI * t * t);
}

/* Lambda(v) = (-1 + sqrt(1 + alpha^2 tan^2(theta_v))) / 2, cosTheta = v.z. */
UB_INLINE float ub_ggx_lambda(float cosTheta, float alpha) {
    float c2 = cosTheta * cosTheta;
    if (c2 <= 0.0f) return 1e30f;
    float tan2 = ub_fmax(0.0f, 1.0f - c2) / c2;
    return 0.5f * (-1.0f + ub_sqrt(1.0f + alpha * alpha * tan2));
}

UB_INLINE float ub_ggx_g1(float cosTheta, float alpha) {
    return 1.0f / (1.0f + ub_ggx_lambda(cosTheta, alpha));
}

/* Height-correlated Smith G2 (reflection). */
UB_INLINE float ub_ggx_g2_correlated(float cosThetaI, float cosThetaO, float alpha) {
    return 1.0f / (1.0f + ub_ggx_lambda(cosThetaI, alpha) + ub_ggx_lambda(cosThetaO, alpha));
}

/* Separable Smith G2 (transmission). */
UB_INLINE float ub_ggx_g2_separable(float cosThetaI, float cosThetaO, float alpha) {
    return ub_ggx_g1(cosThetaI, alpha) * ub_ggx_g1(cosThetaO, alpha);
}

/* Density of ub_ggx_sample_visible: D_v(m) = G1(v) max(0, v.m) D(m) / v.z,
 * with v.z = cosThetaV > 0, vDotM = v.m, m.z = cosThetaM. */
UB_INLINE float ub_ggx_visible_pdf(float cosThetaV, float vDotM, float cosThetaM, float alpha) {
    if (cosThetaV <= 0.0f || vDotM <= 0.0f) return 0.0f;
    return ub_ggx_g1(cosThetaV, alpha) * vDotM * ub_ggx_d(cosThetaM, alpha) / cosThetaV;
}

/* Samples a microfacet normal m visible from v (v.z > 0, unit) from (u1, u2) in [0,1)^2
 * (Heitz 2018, Sec. 3-4) for roughness alphaU along x and alphaV along y (equal: isotropic):
 * stretch v to the alpha = 1 configuration, sample the projected half disk, lift it onto
 * the hemisphere, unstretch. */
UB_INLINE void ub_ggx_sample_visible(float vx, float vy, float vz, float alphaU, float alphaV,
                                     float u1, float u2, UB_PRIVATE float* mx, UB_PRIVATE float* my,
                                     UB_PRIVATE float* mz) {
    /* Stretched view direction. */
    float hx = alphaU * vx, hy = alphaV * vy, hz = vz;
    float inv = 1.0f / ub_sqrt(hx * hx + hy * hy + hz * hz);
    hx *= inv;
    hy *= inv;
    hz *= inv;
    /* Orthonormal basis (t1, t2, h); t1 is horizontal. */
    float lensq = hx * hx + hy * hy;
    float t1x = 1.0f, t1y = 0.0f;
    if (lensq > 0.0f) {
        float il = 1.0f / ub_sqrt(lensq);
        t1x = -hy * il;
        t1y = hx * il;
    }
    /* t2 = h x t1 with t1.z = 0. */
    float t2x = -hz * t1y;
    float t2y = hz * t1x;
    float t2z = hx * t1y - hy * t1x;
    /* Uniform point on the unit disk, the second coordinate squeezed onto the
     * visible part of the projected hemisphere. */
    float r = ub_sqrt(u1);
    float phi = 2.0f * UB_PI * u2;
    float p1 = r * ub_cos(phi);
    float p2 = r * ub_sin(phi);
    float s = 0.5f * (1.0f + hz);
    p2 = (1.0f - s) * ub_sqrt(ub_fmax(0.0f, 1.0f - p1 * p1)) + s * p2;
    float p3 = ub_sqrt(ub_fmax(0.0f, 1.0f - p1 * p1 - p2 * p2));
    /* Normal in the stretched configuration, then unstretched. */
    float nx = p1 * t1x + p2 * t2x + p3 * hx;
    float ny = p1 * t1y + p2 * t2y + p3 * hy;
    float nz = p2 * t2z + p3 * hz;
    float ex = alphaU * nx, ey = alphaV * ny, ez = ub_fmax(1e-7f, nz);
    float ie = 1.0f / ub_sqrt(ex * ex + ey * ey + ez * ez);
    *mx = ex * ie;
    *my = ey * ie;
    *mz = ez * ie;
}

/* Beckmann D(m), m.z = cosThetaM; zero below the surface. */
UB_INLINE float ub_beckmann_d(float cosThetaM, float alpha) {
    if (cosThetaM <= 0.0f) return 0.0f;
    float c2 = cosThetaM * cosThetaM, a2 = alpha * alpha;
    float tan2 = ub_fmax(0.0f, 1.0f - c2) / c2;
    return ub_exp(-tan2 / a2) / (UB_PI * a2 * c2 * c2);
}

/* Beckmann Lambda(v), cosTheta = v.z > 0 (written with erfc: (erf(a) - 1) / 2 = -erfc(a) / 2,
 * exact for large a where erf(a) rounds to 1). */
UB_INLINE float ub_beckmann_lambda(float cosTheta, float alpha) {
    float c2 = cosTheta * cosTheta;
    if (c2 <= 0.0f) return 1e30f;
    float s2 = ub_fmax(0.0f, 1.0f - c2);
    if (s2 <= 0.0f) return 0.0f;
    float a = cosTheta / (alpha * ub_sqrt(s2)); /* 1 / (alpha tan theta) */
    if (a > 9.0f) return 0.0f;                  /* exp(-81): below float resolution of 1 + Lambda */
    return 0.5f * (ub_exp(-a * a) / (a * 1.7724538509055160273f) - ub_erfc(a));
}

#define UB_MF_GGX 0u
#define UB_MF_BECKMANN 1u

UB_INLINE float ub_mf_d(ub_uint dist, float cosThetaM, float alpha) {
    return dist == UB_MF_BECKMANN ? ub_beckmann_d(cosThetaM, alpha) : ub_ggx_d(cosThetaM, alpha);
}
UB_INLINE float ub_mf_lambda(ub_uint dist, float cosTheta, float alpha) {
    return dist == UB_MF_BECKMANN ? ub_beckmann_lambda(cosTheta, alpha)
                                  : ub_ggx_lambda(cosTheta, alpha);
}
UB_INLINE float ub_mf_g1(ub_uint dist, float cosTheta, float alpha) {
    return 1.0f / (1.0f + ub_mf_lambda(dist, cosTheta, alpha));
}
UB_INLINE float ub_mf_g2_correlated(ub_uint dist, float cosThetaI, float cosThetaO, float alpha) {
    return 1.0f /
           (1.0f + ub_mf_lambda(dist, cosThetaI, alpha) + ub_mf_lambda(dist, cosThetaO, alpha));
}
UB_INLINE float ub_mf_g2_separable(ub_uint dist, float cosThetaI, float cosThetaO, float alpha) {
    return ub_mf_g1(dist, cosThetaI, alpha) * ub_mf_g1(dist, cosThetaO, alpha);
}
/* D_v(m) = G1(v) max(0, v.m) D(m) / v.z (Heitz 2014, eq. 38) for either distribution. */
UB_INLINE float ub_mf_visible_pdf(ub_uint dist, float cosThetaV, float vDotM, float cosThetaM,
                                  float alpha) {
    if (cosThetaV <= 0.0f || vDotM <= 0.0f) return 0.0f;
    return ub_mf_g1(dist, cosThetaV, alpha) * vDotM * ub_mf_d(dist, cosThetaM, alpha) / cosThetaV;
}

/* Anisotropic roughness (banner): the roughness seen along the azimuth of (vx, vy). */
UB_INLINE float ub_mf_alpha_along(float vx, float vy, float alphaU, float alphaV) {
    if (alphaU == alphaV) return alphaU;
    float r2 = vx * vx + vy * vy;
    if (!(r2 > 0.0f)) return alphaU; /* normal incidence: Lambda = 0 for any roughness */
    return ub_sqrt((vx * vx * alphaU * alphaU + vy * vy * alphaV * alphaV) / r2);
}
/* D(m) for a unit microfacet normal m (Heitz 2014, Sec. 5.4: GGX and Beckmann). */
UB_INLINE float ub_mf_d_aniso(ub_uint dist, float mx, float my, float mz, float alphaU,
                              float alphaV) {
    if (alphaU == alphaV) return ub_mf_d(dist, mz, alphaU);
    if (mz <= 0.0f) return 0.0f;
    float x = mx / alphaU, y = my / alphaV;
    float slope2 = x * x + y * y; /* m.z^2 tan^2 theta (cos^2 phi / aU^2 + sin^2 phi / aV^2) */
    float mz2 = mz * mz;
    if (dist == UB_MF_BECKMANN)
        return ub_exp(-slope2 / mz2) / (UB_PI * alphaU * alphaV * mz2 * mz2);
    float t = mz2 + slope2; /* cos^2 (1 + tan^2 (...)) */
    return 1.0f / (UB_PI * alphaU * alphaV * t * t);
}
UB_INLINE float ub_mf_lambda_aniso(ub_uint dist, float vx, float vy, float vz, float alphaU,
                                   float alphaV) {
    return ub_mf_lambda(dist, vz, ub_mf_alpha_along(vx, vy, alphaU, alphaV));
}
UB_INLINE float ub_mf_g1_aniso(ub_uint dist, float vx, float vy, float vz, float alphaU,
                               float alphaV) {
    return 1.0f / (1.0f + ub_mf_lambda_aniso(dist, vx, vy, vz, alphaU, alphaV));
}
/* D_v(m) = G1(v) max(0, v.m) D(m) / v.z (Heitz 2014, eq. 38), v = (vx, vy, vz) with vz > 0
 * and m unit; vDotM = v.m. */
UB_INLINE float ub_mf_visible_pdf_aniso(ub_uint dist, float vx, float vy, float vz, float vDotM,
                                        float mx, float my, float mz, float alphaU, float alphaV) {
    if (vz <= 0.0f || vDotM <= 0.0f) return 0.0f;
    return ub_mf_g1_aniso(dist, vx, vy, vz, alphaU, alphaV) * vDotM *
           ub_mf_d_aniso(dist, mx, my, mz, alphaU, alphaV) / vz;
}

/* |d omega_o / d omega_m| for reflection (Walter et al. 2007, eq. 14). */
UB_INLINE float ub_jacobian_reflect(float oDotM) {
    return 1.0f / (4.0f * ub_fabs(oDotM));
}

/* |d omega_o / d omega_m| for refraction from the side of i (IOR etaI) to the side of o
 * (IOR etaO) (Walter et al. 2007, eq. 17). */
UB_INLINE float ub_jacobian_refract(float etaI, float iDotM, float etaO, float oDotM) {
    float denom = etaI * iDotM + etaO * oDotM;
    return etaO * etaO * ub_fabs(oDotM) / (denom * denom);
}

#endif /* UB_MICROFACET_H */
