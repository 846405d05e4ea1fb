/* Fresnel reflectance for unpolarised light (host C++ and OpenCL C).
 *
 * Both formulas are the exact ones (no Schlick approximation):
 *  - dielectric: average of the squared s- and p-amplitude coefficients
 *    (Born & Wolf, Principles of Optics, Sec. 1.5.2; Walter et al. 2007, eq. 22
 *    is the same quantity written without cos(theta_t));
 *  - conductor: complex relative IOR eta + i k, the closed form of the squared
 *    amplitudes for an absorbing medium (Born & Wolf Sec. 14.2; the same form
 *    appears in Mitsuba 0.5's fresnelConductorExact).
 * Cosines are taken on the side of the incident direction, so they are >= 0.
 */
#ifndef UB_FRESNEL_H
#define UB_FRESNEL_H

#include "ub_defs.h"

/* Dielectric interface. cosThetaI: |cos| of the incident direction with the normal;
 * eta = eta_t / eta_i (IOR of the transmitted side over the incident side).
 * Writes |cos(theta_t)| into *cosThetaT (0 on total internal reflection, where F = 1). */
UB_INLINE float ub_fresnel_dielectric_ct(float cosThetaI, float eta, UB_PRIVATE float* cosThetaT) {
    float c = ub_clampf(cosThetaI, 0.0f, 1.0f);
    float sin2T = (1.0f - c * c) / (eta * eta); /* Snell: sin_t = sin_i / eta */
    if (sin2T >= 1.0f) {
        *cosThetaT = 0.0f;
        return 1.0f; /* total internal reflection */
    }
    float ct = ub_sqrt(1.0f - sin2T);
    *cosThetaT = ct;
    /* Amplitude coefficients divided through by eta_i. */
    float rs = (c - eta * ct) / (c + eta * ct);
    float rp = (eta * c - ct) / (eta * c + ct);
    return 0.5f * (rs * rs + rp * rp);
}

UB_INLINE float ub_fresnel_dielectric(float cosThetaI, float eta) {
    float ct;
    return ub_fresnel_dielectric_ct(cosThetaI, eta, &ct);
}

/* Conductor interface, relative complex IOR eta + i k (one wavelength / channel).
 * With a^2 + b^2 = |(eta + i k)^2 - sin^2|, a = Re sqrt((eta + i k)^2 - sin^2):
 *   Rs = (a^2+b^2 - 2a cos + cos^2) / (a^2+b^2 + 2a cos + cos^2)
 *   Rp = Rs (cos^2 (a^2+b^2) - 2a cos sin^2 + sin^4) / (cos^2 (a^2+b^2) + 2a cos sin^2 + sin^4)
 * For k = 0 this reduces to the dielectric formula above (tests check it). */
UB_INLINE float ub_fresnel_conductor(float cosThetaI, float eta, float k) {
    float c = ub_clampf(cosThetaI, 0.0f, 1.0f);
    float c2 = c * c;
    float s2 = 1.0f - c2;
    float t0 = eta * eta - k * k - s2;
    float a2b2 = ub_sqrt(t0 * t0 + 4.0f * eta * eta * k * k);
    float a = ub_sqrt(ub_fmax(0.0f, 0.5f * (a2b2 + t0)));
    float t1 = a2b2 + c2;
    float t2 = 2.0f * a * c;
    if (t1 + t2 <= 0.0f) return 1.0f;
    float rs = (t1 - t2) / (t1 + t2);
    float t3 = c2 * a2b2 + s2 * s2;
    float t4 = t2 * s2;
    if (t3 + t4 <= 0.0f) return rs;
    float rp = rs * (t3 - t4) / (t3 + t4);
    return 0.5f * (rs + rp);
}

#endif /* UB_FRESNEL_H */
