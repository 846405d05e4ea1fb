// Geometry layer: ray-triangle and ray-sphere hits, occlusion, self-intersection
// robustness of spawned rays, transforms, areas and the scene bounding sphere.
#include "scene/scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <thread>

#include "core/error.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "scene/shapes.h"

using namespace ub;

namespace {

/// Latitude-longitude tessellation of a sphere with shared vertices (watertight and
/// convex: every quad is a planar trapezoid), counter-clockwise from outside.
TriangleMesh makeUvSphere(const Vec3& c, float r, int nTheta, int nPhi, bool withNormals) {
    TriangleMesh m;
    auto vert = [&](const Vec3& n) {
        m.positions.push_back(c + r * n);
        if (withNormals) m.normals.push_back(n);
    };
    vert(Vec3(0, 0, 1));
    for (int i = 1; i < nTheta; ++i) {
        double th = M_PI * i / nTheta;
        for (int j = 0; j < nPhi; ++j) {
            double ph = 2 * M_PI * j / nPhi;
            vert(Vec3(float(std::sin(th) * std::cos(ph)), float(std::sin(th) * std::sin(ph)),
                      float(std::cos(th))));
        }
    }
    vert(Vec3(0, 0, -1));
    const uint32_t south = uint32_t(m.positions.size() - 1);
    auto ring = [&](int i, int j) { return uint32_t(1 + (i - 1) * nPhi + (j % nPhi)); };
    auto tri = [&](uint32_t a, uint32_t b, uint32_t d) {
        m.indices.insert(m.indices.end(), {a, b, d});
    };
    for (int j = 0; j < nPhi; ++j) {
        tri(0, ring(1, j), ring(1, j + 1));
        for (int i = 1; i + 1 < nTheta; ++i) {
            tri(ring(i, j), ring(i + 1, j), ring(i + 1, j + 1));
            tri(ring(i, j), ring(i + 1, j + 1), ring(i, j + 1));
        }
        tri(south, ring(nTheta - 1, j + 1), ring(nTheta - 1, j));
    }
    return m;
}

Ray makeRay(const Vec3& o, const Vec3& d) {
    Ray r;
    r.org = o;
    r.dir = normalize(d);
    return r;
}

/// Roots of |o + t d - c|^2 = r^2 in double (d unit), for reference values.
bool sphereRoots(const Vec3& o, const Vec3& d, const Vec3& c, double r, double* t0, double* t1) {
    double f[3] = {double(o.x) - c.x, double(o.y) - c.y, double(o.z) - c.z};
    double dd[3] = {d.x, d.y, d.z};
    double a = dd[0] * dd[0] + dd[1] * dd[1] + dd[2] * dd[2];
    double b = f[0] * dd[0] + f[1] * dd[1] + f[2] * dd[2];
    double cc = f[0] * f[0] + f[1] * f[1] + f[2] * f[2] - r * r;
    double disc = b * b - a * cc;
    if (disc < 0) return false;
    *t0 = (-b - std::sqrt(disc)) / a;
    *t1 = (-b + std::sqrt(disc)) / a;
    return true;
}

float maxAbs3(const Vec3& p) {
    return std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});
}

}  // namespace

TEST(Scene, TriangleHitDistanceNormalUv) {
    Scene scene;
    TriangleMesh rect = makeRectangle();
    transformMesh(rect, Transform::translate({0, 0, -2}) * Transform::scale({2, 2, 1}));
    uint32_t id = scene.addMesh(rect, 3, 5, "floor");
    scene.commit();
    Hit h;
    ASSERT_TRUE(scene.intersect(makeRay({0.5f, 0.25f, 3}, {0, 0, -1}), &h));
    EXPECT_NEAR(h.dist, 5.0f, 1e-5f);
    EXPECT_NEAR(h.pos.x, 0.5f, 1e-6f);
    EXPECT_NEAR(h.pos.y, 0.25f, 1e-6f);
    EXPECT_NEAR(h.pos.z, -2.0f, 1e-6f);
    EXPECT_FLOAT_EQ(h.geoNormal.z, 1.0f);
    EXPECT_FLOAT_EQ(h.shadingNormal.z, 1.0f);
    // Object-space point (0.25, 0.125) of [-1,1]^2 -> uv ((x+1)/2, (y+1)/2).
    EXPECT_NEAR(h.uv.x, 0.625f, 1e-6f);
    EXPECT_NEAR(h.uv.y, 0.5625f, 1e-6f);
    EXPECT_EQ(h.shapeId, id);
    EXPECT_EQ(h.materialId, 3);
    EXPECT_EQ(h.lightId, 5);
    // From below: the geometric normal stays the shape's front side (+z).
    ASSERT_TRUE(scene.intersect(makeRay({-1, 1, -7}, {0, 0, 1}), &h));
    EXPECT_NEAR(h.dist, 5.0f, 1e-5f);
    EXPECT_FLOAT_EQ(h.geoNormal.z, 1.0f);
    // Misses: outside the rectangle, pointing away, and beyond tMax.
    EXPECT_FALSE(scene.intersect(makeRay({2.5f, 0, 3}, {0, 0, -1}), &h));
    EXPECT_FALSE(scene.intersect(makeRay({0, 0, 3}, {0, 0, 1}), &h));
    Ray shortRay = makeRay({0, 0, 3}, {0, 0, -1});
    shortRay.tMax = 4.9f;
    EXPECT_FALSE(scene.intersect(shortRay, &h));
    shortRay.tMax = 5.1f;
    shortRay.tMin = 5.05f;
    EXPECT_FALSE(scene.intersect(shortRay, &h));
}

TEST(Scene, GeometricNormalFollowsWinding) {
    // Triangle (0,0,0), (0,1,0), (1,0,0): cross(p1-p0, p2-p0) = -z.
    TriangleMesh m;
    m.positions = {{0, 0, 0}, {0, 1, 0}, {1, 0, 0}};
    m.indices = {0, 1, 2};
    Scene scene;
    scene.addMesh(m, 0, -1, "tri");
    scene.commit();
    Hit h;
    ASSERT_TRUE(scene.intersect(makeRay({0.2f, 0.2f, 1}, {0, 0, -1}), &h));
    EXPECT_FLOAT_EQ(h.geoNormal.z, -1.0f);
    EXPECT_FLOAT_EQ(h.shadingNormal.z, -1.0f);
    // No uvs: uv = barycentrics (b1, b2) of p = b0 p0 + b1 p1 + b2 p2.
    EXPECT_NEAR(h.uv.x, 0.2f, 1e-6f);
    EXPECT_NEAR(h.uv.y, 0.2f, 1e-6f);
}

TEST(Scene, ShadingNormalsInterpolatedAndFlippedToGeometricSide) {
    TriangleMesh m;
    m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};  // geoNormal +z
    m.indices = {0, 1, 2};
    Vec3 a = normalize(Vec3(1, 0, 1)), b = normalize(Vec3(0, 1, 1)), c(0, 0, 1);
    m.normals = {a, b, c};
    m.uvs = {{0, 0}, {4, 0}, {0, 2}};
    TriangleMesh flipped = m;
    for (Vec3& n : flipped.normals) n = -n;
    transformMesh(flipped, Transform::translate({0, 0, -5}));
    Scene scene;
    scene.addMesh(m, 0, -1, "smooth");
    scene.addMesh(flipped, 0, -1, "flipped");
    scene.commit();
    // Point with barycentrics b0 = 0.5, b1 = 0.3, b2 = 0.2.
    Vec3 expected = normalize(0.5f * a + 0.3f * b + 0.2f * c);
    Hit h;
    ASSERT_TRUE(scene.intersect(makeRay({0.3f, 0.2f, 1}, {0, 0, -1}), &h));
    EXPECT_NEAR(h.shadingNormal.x, expected.x, 1e-5f);
    EXPECT_NEAR(h.shadingNormal.y, expected.y, 1e-5f);
    EXPECT_NEAR(h.shadingNormal.z, expected.z, 1e-5f);
    EXPECT_NEAR(h.uv.x, 0.3f * 4, 1e-5f);
    EXPECT_NEAR(h.uv.y, 0.2f * 2, 1e-5f);
    // Vertex normals opposite to the geometric normal are flipped into its hemisphere.
    Ray below = makeRay({0.3f, 0.2f, -4}, {0, 0, -1});
    ASSERT_TRUE(scene.intersect(below, &h));
    EXPECT_EQ(h.shapeId, 1u);
    EXPECT_NEAR(h.shadingNormal.x, expected.x, 1e-5f);
    EXPECT_NEAR(h.shadingNormal.z, expected.z, 1e-5f);
    EXPECT_GT(dot(h.shadingNormal, h.geoNormal), 0.0f);
}

TEST(Scene, SphereHitFromOutside) {
    Scene scene;
    scene.addSphere({1, 2, 3}, 2, 1, 0, "ball");
    scene.commit();
    Hit h;
    ASSERT_TRUE(scene.intersect(makeRay({1, 2, 10}, {0, 0, -1}), &h));
    EXPECT_NEAR(h.dist, 5.0f, 1e-5f);
    EXPECT_NEAR(h.pos.z, 5.0f, 1e-6f);
    EXPECT_NEAR(h.geoNormal.z, 1.0f, 1e-6f);
    EXPECT_NEAR(h.uv.y, 0.0f, 1e-3f);  // v = theta / pi, north pole
    EXPECT_EQ(h.materialId, 1);
    EXPECT_EQ(h.lightId, 0);
    // Oblique hit: analytic distance from the quadratic.
    Ray r = makeRay({-4, 0, 0}, {1, 0.4f, 0.5f});
    double t0, t1;
    ASSERT_TRUE(sphereRoots(r.org, r.dir, {1, 2, 3}, 2, &t0, &t1));
    ASSERT_TRUE(scene.intersect(r, &h));
    EXPECT_NEAR(h.dist, t0, 1e-5 * t0);
    Vec3 n = normalize(h.pos - Vec3(1, 2, 3));
    EXPECT_NEAR(dot(n, h.geoNormal), 1.0f, 1e-6f);
    EXPECT_NEAR(length(h.pos - Vec3(1, 2, 3)), 2.0f, 1e-5f);
    // Equator at phi = 0: uv = (0, 0.5).
    ASSERT_TRUE(scene.intersect(makeRay({10, 2, 3}, {-1, 0, 0}), &h));
    EXPECT_NEAR(h.uv.x, 0.0f, 1e-6f);
    EXPECT_NEAR(h.uv.y, 0.5f, 1e-6f);
    // Miss beside the sphere.
    EXPECT_FALSE(scene.intersect(makeRay({1, 4.01f, 10}, {0, 0, -1}), &h));
}

TEST(Scene, RayFromInsideSphereHitsFarSide) {
    Scene scene;
    scene.addSphere({0, 0, 0}, 1, 0, -1, "glass");
    scene.commit();
    Hit h;
    ASSERT_TRUE(scene.intersect(makeRay({0, 0, 0}, {0, 1, 0}), &h));
    EXPECT_NEAR(h.dist, 1.0f, 1e-6f);
    EXPECT_NEAR(h.geoNormal.y, 1.0f, 1e-6f);  // outward normal even from inside
    // Entering through the front, then continuing from the hit: the far side.
    ASSERT_TRUE(scene.intersect(makeRay({0, 0, -3}, {0, 0, 1}), &h));
    EXPECT_NEAR(h.dist, 2.0f, 1e-6f);
    Ray inside = scene.spawnRay(h, Vec3(0, 0, 1));
    Hit far;
    ASSERT_TRUE(scene.intersect(inside, &far));
    EXPECT_NEAR(far.pos.z, 1.0f, 1e-5f);
    EXPECT_NEAR(far.geoNormal.z, 1.0f, 1e-6f);
    // Leaving through the far side: nothing else in the scene.
    EXPECT_FALSE(scene.intersect(scene.spawnRay(far, Vec3(0, 0, 1)), &h));
}

TEST(Scene, OcclusionTrueAndFalse) {
    Scene scene;
    TriangleMesh floor = makeRectangle();
    transformMesh(floor, Transform::scale({5, 5, 1}));  // z = 0, normal +z
    TriangleMesh ceiling = makeRectangle();
    transformMesh(ceiling, Transform::translate({0, 0, 4}) * Transform::scale({5, -5, 1}));
    scene.addMesh(floor, 0, -1, "floor");
    scene.addMesh(ceiling, 0, -1, "ceiling");  // mirrored: normal stays +z
    scene.addSphere({0, 0, 2}, 0.5f, 0, -1, "blocker");
    scene.commit();
    const Vec3 up(0, 0, 1), zero(0, 0, 0);
    // Segment through the blocker, and segments beside it (ends on both surfaces).
    EXPECT_TRUE(scene.occluded({0, 0, 0}, up, {0, 0, 4}, up));
    EXPECT_FALSE(scene.occluded({2, 0, 0}, up, {2, 0, 4}, up));
    EXPECT_FALSE(scene.occluded({2, 2, 0}, up, {-3, 1, 4}, up));
    // Point light (zero normal) above the floor, inside the room.
    EXPECT_FALSE(scene.occluded({1, 1, 0}, up, {1, 1, 3}, zero));
    EXPECT_TRUE(scene.occluded({0, 0, 0}, up, {0, 0, 3}, zero));
    // Ends short of the blocker: the segment is open.
    EXPECT_FALSE(scene.occluded({0, 0, 0}, up, {0, 0, 1.4f}, zero));
    EXPECT_TRUE(scene.occluded({0, 0, 0}, up, {0, 0, 1.6f}, zero));
    // Point on the blocker's surface towards the floor: not occluded by itself.
    EXPECT_FALSE(scene.occluded({0, 0, 1.5f}, -up, {0, 0, 0}, up));
    EXPECT_TRUE(scene.occluded({0, 0, 2.5f}, up, {0, 0, 0}, up));
    // Towards infinity.
    EXPECT_TRUE(scene.occludedToInfinity({0, 0, 0}, up, up));
    EXPECT_TRUE(scene.occludedToInfinity({3, 3, 0}, up, up));  // ceiling
    EXPECT_FALSE(scene.occludedToInfinity({3, 3, 0}, up, normalize(Vec3(1, 1, 0.1f))));
    EXPECT_FALSE(scene.occludedToInfinity({0, 0, 2.5f}, up, normalize(Vec3(1, 0, 0.1f))));
}

// Self-intersection robustness, analytic sphere. For each of 10^5 hits (half from
// outside, half from inside) a random direction is spawned: if it leaves the convex
// side it must miss everything (the sphere is alone); otherwise it must hit the
// sphere exactly where the double-precision quadratic from the spawned origin says
// (the far root), i.e. never at t ~ 0 on the surface it left. Repeated far from the
// world origin, where the offset must scale with the coordinates.
TEST(Scene, SpawnedRaysFromSphereNeverSelfIntersect) {
    struct Case {
        Vec3 c;
        float r;
    };
    for (Case cs :
         {Case{{0, 0, 0}, 1.0f}, Case{{1000, -500, 200}, 3.0f}, Case{{0.01f, 0, 0}, 1e-3f}}) {
        Scene scene;
        scene.addSphere(cs.c, cs.r, 0, -1, "s");
        scene.commit();
        Rng rng(42, 7);
        const float scale = 1.0f + maxAbs3(cs.c) + cs.r;
        int checked = 0;
        for (int i = 0; i < 100000; ++i) {
            Ray primary;
            if (i % 2 == 0) {
                Vec3 o = cs.c + 3.0f * cs.r * sampleUniformSphere(rng.uniform2());
                Vec3 target = cs.c + 0.9f * cs.r * sampleUniformSphere(rng.uniform2());
                primary = makeRay(o, target - o);
            } else {
                Vec3 o = cs.c + 0.5f * cs.r * sampleUniformSphere(rng.uniform2());
                primary = makeRay(o, sampleUniformSphere(rng.uniform2()));
            }
            Hit h;
            ASSERT_TRUE(scene.intersect(primary, &h)) << "case r=" << cs.r << " i=" << i;
            Vec3 d = sampleUniformSphere(rng.uniform2());
            Ray r = scene.spawnRay(h, d);
            // The offset is tiny compared with the scene.
            ASSERT_LE(length(r.org - h.pos), 2e-5f * (1.0f + maxAbs3(h.pos)));
            Hit h2;
            bool hit = scene.intersect(r, &h2);
            double t0, t1;
            bool line = sphereRoots(r.org, r.dir, cs.c, cs.r, &t0, &t1);
            if (dot(d, h.geoNormal) >= 0.0f) {
                ASSERT_FALSE(hit) << "outgoing ray re-hit the sphere at t=" << h2.dist;
                if (line) ASSERT_LE(t1, 0.0);  // both roots behind: origin is outside
            } else {
                ASSERT_TRUE(hit) << "ray into the sphere escaped";
                ASSERT_TRUE(line);
                ASSERT_LT(t0, 0.0);  // spawned origin strictly inside
                ASSERT_NEAR(h2.dist, t1, 1e-5 * scale) << "case r=" << cs.r << " i=" << i;
                ++checked;
            }
        }
        EXPECT_GT(checked, 40000);  // about half the directions go inwards
    }
}

TEST(Scene, RaysFromInsideClosedSphereAlwaysHit) {
    Scene scene;
    const Vec3 c(3, -2, 1);
    const float rad = 2.0f;
    scene.addSphere(c, rad, 0, -1, "s");
    scene.commit();
    Rng rng(3, 1);
    for (int i = 0; i < 100000; ++i) {
        // Radius fraction up to 1 - 1e-5: points very close to the surface included.
        float f = std::min(std::cbrt(rng.uniform()), 1.0f - 1e-5f);
        Vec3 o = c + rad * f * sampleUniformSphere(rng.uniform2());
        Ray r = makeRay(o, sampleUniformSphere(rng.uniform2()));
        Hit h;
        ASSERT_TRUE(scene.intersect(r, &h)) << i;
        double t0, t1;
        ASSERT_TRUE(sphereRoots(r.org, r.dir, c, rad, &t0, &t1));
        ASSERT_NEAR(h.dist, t1, 1e-5 * (1 + 3 + rad));
        ASSERT_GT(dot(h.geoNormal, r.dir), 0.0f);
    }
}

// Same property on a tessellated (convex, watertight) sphere: leaving through the
// outside never hits anything; going inwards always hits a *different* triangle
// (a planar triangle cannot be hit again) at a distance > 0, and never leaks out.
TEST(Scene, SpawnedRaysFromTessellatedMeshNeverSelfIntersect) {
    for (Vec3 c : {Vec3(0, 0, 0), Vec3(1000, -500, 200)}) {
        const float rad = 2.0f;
        Scene scene;
        scene.addMesh(makeUvSphere(c, rad, 24, 48, false), 0, -1, "mesh");
        scene.commit();
        Rng rng(11, 5);
        int inward = 0;
        for (int i = 0; i < 100000; ++i) {
            Ray primary;
            if (i % 2 == 0) {
                Vec3 o = c + 3.0f * rad * sampleUniformSphere(rng.uniform2());
                Vec3 target = c + 0.5f * rad * sampleUniformSphere(rng.uniform2());
                primary = makeRay(o, target - o);
            } else {
                primary = makeRay(c + 0.5f * rad * sampleUniformSphere(rng.uniform2()),
                                  sampleUniformSphere(rng.uniform2()));
            }
            Hit h;
            ASSERT_TRUE(scene.intersect(primary, &h)) << i;
            Vec3 d = sampleUniformSphere(rng.uniform2());
            Hit h2;
            bool hit = scene.intersect(scene.spawnRay(h, d), &h2);
            if (dot(d, h.geoNormal) >= 0.0f) {
                ASSERT_FALSE(hit) << "outgoing ray re-hit prim " << h2.primId << " at t=" << h2.dist
                                  << " (left prim " << h.primId << ")";
            } else {
                ASSERT_TRUE(hit) << "ray into the closed mesh escaped, i=" << i;
                ASSERT_NE(h2.primId, h.primId);
                ASSERT_GT(h2.dist, 0.0f);
                ++inward;
            }
        }
        EXPECT_GT(inward, 40000);
    }
}

TEST(Scene, MirrorTransformKeepsNormalsOutward) {
    const Vec3 c(1, 2, 3);
    Transform mirror = Transform::translate(c) * Transform::scale({-1, 2, 0.5f}) *
                       Transform::rotate(30, {1, 1, 0});
    ASSERT_LT(mirror.determinant3(), 0.0f);
    TriangleMesh cube = makeCube();
    transformMesh(cube, mirror);
    TriangleMesh ball = makeUvSphere({0, 0, 0}, 1, 8, 16, true);
    transformMesh(ball, Transform::translate({10, 0, 0}) * Transform::scale({-1, 1, 1}));
    // Geometric normals (winding) and vertex normals point away from the centre.
    for (const TriangleMesh* m : {&cube, &ball}) {
        Vec3 centre = (m == &cube) ? c : Vec3(10, 0, 0);
        for (size_t t = 0; t < m->triangleCount(); ++t) {
            const Vec3& p0 = m->positions[m->indices[3 * t]];
            const Vec3& p1 = m->positions[m->indices[3 * t + 1]];
            const Vec3& p2 = m->positions[m->indices[3 * t + 2]];
            Vec3 centroid = (p0 + p1 + p2) / 3.0f;
            EXPECT_GT(dot(cross(p1 - p0, p2 - p0), centroid - centre), 0.0f) << t;
        }
        for (size_t v = 0; v < m->normals.size(); ++v) {
            EXPECT_NEAR(length(m->normals[v]), 1.0f, 1e-5f);
            EXPECT_GT(dot(m->normals[v], m->positions[v] - centre), 0.99f);
        }
    }
    // And through the scene: hits from outside report outward normals.
    Scene scene;
    scene.addMesh(cube, 0, -1, "cube");
    scene.commit();
    Rng rng(5, 5);
    for (int i = 0; i < 1000; ++i) {
        Vec3 o = c + 10.0f * sampleUniformSphere(rng.uniform2());
        Hit h;
        ASSERT_TRUE(scene.intersect(makeRay(o, c - o), &h));
        EXPECT_LT(dot(h.geoNormal, c - o), 0.0f);
    }
}

TEST(Shapes, MeshAreaMatchesAnalytic) {
    EXPECT_FLOAT_EQ(meshArea(makeRectangle()), 4.0f);
    EXPECT_FLOAT_EQ(meshArea(makeCube()), 24.0f);
    TriangleMesh box = makeCube();
    // Box with half extents (1,2,3), rotated and translated: 8 (1*2 + 2*3 + 1*3) = 88.
    transformMesh(box, Transform::translate({4, 5, 6}) * Transform::rotate(40, {1, 2, 3}) *
                           Transform::scale({1, 2, 3}));
    EXPECT_NEAR(meshArea(box), 88.0f, 88.0f * 1e-5f);
    TriangleMesh rect = makeRectangle();
    transformMesh(rect, Transform::rotate(70, {0, 1, 1}) * Transform::scale({3, 0.5f, 1}));
    EXPECT_NEAR(meshArea(rect), 6.0f, 6e-5f);
    // Each rectangle/cube face is a square of side 2 covering uv [0,1]^2.
    TriangleMesh r0 = makeRectangle();
    ASSERT_EQ(r0.uvs.size(), r0.positions.size());
    for (size_t i = 0; i < r0.positions.size(); ++i) {
        EXPECT_FLOAT_EQ(r0.uvs[i].x, 0.5f * (r0.positions[i].x + 1));
        EXPECT_FLOAT_EQ(r0.uvs[i].y, 0.5f * (r0.positions[i].y + 1));
    }
    // A finely tessellated sphere of radius 2 approaches 4 pi r^2 from below
    // (inscribed polyhedron; relative deficit ~ (pi/nTheta)^2/... < 1% at 96x192).
    float a = meshArea(makeUvSphere({0, 0, 0}, 2, 96, 192, false));
    EXPECT_LT(a, 16 * kPi);
    EXPECT_GT(a, 0.99f * 16 * kPi);
}

TEST(Shapes, RectangleAndCubeNormalsPointOutward) {
    TriangleMesh r = makeRectangle();
    ASSERT_EQ(r.triangleCount(), 2u);
    for (size_t t = 0; t < 2; ++t) {
        const Vec3& p0 = r.positions[r.indices[3 * t]];
        Vec3 n = normalize(
            cross(r.positions[r.indices[3 * t + 1]] - p0, r.positions[r.indices[3 * t + 2]] - p0));
        EXPECT_FLOAT_EQ(n.z, 1.0f);
    }
    TriangleMesh c = makeCube();
    ASSERT_EQ(c.triangleCount(), 12u);
    int perAxis[6] = {0, 0, 0, 0, 0, 0};
    for (size_t t = 0; t < 12; ++t) {
        const Vec3& p0 = c.positions[c.indices[3 * t]];
        const Vec3& p1 = c.positions[c.indices[3 * t + 1]];
        const Vec3& p2 = c.positions[c.indices[3 * t + 2]];
        Vec3 n = normalize(cross(p1 - p0, p2 - p0));
        Vec3 centroid = (p0 + p1 + p2) / 3.0f;
        EXPECT_NEAR(dot(n, centroid), 1.0f, 1e-6f);  // the face plane is at distance 1
        for (int k = 0; k < 3; ++k)
            if (std::fabs(n[k]) > 0.999f) {
                EXPECT_EQ(n[k] > 0, centroid[k] > 0);
                perAxis[2 * k + (n[k] > 0)]++;
            }
    }
    for (int k = 0; k < 6; ++k) EXPECT_EQ(perAxis[k], 2);
}

TEST(Scene, SceneSphereContainsAllGeometry) {
    Scene scene;
    Rng rng(9, 9);
    std::vector<std::pair<Vec3, float>> balls;
    std::vector<Vec3> points;
    for (int k = 0; k < 5; ++k) {
        TriangleMesh m = makeCube();
        Vec3 t = 20.0f * (rng.uniform3() - Vec3(0.5f));
        transformMesh(m, Transform::translate(t) *
                             Transform::rotate(90 * rng.uniform(), {1, 2, 0}) *
                             Transform::scale(Vec3(0.1f) + 3.0f * rng.uniform3()));
        points.insert(points.end(), m.positions.begin(), m.positions.end());
        scene.addMesh(m, 0, -1, "box");
        Vec3 c = 30.0f * (rng.uniform3() - Vec3(0.5f));
        float r = 0.1f + 2 * rng.uniform();
        balls.push_back({c, r});
        scene.addSphere(c, r, 0, -1, "ball");
    }
    scene.commit();
    const SceneSphere& s = scene.sceneSphere;
    ASSERT_GT(s.radius, 0.0f);
    EXPECT_FLOAT_EQ(s.invRadiusSqr, 1.0f / (s.radius * s.radius));
    for (const Vec3& p : points) {
        EXPECT_LE(length(p - s.center), s.radius);
        for (int k = 0; k < 3; ++k) {
            EXPECT_GE(p[k], scene.bounds.lo[k]);
            EXPECT_LE(p[k], scene.bounds.hi[k]);
        }
    }
    for (auto& b : balls) EXPECT_LE(length(b.first - s.center) + b.second, s.radius);
    // Not wastefully large: at most the box's half diagonal (plus rounding).
    EXPECT_LE(s.radius, 0.5f * length(scene.bounds.hi - scene.bounds.lo) * 1.001f);
    EXPECT_EQ(scene.shapes.size(), 10u);
    EXPECT_EQ(scene.shapes[0].triangleCount, 12u);
    EXPECT_TRUE(scene.shapes[1].isSphere);
}

TEST(Scene, SceneSphereOfEmptyAndFlatScenesHasPositiveRadius) {
    Scene empty;
    empty.commit();
    EXPECT_GT(empty.sceneSphere.radius, 0.0f);
    EXPECT_TRUE(std::isfinite(empty.sceneSphere.invRadiusSqr));
    Hit h;
    EXPECT_FALSE(empty.intersect(makeRay({0, 0, 0}, {0, 0, 1}), &h));
    EXPECT_FALSE(empty.occluded({0, 0, 0}, {0, 0, 0}, {1, 1, 1}, {0, 0, 0}));

    Scene flat;
    flat.addMesh(makeRectangle(), 0, -1, "rect");
    flat.commit();
    EXPECT_NEAR(flat.sceneSphere.radius, std::sqrt(2.0f), 1e-4f);
    // A single point (one degenerate triangle) still gives radius > 0.
    TriangleMesh dot1;
    dot1.positions = {{5, 5, 5}, {5, 5, 5}, {5, 5, 5}};
    dot1.indices = {0, 1, 2};
    Scene point;
    point.addMesh(dot1, 0, -1, "point");
    point.commit();
    EXPECT_GT(point.sceneSphere.radius, 0.0f);
    EXPECT_TRUE(std::isfinite(point.sceneSphere.invRadiusSqr));
    EXPECT_LE(length(Vec3(5, 5, 5) - point.sceneSphere.center), point.sceneSphere.radius);
}

TEST(Scene, AddMeshRejectsInvalidMeshes) {
    auto message = [](TriangleMesh m) -> std::string {
        Scene s;
        try {
            s.addMesh(std::move(m), 0, -1, "bad");
        } catch (const InputError& e) {
            return e.what();
        }
        return "";
    };
    TriangleMesh m = makeRectangle();
    m.indices[4] = 17;
    EXPECT_NE(message(m).find("vertex index 17 out of range (mesh has 4 vertices)"),
              std::string::npos);
    m = makeRectangle();
    m.positions[3].y = NAN;
    EXPECT_NE(message(m).find("non-finite vertex position at vertex 3"), std::string::npos);
    m = makeRectangle();
    m.indices.pop_back();
    EXPECT_NE(message(m).find("not a multiple of 3"), std::string::npos);
    EXPECT_NE(message(TriangleMesh()).find("mesh 'bad' has no triangles"), std::string::npos);
    m = makeRectangle();
    m.normals.resize(2);
    EXPECT_NE(message(m).find("2 normals for 4 vertices"), std::string::npos);
    Scene s;
    EXPECT_THROW(s.addSphere({0, 0, 0}, 0.0f, 0, -1, "zero"), InputError);
    EXPECT_THROW(s.addSphere({0, NAN, 0}, 1.0f, 0, -1, "nan"), InputError);
    s.commit();
    EXPECT_THROW(s.commit(), std::logic_error);
    EXPECT_THROW(s.addSphere({0, 0, 0}, 1.0f, 0, -1, "late"), std::logic_error);
}

TEST(Scene, ConcurrentQueriesMatchSerial) {
    Scene scene;
    scene.addMesh(makeUvSphere({0, 0, 0}, 1, 16, 32, true), 0, -1, "mesh");
    scene.addSphere({2, 0, 0}, 0.7f, 0, -1, "ball");
    scene.commit();
    const int n = 20000;
    std::vector<Ray> rays(n);
    Rng rng(1, 2);
    for (Ray& r : rays) {
        Vec3 o = Vec3(0.5f, 0, 0) + 5.0f * sampleUniformSphere(rng.uniform2());
        Vec3 target = 2.0f * (rng.uniform3() - Vec3(0.5f));
        r = makeRay(o, target - o);
    }
    std::vector<float> serial(n), parallel(n);
    for (int i = 0; i < n; ++i) {
        Hit h;
        serial[i] = scene.intersect(rays[i], &h) ? h.dist : -1.0f;
    }
    std::vector<std::thread> threads;
    for (int t = 0; t < 4; ++t)
        threads.emplace_back([&, t] {
            for (int i = t; i < n; i += 4) {
                Hit h;
                parallel[i] = scene.intersect(rays[i], &h) ? h.dist : -1.0f;
            }
        });
    for (auto& th : threads) th.join();
    int hits = 0;
    for (int i = 0; i < n; ++i) {
        EXPECT_EQ(serial[i], parallel[i]);
        hits += serial[i] > 0;
    }
    EXPECT_GT(hits, n / 2);  // most rays aim at the unit sphere
}

// Coordinates beyond what the tracer handles are scene errors naming the value; rays built
// at run time that Embree would reject (NaN, huge) are misses and block shadow rays instead
// of aborting inside Embree (its `ray.valid()` assertion; issue: a camera at z = 1e9).
TEST(Scene, OutOfRangeCoordinatesAreErrorsAndBadRaysAreGuarded) {
    {
        Scene scene;
        scene.addSphere({0, 0, 0}, 1, 0, -1, "ball");
        scene.camera.setup({0.0f, 4294967296.0f, 0.0f}, {0, 0, 0}, {0, 0, 1}, 45.0f, 8, 8);
        try {
            scene.commit();
            ADD_FAILURE() << "no error";
        } catch (const InputError& e) {
            const std::string m = e.diagnostics().at(0).format();
            EXPECT_NE(m.find("camera position"), std::string::npos) << m;
            EXPECT_NE(m.find("coordinate y = 4294967296"), std::string::npos) << m;
        }
    }
    {
        Scene scene;
        scene.addSphere({2e7f, 0, 0}, 1, 0, -1, "far ball");
        try {
            scene.commit();
            ADD_FAILURE() << "no error";
        } catch (const InputError& e) {
            EXPECT_NE(e.diagnostics().at(0).format().find("shape 'far ball'"), std::string::npos);
        }
    }
    Scene scene;
    scene.addSphere({0, 0, 0}, 1, 0, -1, "ball");
    scene.commit();
    Hit h;
    const float nan = std::nanf("");
    EXPECT_FALSE(scene.intersect(makeRay({nan, 0, 5}, {0, 0, -1}), &h));
    EXPECT_FALSE(scene.intersect(makeRay({0, 0, 5}, {0, nan, -1}), &h));
    EXPECT_FALSE(scene.intersect(makeRay({0, 0, 1e19f}, {0, 0, -1}), &h));
    EXPECT_TRUE(scene.intersect(makeRay({0, 0, 5}, {0, 0, -1}), &h));  // still hits
}
