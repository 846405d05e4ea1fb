#include "scene/shapes.h"

#include <utility>

namespace ub {

namespace {

/// Appends the square face c + [-1,1] s + [-1,1] t (two triangles). With s x t = n the
/// winding is counter-clockwise seen from the side n points to, so
/// cross(p1 - p0, p2 - p0) = 4 s x t points along n.
void addFace(TriangleMesh& m, const Vec3& c, const Vec3& s, const Vec3& t) {
    uint32_t base = uint32_t(m.positions.size());
    m.positions.push_back(c - s - t);
    m.positions.push_back(c + s - t);
    m.positions.push_back(c + s + t);
    m.positions.push_back(c - s + t);
    m.uvs.push_back(Vec2(0, 0));
    m.uvs.push_back(Vec2(1, 0));
    m.uvs.push_back(Vec2(1, 1));
    m.uvs.push_back(Vec2(0, 1));
    for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(base + i);
}

}  // namespace

TriangleMesh makeRectangle() {
    TriangleMesh m;
    addFace(m, Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0));
    return m;
}

TriangleMesh makeCube() {
    TriangleMesh m;
    const Vec3 x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
    // (center = normal, s, t) with s x t = normal.
    addFace(m, x, y, z);
    addFace(m, -x, z, y);
    addFace(m, y, z, x);
    addFace(m, -y, x, z);
    addFace(m, z, x, y);
    addFace(m, -z, y, x);
    return m;
}

void transformMesh(TriangleMesh& mesh, const Transform& toWorld) {
    for (Vec3& p : mesh.positions) p = toWorld.point(p);
    if (!mesh.normals.empty()) {
        // Normals are covectors: multiply by the inverse transpose (computed once).
        Transform inv = toWorld.inverse();
        for (Vec3& n : mesh.normals) {
            Vec3 t(inv.m[0][0] * n.x + inv.m[1][0] * n.y + inv.m[2][0] * n.z,
                   inv.m[0][1] * n.x + inv.m[1][1] * n.y + inv.m[2][1] * n.z,
                   inv.m[0][2] * n.x + inv.m[1][2] * n.y + inv.m[2][2] * n.z);
            float len = length(t);
            n = len > 0.0f ? t / len : t;
        }
    }
    // A mirroring transform turns cross(p1 - p0, p2 - p0) inwards; swapping two
    // vertices of every triangle restores the outward geometric normal.
    if (toWorld.determinant3() < 0.0f)
        for (size_t i = 0; i + 2 < mesh.indices.size(); i += 3)
            std::swap(mesh.indices[i + 1], mesh.indices[i + 2]);
}

float meshArea(const TriangleMesh& mesh) {
    double area = 0.0;
    for (size_t i = 0; i + 2 < mesh.indices.size(); i += 3) {
        const Vec3& p0 = mesh.positions[mesh.indices[i]];
        const Vec3& p1 = mesh.positions[mesh.indices[i + 1]];
        const Vec3& p2 = mesh.positions[mesh.indices[i + 2]];
        area += 0.5 * double(length(cross(p1 - p0, p2 - p0)));
    }
    return float(area);
}

}  // namespace ub
