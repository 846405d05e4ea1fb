// Trilinear grid density (GridFilter::kTrilinear, src/scene/medium_trilinear.*):
// the density interpolates voxel centres with clamp-to-edge, the exact optical
// depth agrees with numerical quadrature of the density, and free-flight
// sampling inverts it.
#include "scene/medium_trilinear.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "scene/medium.h"

using namespace ub;

namespace {

/// A 5 x 4 x 6 grid of random densities in [0, 3) (no zeros, so every voxel is active).
Medium randomTrilinearMedium(uint32_t seed, const Transform& localToWorld, float scale) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.05f, 3.0f);
    DenseFloatGrid d(5, 4, 6);
    for (auto& v : d.values) v = u(rng);
    GridMediumOptions o;
    o.filter = GridFilter::kTrilinear;
    o.domainLo[0] = o.domainLo[1] = o.domainLo[2] = 0;
    o.domainHi[0] = 4;
    o.domainHi[1] = 3;
    o.domainHi[2] = 5;
    return Medium::heterogeneous(VdbGrid::fromDense(d, "density"), scale, Rgb(0.8f), 0.0f,
                                 localToWorld, o);
}

/// Optical depth by the composite Simpson rule on trilinearDensityAt (40000 intervals) over
/// the part of the ray inside the domain's cells: the density jumps to 0 at the domain faces,
/// so the rule must not straddle them (slab test in cell space, [lo, hi + 1) per axis).
double quadratureTau(const Medium& m, const Vec3& o, const Vec3& d, float len) {
    const Vec3 P = m.worldToCell.point(o), D = m.worldToCell.vector(d);
    double t0 = 0, t1 = len;
    for (int a = 0; a < 3; ++a) {
        double lo = m.domainLo[a], hi = m.domainHi[a] + 1.0;
        if (D[a] == 0) {
            if (P[a] < lo || P[a] >= hi) return 0;
            continue;
        }
        double ta = (lo - P[a]) / D[a], tb = (hi - P[a]) / D[a];
        t0 = std::max(t0, std::min(ta, tb));
        t1 = std::min(t1, std::max(ta, tb));
    }
    if (!(t0 < t1)) return 0;
    const int n = 40000;
    const double h = (t1 - t0) / n;
    double s = 0;
    for (int i = 0; i <= n; ++i) {
        double w = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2);
        // Stay a hair inside the end points so that they evaluate inside the domain.
        double t = std::clamp(t0 + i * h, t0 + 1e-6 * h, t1 - 1e-6 * h);
        s += w * trilinearDensityAt(m, o + d * float(t));
    }
    return s * h / 3.0 * m.densityScale;
}

}  // namespace

TEST(TrilinearMedium, InterpolatesVoxelCentresAndClampsAtEdges) {
    Medium m = randomTrilinearMedium(3, Transform(), 1.0f);
    // Voxel (i, j, k) of a unit-voxel grid covers cell [i, i+1): its centre is (i+1/2, ...)
    // in cell space, i.e. index point (i, j, k) in the grid's local space.
    auto voxel = [&](int i, int j, int k) {
        return m.grid->grid().getAccessor().getValue(nanovdb::Coord(i, j, k));
    };
    EXPECT_NEAR(trilinearDensityAt(m, Vec3(2, 1, 3)), voxel(2, 1, 3), 1e-5f);
    // Midway between two centres along x: their average.
    EXPECT_NEAR(trilinearDensityAt(m, Vec3(2.5f, 1, 3)), 0.5f * (voxel(2, 1, 3) + voxel(3, 1, 3)),
                1e-5f);
    // Between the last centre and the domain face: clamped to the edge voxel.
    EXPECT_NEAR(trilinearDensityAt(m, Vec3(4.3f, 1, 3)), voxel(4, 1, 3), 1e-5f);
    EXPECT_NEAR(trilinearDensityAt(m, Vec3(-0.4f, 1, 3)), voxel(0, 1, 3), 1e-5f);
    // Outside the domain's cells: no medium.
    EXPECT_EQ(trilinearDensityAt(m, Vec3(4.6f, 1, 3)), 0.0f);
    EXPECT_EQ(trilinearDensityAt(m, Vec3(2, -0.6f, 3)), 0.0f);
}

TEST(TrilinearMedium, OpticalDepthMatchesQuadrature) {
    // Rotated, non-uniformly scaled grid; rays from outside and inside, random directions.
    // Simpson's rule with 40000 intervals on a piecewise cubic with ~20 kinks has a relative
    // error below 1e-6; float evaluation of the density limits both sides to ~1e-5.
    Transform xf = Transform::translate(Vec3(0.3f, -1, 2)) * Transform::rotate(30, Vec3(1, 2, 3)) *
                   Transform::scale(Vec3(0.4f, 0.7f, 0.5f));
    Medium m = randomTrilinearMedium(11, xf, 1.7f);
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-1, 1);
    const Vec3 c = m.worldBounds.center();
    for (int k = 0; k < 20; ++k) {
        Vec3 o = c + Vec3(u(rng), u(rng), u(rng)) * 3.0f;
        Vec3 d = normalize(Vec3(u(rng), u(rng), u(rng)));
        const float len = 6.0f;
        double tau = -std::log(double(transmittance(m, o, d, len).x));
        double ref = quadratureTau(m, o, d, len);
        EXPECT_NEAR(tau, ref, 2e-5 * std::max(1.0, ref)) << "ray " << k;
    }
}

TEST(TrilinearMedium, FreeFlightInvertsOpticalDepth) {
    // The sampled distance t satisfies tau(0, t) = -ln(1 - u) (Newton tolerance 1e-12 relative;
    // float transmittance limits the check to ~1e-5), its pdf is sigma_t(t) T(0, t), and a
    // pass happens exactly when tau(0, tMax) < -ln(1 - u).
    Medium m = randomTrilinearMedium(17, Transform::scale(Vec3(0.5f)), 2.0f);
    const Vec3 o(-0.5f, 0.9f, 1.3f), d = normalize(Vec3(1, 0.2f, 0.3f));
    const float tMax = 4.0f;
    const double tauMax = -std::log(double(transmittance(m, o, d, tMax).x));
    for (int k = 1; k < 50; ++k) {
        const float uDist = k / 50.0f;
        const double target = -std::log1p(-double(uDist));
        FreeFlightSample s = sampleFreeFlight(m, o, d, tMax, 0.3f, uDist);
        EXPECT_EQ(s.scattered, target < tauMax) << k;
        if (!s.scattered) {
            EXPECT_NEAR(s.pdf, std::exp(-tauMax), 1e-5);
            continue;
        }
        const double tau = -std::log(double(transmittance(m, o, d, s.t).x));
        EXPECT_NEAR(tau, target, 2e-5 * std::max(1.0, target)) << k;
        const double sigmaT = m.densityScale * trilinearDensityAt(m, o + d * s.t);
        EXPECT_NEAR(s.pdf, sigmaT * std::exp(-tau), 1e-4 * std::max(1.0, sigmaT)) << k;
        EXPECT_NEAR(s.weight.x, 0.8f, 1e-4f);  // T sigma_s / (sigma_t T) = albedo
    }
}

TEST(TrilinearMedium, ConstantGridEqualsNearest) {
    DenseFloatGrid d(3, 3, 3, 1.5f);
    auto grid = VdbGrid::fromDense(d, "density");
    GridMediumOptions o;
    o.filter = GridFilter::kTrilinear;
    Medium tri = Medium::heterogeneous(grid, 1.0f, Rgb(1.0f), 0.0f, Transform(), o);
    Medium near = Medium::heterogeneous(grid, 1.0f, Rgb(1.0f), 0.0f, Transform());
    const Vec3 org(-2, 0.3f, 0.8f), dir = normalize(Vec3(1, 0.1f, 0.05f));
    EXPECT_NEAR(transmittance(tri, org, dir, 8).x, transmittance(near, org, dir, 8).x, 1e-6f);
}
