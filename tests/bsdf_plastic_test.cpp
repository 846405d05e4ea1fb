// Tests of the Plastic, RoughPlastic and ThinDielectric BSDFs (scene/bsdf_plastic.cpp) and
// kernels/shared/ub_plastic.h, in the style of bsdf_test.cpp.
//
// Parameter grid: smooth plastic at IOR 1.49 (Mitsuba's polypropylene default) and 1.9
// with a coloured base, linear and nonlinear; rough plastic at GGX alpha 0.05, 0.3, 0.8;
// incidence 5, 45 and 80 degrees; dirFix on the front and on the back (two-sided: the
// back mirrors the front); a tilted normal so the frame code is exercised.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "core/rng.h"
#include "core/sampling.h"
#include "kernels/shared/ub_fresnel.h"
#include "kernels/shared/ub_plastic.h"
#include "scene/bsdf.h"
#include "tests/support/bsdf_probe.h"
#include "tests/support/chi2.h"

using namespace ub;

namespace {

using ub::test::albedo;
using ub::test::Albedo;
using ub::test::TestFrame;

const Vec3 kNormal = normalize(Vec3(-0.3f, 0.2f, 0.9f));
const float kAnglesDeg[] = {5.0f, 45.0f, 80.0f};
const float kSides[] = {1.0f, -1.0f};

struct NamedMaterial {
    std::string name;
    Material mat;
    bool sharp;  ///< narrow lobe: finer chi-square bins
};

Material plastic(float ior, bool nonlinear = false) {
    Material m;
    m.type = MaterialType::Plastic;
    m.ior = ior;
    m.diffuse = Rgb(0.1f, 0.27f, 0.36f);
    m.nonlinear = nonlinear;
    prepareMaterial(m);
    return m;
}
Material roughPlastic(float alpha, float ior = 1.49f) {
    Material m;
    m.type = MaterialType::RoughPlastic;
    m.ior = ior;
    m.alpha = alpha;
    m.diffuse = Rgb(0.7f, 0.5f, 0.2f);
    m.specular = Rgb(0.9f, 0.8f, 1.0f);
    prepareMaterial(m);
    return m;
}
/// The same rough material with Beckmann microfacets (Mitsuba 3's default), re-prepared.
Material beckmann(Material m) {
    m.distribution = MicrofacetDistribution::kBeckmann;
    prepareMaterial(m);
    return m;
}
Material thinGlass(float ior) {
    Material m;
    m.type = MaterialType::ThinDielectric;
    m.ior = ior;
    m.specular = Rgb(0.9f, 0.8f, 0.7f);
    m.transmittance = Rgb(0.5f, 0.6f, 0.7f);
    return m;
}

std::vector<NamedMaterial> plasticMaterials() {
    return {{"Plastic1.49", plastic(1.49f), false},
            {"Plastic1.9nonlinear", plastic(1.9f, true), false},
            {"RoughPlastic0.05", roughPlastic(0.05f), true},
            {"RoughPlastic0.3", roughPlastic(0.3f), false},
            {"RoughPlastic0.8", roughPlastic(0.8f, 1.9f), false},
            {"RoughPlastic0.3Beckmann", beckmann(roughPlastic(0.3f)), false}};
}

Vec3 directionAt(const Vec3& n, float thetaDeg, float side, float phiDeg = 30.0f) {
    float t = thetaDeg * kPi / 180.0f, p = phiDeg * kPi / 180.0f;
    return Frame(n).toWorld(
        Vec3(std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), side * std::cos(t)));
}

Bsdf makeBsdf(const Material& m, const Vec3& dirFix, bool fromLight = false) {
    Bsdf b;
    b.setup(m, dirFix, kNormal, kNormal, fromLight);
    return b;
}
// A Bsdf keeps a pointer to its material: a temporary would dangle.
Bsdf makeBsdf(Material&&, const Vec3&, bool = false) = delete;

struct Config {
    std::shared_ptr<const NamedMaterial> m;
    float theta, side;
    Vec3 dirFix() const { return directionAt(kNormal, theta, side); }
    std::string label() const {
        return m->name + " theta=" + std::to_string(int(theta)) + (side > 0 ? " front" : " back");
    }
};

std::vector<Config> configs(const std::vector<NamedMaterial>& mats) {
    std::vector<Config> r;
    for (auto& m : mats)
        for (float t : kAnglesDeg)
            for (float s : kSides) r.push_back({std::make_shared<const NamedMaterial>(m), t, s});
    return r;
}

bool nearRel(float a, float b, float rel = 1e-4f) {
    return std::fabs(a - b) <= rel * std::max(std::fabs(a), std::fabs(b)) + 1e-20f;
}
bool nearRel(const Rgb& a, const Rgb& b, float rel = 1e-4f) {
    return nearRel(a.x, b.x, rel) && nearRel(a.y, b.y, rel) && nearRel(a.z, b.z, rel);
}
std::string str(const Rgb& c) {
    return "(" + std::to_string(c.x) + ", " + std::to_string(c.y) + ", " + std::to_string(c.z) +
           ")";
}

/// The mirror direction of dirFix about the normal on dirFix's side.
Vec3 mirrorOf(const Vec3& fix) {
    return reflect(fix, dot(fix, kNormal) > 0 ? kNormal : -kNormal);
}

/// Exact hemispherical diffuse reflectance 2 int_0^1 F(mu, eta) mu dmu (midpoint rule,
/// 200k cells: error far below 1e-6 even with the TIR kink).
double exactFdr(float eta) {
    const int n = 200000;
    double sum = 0;
    for (int i = 0; i < n; ++i) {
        double mu = (i + 0.5) / n;
        sum += ub_fresnel_dielectric(float(mu), eta) * mu;
    }
    return 2.0 * sum / n;
}

}  // namespace

// ---------------------------------------------------------------------------------------
// Chi-square of the non-delta lobes (same binning and bounds as bsdf_test.cpp: 200k
// samples, 40 x 80 cells with 10 x 10 quadrature, 100 x 200 with 4 x 4 for the alpha =
// 0.05 lobe; overall significance 1%, Sidak-corrected). The smooth plastic's delta
// reflection is sampled with probability P(specular | dirFix); those samples count as
// missing mass, which the pdf of the diffuse lobe, (1 - P) cos / pi, accounts for.
TEST(Bsdf, PlasticChiSquare) {
    const std::vector<Config> cs = configs(plasticMaterials());
    const double alpha = ub::test::sidak(0.01, int(cs.size()));
    uint64_t seed = 500;
    for (const Config& c : cs) {
        const Vec3 dirFix = c.dirFix();
        const Bsdf bsdf = makeBsdf(c.m->mat, dirFix);
        ASSERT_TRUE(bsdf.isValid()) << c.label();
        const TestFrame tf(kNormal, dirFix);
        Rng rng(seed++, 7);
        auto sample = [&]() {
            Vec3 dir;
            float pdfW, cosGen;
            uint32_t event;
            bsdf.sample(rng.uniform3(), &dir, &pdfW, &cosGen, &event);
            return pdfW > 0 && !(event & kEventSpecular) ? tf.toTest(dir) : Vec3(0.0f);
        };
        auto pdf = [&](const Vec3& d) { return double(bsdf.pdf(tf.toWorld(d))); };
        const bool sharp = c.m->sharp;
        auto res = ub::test::chi2TestSphere(sample, pdf, 200000, sharp ? 100 : 40, sharp ? 200 : 80,
                                            sharp ? 4 : 10);
        EXPECT_TRUE(res.message.empty()) << c.label() << ": " << res.message;
        EXPECT_GT(res.pValue, alpha)
            << c.label() << ": chi2 = " << res.statistic << ", dof = " << res.dof;
    }
}

// sample() agrees with evaluate()/pdf() for the non-delta lobes (relative 1e-4: the same
// float code path); delta samples of the smooth plastic are the mirror direction with
// pdf P(specular | dirFix) and throughput specular F(cos) / P.
TEST(Bsdf, PlasticSampleMatchesEvaluateAndPdf) {
    uint64_t seed = 600;
    for (const Config& c : configs(plasticMaterials())) {
        for (bool fromLight : {false, true}) {
            const Vec3 fix = c.dirFix();
            const Bsdf bsdf = makeBsdf(c.m->mat, fix, fromLight);
            Rng rng(seed++, 11);
            int diffuse = 0, delta = 0;
            for (int i = 0; i < 2000; ++i) {
                Vec3 dir;
                float pdfW, cosGen;
                uint32_t event;
                Rgb f = bsdf.sample(rng.uniform3(), &dir, &pdfW, &cosGen, &event);
                if (pdfW == 0) {
                    ASSERT_TRUE(isBlack(f)) << c.label();
                    continue;
                }
                ASSERT_NEAR(length(dir), 1.0f, 1e-5f) << c.label();
                if (event & kEventSpecular) {
                    ++delta;
                    ASSERT_EQ(c.m->mat.type, MaterialType::Plastic);
                    ASSERT_EQ(event, uint32_t(kEventReflect));
                    ASSERT_NEAR(length(dir - mirrorOf(fix)), 0.0f, 1e-5f) << c.label();
                    const float cosI = std::fabs(dot(fix, kNormal));
                    const float fres = ub_fresnel_dielectric(cosI, c.m->mat.ior);
                    ASSERT_TRUE(nearRel(f * (cosGen / pdfW) * pdfW, c.m->mat.specular * fres))
                        << c.label() << str(f);
                    continue;
                }
                ++diffuse;
                float cosEval, pdfEval, revEval;
                Rgb fEval = bsdf.evaluate(dir, &cosEval, &pdfEval, &revEval);
                ASSERT_TRUE(nearRel(f, fEval)) << c.label() << str(f) << " vs " << str(fEval);
                ASSERT_TRUE(nearRel(pdfW, pdfEval)) << c.label() << pdfW << " vs " << pdfEval;
                ASSERT_TRUE(nearRel(revEval, bsdf.pdf(dir, true))) << c.label();
                ASSERT_TRUE(nearRel(cosGen, cosEval)) << c.label();
                ASSERT_TRUE(event == kEventDiffuse || event == kEventGlossy) << c.label();
            }
            EXPECT_GT(diffuse, 200) << c.label();
            if (c.m->mat.type == MaterialType::Plastic) EXPECT_GT(delta, 0) << c.label();
        }
    }
}

// The reverse pdf of (a -> b) is the pdf of a BSDF set up at b sampling a, and the
// plastics are reciprocal, f(a, b) = f(b, a), in both transport modes (Ns = Ng).
TEST(Bsdf, PlasticReversePdfAndReciprocity) {
    uint64_t seed = 700;
    for (const Config& c : configs(plasticMaterials())) {
        const Vec3 a = c.dirFix();
        const Bsdf bsdfA = makeBsdf(c.m->mat, a);
        Rng rng(seed++, 13);
        int checked = 0;
        for (int i = 0; i < 500; ++i) {
            Vec3 b;
            float pdfW, cosGen;
            uint32_t event;
            bsdfA.sample(rng.uniform3(), &b, &pdfW, &cosGen, &event);
            if (pdfW == 0 || (event & kEventSpecular)) continue;
            float pdfAB, revAB, pdfBA, revBA;
            Rgb fAB = bsdfA.evaluate(b, nullptr, &pdfAB, &revAB);
            for (bool fromLight : {false, true}) {
                const Bsdf bsdfB = makeBsdf(c.m->mat, b, fromLight);
                Rgb fBA = bsdfB.evaluate(a, nullptr, &pdfBA, &revBA);
                ASSERT_TRUE(nearRel(revAB, pdfBA)) << c.label() << revAB << " vs " << pdfBA;
                ASSERT_TRUE(nearRel(pdfAB, revBA)) << c.label() << pdfAB << " vs " << revBA;
                ASSERT_TRUE(nearRel(fAB, fBA)) << c.label() << str(fAB) << " vs " << str(fBA);
            }
            ++checked;
        }
        EXPECT_GT(checked, 100) << c.label();
    }
}

// The delta reflection of the smooth plastic is picked with probability
// P = F w / (F w + (1 - F)(1 - w)), w = mean(specular) / (mean(diffuse) + mean(specular))
// (binomial z-test at 4 sigma over 20000 samples, 6 checks: false-failure rate 4e-4).
TEST(Bsdf, PlasticSpecularSelectionFrequency) {
    const Material m = plastic(1.49f);
    for (float theta : kAnglesDeg)
        for (float side : kSides) {
            const Vec3 fix = directionAt(kNormal, theta, side);
            const Bsdf b = makeBsdf(m, fix);
            const float fres = ub_fresnel_dielectric(std::cos(theta * kPi / 180), m.ior);
            const float meanD = (m.diffuse.x + m.diffuse.y + m.diffuse.z) / 3, meanS = 1.0f;
            const float w = meanS / (meanD + meanS);
            const double p = fres * w / (fres * w + (1 - fres) * (1 - w));
            Rng rng(uint64_t(theta) + (side > 0 ? 0 : 100), 3);
            const int n = 20000;
            int deltas = 0;
            for (int i = 0; i < n; ++i) {
                Vec3 dir;
                float pdfW, cosGen;
                uint32_t event;
                b.sample(rng.uniform3(), &dir, &pdfW, &cosGen, &event);
                if (event & kEventSpecular) {
                    ++deltas;
                    ASSERT_NEAR(pdfW, p, 1e-5) << theta;
                }
            }
            EXPECT_NEAR(double(deltas) / n, p, 4 * std::sqrt(p * (1 - p) / n) + 1e-9)
                << theta << " " << side;
        }
}

// White furnace of the smooth plastic (linear mode, diffuse = specular = 1). Summing the
// internal reflections exactly gives the albedo
//   F_i + (1 - F_i) (1 - Fdr_ext) / (eta^2 (1 - Fdr_int)),
// with Fdr_ext = Fdr(eta), Fdr_int = Fdr(1/eta) exact hemispherical integrals; since
// 1 - Fdr_ext = eta^2 (1 - Fdr_int) (reciprocity of the interface) that is exactly 1. The
// model uses a fit for Fdr_int (d'Eon & Irving / Egan & Hilgeman, < 0.6% error), so the
// Monte Carlo albedo must match the formula with the fitted Fdr_int within 4 standard
// errors, and that value must be within 0.5% of 1.
// Nonlinear mode with rho = 0.5 replaces 1 - Fdr_int by 1 - rho Fdr_int: the full
// geometric series of internal bounces off an albedo-rho base; same check.
TEST(Bsdf, PlasticFurnaceMatchesInternalScatteringSum) {
    for (float ior : {1.49f, 1.9f})
        for (bool nonlinear : {false, true}) {
            Material m = plastic(ior, nonlinear);
            const float rho = nonlinear ? 0.5f : 1.0f;
            m.diffuse = Rgb(rho);
            m.specular = Rgb(1.0f);
            const double fdrExt = exactFdr(ior), fdrInt = exactFdr(1.0f / ior);
            const double fdrIntFit = m.internalReflectance;
            EXPECT_NEAR(fdrIntFit, fdrInt, 0.006 * fdrInt) << ior;
            EXPECT_NEAR(1.0 - fdrExt, ior * ior * (1.0 - fdrInt), 1e-4) << ior;
            for (float theta : kAnglesDeg) {
                const float fres = ub_fresnel_dielectric(std::cos(theta * kPi / 180), ior);
                const double denom = nonlinear ? 1.0 - rho * fdrIntFit : 1.0 - fdrIntFit;
                const double expected =
                    fres + (1.0 - fres) * rho * (1.0 - fdrExt) / (ior * ior * denom);
                const Albedo a = albedo(makeBsdf(m, directionAt(kNormal, theta, 1)), 200000,
                                        uint64_t(theta * 7 + ior * 100 + nonlinear));
                EXPECT_NEAR(a.mean.x, expected, 4 * a.stdErr.x + 1e-5)
                    << "ior " << ior << " theta " << theta << " nonlinear " << nonlinear;
                if (!nonlinear) EXPECT_NEAR(expected, 1.0, 0.005) << ior << " " << theta;
            }
        }
}

// Rough plastic energy: at most 1 + 3 standard errors with a white base and coating (the
// rough coating loses energy, never creates it). At alpha = 0.05 it is close to the
// smooth plastic's 1: above 0.95 at 5 and 45 degrees (single-scattering GGX loss at
// alpha 0.05 is below 1% (Heitz et al. 2016, Fig. 1); the rest is the difference between
// Mitsuba's discretised internal reflectance and the exact one, about 2%).
TEST(Bsdf, RoughPlasticAlbedoAtMostOne) {
    for (float alpha : {0.05f, 0.3f, 0.8f})
        for (float theta : kAnglesDeg) {
            Material m = roughPlastic(alpha);
            m.diffuse = Rgb(1.0f);
            m.specular = Rgb(1.0f);
            const Albedo a = albedo(makeBsdf(m, directionAt(kNormal, theta, 1)), 100000,
                                    uint64_t(alpha * 1000 + theta));
            EXPECT_LE(a.mean.x, 1.0f + 3.0f * a.stdErr.x) << alpha << " " << theta;
            if (alpha == 0.05f && theta < 60) EXPECT_GT(a.mean.x, 0.95f) << theta;
        }
}

// As alpha -> 0 the rough coating's tables approach the smooth interface: T(mu) -> 1 -
// F(mu, eta), and the internal reflectance -> Mitsuba's discretised sum 2/64 sum_k
// F(mu_k, 1/eta) mu_k. At alpha = 1e-3 the visible normals stay within ~0.1 degree of
// the normal, so the tables agree to 2e-3 except at the grazing end (mu < 0.05) where
// F varies fastest. Also T in [0, 1] for every alpha.
TEST(Bsdf, RoughPlasticTablesApproachSmoothCoating) {
    Material m = roughPlastic(1e-3f, 1.5f);
    double internal = 0;
    for (int k = 0; k < UB_ROUGH_PLASTIC_TABLE_SIZE; ++k) {
        const float mu = std::max(1e-6f, float(k) / (UB_ROUGH_PLASTIC_TABLE_SIZE - 1));
        internal += ub_fresnel_dielectric(mu, 1.0f / 1.5f) * mu;
        if (mu > 0.05f)
            EXPECT_NEAR(m.coatingTransmittance[size_t(k)], 1.0f - ub_fresnel_dielectric(mu, 1.5f),
                        2e-3f)
                << mu;
    }
    EXPECT_NEAR(m.internalReflectance, 2.0 * internal / UB_ROUGH_PLASTIC_TABLE_SIZE, 2e-3);
    for (float alpha : {0.05f, 0.3f, 0.8f}) {
        Material r = roughPlastic(alpha, 1.9f);
        for (float t : r.coatingTransmittance) {
            EXPECT_GE(t, 0.0f);
            EXPECT_LE(t, 1.0f);
        }
        EXPECT_GT(r.internalReflectance, 0.0f);
        EXPECT_LT(r.internalReflectance, 1.0f);
    }
}

// A plastic used without prepareMaterial() is a programming error, not a silent default.
TEST(Bsdf, UnpreparedPlasticThrows) {
    Material m = roughPlastic(0.3f);
    m.alpha = 0.5f;  // changed after prepareMaterial()
    Bsdf b;
    EXPECT_THROW(b.setup(m, kNormal, kNormal, kNormal, false), std::logic_error);
}

// A one-sided plastic is black from the back; the two-sided one mirrors the front.
TEST(Bsdf, PlasticSides) {
    for (auto& nm : plasticMaterials()) {
        Material one = nm.mat;
        one.twoSided = false;
        const Vec3 back = directionAt(kNormal, 30, -1), genBack = directionAt(kNormal, 40, -1, 200);
        Bsdf b = makeBsdf(one, back);
        EXPECT_TRUE(b.isValid()) << nm.name;
        EXPECT_EQ(b.continuationProb(), 0.0f) << nm.name;
        EXPECT_TRUE(isBlack(b.evaluate(genBack, nullptr, nullptr, nullptr))) << nm.name;
        Vec3 dir;
        float pdfW, cosGen;
        EXPECT_TRUE(isBlack(b.sample(Vec3(0.1f, 0.2f, 0.01f), &dir, &pdfW, &cosGen, nullptr)));
        Bsdf two = makeBsdf(nm.mat, back);
        EXPECT_FALSE(isBlack(two.evaluate(genBack, nullptr, nullptr, nullptr))) << nm.name;
        EXPECT_GT(two.continuationProb(), 0.0f) << nm.name;
    }
}

// ---------------------------------------------------------------------------------------
// Thin dielectric.

// Reflection with probability R' = 2r / (1 + r) (binomial z-test, 4 sigma, 12 checks),
// mirror direction, throughput `specular`; otherwise straight through (dir = -dirFix),
// throughput `transmittance` in both transport modes (no eta^2: the light leaves into the
// medium it came from). Both sides behave alike; no non-delta lobe.
TEST(Bsdf, ThinDielectricReflectanceAndStraightTransmission) {
    for (float ior : {1.5f, 1.33f})
        for (float side : kSides)
            for (float theta : kAnglesDeg) {
                const Material m = thinGlass(ior);
                const Vec3 fix = directionAt(kNormal, theta, side);
                const float r = ub_fresnel_dielectric(std::cos(theta * kPi / 180), ior);
                const double reflectance = 2 * r / (1 + r);
                for (bool fromLight : {false, true}) {
                    const Bsdf b = makeBsdf(m, fix, fromLight);
                    ASSERT_TRUE(b.isValid() && b.isDelta());
                    EXPECT_TRUE(isBlack(b.evaluate(-fix, nullptr, nullptr, nullptr)));
                    EXPECT_EQ(b.pdf(mirrorOf(fix)), 0.0f);
                    Rng rng(uint64_t(theta * 10 + side + ior * 1000), 3);
                    const int n = 20000;
                    int reflections = 0;
                    for (int i = 0; i < n; ++i) {
                        Vec3 dir;
                        float pdfW, cosGen;
                        uint32_t ev;
                        Rgb f = b.sample(rng.uniform3(), &dir, &pdfW, &cosGen, &ev);
                        ASSERT_GT(pdfW, 0.0f);
                        Rgb w = f * (cosGen / pdfW);
                        if (ev == kEventReflect) {
                            ++reflections;
                            ASSERT_NEAR(pdfW, reflectance, 1e-5);
                            ASSERT_TRUE(nearRel(w, m.specular, 1e-5f)) << str(w);
                            ASSERT_NEAR(length(dir - mirrorOf(fix)), 0.0f, 1e-5f);
                        } else {
                            ASSERT_EQ(ev, uint32_t(kEventRefract));
                            ASSERT_NEAR(pdfW, 1 - reflectance, 1e-5);
                            ASSERT_TRUE(nearRel(w, m.transmittance, 1e-5f)) << str(w);
                            ASSERT_NEAR(length(dir + fix), 0.0f, 1e-6f);
                        }
                    }
                    EXPECT_NEAR(double(reflections) / n, reflectance,
                                4 * std::sqrt(reflectance * (1 - reflectance) / n) + 1e-9)
                        << "ior " << ior << " theta " << theta << " side " << side;
                }
            }
}

// The multiple-interreflection sum: r + (1-r)^2 r / (1 - r^2) = 2r / (1 + r), summed here
// term by term (1000 bounces), and the sheet conserves energy: R' + T' = 1.
TEST(Bsdf, ThinDielectricInterreflectionSum) {
    for (float r : {0.0f, 0.04f, 0.3f, 0.9f}) {
        double reflect = r, transmit = 0, inside = 1 - r;  // energy inside after entering
        for (int k = 0; k < 1000; ++k) {
            transmit += inside * (1 - r);  // leaves through the far side
            inside *= r;
            reflect += inside * (1 - r);  // back through the near side
            inside *= r;
        }
        EXPECT_NEAR(ub_thin_dielectric_reflectance(r), reflect, 1e-6) << r;
        EXPECT_NEAR(reflect + transmit, 1.0, 1e-6) << r;
    }
}

// ---------------------------------------------------------------------------------------
// Shared math.

// Fdr fits against the exact integral: < 0.2% relative error for eta >= 1 (d'Eon & Irving)
// and < 0.6% for eta < 1 down to 1/2 (Egan & Hilgeman) (the errors the papers state).
TEST(Fresnel, DiffuseReflectanceFit) {
    for (float eta : {1.1f, 1.33f, 1.5f, 1.9f, 2.5f})
        EXPECT_NEAR(ub_fresnel_diffuse_reflectance(eta), exactFdr(eta), 0.002 * exactFdr(eta))
            << eta;
    for (float eta : {1.1f, 1.33f, 1.5f, 1.9f})
        EXPECT_NEAR(ub_fresnel_diffuse_reflectance(1 / eta), exactFdr(1 / eta),
                    0.006 * exactFdr(1 / eta))
            << eta;
}
