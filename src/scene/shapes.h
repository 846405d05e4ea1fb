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
/// Applies a transform to positions and normals. If the transform mirrors
/// (negative determinant) the winding is flipped so normals stay outward.
void transformMesh(TriangleMesh& mesh, const Transform& toWorld);
/// Total surface area.
float meshArea(const TriangleMesh& mesh);

}  // namespace ub
