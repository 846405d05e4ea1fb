// Sampling of visible microfacet normals (host only; the densities are
// kernels/shared/ub_microfacet.h's ub_mf_visible_pdf, D_v(m) = G1(v) max(0, v.m) D(m) / v.z).
//   GGX       Heitz 2018, "Sampling the GGX distribution of visible normals" (shared code).
//   Beckmann  Heitz & d'Eon 2014, "Importance sampling microfacet-based BSDFs using the
//             distribution of visible normals", Sec. 4: stretch v to alpha = 1, sample the
//             visible slopes of the standard Beckmann distribution, rotate and unstretch.
//             The slope CDFs are inverted to double precision by safeguarded Newton
//             iteration (no fitted approximations), so samples follow D_v exactly up to
//             float rounding of the result.
#pragma once

#include <cstdint>

#include "core/vec.h"

namespace ub {

/// A microfacet normal visible from v (unit, v.z > 0) for distribution dist (UB_MF_*) and
/// roughness alpha, from (u1, u2) in [0, 1)^2.
Vec3 sampleVisibleNormal(uint32_t dist, const Vec3& v, float alpha, float u1, float u2);
/// The same for anisotropic roughness: alphaU along the local x axis, alphaV along y.
Vec3 sampleVisibleNormal(uint32_t dist, const Vec3& v, float alphaU, float alphaV, float u1,
                         float u2);

/// x with (1 + erf(x)) / 2 = u, for u in (0, 1) (clamped to [-9, 9] at the ends).
double inverseNormalCdfErf(double u);

}  // namespace ub
