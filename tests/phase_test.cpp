// Henyey-Greenstein phase function (kernels/shared/ub_phase.h): normalisation,
// sampling against the pdf (chi-square), the mean cosine, symmetry.
#include <gtest/gtest.h>

#include <cmath>

#include "core/rng.h"
#include "core/vec.h"
#include "kernels/shared/ub_phase.h"
#include "tests/support/chi2.h"

namespace ub {
namespace {

const float kGs[] = {-0.9f, 0.0f, 0.6f, 0.9f};
constexpr int kGCount = 4;

ub_float3 toF3(const Vec3& v) {
    return ub_make_float3(v.x, v.y, v.z);
}
Vec3 toVec3(const ub_float3& v) {
    return {v.x, v.y, v.z};
}

// 2 pi * integral over cosTheta in [-1, 1] of p(cosTheta) must be 1. Composite
// midpoint rule in double over the float eval with 2^20 cells; for g = +-0.9 the
// integrand's second derivative is at most ~2e5 near the peak, so the rule's
// error is below 2 * 2e5 * (2 / 2^20)^2 / 24 ~ 6e-8, far under the 1e-3 bound.
TEST(HenyeyGreenstein, Normalized) {
    for (float g : {-0.99f, -0.9f, -0.3f, 0.0f, 0.2f, 0.6f, 0.9f, 0.99f}) {
        const int n = 1 << 20;
        double sum = 0;
        for (int i = 0; i < n; ++i) {
            double mu = -1.0 + (i + 0.5) * 2.0 / n;
            sum += ub_hg_eval(float(mu), g);
        }
        double integral = 2.0 * M_PI * sum * (2.0 / n);
        EXPECT_NEAR(integral, 1.0, 1e-3) << "g = " << g;
    }
}

// Sampled directions against ub_hg_pdf. Bins are laid out around the propagation
// direction -wFix (a fixed, oblique wFix so that the world-frame code is
// exercised). Four g values share an overall significance of 1% (Sidak).
// The cell integrals use 64x64 midpoints per cell: with the default 8x8 the
// peak of g = +-0.9 (p rises from 0.18 to 15 across the first z-bin) is
// under-integrated by a few percent, which 1e6 samples detect.
TEST(HenyeyGreenstein, SamplingChiSquare) {
    const Vec3 wFix = normalize(Vec3(0.3f, -0.5f, 0.8f));
    const Frame frame(-wFix);  // +z of the binning frame = propagation direction
    const double alpha = test::sidak(0.01, kGCount);
    for (int k = 0; k < kGCount; ++k) {
        const float g = kGs[k];
        Rng rng(1234, k);
        auto sample = [&]() {
            float pdfW;
            Vec3 w = toVec3(ub_hg_sample(toF3(wFix), g, rng.uniform(), rng.uniform(), &pdfW));
            // The reported pdf must be the pdf of the returned direction.
            EXPECT_NEAR(pdfW, ub_hg_pdf(toF3(wFix), toF3(w), g), 1e-4f * pdfW);
            return frame.toLocal(w);
        };
        auto pdf = [&](const Vec3& local) {
            return double(ub_hg_pdf(toF3(wFix), toF3(frame.toWorld(local)), g));
        };
        test::Chi2Result r = test::chi2TestSphere(sample, pdf, 1000000, 20, 40, 64);
        ASSERT_TRUE(r.message.empty()) << r.message;
        EXPECT_GT(r.pValue, alpha)
            << "g = " << g << " chi2 = " << r.statistic << " dof = " << r.dof;
    }
}

// E[cosTheta] = g with cosTheta = -dot(wFix, wGen): pins down the sign
// convention (g > 0 scatters forward, away from wFix). 200k samples; the
// standard error is sqrt(Var/n) with Var(cosTheta) <= 1, bound 4 sigma.
TEST(HenyeyGreenstein, MeanCosineIsG) {
    const Vec3 wFix = normalize(Vec3(-0.2f, 0.9f, 0.1f));
    for (int k = 0; k < kGCount; ++k) {
        const float g = kGs[k];
        Rng rng(99, k);
        const int n = 200000;
        double sum = 0, sum2 = 0;
        for (int i = 0; i < n; ++i) {
            float pdfW;
            Vec3 w = toVec3(ub_hg_sample(toF3(wFix), g, rng.uniform(), rng.uniform(), &pdfW));
            EXPECT_NEAR(length(w), 1.0f, 1e-4f);
            double c = -dot(wFix, w);
            sum += c;
            sum2 += c * c;
        }
        double mean = sum / n, var = sum2 / n - mean * mean;
        EXPECT_NEAR(mean, g, 4.0 * std::sqrt(var / n) + 1e-6) << "g = " << g;
    }
}

// HG is its own adjoint: p(wGen | wFix) = p(wFix | wGen).
TEST(HenyeyGreenstein, Reciprocal) {
    Rng rng(5, 0);
    for (int i = 0; i < 1000; ++i) {
        ub_float3 a = toF3(normalize(rng.uniform3() - Vec3(0.5f)));
        ub_float3 b = toF3(normalize(rng.uniform3() - Vec3(0.5f)));
        float g = 1.8f * rng.uniform() - 0.9f;
        EXPECT_FLOAT_EQ(ub_hg_pdf(a, b, g), ub_hg_pdf(b, a, g));
    }
}

// The sampling map covers [-1, 1] monotonically, g = 0 is uniform in cosTheta.
TEST(HenyeyGreenstein, SampleCosThetaEndpoints) {
    for (float g : kGs) {
        EXPECT_NEAR(ub_hg_sample_cos_theta(g, 0.0f), -1.0f, 1e-5f) << g;
        EXPECT_NEAR(ub_hg_sample_cos_theta(g, 1.0f), 1.0f, 1e-5f) << g;
        float prev = -2.0f;
        for (int i = 0; i <= 100; ++i) {
            float c = ub_hg_sample_cos_theta(g, i / 100.0f);
            EXPECT_GE(c, prev) << g;
            prev = c;
        }
    }
    EXPECT_FLOAT_EQ(ub_hg_sample_cos_theta(0.0f, 0.25f), -0.5f);
}

}  // namespace
}  // namespace ub
