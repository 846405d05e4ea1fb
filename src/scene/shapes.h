// Built-in shapes as triangle meshes in object space, and mesh utilities.
// Winding is counter-clockwise seen from outside, so the geometric normal
// normalize(cross(p1 - p0, p2 - p0)) points outward (and area lights emit
// on that side).
#pragma once

#include "core/vec.h"
#include "scene/scene.h"

namespace ub {

/// Square [-1,1]^2 in the z = 0 plane, normal +z, uv in [0,1]^2.
TriangleMesh makeRectangle();
/// Cube [-1,1]^3 with outward normals (12 triangles, flat).
TriangleMesh makeCube();

/// Segments around the circle of makeDisk() and makeCylinder(). The polygon inscribed in the
/// unit circle with N = 512 sides has area (N/2) sin(2 pi/N) = pi (1 - 2.5e-5) and perimeter
/// 2 N sin(pi/N) = 2 pi (1 - 6.3e-6): the disk's area (and an emitting disk's power) is
/// within 2.5e-5 of the analytic shape's, the cylinder's within 6.3e-6.
constexpr int kRoundSegments = 512;
/// Unit disk in the z = 0 plane, normal +z (Mitsuba's `disk`): a fan of `segments` triangles,
/// uv = (r, phi / 2 pi) as Mitsuba defines them (phi = atan2(y, x) in [0, 2 pi)). The centre
/// is repeated per triangle with v at the middle of its wedge, the seam at phi = 0 has
/// vertices with v = 0 and v = 1. No vertex normals (flat).
TriangleMesh makeDisk(int segments = kRoundSegments);
/// Open cylinder x^2 + y^2 = 1, 0 <= z <= 1, no caps, normals outward (Mitsuba's `cylinder`
/// in its object space): 2 `segments` triangles, smooth per-vertex shading normals
/// (cos phi, sin phi, 0), uv = (phi / 2 pi, z) as Mitsuba's, the seam at phi = 0 repeated
/// with u = 0 and u = 1 (at bit-identical positions).
TriangleMesh makeCylinder(int segments = kRoundSegments);
/// Places makeCylinder()'s unit cylinder on the axis p0 -> p1 with the given radius
/// (Mitsuba's `cylinder`): translate(p0) * frame(p1 - p0) * scale(radius, radius, |p1 - p0|),
/// with the frame's x and y axes those of Frame(normalize(p1 - p0)) (Mitsuba's basis, which
/// fixes where u = 0 lies). Needs p0 != p1.
Transform cylinderPlacement(const Vec3& p0, const Vec3& p1, float radius);
/// True if t (a placed cylinder's object-to-world) keeps the cylinder circular: mutually
/// orthogonal columns, the first two of equal length (relative tolerance 1e-4), no mirroring.
bool keepsCylinderCircular(const Transform& t);
/// Applies a transform to positions and normals. If the transform mirrors
/// (negative determinant) the winding is flipped so normals stay outward.
void transformMesh(TriangleMesh& mesh, const Transform& toWorld);
/// Total surface area.
float meshArea(const TriangleMesh& mesh);

}  // namespace ub
