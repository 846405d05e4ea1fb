// Perturbed shading normals: Mitsuba 3's `normalmap` and `bumpmap` BSDF wrappers
// (Material::perturbation). Scene::intersect replaces a hit's shading normal by the perturbed
// one, so every integrator, and every light vertex stored for later, sees the same normal;
// the BSDF of the wrapped material is then evaluated in the perturbed frame (scene/bsdf.h
// adds the light-side rule and the shadow-terminator factor).
//
// Surface tangents follow Mitsuba's parameterisations: on a triangle with uvs, dp/du and
// dp/dv solve dp = dp/du du + dp/dv dv over its two edges (a degenerate uv triangle falls
// back to the orthonormal basis of the face normal, Frame); without uvs the parameterisation
// is barycentric (dp/du = p1 - p0, dp/dv = p2 - p0); on a sphere they are the derivatives of
// its spherical coordinates u = phi / 2pi, v = theta / pi.
//
// The shading frame of a point is (s, t, n): n the unperturbed shading normal, s = dp/du made
// orthogonal to n (Gram-Schmidt), t = n x s.
//  * Normal map: the texel c (RGB in [0, 1], read raw) is the tangent-space normal 2 c - 1 in
//    that frame: n' = normalize(s x + t y + n z).
//  * Bump map (Blinn 1978, "Simulation of wrinkled surfaces", with Mitsuba's convention of
//    replacing the normal components of the tangents): with the height gradient (h_u, h_v) =
//    scale x Texture::luminanceGradient, dp/du' = dp/du + (h_u - n.dp/du) n and likewise for
//    v; n' = normalize(dp/du' x dp/dv'), flipped to the side of the geometric normal.
// A perturbed normal on the back of the geometric surface (a normal-map texel with z < 0) is
// flipped to its front, as every hit's shading normal is (Scene::intersect's Hit). Degenerate
// results (a zero tangent-space normal, parallel tangents) keep the unperturbed normal.
#pragma once

#include "core/vec.h"
#include "scene/material.h"
#include "scene/texture.h"

namespace ub {

/// Mitsuba's shading tangent s: dpdu without its component along unit n, normalised; the
/// tangent of Frame(n) where that is zero or not finite.
Vec3 shadingTangent(const Vec3& n, const Vec3& dpdu);

/// The normal-mapped normal for texel c at a point with unit shading normal n, tangent dpdu.
Vec3 normalMapNormal(const Rgb& texel, const Vec3& n, const Vec3& dpdu);

/// The bump-mapped normal for the scaled height gradient (h_u, h_v), unit shading normal n,
/// tangents dpdu, dpdv and unit geometric normal ng (the side the result is flipped to).
Vec3 bumpMapNormal(const Vec2& heightGradient, const Vec3& n, const Vec3& dpdu, const Vec3& dpdv,
                   const Vec3& ng);

/// The shading normal of material m at a point (uv, unit shading normal n, unit geometric
/// normal ng, tangents dpdu/dpdv): perturbed by its normal or bump map, on ng's side; n itself
/// without a perturbation. `texture` is Scene::textures[m.perturbationTexture].
Vec3 perturbedShadingNormal(const Material& m, const Texture& texture, const Vec2& uv,
                            const Vec3& n, const Vec3& ng, const Vec3& dpdu, const Vec3& dpdv);

/// Estevez et al. 2019 (Ray Tracing Gems, "A Microfacet-Based Shadowing Function to Solve the
/// Bump Terminator Problem"): a^2 = min(tan^2(theta) / 8, 1) for the angle theta between the
/// perturbed unit normal and the unperturbed one.
/// The factor itself is applied by the BSDF (ub_bsdf_perturbed_factor, kernels/shared/ub_bsdf.h).
float shadowTerminatorAlpha2(const Vec3& perturbed, const Vec3& unperturbed);

}  // namespace ub
