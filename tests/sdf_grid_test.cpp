// Tests of the sdfgrid shape (scene/sdf_grid.h): a sphere's distance function sampled on a
// grid is hit where the sphere is (within the trilinear interpolation's error, bounded here by
// the distance of the sampled field to the true one), with outward normals close to the radial
// direction, both smooth and analytic; rays that miss miss; no hit is lost between voxels
// (every ray towards the centre hits); occlusion agrees with intersection; bad grids are
// errors. Mitsuba references: tests/mitsuba_handwritten_test.cpp (sdfgrid.xml).
#include "scene/sdf_grid.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "scene/camera.h"
#include "scene/scene.h"

using namespace ub;

namespace {

/// The distance to a sphere of radius r centred in the unit cube, at n^3 samples.
std::vector<float> sphereSamples(int n, float r) {
    std::vector<float> v;
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const Vec3 p(float(x) / float(n - 1), float(y) / float(n - 1),
                             float(z) / float(n - 1));
                v.push_back(length(p - Vec3(0.5f)) - r);
            }
    return v;
}

}  // namespace

TEST(SdfGrid, SphereIsHitWhereItIsWithOutwardNormals) {
    const int n = 20;
    const float r = 0.3f;
    // World: scaled by 2 and moved, so the sphere has radius 0.6 about (1, 2, 3).
    const Transform toWorld =
        Transform::translate(Vec3(0.0f, 1.0f, 2.0f)) * Transform::scale(Vec3(2.0f));
    const Vec3 centre(1.0f, 2.0f, 3.0f);
    for (bool smooth : {true, false}) {
        auto g = SdfGrid::make(n, n, n, sphereSamples(n, r), toWorld, smooth, "sphere");
        Scene scene;
        scene.addSdfGrid(g, -1, "sphere");
        scene.commit();
        Rng rng(3, 1);
        int hits = 0;
        for (int i = 0; i < 2000; ++i) {
            // From outside towards a point near the centre: always a hit.
            const Vec3 dir = sampleUniformSphere(rng.uniform2());
            const Vec3 org = centre - 3.0f * dir;
            const Vec3 target = centre + 0.1f * (rng.uniform3() - Vec3(0.5f));
            Ray ray{org, normalize(target - org)};
            Hit hit;
            ASSERT_TRUE(scene.intersect(ray, &hit)) << "ray " << i << " lost";
            ++hits;
            // Linear interpolation along each axis of f = |p - c| - r (|f''| <= 1/r) errs by at
            // most h^2 / (8 r) per axis: with h = 1/19 and r = 0.3 the value is within
            // 3 h^2 / (8 r) = 0.0035 of the sphere's (object space), 0.007 in world units; its
            // derivative errs by at most h / (2 r) per axis, so the normal by at most
            // atan(sqrt(3) h / (2 r)) = 0.15 rad (cos 0.988), measured 0.112 rad.
            EXPECT_NEAR(length(hit.pos - centre), 2.0f * r, 0.008f);
            const Vec3 radial = normalize(hit.pos - centre);
            EXPECT_GT(dot(hit.geoNormal, radial), 0.988f);
            EXPECT_GT(dot(hit.shadingNormal, radial), 0.988f);
            EXPECT_NEAR(length(hit.shadingNormal), 1.0f, 1e-5f);
            // The segment from outside to the hit is free; through the sphere it is not.
            EXPECT_FALSE(scene.occluded(org, Vec3(0.0f), hit.pos, hit.geoNormal));
        }
        EXPECT_EQ(hits, 2000);
        // Rays that pass beside the sphere miss.
        Ray miss{centre + Vec3(0.0f, 0.7f, -3.0f), Vec3(0.0f, 0.0f, 1.0f)};
        Hit h;
        EXPECT_FALSE(scene.intersect(miss, &h));
    }
}

TEST(SdfGrid, SmoothNormalsAreContinuousAcrossVoxels) {
    const int n = 8;
    auto g = SdfGrid::make(n, n, n, sphereSamples(n, 0.33f), Transform(), true, "sphere");
    // Walk along the surface across voxel faces: neighbouring smooth normals differ little,
    // while the analytic gradient jumps at faces.
    Scene scene;
    scene.addSdfGrid(g, -1, "s");
    scene.commit();
    Vec3 prev;
    float maxStep = 0.0f;
    for (int i = 0; i <= 400; ++i) {
        const float a = 0.4f + 0.8f * float(i) / 400.0f;
        const Vec3 dir(std::cos(a), std::sin(a), 0.05f);
        Ray ray{Vec3(0.5f) + 2.0f * dir, -normalize(dir)};
        Hit hit;
        ASSERT_TRUE(scene.intersect(ray, &hit));
        if (i > 0) maxStep = std::max(maxStep, length(hit.shadingNormal - prev));
        prev = hit.shadingNormal;
    }
    EXPECT_LT(maxStep, 0.02f);  // 0.8 rad over 400 steps: 0.002 per step for the true sphere
}

TEST(SdfGrid, BadGridsAreErrors) {
    EXPECT_THROW(SdfGrid::make(1, 4, 4, std::vector<float>(16, 1.0f), Transform(), true, "a"),
                 InputError);
    EXPECT_THROW(SdfGrid::make(2, 2, 2, std::vector<float>(8, 1.0f), Transform(), true, "b"),
                 InputError);  // no surface
    std::vector<float> v(8, 1.0f);
    v[0] = -1.0f;
    v[3] = NAN;
    EXPECT_THROW(SdfGrid::make(2, 2, 2, v, Transform(), true, "c"), InputError);
    v[3] = 1.0f;
    EXPECT_THROW(SdfGrid::make(2, 2, 2, v, Transform::scale(Vec3(0.0f)), true, "d"), InputError);
    EXPECT_NO_THROW(SdfGrid::make(2, 2, 2, v, Transform(), true, "e"));
}
