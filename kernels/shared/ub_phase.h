/* Henyey-Greenstein phase function (Henyey & Greenstein 1941, "Diffuse
 * radiation in the galaxy", ApJ 93, eq. 3), shared by host C++ and OpenCL C.
 *
 * Direction convention (the same as src/scene/bsdf.h):
 *  - both directions point AWAY from the scattering point;
 *  - wFix points towards the previous vertex of the subpath being traced
 *    (-ray.dir of the incoming ray), wGen towards the next vertex (sampled or
 *    evaluated);
 *  - light (or importance) propagates along -wFix into the point and leaves
 *    along wGen, so the scattering angle theta is the angle between the two
 *    PROPAGATION directions:  cosTheta = dot(-wFix, wGen) = -dot(wFix, wGen).
 *    cosTheta = 1 means no deflection (wGen = -wFix);
 *  - g in (-1, 1) is the mean cosine of theta: g > 0 scatters forward
 *    (wGen close to -wFix), g < 0 backward (wGen close to wFix), g = 0 is
 *    isotropic.
 * HG depends on cosTheta only and is symmetric in (wFix, wGen), so it is its
 * own adjoint: the reverse pdf equals the forward pdf. Sampling is exact, so
 * the value equals the solid-angle pdf (suffix W) and the sampling weight
 * value / pdfW is 1.
 */
#ifndef UB_PHASE_H
#define UB_PHASE_H

#include "ub_defs.h"
#include "ub_vec3.h"

/* p(cosTheta) per steradian:
 *   (1 - g^2) / (4 pi (1 + g^2 - 2 g cosTheta)^(3/2)). */
UB_INLINE float ub_hg_eval(float cosTheta, float g) {
    float denom = 1.0f + g * g - 2.0f * g * cosTheta;
    return (0.25f * UB_INV_PI) * (1.0f - g * g) / (denom * ub_sqrt(denom));
}

/* Samples cosTheta by inverting the HG CDF in cosTheta,
 *   P(cosTheta) = (1 - g^2) / (2 g) * (1 / sqrt(1 + g^2 - 2 g cosTheta) - 1 / (1 + g)).
 * The usual closed form (1 + g^2 - ((1 - g^2) / (1 - g + 2 g u))^2) / (2 g)
 * cancels catastrophically for small |g|; expanding it with v = 2u - 1 gives
 *   cosTheta = [ g (1 + g^2) / 2 v^2 + (1 + g^2) v + g (3 - g^2) / 2 ] / (1 + g v)^2,
 * algebraically the same, well conditioned for every g in (-1, 1) including
 * 0 (then cosTheta = v, uniform), with no branch.
 * u = 0 maps to -1, u = 1 to +1. */
UB_INLINE float ub_hg_sample_cos_theta(float g, float u) {
    float v = 2.0f * u - 1.0f;
    float g2 = g * g;
    float num = (0.5f * g * (1.0f + g2) * v + (1.0f + g2)) * v + 0.5f * g * (3.0f - g2);
    float den = 1.0f + g * v;
    return ub_clampf(num / (den * den), -1.0f, 1.0f);
}

/* Phase function value (= solid-angle pdf) for directions pointing away from
 * the scattering point; see the convention above. */
UB_INLINE float ub_hg_eval_dirs(ub_float3 wFix, ub_float3 wGen, float g) {
    return ub_hg_eval(-ub_f3_dot(wFix, wGen), g);
}

/* Solid-angle pdf of ub_hg_sample; identical to the value (and, by symmetry,
 * to the reverse pdf p(wFix | wGen)). */
UB_INLINE float ub_hg_pdf(ub_float3 wFix, ub_float3 wGen, float g) {
    return ub_hg_eval_dirs(wFix, wGen, g);
}

/* Samples wGen given the unit direction wFix and u1, u2 in [0, 1).
 * Writes the solid-angle pdf (= phase value) to *pdfW. */
UB_INLINE ub_float3 ub_hg_sample(ub_float3 wFix, float g, float u1, float u2,
                                 UB_PRIVATE float* pdfW) {
    float cosTheta = ub_hg_sample_cos_theta(g, u1);
    float sinTheta = ub_sqrt(ub_fmax(0.0f, 1.0f - cosTheta * cosTheta));
    float phi = 2.0f * UB_PI * u2;
    ub_float3 forward = ub_f3_neg(wFix); /* propagation direction of the incoming light */
    ub_float3 s, t;
    ub_f3_basis(forward, &s, &t);
    ub_float3 wGen = ub_f3_add(
        ub_f3_add(ub_f3_scale(s, sinTheta * ub_cos(phi)), ub_f3_scale(t, sinTheta * ub_sin(phi))),
        ub_f3_scale(forward, cosTheta));
    *pdfW = ub_hg_eval(cosTheta, g);
    return wGen;
}

#endif /* UB_PHASE_H */
