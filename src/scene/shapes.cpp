#include "scene/shapes.h"

#include <cmath>
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

namespace {

/// Point i of `segments` on the unit circle (index `segments` is index 0, bit for bit).
Vec3 circlePoint(int i, int segments) {
    const double phi = 2.0 * 3.14159265358979323846 * double(i % segments) / double(segments);
    return Vec3(float(std::cos(phi)), float(std::sin(phi)), 0.0f);
}

}  // namespace

TriangleMesh makeDisk(int segments) {
    TriangleMesh m;
    const float n = float(segments);
    for (int i = 0; i < segments; ++i) {
        const uint32_t base = uint32_t(m.positions.size());
        m.positions.push_back(Vec3(0.0f));
        m.positions.push_back(circlePoint(i, segments));
        m.positions.push_back(circlePoint(i + 1, segments));
        m.uvs.push_back(Vec2(0.0f, (float(i) + 0.5f) / n));
        m.uvs.push_back(Vec2(1.0f, float(i) / n));
        m.uvs.push_back(Vec2(1.0f, float(i + 1) / n));
        // Counter-clockwise seen from +z: the geometric normal is +z.
        for (uint32_t k : {0u, 1u, 2u}) m.indices.push_back(base + k);
    }
    return m;
}

TriangleMesh makeCylinder(int segments) {
    TriangleMesh m;
    const float n = float(segments);
    for (int i = 0; i <= segments; ++i) {
        const Vec3 c = circlePoint(i, segments);
        const float u = float(i) / n;
        m.positions.push_back(c);                     // 2i: bottom (z = 0)
        m.positions.push_back(Vec3(c.x, c.y, 1.0f));  // 2i + 1: top (z = 1)
        m.normals.push_back(c);
        m.normals.push_back(c);
        m.uvs.push_back(Vec2(u, 0.0f));
        m.uvs.push_back(Vec2(u, 1.0f));
    }
    for (int i = 0; i < segments; ++i) {
        const uint32_t b0 = uint32_t(2 * i), t0 = b0 + 1, b1 = b0 + 2, t1 = b0 + 3;
        // Counter-clockwise seen from outside: cross(b1 - b0, t1 - b0) points away from the axis.
        for (uint32_t k : {b0, b1, t1, b0, t1, t0}) m.indices.push_back(k);
    }
    return m;
}

Transform cylinderPlacement(const Vec3& p0, const Vec3& p1, float radius) {
    const float len = length(p1 - p0);
    const Frame f((p1 - p0) / len);
    Transform t;
    for (int i = 0; i < 3; ++i) {
        t.m[i][0] = f.s[i] * radius;
        t.m[i][1] = f.t[i] * radius;
        t.m[i][2] = f.n[i] * len;
        t.m[i][3] = p0[i];
    }
    return t;
}

bool keepsCylinderCircular(const Transform& t) {
    Vec3 c[3];
    for (int j = 0; j < 3; ++j) c[j] = Vec3(t.m[0][j], t.m[1][j], t.m[2][j]);
    const float l0 = length(c[0]), l1 = length(c[1]), l2 = length(c[2]);
    const float tol = 1e-4f;
    return std::fabs(l0 - l1) <= tol * l0 && std::fabs(dot(c[0], c[1])) <= tol * l0 * l1 &&
           std::fabs(dot(c[0], c[2])) <= tol * l0 * l2 &&
           std::fabs(dot(c[1], c[2])) <= tol * l1 * l2 && t.determinant3() > 0.0f;
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
