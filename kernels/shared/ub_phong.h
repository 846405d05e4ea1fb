/* Lambert and modified Phong lobes (host C++ and OpenCL C), in the lobe's own
 * frame: cosAlpha is the cosine between the generated direction and the lobe
 * axis (the shading normal for Lambert, the mirror direction of dirFix for
 * Phong). All densities are in solid angle.
 *
 * Modified Phong (Lafortune & Willems 1994, "Using the modified Phong
 * reflectance model for physically based rendering"):
 *   f = rho (n + 2) / (2 pi) cos^n(alpha),
 * normalised so that its albedo is rho at normal incidence and below rho
 * elsewhere. It is sampled with the power-cosine density around the lobe axis
 *   p = (n + 1) / (2 pi) cos^n(alpha),
 * which is symmetric in the two directions (cos(alpha) is the same when the
 * roles of dirFix and dirGen are swapped), so its reverse pdf is the same value.
 */
#ifndef UB_PHONG_H
#define UB_PHONG_H

#include "ub_defs.h"

/* Lambert: f = rho / pi; cosine-weighted density cos(theta) / pi. */
UB_INLINE float ub_lambert_pdf(float cosTheta) {
    return ub_fmax(0.0f, cosTheta) * UB_INV_PI;
}

/* Energy-normalised modified Phong lobe without rho: (n + 2)/(2 pi) cos^n. */
UB_INLINE float ub_phong_lobe(float cosAlpha, float exponent) {
    if (cosAlpha <= 0.0f) return 0.0f;
    return (exponent + 2.0f) * (0.5f * UB_INV_PI) * ub_pow(cosAlpha, exponent);
}

/* Power-cosine density around the lobe axis: (n + 1)/(2 pi) cos^n. */
UB_INLINE float ub_power_cos_pdf(float cosAlpha, float exponent) {
    if (cosAlpha <= 0.0f) return 0.0f;
    return (exponent + 1.0f) * (0.5f * UB_INV_PI) * ub_pow(cosAlpha, exponent);
}

/* Samples the power-cosine density around +z by inverting its CDF in cos(alpha):
 * P(cos <= c) = c^(n+1), so cos(alpha) = u1^(1/(n+1)); phi = 2 pi u2. */
UB_INLINE void ub_power_cos_sample(float u1, float u2, float exponent, UB_PRIVATE float* x,
                                   UB_PRIVATE float* y, UB_PRIVATE float* z) {
    float cosA = ub_pow(u1, 1.0f / (exponent + 1.0f));
    float sinA = ub_sqrt(ub_fmax(0.0f, 1.0f - cosA * cosA));
    float phi = 2.0f * UB_PI * u2;
    *x = sinA * ub_cos(phi);
    *y = sinA * ub_sin(phi);
    *z = cosA;
}

#endif /* UB_PHONG_H */
