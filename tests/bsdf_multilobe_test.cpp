// Tests of the MultiLobe material (SmallUPBP's sum of lobes, scene/bsdf.cpp): Lambert +
// Phong + Fresnel-weighted mirror + smooth refraction, with lobe probabilities from the
// lobes' albedos seen from dirFix (kernels/shared/ub_bsdf.h ub_bsdf_multilobe_probs).
//
//  * chi-square of the non-delta lobes against pdf() (delta samples are missing mass);
//  * the delta lobes are picked with their probabilities (binomial bound, 5 sigma) and
//    carry the weights F mirror / P and (1 - F) eta^2 / P (radiance), Snell's direction;
//  * reverse pdfs are exact: pdf(gen, reverse) of the BSDF at dirFix equals pdf(fix) of the
//    BSDF set up at dirGen (lobe probabilities of that direction), and f is reciprocal;
//  * the expected sample weight, E[f cos / pdf], equals the quadrature of f cos over the
//    sphere plus the delta weights (sampling and evaluation agree in expectation);
//  * white-furnace bound: a material whose lobes add to at most 1 reflects at most 1.
// Directions at 5, 45 and 80 degrees, on both sides of a tilted normal (inside a
// refracting material the Lambert and Phong lobes are zero, as in SmallUPBP).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "core/rng.h"
#include "core/sampling.h"
#include "kernels/shared/ub_fresnel.h"
#include "scene/bsdf.h"
#include "tests/support/bsdf_probe.h"
#include "tests/support/chi2.h"

using namespace ub;

namespace {

const Vec3 kNormal = normalize(Vec3(-0.3f, 0.2f, 0.93f));
const float kAnglesDeg[] = {5.0f, 45.0f, 80.0f};
const float kSides[] = {1.0f, -1.0f};

struct NamedMaterial {
    std::string name;
    Material mat;
};

Material multiLobe(Rgb kd, Rgb ks, float ns, Rgb mirror, float ior) {
    Material m;
    m.type = MaterialType::MultiLobe;
    m.diffuse = kd;
    m.glossy = ks;
    m.exponent = ns;
    m.specular = mirror;
    m.refract = ior > 0.0f;
    if (m.refract) {
        m.ior = ior;
        m.twoSided = false;
    }
    return m;
}

std::vector<NamedMaterial> materials() {
    return {
        // SmallUPBP's candle wax: diffuse plus index-matched refraction (F = 0).
        {"Wax", multiLobe(Rgb(0.588f), Rgb(0.0f), 1.0f, Rgb(0.0f), 1.0f)},
        {"GlazedGlass",
         multiLobe(Rgb(0.2f, 0.15f, 0.1f), Rgb(0.3f), 20.0f, Rgb(1.0f, 0.8f, 0.6f), 1.5f)},
        {"Lacquer", multiLobe(Rgb(0.3f, 0.2f, 0.1f), Rgb(0.2f), 50.0f, Rgb(0.4f), -1.0f)},
        {"GlossyWater", multiLobe(Rgb(0.0f), Rgb(0.4f), 10.0f, Rgb(1.0f), 1.33f)},
    };
}

Vec3 directionAt(float thetaDeg, float side, float phiDeg = 30.0f) {
    const float t = thetaDeg * kPi / 180.0f, p = phiDeg * kPi / 180.0f;
    return Frame(kNormal).toWorld(
        Vec3(std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), side * std::cos(t)));
}

Bsdf makeBsdf(const Material& m, const Vec3& dirFix, bool fromLight = false) {
    Bsdf b;
    b.setup(m, dirFix, kNormal, kNormal, fromLight);
    return b;
}

/// The relative IOR across the interface seen from dirFix (outside: the normal's side).
float etaGenOverFix(const Material& m, const Vec3& fix) {
    return dot(fix, kNormal) > 0.0f ? m.ior : 1.0f / m.ior;
}

}  // namespace

TEST(MultiLobe, NonDeltaLobesChiSquare) {
    const auto mats = materials();
    int tests = 0;
    for (const auto& m : mats)
        for (float s : kSides) tests += (s < 0 && m.mat.refract) ? 0 : 3;
    const double alpha = ub::test::sidak(0.01, tests);
    uint64_t seed = 900;
    for (const auto& m : mats)
        for (float theta : kAnglesDeg)
            for (float side : kSides) {
                if (side < 0 && m.mat.refract) continue;  // inside: no non-delta lobe
                const Vec3 fix = directionAt(theta, side);
                const Bsdf bsdf = makeBsdf(m.mat, fix);
                ASSERT_TRUE(bsdf.isValid());
                const ub::test::TestFrame tf(kNormal, fix);
                Rng rng(seed++, 5);
                auto sample = [&]() {
                    Vec3 dir;
                    float pdfW, cosGen;
                    uint32_t event;
                    bsdf.sample(rng.uniform3(), &dir, &pdfW, &cosGen, &event);
                    return pdfW > 0 && !(event & kEventSpecular) ? tf.toTest(dir) : Vec3(0.0f);
                };
                auto pdf = [&](const Vec3& d) { return double(bsdf.pdf(tf.toWorld(d))); };
                auto res = ub::test::chi2TestSphere(sample, pdf, 200000, 40, 80, 10);
                const std::string label = m.name + " theta " + std::to_string(int(theta)) +
                                          (side > 0 ? " front" : " back");
                EXPECT_TRUE(res.message.empty()) << label << ": " << res.message;
                EXPECT_GT(res.pValue, alpha)
                    << label << ": chi2 = " << res.statistic << ", dof = " << res.dof;
            }
}

TEST(MultiLobe, DeltaLobesProbabilitiesWeightsAndDirections) {
    for (const auto& m : materials())
        for (float theta : kAnglesDeg)
            for (float side : kSides)
                for (bool fromLight : {false, true}) {
                    const Vec3 fix = directionAt(theta, side);
                    const Bsdf bsdf = makeBsdf(m.mat, fix, fromLight);
                    const float cosFix = std::fabs(dot(fix, kNormal));
                    const float eta = m.mat.refract ? etaGenOverFix(m.mat, fix) : 1.0f;
                    const float fresnel = m.mat.refract ? ub_fresnel_dielectric(cosFix, eta) : 1.0f;
                    // Lobe albedos; inside a refracting material the Lambert and Phong lobes
                    // are still counted in the selection (and fail when picked).
                    const float d = luminance(m.mat.diffuse), p = luminance(m.mat.glossy);
                    const float r = fresnel * luminance(m.mat.specular);
                    const float t = m.mat.refract ? 1.0f - fresnel : 0.0f;
                    const double pr = r / (d + p + r + t), pt = t / (d + p + r + t);
                    Rng rng(uint64_t(theta * 10 + side + 3), 9);
                    const int n = 40000;
                    int reflections = 0, refractions = 0;
                    for (int i = 0; i < n; ++i) {
                        Vec3 dir;
                        float pdfW, cosGen;
                        uint32_t event;
                        const Rgb f = bsdf.sample(rng.uniform3(), &dir, &pdfW, &cosGen, &event);
                        if (!(pdfW > 0) || !(event & kEventSpecular)) continue;
                        const Rgb w = f * (cosGen / pdfW);
                        if (event & kEventReflect) {
                            ++reflections;
                            EXPECT_NEAR(pdfW, pr, 1e-5);
                            const Vec3 mirror = reflect(fix, side > 0 ? kNormal : -kNormal);
                            EXPECT_NEAR(dot(dir, mirror), 1.0f, 1e-5f);
                            for (int c = 0; c < 3; ++c)
                                EXPECT_NEAR(w[c], fresnel * m.mat.specular[c] / pr, 1e-4);
                        } else {
                            ++refractions;
                            EXPECT_NEAR(pdfW, pt, 1e-5);
                            // Snell: sin_gen = sin_fix / eta, on the other side.
                            const float cosGenN = dot(dir, kNormal), cosFixN = dot(fix, kNormal);
                            EXPECT_LT(cosGenN * cosFixN, 0.0f);
                            EXPECT_NEAR(std::sqrt(std::max(0.0f, 1.0f - cosGenN * cosGenN)),
                                        std::sqrt(std::max(0.0f, 1.0f - cosFixN * cosFixN)) / eta,
                                        1e-4f);
                            const float scale = fromLight ? 1.0f : 1.0f / (eta * eta);
                            for (int c = 0; c < 3; ++c)
                                EXPECT_NEAR(w[c], (1.0f - fresnel) * scale / pt, 1e-4);
                        }
                    }
                    for (auto [count, prob] : {std::pair<int, double>(reflections, pr),
                                               std::pair<int, double>(refractions, pt)}) {
                        const double sigma = std::sqrt(n * prob * (1 - prob));
                        EXPECT_NEAR(count, n * prob, 5 * sigma + 1)
                            << m.name << " theta " << theta << " side " << side;
                    }
                }
}

TEST(MultiLobe, ReversePdfsAreExactAndValuesReciprocal) {
    Rng rng(3, 3);
    for (const auto& m : materials()) {
        int checked = 0;
        for (int i = 0; i < 4000; ++i) {
            const Vec3 fix = sampleUniformSphere(rng.uniform2());
            const Vec3 gen = sampleUniformSphere(rng.uniform2());
            const Bsdf a = makeBsdf(m.mat, fix), b = makeBsdf(m.mat, gen);
            if (!a.isValid() || !b.isValid()) continue;
            float pdA, prA, pdB, prB, c;
            const Rgb fa = a.evaluate(gen, &c, &pdA, &prA);
            const Rgb fb = b.evaluate(fix, &c, &pdB, &prB);
            EXPECT_NEAR(prA, pdB, 1e-5f * std::max(prA, pdB) + 1e-12f) << m.name;
            EXPECT_NEAR(pdA, prB, 1e-5f * std::max(pdA, prB) + 1e-12f) << m.name;
            for (int k = 0; k < 3; ++k)
                EXPECT_NEAR(fa[k], fb[k], 1e-5f * std::max(fa[k], fb[k]) + 1e-12f) << m.name;
            checked += pdA > 0.0f;
        }
        EXPECT_GT(checked, 300) << m.name;
    }
}

// E[f cos / pdf] over sample() against the midpoint quadrature of f cos over the front
// hemisphere (400 x 800 cells in (cos theta, phi) of the shading frame) plus the delta
// lobes' weights F mirror + (1 - F)/eta^2: within 5 standard errors + 2e-3 (quadrature).
TEST(MultiLobe, SampleWeightsMatchEvaluateInExpectation) {
    for (const auto& m : materials())
        for (float theta : {10.0f, 60.0f}) {
            const Vec3 fix = directionAt(theta, 1.0f);
            const Bsdf bsdf = makeBsdf(m.mat, fix);
            const ub::test::Albedo mc = ub::test::albedo(bsdf, 400000, 11);
            const Frame fr(kNormal);
            const int nz = 400, nphi = 800;
            double quad[3] = {0, 0, 0};
            for (int i = 0; i < nz; ++i)
                for (int j = 0; j < nphi; ++j) {
                    const float cz = (i + 0.5f) / nz, phi = 2 * kPi * (j + 0.5f) / nphi;
                    const float sz = std::sqrt(1 - cz * cz);
                    const Vec3 d = fr.toWorld(Vec3(sz * std::cos(phi), sz * std::sin(phi), cz));
                    float c;
                    const Rgb f = bsdf.evaluate(d, &c, nullptr, nullptr);
                    for (int k = 0; k < 3; ++k) quad[k] += f[k] * c * (1.0 / nz) * (2 * kPi / nphi);
                }
            const float cosFix = dot(fix, kNormal);
            const float fresnel = m.mat.refract ? ub_fresnel_dielectric(cosFix, m.mat.ior) : 1.0f;
            for (int k = 0; k < 3; ++k) {
                const double delta =
                    fresnel * m.mat.specular[k] +
                    (m.mat.refract ? (1 - fresnel) / (m.mat.ior * m.mat.ior) : 0.0);
                EXPECT_NEAR(mc.mean[k], quad[k] + delta, 5 * mc.stdErr[k] + 2e-3)
                    << m.name << " theta " << theta << " channel " << k;
            }
        }
}

TEST(MultiLobe, FurnaceBoundWhenLobesAddToAtMostOne) {
    const Material m = multiLobe(Rgb(0.5f, 0.3f, 0.2f), Rgb(0.2f), 30.0f, Rgb(0.3f), -1.0f);
    for (float theta : kAnglesDeg) {
        const Bsdf bsdf = makeBsdf(m, directionAt(theta, 1.0f));
        const ub::test::Albedo a = ub::test::albedo(bsdf, 200000, 21);
        for (int k = 0; k < 3; ++k) EXPECT_LE(a.mean[k], 1.0f + 4 * a.stdErr[k]) << theta;
        EXPECT_LE(bsdf.continuationProb(), 1.0f);
        EXPECT_FALSE(bsdf.isDelta());
    }
    // Only delta lobes: a delta BSDF (no connections or merging at it).
    const Material glass = multiLobe(Rgb(0.0f), Rgb(0.0f), 1.0f, Rgb(1.0f), 1.5f);
    EXPECT_TRUE(makeBsdf(glass, directionAt(45, 1)).isDelta());
}
