#include <gtest/gtest.h>

#include "core/rng.h"
#include "core/sampling.h"
#include "core/vec.h"

using namespace ub;

TEST(Rng, SameStreamIsDeterministic) {
    Rng a = Rng::forPath(7, 3, 1234), b = Rng::forPath(7, 3, 1234);
    for (int i = 0; i < 100; ++i) EXPECT_EQ(a.nextU32(), b.nextU32());
}

TEST(Rng, DifferentPixelsGiveDifferentStreams) {
    Rng a = Rng::forPath(7, 3, 1234), b = Rng::forPath(7, 3, 1235);
    int same = 0;
    for (int i = 0; i < 100; ++i) same += a.nextU32() == b.nextU32();
    EXPECT_LE(same, 1);
}

TEST(Rng, UniformMeanAndRange) {
    Rng r(1, 1);
    double s = 0;
    const int n = 200000;
    for (int i = 0; i < n; ++i) {
        float u = r.uniform();
        ASSERT_GE(u, 0.0f);
        ASSERT_LT(u, 1.0f);
        s += u;
    }
    // Standard error of the mean of U(0,1): sqrt(1/12/n) = 6.5e-4; bound at 5 sigma.
    EXPECT_NEAR(s / n, 0.5, 5 * std::sqrt(1.0 / 12.0 / n));
}

TEST(Transform, InverseRoundTrip) {
    Transform t = Transform::translate({1, 2, 3}) * Transform::rotate(33, {1, 1, 0}) *
                  Transform::scale({2, 0.5f, 3});
    Transform ti = t.inverse();
    Vec3 p(0.3f, -4, 7);
    Vec3 q = ti.point(t.point(p));
    EXPECT_NEAR(q.x, p.x, 1e-4);
    EXPECT_NEAR(q.y, p.y, 1e-4);
    EXPECT_NEAR(q.z, p.z, 1e-4);
}

TEST(Frame, IsOrthonormal) {
    Rng r(3, 4);
    for (int i = 0; i < 1000; ++i) {
        Frame f(sampleUniformSphere(r.uniform2()));
        EXPECT_NEAR(dot(f.s, f.t), 0, 1e-5);
        EXPECT_NEAR(dot(f.s, f.n), 0, 1e-5);
        EXPECT_NEAR(length(f.s), 1, 1e-5);
        EXPECT_NEAR(length(f.t), 1, 1e-5);
        Vec3 v(0.2f, -0.5f, 0.7f);
        Vec3 w = f.toWorld(f.toLocal(v));
        EXPECT_NEAR(length(w - v), 0, 1e-5);
    }
}

TEST(Distribution1D, DiscreteFrequenciesMatchPmf) {
    std::vector<float> f = {1, 0, 3, 6};
    Distribution1D d(f);
    Rng r(5, 6);
    const int n = 100000;
    std::vector<int> counts(4, 0);
    for (int i = 0; i < n; ++i) counts[d.sampleDiscrete(r.uniform())]++;
    EXPECT_EQ(counts[1], 0);
    for (int i = 0; i < 4; ++i) {
        double p = d.pmf(i);
        // binomial standard deviation, 5 sigma bound
        EXPECT_NEAR(counts[i] / double(n), p, 5 * std::sqrt(p * (1 - p) / n) + 1e-9);
    }
}

TEST(Distribution2D, PdfMatchesSampledPdf) {
    std::vector<float> f = {1, 2, 3, 4, 5, 6};
    Distribution2D d(f, 3, 2);
    Rng r(9, 9);
    for (int i = 0; i < 1000; ++i) {
        float pdf;
        Vec2 p = d.sampleContinuous(r.uniform2(), &pdf);
        EXPECT_NEAR(pdf, d.pdf(p), 1e-4f * pdf);
    }
}
