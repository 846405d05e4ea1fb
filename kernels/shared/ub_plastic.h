/* Coated-diffuse ("plastic") and thin-sheet lobe math (host C++ and OpenCL C).
 *
 * Plastic, after Mitsuba 3's `plastic` / `roughplastic` (Weidlich & Wilkie 2007,
 * "Arbitrarily layered micro-facet surfaces"; Kelemen & Szirmay-Kalos 2001 for the
 * coupling of a specular coating and a diffuse base): a dielectric coating of
 * relative IOR eta = n_inside / n_outside over a Lambertian base of albedo rho.
 * Light refracted into the layer bounces between the base and the underside of the
 * coating; summing the geometric series of internal reflections gives the diffuse
 * term
 *   f_d(i, o) = rho / (1 - Fdr_int) * T(i) T(o) / (pi eta^2)           (linear)
 *   f_d(i, o) = rho / (1 - rho Fdr_int) * T(i) T(o) / (pi eta^2)       (nonlinear)
 * where T is the coating's directional transmittance (1 - F for a smooth coating)
 * and Fdr_int the hemispherical (cosine-weighted) reflectance of the coating seen
 * from inside. The 1/eta^2 accounts for the compression of solid angle across the
 * interface. "linear" (Mitsuba's default, nonlinear = false) keeps the texture
 * colour: the sum is taken with an albedo-1 base.
 *
 * Thin dielectric (Mitsuba 3's `thindielectric`): a sheet with two parallel smooth
 * interfaces; light refracting into it leaves either side after any number of
 * internal reflections. With single-interface reflectance r, the total reflectance
 * is r + (1-r)^2 r (1 + r^2 + r^4 + ...) = 2r / (1 + r) (Stokes' relations for a
 * plate without absorption) and the rest, (1 - r) / (1 + r), is transmitted along
 * the incident direction (the two refractions cancel).
 */
#ifndef UB_PLASTIC_H
#define UB_PLASTIC_H

#include "ub_defs.h"

/* Number of cos(theta) samples of a rough plastic's coating-transmittance table,
 * uniform in mu = cos(theta) over [0, 1] (as Mitsuba 3's roughplastic). */
#define UB_ROUGH_PLASTIC_TABLE_SIZE 64

/* Hemispherical diffuse Fresnel reflectance Fdr(eta) = 2 int_0^1 F(mu, eta) mu dmu for
 * light arriving uniformly (cosine-weighted) from the side of relative IOR eta =
 * n_transmitted / n_incident. Polynomial fits: eta < 1, Egan & Hilgeman 1973
 * (as quoted by d'Eon & Irving 2011, eq. 6; < 0.6% error for 1/eta < 2); eta >= 1,
 * d'Eon & Irving 2011, "A quantized-diffusion model for rendering translucent
 * materials", eq. 5 (< 0.2% error up to eta = 10). Mitsuba 3 uses the same pair. */
UB_INLINE float ub_fresnel_diffuse_reflectance(float eta) {
    float invEta = 1.0f / eta;
    if (eta < 1.0f) return 0.0636f * invEta + eta * (eta * -1.4399f + 0.7099f) + 0.6681f;
    /* Horner form of sum_k c_k invEta^k, c = (0.919317, -3.4793, 6.75335, -7.80989,
     * 4.98554, -1.36881). */
    float r = -1.36881f;
    r = r * invEta + 4.98554f;
    r = r * invEta - 7.80989f;
    r = r * invEta + 6.75335f;
    r = r * invEta - 3.4793f;
    r = r * invEta + 0.919317f;
    return r;
}

/* Diffuse-base factor of the plastic models: rho / (1 - Fint) (linear) or
 * rho / (1 - rho Fint) (nonlinear), for one channel. */
UB_INLINE float ub_plastic_base(float rho, float internalReflectance, int nonlinear) {
    float denom = 1.0f - (nonlinear ? rho * internalReflectance : internalReflectance);
    return denom > 0.0f ? rho / denom : 0.0f;
}

/* Linear interpolation in a table of UB_ROUGH_PLASTIC_TABLE_SIZE values sampled at
 * mu_k = k / (size - 1); mu outside [0, 1] is clamped. */
UB_INLINE float ub_plastic_table_lookup(UB_GLOBAL const float* table, float mu) {
    float x = ub_clampf(mu, 0.0f, 1.0f) * (float)(UB_ROUGH_PLASTIC_TABLE_SIZE - 1);
    int i = (int)x;
    if (i > UB_ROUGH_PLASTIC_TABLE_SIZE - 2) i = UB_ROUGH_PLASTIC_TABLE_SIZE - 2;
    float w = x - (float)i;
    return (1.0f - w) * table[i] + w * table[i + 1];
}

/* Thin sheet: total reflectance 2r / (1 + r) from the single-interface Fresnel
 * reflectance r (see the banner). */
UB_INLINE float ub_thin_dielectric_reflectance(float r) {
    return 2.0f * r / (1.0f + r);
}

#endif /* UB_PLASTIC_H */
