/* Scalar pdf conversions used by light sampling and by the MIS partials of the
 * bidirectional estimators ("Implementing Vertex Connection and Merging",
 * Georgiev 2012, Sec. 5; Veach 1997, Sec. 8.2.2). Measures: *_w solid angle,
 * *_a area, *_uv the unit square of a lat-long map. C99 subset (ub_defs.h).
 */
#ifndef UB_LIGHT_PDF_H
#define UB_LIGHT_PDF_H

#include "ub_defs.h"

/* Solid-angle pdf at a receiver of a point sampled with area pdf pdfA at distance^2
 * distSqr whose surface cosine towards the receiver is cosAtPoint (Veach eq. 8.10). */
UB_INLINE float ub_pdf_a_to_w(float pdfA, float distSqr, float cosAtPoint) {
    return pdfA * distSqr / cosAtPoint;
}

/* Inverse of ub_pdf_a_to_w: area pdf at a point from a solid-angle pdf. */
UB_INLINE float ub_pdf_w_to_a(float pdfW, float distSqr, float cosAtPoint) {
    return pdfW * cosAtPoint / distSqr;
}

/* Cosine-weighted hemisphere pdf (solid angle) for cosTheta > 0, else 0. */
UB_INLINE float ub_cos_hemisphere_pdf_w(float cosTheta) {
    return ub_fmax(cosTheta, 0.0f) * UB_INV_PI;
}

/* Area pdf of a uniform point on a disk of radius r = 1/sqrt(invRadiusSqr): the
 * position pdf with which lights at infinity place emitted rays on the scene-sphere
 * disk (tech. rep. Sec. 5.1). */
UB_INLINE float ub_disk_pdf_a(float invRadiusSqr) {
    return invRadiusSqr * UB_INV_PI;
}

/* Solid-angle pdf of a lat-long direction (theta in [0,pi], phi in [0,2pi)) sampled with
 * density pdfUv on the unit square u = phi / 2pi, v = theta / pi:
 * d omega = sin(theta) dtheta dphi = 2 pi^2 sin(theta) du dv (pbrt-v3 Sec. 14.2.4).
 * Returns 0 at the poles (sin(theta) = 0), where the map has measure zero. */
UB_INLINE float ub_latlong_pdf_w(float pdfUv, float sinTheta) {
    return sinTheta > 0.0f ? pdfUv / (2.0f * UB_PI * UB_PI * sinTheta) : 0.0f;
}

#endif /* UB_LIGHT_PDF_H */
