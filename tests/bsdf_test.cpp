// Tests of scene/bsdf.h and the lobe math in kernels/shared/ub_{fresnel,microfacet,phong}.h.
//
// Parameter grid (every non-delta material): Phong exponents 1, 20, 500; GGX alpha
// 0.05, 0.3, 0.8; rough dielectric IOR 1.5 and 1/1.5; incidence 5, 45 and 80 degrees
// from the normal; dirFix on the front and on the back side; fromLight false and true.
// The normal is tilted (not +z) so the frame code is exercised too. Anisotropic GGX and
// Beckmann materials (alpha_u != alpha_v) are oriented by the tangent kTangent, which the
// BSDF makes orthogonal to the normal, as Hit::tangent is.
#include "scene/bsdf.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "core/rng.h"
#include "core/sampling.h"
#include "kernels/shared/ub_fresnel.h"
#include "kernels/shared/ub_microfacet.h"
#include "scene/microfacet_sampling.h"
#include "scene/normal_perturbation.h"
#include "tests/support/bsdf_probe.h"
#include "tests/support/chi2.h"

using namespace ub;

namespace {

using ub::test::albedo;
using ub::test::Albedo;
using ub::test::TestFrame;

const Vec3 kNormal = normalize(Vec3(0.2f, -0.3f, 0.9f));
const Vec3 kTangent = normalize(Vec3(0.6f, 0.7f, 0.1f));
const float kAnglesDeg[] = {5.0f, 45.0f, 80.0f};
const float kSides[] = {1.0f, -1.0f};
const bool kFromLight[] = {false, true};

struct NamedMaterial {
    std::string name;
    Material mat;
    bool sharp;  ///< narrow lobe: needs finer chi-square bins
};

Material phong(float exponent) {
    Material m;
    m.type = MaterialType::Phong;
    m.diffuse = Rgb(0.2f, 0.25f, 0.3f);
    m.glossy = Rgb(0.7f, 0.6f, 0.5f);
    m.exponent = exponent;
    return m;
}
Material conductor(float alpha) {
    Material m;
    m.type = MaterialType::RoughConductor;
    m.alpha = alpha;
    return m;
}
Material roughGlass(float alpha, float ior) {
    Material m;
    m.type = MaterialType::RoughDielectric;
    m.alpha = alpha;
    m.ior = ior;
    return m;
}
Material glass(float ior) {
    Material m;
    m.type = MaterialType::Dielectric;
    m.ior = ior;
    return m;
}

std::vector<NamedMaterial> diffuseMaterials() {
    Material m;
    m.diffuse = Rgb(0.8f, 0.6f, 0.4f);
    return {{"Diffuse", m, false}};
}
std::vector<NamedMaterial> phongMaterials() {
    return {
        {"Phong1", phong(1), false}, {"Phong20", phong(20), false}, {"Phong500", phong(500), true}};
}
/// The same material with Mitsuba's separable Smith masking-shadowing (reflection).
Material separable(Material m) {
    m.separableMasking = true;
    return m;
}
std::vector<NamedMaterial> conductorMaterials() {
    return {{"Conductor0.05", conductor(0.05f), true},
            {"Conductor0.3", conductor(0.3f), false},
            {"Conductor0.8", conductor(0.8f), false},
            {"Conductor0.5Separable", separable(conductor(0.5f)), false}};
}
std::vector<NamedMaterial> roughGlassMaterials() {
    std::vector<NamedMaterial> r;
    for (float ior : {1.5f, 1.0f / 1.5f})
        for (float alpha : {0.05f, 0.3f, 0.8f})
            r.push_back({"RoughGlass" + std::to_string(alpha) + "_ior" + std::to_string(ior),
                         roughGlass(alpha, ior), alpha < 0.1f});
    r.push_back({"RoughGlass0.5_ior1.5Separable", separable(roughGlass(0.5f, 1.5f)), false});
    return r;
}
/// Beckmann microfacets (Mitsuba 3's default distribution) for the rough materials.
Material beckmann(Material m) {
    m.distribution = MicrofacetDistribution::kBeckmann;
    return m;
}
std::vector<NamedMaterial> beckmannMaterials() {
    return {{"BeckmannConductor0.05", beckmann(conductor(0.05f)), true},
            {"BeckmannConductor0.4", beckmann(conductor(0.4f)), false},
            {"BeckmannConductor0.7Separable", beckmann(separable(conductor(0.7f))), false},
            {"BeckmannGlass0.1_ior1.5", beckmann(roughGlass(0.1f, 1.5f)), false},
            {"BeckmannGlass0.5_ior0.67", beckmann(roughGlass(0.5f, 1.0f / 1.5f)), false}};
}
/// Anisotropic roughness: alpha along the tangent, alphaV across it.
Material anisotropic(Material m, float alphaV) {
    m.alphaV = alphaV;
    return m;
}
std::vector<NamedMaterial> anisotropicMaterials() {
    return {
        {"AnisoConductor0.05x0.4", anisotropic(conductor(0.05f), 0.4f), true},
        {"AnisoConductor0.6x0.2Separable", anisotropic(separable(conductor(0.6f)), 0.2f), false},
        {"AnisoGlass0.1x0.5_ior1.5", anisotropic(roughGlass(0.1f, 1.5f), 0.5f), false},
        {"AnisoBeckmannConductor0.3x0.08", anisotropic(beckmann(conductor(0.3f)), 0.08f), true},
        {"AnisoBeckmannGlass0.4x0.15_ior0.67",
         anisotropic(beckmann(roughGlass(0.4f, 1.0f / 1.5f)), 0.15f), false}};
}
std::vector<NamedMaterial> nonDeltaMaterials() {
    std::vector<NamedMaterial> r;
    for (auto* f : {diffuseMaterials, phongMaterials, conductorMaterials, roughGlassMaterials,
                    beckmannMaterials, anisotropicMaterials})
        for (auto& m : f()) r.push_back(m);
    return r;
}

/// Direction at polar angle thetaDeg from n, on the front (side = 1) or back (side = -1).
Vec3 directionAt(const Vec3& n, float thetaDeg, float side, float phiDeg = 30.0f) {
    float t = thetaDeg * kPi / 180.0f, p = phiDeg * kPi / 180.0f;
    return Frame(n).toWorld(
        Vec3(std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), side * std::cos(t)));
}

Bsdf makeBsdf(const Material& m, const Vec3& dirFix, bool fromLight, const Vec3& ng = kNormal,
              const Vec3& ns = kNormal) {
    Bsdf b;
    b.setup(m, SurfaceColors::of(m), dirFix, ng, ns, fromLight, kTangent);
    return b;
}
// A Bsdf keeps a pointer to its material: a temporary would dangle (ASan found one).
Bsdf makeBsdf(Material&&, const Vec3&, bool, const Vec3& = kNormal, const Vec3& = kNormal) = delete;

struct Config {
    std::shared_ptr<const NamedMaterial> m;
    float theta, side;
    bool fromLight;
    Vec3 dirFix() const { return directionAt(kNormal, theta, side); }
    std::string label() const {
        return m->name + " theta=" + std::to_string(int(theta)) + (side > 0 ? " front" : " back") +
               (fromLight ? " fromLight" : " fromCamera");
    }
};

std::vector<Config> configs(const std::vector<NamedMaterial>& mats, bool bothModes = true) {
    std::vector<Config> r;
    for (auto& m : mats)
        for (float t : kAnglesDeg)
            for (float s : kSides)
                for (bool fl : kFromLight)
                    if (bothModes || !fl)
                        r.push_back({std::make_shared<const NamedMaterial>(m), t, s, fl});
    return r;
}

bool nearRel(float a, float b, float rel = 1e-4f, float abs = 1e-20f) {
    return std::fabs(a - b) <= rel * std::max(std::fabs(a), std::fabs(b)) + abs;
}
bool nearRel(const Rgb& a, const Rgb& b, float rel = 1e-4f) {
    return nearRel(a.x, b.x, rel) && nearRel(a.y, b.y, rel) && nearRel(a.z, b.z, rel);
}
std::string str(const Rgb& c) {
    return "(" + std::to_string(c.x) + ", " + std::to_string(c.y) + ", " + std::to_string(c.z) +
           ")";
}

// ---------------------------------------------------------------------------------------
// Chi-square tests of sample() against pdf().
//
// Binning frame: the shading normal is +x and the plane of incidence is z = 0, so every
// lobe (around the normal, the mirror or the refracted direction) lies on the equator,
// where (z, phi) cells are nearly square. Narrow lobes (Phong 500: sigma ~ 1/sqrt(500)
// rad = 2.6 deg; GGX alpha 0.05: about 3 deg) use 100 x 200 cells (1.1 x 1.8 deg) with a
// 4x4 midpoint rule per cell; the others 40 x 80 cells with 10x10 (6x6 was measured to
// bias the statistic at 1M samples near the total-internal-reflection edge, where the
// refraction pdf has a square-root slope; 10x10 and 24x24 agree). 200k samples per test
// give expected counts in the thousands in the lobe cells, so a pdf that is off by a few
// percent anywhere in the lobe (a wrong Jacobian, lobe probability or normalisation)
// fails by orders of magnitude, while the quadrature error of the expected counts
// (< 0.3% per cell) stays well below the Poisson noise (> 1% per cell).
// Samples that fail count as missing mass: the pdf is the density of successful samples
// only and integrates to less than one exactly when sampling can fail.
// Overall significance 1% over all chi-square tests of this file (Sidak correction).
// fromLight changes only values, never directions or pdfs (PdfIndependentOfTransportMode
// checks that exactly), so the chi-square tests run the fromCamera mode only.
const int kChi2Samples = 200000;
const int kChi2TestCount = int(configs(nonDeltaMaterials(), false).size());
const double kChi2Alpha = ub::test::sidak(0.01, kChi2TestCount);

void runChi2(const std::vector<NamedMaterial>& mats, uint64_t seed) {
    for (const Config& c : configs(mats, false)) {
        const Vec3 dirFix = c.dirFix();
        const Bsdf bsdf = makeBsdf(c.m->mat, dirFix, c.fromLight);
        ASSERT_TRUE(bsdf.isValid()) << c.label();
        const TestFrame tf(kNormal, dirFix);
        Rng rng(seed++, 7);
        auto sample = [&]() {
            Vec3 dir;
            float pdfW, cosGen;
            bsdf.sample(rng.uniform3(), &dir, &pdfW, &cosGen, nullptr);
            return pdfW > 0 ? tf.toTest(dir) : Vec3(0.0f);
        };
        auto pdf = [&](const Vec3& d) { return double(bsdf.pdf(tf.toWorld(d))); };
        const bool sharp = c.m->sharp;
        auto res = ub::test::chi2TestSphere(sample, pdf, kChi2Samples, sharp ? 100 : 40,
                                            sharp ? 200 : 80, sharp ? 4 : 10);
        EXPECT_TRUE(res.message.empty()) << c.label() << ": " << res.message;
        EXPECT_GT(res.pValue, kChi2Alpha)
            << c.label() << ": chi2 = " << res.statistic << ", dof = " << res.dof;
    }
}

}  // namespace

TEST(Bsdf, DiffuseChiSquare) {
    runChi2(diffuseMaterials(), 100);
}
TEST(Bsdf, PhongChiSquare) {
    runChi2(phongMaterials(), 200);
}
TEST(Bsdf, RoughConductorChiSquare) {
    runChi2(conductorMaterials(), 300);
}
TEST(Bsdf, RoughDielectricChiSquare) {
    runChi2(roughGlassMaterials(), 400);
}
TEST(Bsdf, BeckmannChiSquare) {
    runChi2(beckmannMaterials(), 500);
}
TEST(Bsdf, AnisotropicChiSquare) {
    runChi2(anisotropicMaterials(), 600);
}

// ---------------------------------------------------------------------------------------
// Consistency of sample(), evaluate() and pdf() (relative 1e-4: the same float code path).

TEST(Bsdf, SampleMatchesEvaluateAndPdf) {
    uint64_t seed = 1000;
    for (const Config& c : configs(nonDeltaMaterials())) {
        const Bsdf bsdf = makeBsdf(c.m->mat, c.dirFix(), c.fromLight);
        Rng rng(seed++, 11);
        int ok = 0;
        for (int i = 0; i < 1000; ++i) {
            Vec3 dir;
            float pdfW, cosGen, revSampled = -1.0f;
            uint32_t event;
            Rgb f = bsdf.sample(rng.uniform3(), &dir, &pdfW, &cosGen, &event, &revSampled);
            if (pdfW == 0) {
                ASSERT_TRUE(isBlack(f)) << c.label();
                ASSERT_EQ(revSampled, 0.0f) << c.label();
                continue;
            }
            ++ok;
            // The reverse pdf sample() returns is pdf(dir, true) exactly (the same evaluation).
            ASSERT_EQ(revSampled, bsdf.pdf(dir, true)) << c.label();
            float cosEval, pdfEval, revEval;
            Rgb fEval = bsdf.evaluate(dir, &cosEval, &pdfEval, &revEval);
            ASSERT_TRUE(nearRel(f, fEval)) << c.label() << " " << str(f) << " vs " << str(fEval);
            ASSERT_TRUE(nearRel(pdfW, pdfEval)) << c.label() << " " << pdfW << " vs " << pdfEval;
            ASSERT_TRUE(nearRel(pdfW, bsdf.pdf(dir))) << c.label();
            ASSERT_TRUE(nearRel(revEval, bsdf.pdf(dir, true))) << c.label();
            ASSERT_TRUE(nearRel(cosGen, cosEval)) << c.label();
            ASSERT_NEAR(cosGen, std::fabs(dot(dir, kNormal)), 1e-5f) << c.label();
            ASSERT_NEAR(length(dir), 1.0f, 1e-5f) << c.label();
            ASSERT_TRUE(event == kEventDiffuse || event == kEventGlossy) << c.label();
            ASSERT_TRUE(isFinite(f) && std::isfinite(revEval)) << c.label();
        }
        // At least some samples succeed in every configuration (even grazing ones).
        EXPECT_GT(ok, 100) << c.label();
    }
}

TEST(Bsdf, PdfIndependentOfTransportMode) {
    uint64_t seed = 2000;
    for (const Config& c : configs(nonDeltaMaterials(), false)) {
        const Bsdf cam = makeBsdf(c.m->mat, c.dirFix(), false);
        const Bsdf light = makeBsdf(c.m->mat, c.dirFix(), true);
        Rng rng(seed++, 5);
        for (int i = 0; i < 200; ++i) {
            Vec3 d = sampleUniformSphere(rng.uniform2());
            EXPECT_EQ(cam.pdf(d), light.pdf(d)) << c.label();
            EXPECT_EQ(cam.pdf(d, true), light.pdf(d, true)) << c.label();
        }
        // Both modes sample the same directions from the same random numbers.
        for (int i = 0; i < 200; ++i) {
            Vec3 rnd = rng.uniform3(), d0, d1;
            float p0, p1, c0, c1;
            cam.sample(rnd, &d0, &p0, &c0, nullptr);
            light.sample(rnd, &d1, &p1, &c1, nullptr);
            EXPECT_EQ(p0, p1) << c.label();
            if (p0 > 0) EXPECT_EQ(dot(d0, d1), dot(d0, d0)) << c.label();
        }
    }
}

// reversePdfW must be the pdf of a BSDF set up at dirGen sampling dirFix (bidirectional
// MIS depends on it); with Ns = Ng, reflection is reciprocal, f(a, b) = f(b, a), and
// refraction obeys the generalised reciprocity of Veach 1997, Sec. 5.2:
// f_radiance(a, b) / eta_a^2 = f_radiance(b, a) / eta_b^2, equivalently the importance BTDF
// is the adjoint f_importance(b, a) = f_radiance(a, b).
TEST(Bsdf, ReversePdfAndReciprocity) {
    uint64_t seed = 3000;
    for (const Config& c : configs(nonDeltaMaterials())) {
        const Vec3 a = c.dirFix();
        const Bsdf bsdfA = makeBsdf(c.m->mat, a, c.fromLight);
        Rng rng(seed++, 13);
        int reflections = 0, refractions = 0;
        for (int i = 0; i < 500; ++i) {
            Vec3 b;
            float pdfW, cosGen;
            bsdfA.sample(rng.uniform3(), &b, &pdfW, &cosGen, nullptr);
            if (pdfW == 0) continue;
            float pdfAB, revAB;
            Rgb fAB = bsdfA.evaluate(b, nullptr, &pdfAB, &revAB);
            const Bsdf bsdfB = makeBsdf(c.m->mat, b, c.fromLight);
            ASSERT_TRUE(bsdfB.isValid()) << c.label();
            float pdfBA, revBA;
            Rgb fBA = bsdfB.evaluate(a, nullptr, &pdfBA, &revBA);
            ASSERT_TRUE(nearRel(revAB, pdfBA)) << c.label() << " " << revAB << " vs " << pdfBA;
            ASSERT_TRUE(nearRel(pdfAB, revBA)) << c.label() << " " << pdfAB << " vs " << revBA;
            const bool reflect = dot(a, kNormal) * dot(b, kNormal) > 0;
            if (reflect) {
                ++reflections;
                ASSERT_TRUE(nearRel(fAB, fBA))
                    << c.label() << " " << str(fAB) << " vs " << str(fBA);
            } else {
                ++refractions;
                const float ior = c.m->mat.ior;
                const float etaA = dot(a, kNormal) > 0 ? 1.0f : ior;
                const float etaB = dot(b, kNormal) > 0 ? 1.0f : ior;
                const Bsdf radB = makeBsdf(c.m->mat, b, false), impB = makeBsdf(c.m->mat, b, true);
                const Bsdf radA = makeBsdf(c.m->mat, a, false);
                Rgb radAB = radA.evaluate(b, nullptr, nullptr, nullptr);
                Rgb radBA = radB.evaluate(a, nullptr, nullptr, nullptr);
                Rgb impBA = impB.evaluate(a, nullptr, nullptr, nullptr);
                ASSERT_TRUE(nearRel(radAB, impBA))
                    << c.label() << str(radAB) << str(impBA) << str(radBA);
                ASSERT_TRUE(nearRel(radAB / (etaA * etaA), radBA / (etaB * etaB))) << c.label();
            }
        }
        EXPECT_GT(reflections + refractions, 50) << c.label();
    }
}

// ---------------------------------------------------------------------------------------
// Energy. Directional albedo rho(dirFix) = E[f cos / pdf] (per channel) with 10^5 samples:
// never above 1 + 3 standard errors in importance mode (fromLight: no radiance scaling;
// with Ns = Ng the two modes differ only for refraction). A biased sampler or a missing
// Jacobian term shows up as albedo > 1 (e.g. a factor 4 in the microfacet Jacobian).

TEST(Bsdf, AlbedoAtMostOne) {
    uint64_t seed = 4000;
    for (const Config& c : configs(nonDeltaMaterials(), false)) {
        Albedo a = albedo(makeBsdf(c.m->mat, c.dirFix(), true), 100000, seed++);
        for (int k = 0; k < 3; ++k)
            EXPECT_LE(a.mean[k], 1.0f + 3.0f * a.stdErr[k])
                << c.label() << " channel " << k << " albedo " << a.mean[k];
    }
}

// Lambert: every sample weighs exactly rho (f cos / pdf = (rho/pi) cos / (cos/pi)).
TEST(Bsdf, DiffuseAlbedoIsReflectance) {
    for (const Config& c : configs(diffuseMaterials())) {
        Albedo a = albedo(makeBsdf(c.m->mat, c.dirFix(), c.fromLight), 10000, 5);
        EXPECT_TRUE(nearRel(a.mean, c.m->mat.diffuse, 1e-4f)) << c.label() << str(a.mean);
    }
}

// Modified Phong with rho = 1 at normal incidence: albedo exactly 1 (Lafortune & Willems:
// (n+2)/(2 pi) integral of cos^(n+1) = 1). Two-sided bound at 4 standard errors
// (false-failure probability 6e-5 per check).
TEST(Bsdf, PhongAlbedoIsOneAtNormalIncidence) {
    for (float n : {1.0f, 20.0f, 500.0f}) {
        Material m = phong(n);
        m.diffuse = Rgb(0.0f);
        m.glossy = Rgb(1.0f);
        Albedo a = albedo(makeBsdf(m, kNormal, false), 100000, 6);
        EXPECT_NEAR(a.mean.x, 1.0f, 4.0f * a.stdErr.x + 1e-5f) << "exponent " << n;
    }
}

// GGX single scattering loses little energy at small roughness: with F = 1 (conductor
// eta = 0, k = 1e4) the albedo at alpha = 0.05 near normal incidence is above 0.99
// (Heitz et al. 2016, "Multiple-scattering microfacet BSDFs", Fig. 1: the loss is
// negligible below alpha ~ 0.1), and at most 1. Tests the conductor's normalisation.
TEST(Bsdf, RoughConductorFurnace) {
    Material m = conductor(0.05f);
    m.eta = Rgb(0.0f);
    m.k = Rgb(1e4f);
    for (float theta : {5.0f, 45.0f}) {
        Albedo a = albedo(makeBsdf(m, directionAt(kNormal, theta, 1), false), 100000, 7);
        EXPECT_GT(a.mean.x, 0.99f) << theta;
        EXPECT_LE(a.mean.x, 1.0f + 3.0f * a.stdErr.x) << theta;
    }
}

// Rough glass at alpha = 0.05 approaches smooth glass: importance albedo ~ 1, and the
// radiance albedo ~ F + (1 - F) (n_fix / n_gen)^2 (about 0.46 from air into glass at
// normal incidence, 2.2 from glass into air). Tolerance 2%: single-scattering loss at
// alpha = 0.05 is below 1% (see above) plus the spread of F over the microfacets.
TEST(Bsdf, RoughDielectricApproachesSmooth) {
    for (float side : {1.0f, -1.0f}) {
        Material m = roughGlass(0.05f, 1.5f);
        Vec3 fix = directionAt(kNormal, 5.0f, side);
        const float etaFix = side > 0 ? 1.0f : 1.5f, etaGen = side > 0 ? 1.5f : 1.0f;
        float cosT;
        const float fres =
            ub_fresnel_dielectric_ct(std::cos(5.0f * kPi / 180), etaGen / etaFix, &cosT);
        Albedo imp = albedo(makeBsdf(m, fix, true), 100000, 8);
        Albedo rad = albedo(makeBsdf(m, fix, false), 100000, 9);
        const float expectedRad = fres + (1 - fres) * (etaFix / etaGen) * (etaFix / etaGen);
        EXPECT_NEAR(imp.mean.x, 1.0f, 0.02f) << side;
        EXPECT_LE(imp.mean.x, 1.0f + 3.0f * imp.stdErr.x) << side;
        EXPECT_NEAR(rad.mean.x / expectedRad, 1.0f, 0.02f) << side << " " << rad.mean.x;
    }
}

// ---------------------------------------------------------------------------------------
// Delta materials.

TEST(Bsdf, MirrorReflectsExactlyWithSpecularWeight) {
    Material m;
    m.type = MaterialType::Mirror;
    m.specular = Rgb(0.9f, 0.5f, 0.2f);
    for (float side : kSides)
        for (float theta : kAnglesDeg) {
            Vec3 fix = directionAt(kNormal, theta, side);
            Bsdf b = makeBsdf(m, fix, false);
            ASSERT_TRUE(b.isValid() && b.isDelta());
            EXPECT_TRUE(
                isBlack(b.evaluate(directionAt(kNormal, 30, side), nullptr, nullptr, nullptr)));
            EXPECT_EQ(b.pdf(reflect(fix, kNormal)), 0.0f);
            Vec3 dir;
            float pdfW, cosGen;
            uint32_t ev;
            Rgb f = b.sample(Vec3(0.3f, 0.6f, 0.9f), &dir, &pdfW, &cosGen, &ev);
            EXPECT_EQ(ev, uint32_t(kEventReflect));
            EXPECT_EQ(pdfW, 1.0f);
            EXPECT_NEAR(length(dir - reflect(fix, kNormal)), 0.0f, 1e-5f);
            EXPECT_TRUE(nearRel(f * (cosGen / pdfW), m.specular, 1e-5f)) << str(f);
            EXPECT_NEAR(b.continuationProb(), 0.9f, 1e-6f);
        }
}

// Smooth glass: reflection frequency equals F (binomial z-test, 4 sigma, 12 checks), the
// refracted direction obeys Snell's law, and the throughput f cos / pdf of a refraction is
// (n_fix/n_gen)^2 for radiance (camera path from n1 into n2: (n1/n2)^2, pbrt-v4) and 1 for
// importance (Veach 1997, Sec. 5.2). Reflection throughput is 1 in both modes.
TEST(Bsdf, DielectricFresnelSelectionSnellAndRadianceScaling) {
    for (float ior : {1.5f, 1.0f / 1.5f})
        for (float side : kSides)
            for (float theta : kAnglesDeg) {
                Material m = glass(ior);
                Vec3 fix = directionAt(kNormal, theta, side);
                const float etaFix = side > 0 ? 1.0f : ior, etaGen = side > 0 ? ior : 1.0f;
                const float cosI = std::cos(theta * kPi / 180);
                const float fres = ub_fresnel_dielectric(cosI, etaGen / etaFix);
                for (bool fromLight : kFromLight) {
                    Bsdf b = makeBsdf(m, fix, fromLight);
                    ASSERT_TRUE(b.isValid() && b.isDelta());
                    Rng rng(uint64_t(theta * 10 + side), 3);
                    const int n = 20000;
                    int reflections = 0;
                    for (int i = 0; i < n; ++i) {
                        Vec3 dir;
                        float pdfW, cosGen;
                        uint32_t ev;
                        Rgb f = b.sample(rng.uniform3(), &dir, &pdfW, &cosGen, &ev);
                        ASSERT_GT(pdfW, 0.0f);
                        float w = f.x * cosGen / pdfW;
                        if (ev == kEventReflect) {
                            ++reflections;
                            ASSERT_NEAR(pdfW, fres, 1e-6f);
                            ASSERT_NEAR(w, 1.0f, 1e-5f);
                            ASSERT_NEAR(length(dir - reflect(fix, kNormal)), 0.0f, 1e-5f);
                        } else {
                            ASSERT_EQ(ev, uint32_t(kEventRefract));
                            ASSERT_NEAR(pdfW, 1 - fres, 1e-6f);
                            float expected = fromLight ? 1.0f : ub_sqr(etaFix / etaGen);
                            ASSERT_NEAR(w, expected, 1e-5f * expected);
                            // Snell: eta_fix sin_fix = eta_gen sin_gen, opposite sides.
                            float sinGen = length(cross(dir, kNormal));
                            ASSERT_NEAR(etaGen * sinGen, etaFix * std::sin(theta * kPi / 180),
                                        1e-5f);
                            ASSERT_LT(dot(dir, kNormal) * dot(fix, kNormal), 0.0f);
                        }
                    }
                    double sigma = std::sqrt(fres * (1 - fres) / n);
                    EXPECT_NEAR(double(reflections) / n, fres, 4 * sigma + 1e-9)
                        << "ior " << ior << " side " << side << " theta " << theta;
                }
            }
}

// From the dense side beyond the critical angle (41.8 deg for 1.5) every sample reflects
// with weight 1.
TEST(Bsdf, DielectricTotalInternalReflection) {
    const Material m = glass(1.5f);  // outlives b, which points to it
    Bsdf b = makeBsdf(m, directionAt(kNormal, 60.0f, -1.0f), false);
    Rng rng(1, 1);
    for (int i = 0; i < 1000; ++i) {
        Vec3 dir;
        float pdfW, cosGen;
        uint32_t ev;
        Rgb f = b.sample(rng.uniform3(), &dir, &pdfW, &cosGen, &ev);
        ASSERT_EQ(ev, uint32_t(kEventReflect));
        ASSERT_EQ(pdfW, 1.0f);
        ASSERT_NEAR(f.x * cosGen, 1.0f, 1e-5f);
    }
}

// ---------------------------------------------------------------------------------------
// Sides, shading normals, Russian roulette.

TEST(Bsdf, OneSidedBackIsBlackTwoSidedBackMatchesFront) {
    for (auto& nm : nonDeltaMaterials()) {
        if (nm.mat.type == MaterialType::RoughDielectric) continue;
        Material one = nm.mat, two = nm.mat;
        one.twoSided = false;
        two.twoSided = true;
        const Vec3 front = directionAt(kNormal, 30, 1), back = directionAt(kNormal, 30, -1);
        const Vec3 genFront = directionAt(kNormal, 40, 1, 200),
                   genBack = directionAt(kNormal, 40, -1, 200);
        Bsdf oneBack = makeBsdf(one, back, false);
        EXPECT_TRUE(oneBack.isValid());
        EXPECT_EQ(oneBack.continuationProb(), 0.0f) << nm.name;
        EXPECT_TRUE(isBlack(oneBack.evaluate(genBack, nullptr, nullptr, nullptr))) << nm.name;
        EXPECT_EQ(oneBack.pdf(genBack), 0.0f) << nm.name;
        Vec3 dir;
        float pdfW, cosGen;
        EXPECT_TRUE(isBlack(oneBack.sample(Vec3(0.3f, 0.3f, 0.3f), &dir, &pdfW, &cosGen, nullptr)));
        EXPECT_EQ(pdfW, 0.0f);
        // The two-sided back side is the front seen through a flipped normal: the geometry
        // (back, genBack) around n equals (front', genFront') around -n; compare with the
        // BSDF built on -n from the front.
        Bsdf twoBack = makeBsdf(two, back, false);
        Bsdf flipped = makeBsdf(two, back, false, -kNormal, -kNormal);
        float p0, p1;
        Rgb f0 = twoBack.evaluate(genBack, nullptr, &p0, nullptr);
        Rgb f1 = flipped.evaluate(genBack, nullptr, &p1, nullptr);
        EXPECT_FALSE(isBlack(f0)) << nm.name;
        EXPECT_TRUE(nearRel(f0, f1)) << nm.name;
        EXPECT_TRUE(nearRel(p0, p1)) << nm.name;
        EXPECT_TRUE(isBlack(twoBack.evaluate(genFront, nullptr, nullptr, nullptr))) << nm.name;
        EXPECT_TRUE(
            nearRel(twoBack.continuationProb(), makeBsdf(two, front, false).continuationProb()));
        (void)front;
    }
}

// Shading normal tilted 20 degrees from the geometric normal. (1) A reflection direction
// above the shading surface but below the geometric one is black with zero pdf, and no
// sample ever leaves below the geometric surface (or crosses it, for reflection lobes).
// (2) fromLight f_s carries the adjoint factor |fix.Ns||gen.Ng| / (|fix.Ng||gen.Ns|)
// relative to the radiance BSDF with the roles swapped (Veach 1997, Sec. 5.3).
TEST(Bsdf, ShadingNormalGuardAndAdjointFactor) {
    const Vec3 ng = kNormal;
    const Frame fg(ng);
    const Vec3 ns = fg.toWorld(Vec3(std::sin(0.35f), 0.0f, std::cos(0.35f)));
    Material diffuse;
    for (auto& nm : nonDeltaMaterials()) {
        const Material& m = nm.mat;
        if (m.type == MaterialType::RoughDielectric) continue;
        const Vec3 fix = fg.toWorld(normalize(Vec3(0.2f, 0.1f, 1.0f)));
        // Below Ng (z < 0 in fg) but above Ns: tilt towards +x of fg.
        const Vec3 leak = fg.toWorld(normalize(Vec3(1.0f, 0.0f, -0.15f)));
        ASSERT_GT(dot(leak, ns), 0.0f);
        ASSERT_LT(dot(leak, ng), 0.0f);
        for (bool fl : kFromLight) {
            Bsdf b = makeBsdf(m, fix, fl, ng, ns);
            ASSERT_TRUE(b.isValid());
            EXPECT_TRUE(isBlack(b.evaluate(leak, nullptr, nullptr, nullptr))) << nm.name;
            EXPECT_EQ(b.pdf(leak), 0.0f) << nm.name;
            Rng rng(21, 2);
            for (int i = 0; i < 2000; ++i) {
                Vec3 dir;
                float pdfW, cosGen;
                b.sample(rng.uniform3(), &dir, &pdfW, &cosGen, nullptr);
                if (pdfW > 0) ASSERT_GT(dot(dir, ng), 0.0f) << nm.name;
            }
        }
        Rng rng(22, 2);
        for (int i = 0; i < 200; ++i) {
            Vec3 a = fg.toWorld(sampleCosineHemisphere(rng.uniform2()));
            Vec3 c = fg.toWorld(sampleCosineHemisphere(rng.uniform2()));
            if (dot(a, ns) < 0.05f || dot(c, ns) < 0.05f || dot(a, ng) < 0.05f ||
                dot(c, ng) < 0.05f)
                continue;
            Rgb fLight = makeBsdf(m, a, true, ng, ns).evaluate(c, nullptr, nullptr, nullptr);
            Rgb fCam = makeBsdf(m, c, false, ng, ns).evaluate(a, nullptr, nullptr, nullptr);
            float factor = std::fabs(dot(a, ns)) * std::fabs(dot(c, ng)) /
                           (std::fabs(dot(a, ng)) * std::fabs(dot(c, ns)));
            ASSERT_TRUE(nearRel(fLight, fCam * factor, 1e-3f))
                << nm.name << str(fLight) << str(fCam * factor);
        }
    }
}

TEST(Bsdf, ContinuationProbabilityIsMaxAlbedoEstimate) {
    const Vec3 fix = directionAt(kNormal, 30, 1);
    Material d;
    d.diffuse = Rgb(0.8f, 0.6f, 0.4f);
    EXPECT_NEAR(makeBsdf(d, fix, false).continuationProb(), 0.8f, 1e-6f);
    Material p = phong(20);  // diffuse + glossy = (0.9, 0.85, 0.8)
    EXPECT_NEAR(makeBsdf(p, fix, false).continuationProb(), 0.9f, 1e-6f);
    p.glossy = Rgb(1.5f);  // clamped to 1
    EXPECT_EQ(makeBsdf(p, fix, false).continuationProb(), 1.0f);
    Material g = glass(1.5f);
    g.specular = Rgb(0.5f, 0.7f, 0.6f);
    EXPECT_NEAR(makeBsdf(g, fix, false).continuationProb(), 0.7f, 1e-6f);
    Material c = conductor(0.3f);
    float expected = 0;
    for (int k = 0; k < 3; ++k)
        expected =
            std::max(expected, ub_fresnel_conductor(std::cos(30 * kPi / 180), c.eta[k], c.k[k]));
    EXPECT_NEAR(makeBsdf(c, fix, false).continuationProb(), expected, 1e-5f);
}

TEST(Bsdf, GrazingDirFixIsInvalid) {
    Material d;
    Vec3 t = Frame(kNormal).s;  // in the tangent plane
    Bsdf b;
    EXPECT_FALSE(b.setup(d, t, kNormal, kNormal, false));
    EXPECT_FALSE(b.isValid());
}

// ---------------------------------------------------------------------------------------
// Shared lobe math (kernels/shared).

TEST(Fresnel, DielectricKnownValues) {
    // Normal incidence ((n-1)/(n+1))^2, from either side.
    EXPECT_NEAR(ub_fresnel_dielectric(1.0f, 1.5f), 0.04f, 1e-6f);
    EXPECT_NEAR(ub_fresnel_dielectric(1.0f, 1.0f / 1.5f), 0.04f, 1e-6f);
    EXPECT_NEAR(ub_fresnel_dielectric(1.0f, 1.33f), ub_sqr(0.33f / 2.33f), 1e-6f);
    // Brewster angle tan(theta_B) = n: p-polarised reflectance vanishes, F = Rs^2 / 2 with
    // Rs = cos(theta_i + theta_t) / ... = -(n^2 - 1) / (n^2 + 1) = -0.3846 for n = 1.5.
    float thetaB = std::atan(1.5f);
    EXPECT_NEAR(ub_fresnel_dielectric(std::cos(thetaB), 1.5f), 0.5f * ub_sqr(1.25f / 3.25f), 1e-5f);
    // Grazing incidence reflects everything.
    EXPECT_NEAR(ub_fresnel_dielectric(0.0f, 1.5f), 1.0f, 1e-6f);
    // Total internal reflection beyond the critical angle asin(1/1.5) = 41.81 deg.
    float crit = std::asin(1.0f / 1.5f);
    EXPECT_EQ(ub_fresnel_dielectric(std::cos(crit + 0.01f), 1.0f / 1.5f), 1.0f);
    EXPECT_EQ(ub_fresnel_dielectric(std::cos(1.2f), 1.0f / 1.5f), 1.0f);
    EXPECT_LT(ub_fresnel_dielectric(std::cos(crit - 0.01f), 1.0f / 1.5f), 1.0f);
    float cosT;
    ub_fresnel_dielectric_ct(std::cos(1.2f), 1.0f / 1.5f, &cosT);
    EXPECT_EQ(cosT, 0.0f);
}

// F(theta_i, eta) = F(theta_t, 1/eta): the interface reflects equally from both sides.
TEST(Fresnel, DielectricSymmetricAcrossInterface) {
    for (float eta : {1.2f, 1.5f, 2.4f})
        for (float c = 0.05f; c <= 1.0f; c += 0.05f) {
            float cosT;
            float f = ub_fresnel_dielectric_ct(c, eta, &cosT);
            float cosBack;
            EXPECT_NEAR(ub_fresnel_dielectric_ct(cosT, 1.0f / eta, &cosBack), f, 2e-5f);
            EXPECT_NEAR(cosBack, c, 1e-5f);
            // Snell: sin_i = eta sin_t.
            EXPECT_NEAR(std::sqrt(1 - c * c), eta * std::sqrt(1 - cosT * cosT), 1e-5f);
        }
}

TEST(Fresnel, ConductorKnownValues) {
    // k = 0 reduces to the dielectric formula (eta > 1: no total internal reflection).
    for (float eta : {1.2f, 1.5f, 2.4f})
        for (float c = 0.0f; c <= 1.0f; c += 0.1f)
            EXPECT_NEAR(ub_fresnel_conductor(c, eta, 0.0f), ub_fresnel_dielectric(c, eta), 1e-5f);
    // Normal incidence: ((eta-1)^2 + k^2) / ((eta+1)^2 + k^2); gold-like values.
    for (float eta : {0.2f, 0.92f, 1.1f})
        for (float k : {2.14f, 2.45f, 3.9f})
            EXPECT_NEAR(ub_fresnel_conductor(1.0f, eta, k),
                        (ub_sqr(eta - 1) + k * k) / (ub_sqr(eta + 1) + k * k), 1e-5f);
    // Grazing incidence reflects everything; values stay in [0, 1].
    EXPECT_NEAR(ub_fresnel_conductor(0.0f, 0.2f, 3.9f), 1.0f, 1e-6f);
    for (float c = 0.0f; c <= 1.0f; c += 0.01f) {
        float f = ub_fresnel_conductor(c, 0.2f, 3.9f);
        EXPECT_GE(f, 0.0f);
        EXPECT_LE(f, 1.0f);
    }
}

// Integral of D(m) cos(theta_m) over the hemisphere is 1 (Walter eq. 4), and for every view
// direction the visible-normal density integrates to 1 (Heitz 2014, eq. 18 with Smith G1).
// Midpoint rule in (cos theta, phi) with 4000 x 64 cells: error < 1e-3 at alpha >= 0.05.
TEST(Microfacet, GgxNormalisedAndVisibleNormalsIntegrateToOne) {
    for (float alpha : {0.05f, 0.3f, 0.8f}) {
        const int nz = 4000, nphi = 64;
        double sumD = 0;
        double sumVis[3] = {0, 0, 0};
        const float vTheta[3] = {0.1f, 0.8f, 1.4f};
        for (int i = 0; i < nz; ++i) {
            // Cells uniform in cos^2 would be kinder to the peak; uniform in theta instead.
            double theta = (i + 0.5) / nz * (kPi / 2), dTheta = (kPi / 2) / nz;
            double c = std::cos(theta), s = std::sin(theta);
            double d = ub_ggx_d(float(c), alpha);
            sumD += d * c * s * dTheta * 2 * kPi;
            for (int j = 0; j < nphi; ++j) {
                double phi = (j + 0.5) / nphi * 2 * kPi;
                Vec3 m(float(s * std::cos(phi)), float(s * std::sin(phi)), float(c));
                for (int v = 0; v < 3; ++v) {
                    Vec3 dir(std::sin(vTheta[v]), 0.0f, std::cos(vTheta[v]));
                    sumVis[v] += ub_ggx_visible_pdf(dir.z, dot(dir, m), m.z, alpha) * s * dTheta *
                                 (2 * kPi / nphi);
                }
            }
        }
        EXPECT_NEAR(sumD, 1.0, 1e-3) << alpha;
        for (int v = 0; v < 3; ++v) EXPECT_NEAR(sumVis[v], 1.0, 2e-3) << alpha << " " << v;
    }
}

// The same for Beckmann (D, Lambda and G1 of kernels/shared/ub_microfacet.h), and the visible
// normals sampled on the host (scene/microfacet_sampling.cpp) follow that density: the mean
// of m over 200,000 samples matches the integral of m D_v(m) within 5 standard errors.
TEST(Microfacet, BeckmannNormalisedAndVisibleNormalsIntegrateToOne) {
    for (float alpha : {0.05f, 0.3f, 0.8f}) {
        const int nz = 4000, nphi = 64;
        double sumD = 0;
        double sumVis[3] = {0, 0, 0}, meanX[3] = {0, 0, 0}, meanZ[3] = {0, 0, 0};
        const float vTheta[3] = {0.1f, 0.8f, 1.4f};
        for (int i = 0; i < nz; ++i) {
            double theta = (i + 0.5) / nz * (kPi / 2), dTheta = (kPi / 2) / nz;
            double c = std::cos(theta), s = std::sin(theta);
            sumD += ub_beckmann_d(float(c), alpha) * c * s * dTheta * 2 * kPi;
            for (int j = 0; j < nphi; ++j) {
                double phi = (j + 0.5) / nphi * 2 * kPi;
                Vec3 m(float(s * std::cos(phi)), float(s * std::sin(phi)), float(c));
                for (int v = 0; v < 3; ++v) {
                    Vec3 dir(std::sin(vTheta[v]), 0.0f, std::cos(vTheta[v]));
                    const double w =
                        ub_mf_visible_pdf(UB_MF_BECKMANN, dir.z, dot(dir, m), m.z, alpha) * s *
                        dTheta * (2 * kPi / nphi);
                    sumVis[v] += w;
                    meanX[v] += w * m.x;
                    meanZ[v] += w * m.z;
                }
            }
        }
        EXPECT_NEAR(sumD, 1.0, 1e-3) << alpha;
        for (int v = 0; v < 3; ++v) {
            EXPECT_NEAR(sumVis[v], 1.0, 2e-3) << alpha << " " << v;
            Vec3 dir(std::sin(vTheta[v]), 0.0f, std::cos(vTheta[v]));
            Rng rng(77 + uint64_t(v), 3);
            const int n = 200000;
            double sx = 0, sz = 0, sx2 = 0, sz2 = 0;
            for (int k = 0; k < n; ++k) {
                const Vec2 u = rng.uniform2();
                const Vec3 m = sampleVisibleNormal(UB_MF_BECKMANN, dir, alpha, u.x, u.y);
                ASSERT_NEAR(length(m), 1.0f, 1e-5f);
                ASSERT_GT(dot(m, dir), -1e-6f) << "an invisible normal";
                sx += m.x;
                sz += m.z;
                sx2 += double(m.x) * m.x;
                sz2 += double(m.z) * m.z;
            }
            const double ex = sx / n, ez = sz / n;
            const double se = std::sqrt(std::max(sx2 / n - ex * ex, sz2 / n - ez * ez) / n);
            EXPECT_NEAR(ex, meanX[v] / sumVis[v], 5 * se + 2e-4) << alpha << " " << v;
            EXPECT_NEAR(ez, meanZ[v] / sumVis[v], 5 * se + 2e-4) << alpha << " " << v;
        }
    }
}

// The tangent orients an anisotropic lobe: turning it by 90 degrees about the normal is the
// same as swapping alpha_u and alpha_v, and an isotropic material ignores it.
TEST(Bsdf, AnisotropicLobeFollowsTheTangent) {
    const Vec3 turned = cross(kNormal, shadingTangent(kNormal, kTangent));
    for (Material base : {conductor(0.05f), beckmann(roughGlass(0.1f, 1.5f))}) {
        Material a = anisotropic(base, 0.4f), b = anisotropic(base, 0.05f);
        b.alpha = a.alphaV;
        b.alphaV = a.alpha;
        const Vec3 fix = directionAt(kNormal, 40.0f, 1.0f);
        Bsdf ba, bb, iso1, iso2;
        ba.setup(a, SurfaceColors::of(a), fix, kNormal, kNormal, false, kTangent);
        bb.setup(b, SurfaceColors::of(b), fix, kNormal, kNormal, false, turned);
        iso1.setup(base, SurfaceColors::of(base), fix, kNormal, kNormal, false, kTangent);
        iso2.setup(base, SurfaceColors::of(base), fix, kNormal, kNormal, false, turned);
        Rng rng(17, 3);
        int differ = 0;
        for (int i = 0; i < 200; ++i) {
            const Vec3 gen = sampleUniformSphere(rng.uniform2());
            float pa, pb, ra, rb;
            const Rgb fa = ba.evaluate(gen, nullptr, &pa, &ra);
            const Rgb fb = bb.evaluate(gen, nullptr, &pb, &rb);
            ASSERT_TRUE(nearRel(fa, fb, 1e-3f)) << str(fa) << " vs " << str(fb);
            ASSERT_TRUE(nearRel(pa, pb, 1e-3f) && nearRel(ra, rb, 1e-3f)) << pa << " vs " << pb;
            const Rgb f1 = iso1.evaluate(gen, nullptr, nullptr, nullptr);
            const Rgb f2 = iso2.evaluate(gen, nullptr, nullptr, nullptr);
            ASSERT_TRUE(nearRel(f1, f2, 1e-4f)) << str(f1) << " vs " << str(f2);
            // The lobe does depend on the tangent: not turning it changes the values.
            Bsdf wrong;
            wrong.setup(b, SurfaceColors::of(b), fix, kNormal, kNormal, false, kTangent);
            const Rgb fw = wrong.evaluate(gen, nullptr, nullptr, nullptr);
            if (!nearRel(fa, fw, 0.05f)) ++differ;
        }
        EXPECT_GT(differ, 20);
    }
}

// Anisotropic D (Heitz 2014, Sec. 5.4) is normalised, integral D(m) m.z dm = 1, its visible
// normals integrate to one for views at several azimuths, and the host's samplers (GGX and
// Beckmann) follow D_v: the sample mean of m matches the integral of m D_v(m) within 5
// standard errors (200,000 samples). Equal roughnesses give the isotropic functions exactly.
TEST(Microfacet, AnisotropicNormalisedAndVisibleNormalsIntegrateToOne) {
    const float alphas[2][2] = {{0.1f, 0.5f}, {0.6f, 0.2f}};
    for (uint32_t dist : {uint32_t(UB_MF_GGX), uint32_t(UB_MF_BECKMANN)}) {
        for (const auto& a : alphas) {
            const float au = a[0], av = a[1];
            const int nz = 2000, nphi = 256;
            const Vec3 views[3] = {normalize(Vec3(0.1f, 0.05f, 1.0f)),
                                   normalize(Vec3(0.5f, 0.6f, 0.6f)),
                                   normalize(Vec3(-0.9f, 0.3f, 0.2f))};
            double sumD = 0, sumVis[3] = {0, 0, 0};
            double mean[3][3] = {};
            for (int i = 0; i < nz; ++i) {
                double theta = (i + 0.5) / nz * (kPi / 2), dTheta = (kPi / 2) / nz;
                double c = std::cos(theta), s = std::sin(theta);
                for (int j = 0; j < nphi; ++j) {
                    double phi = (j + 0.5) / nphi * 2 * kPi, dPhi = 2 * kPi / nphi;
                    Vec3 m(float(s * std::cos(phi)), float(s * std::sin(phi)), float(c));
                    const double dw = s * dTheta * dPhi;
                    sumD += ub_mf_d_aniso(dist, m.x, m.y, m.z, au, av) * c * dw;
                    for (int v = 0; v < 3; ++v) {
                        const Vec3& w = views[v];
                        const double p = ub_mf_visible_pdf_aniso(dist, w.x, w.y, w.z, dot(w, m),
                                                                 m.x, m.y, m.z, au, av) *
                                         dw;
                        sumVis[v] += p;
                        mean[v][0] += p * m.x;
                        mean[v][1] += p * m.y;
                        mean[v][2] += p * m.z;
                    }
                }
            }
            const std::string label = std::string(dist == UB_MF_GGX ? "ggx " : "beckmann ") +
                                      std::to_string(au) + "x" + std::to_string(av);
            EXPECT_NEAR(sumD, 1.0, 2e-3) << label;
            for (int v = 0; v < 3; ++v) {
                EXPECT_NEAR(sumVis[v], 1.0, 3e-3) << label << " view " << v;
                Rng rng(91 + uint64_t(v), 5);
                const int n = 200000;
                double sum[3] = {0, 0, 0}, sum2[3] = {0, 0, 0};
                for (int k = 0; k < n; ++k) {
                    const Vec2 u = rng.uniform2();
                    const Vec3 m = sampleVisibleNormal(dist, views[v], au, av, u.x, u.y);
                    ASSERT_NEAR(length(m), 1.0f, 1e-5f) << label;
                    ASSERT_GT(dot(m, views[v]), -1e-6f) << label << ": an invisible normal";
                    const float c3[3] = {m.x, m.y, m.z};
                    for (int q = 0; q < 3; ++q) {
                        sum[q] += c3[q];
                        sum2[q] += double(c3[q]) * c3[q];
                    }
                }
                for (int q = 0; q < 3; ++q) {
                    const double e = sum[q] / n;
                    const double se = std::sqrt(std::max(0.0, sum2[q] / n - e * e) / n);
                    EXPECT_NEAR(e, mean[v][q] / sumVis[v], 5 * se + 3e-4)
                        << label << " view " << v << " component " << q;
                }
            }
        }
        // Isotropic special case: the same values as the isotropic functions.
        for (float alpha : {0.05f, 0.4f}) {
            const Vec3 m = normalize(Vec3(0.3f, -0.2f, 0.9f)),
                       v = normalize(Vec3(-0.5f, 0.1f, 0.7f));
            EXPECT_EQ(ub_mf_d_aniso(dist, m.x, m.y, m.z, alpha, alpha), ub_mf_d(dist, m.z, alpha));
            EXPECT_EQ(ub_mf_lambda_aniso(dist, v.x, v.y, v.z, alpha, alpha),
                      ub_mf_lambda(dist, v.z, alpha));
            const Vec3 s1 = sampleVisibleNormal(dist, v, alpha, alpha, 0.3f, 0.7f);
            const Vec3 s0 = sampleVisibleNormal(dist, v, alpha, 0.3f, 0.7f);
            EXPECT_EQ(s1.x, s0.x);
            EXPECT_EQ(s1.z, s0.z);
        }
    }
}

// Glass with a shading normal tilted 30 degrees from the geometric one: every successful
// sample reflects back to dirFix's geometric side or refracts to the other side (never a
// light leak), and configurations where the shading-normal reflection would cross the
// geometric surface do fail.
TEST(Bsdf, DielectricGeometricSideGuard) {
    const Vec3 ng = kNormal;
    const Frame fg(ng);
    const Vec3 ns = fg.toWorld(Vec3(std::sin(0.52f), 0.0f, std::cos(0.52f)));
    for (MaterialType type : {MaterialType::Dielectric, MaterialType::RoughDielectric}) {
        Material m = roughGlass(0.3f, 1.5f);
        m.type = type;
        Rng rng(31, 4);
        int failed = 0, succeeded = 0;
        for (int i = 0; i < 4000; ++i) {
            Vec3 fix = sampleUniformSphere(rng.uniform2());
            if (dot(fix, ns) * dot(fix, ng) <= 0.0f) continue;
            Bsdf b = makeBsdf(m, fix, i % 2 == 0, ng, ns);
            if (!b.isValid()) continue;
            Vec3 dir;
            float pdfW, cosGen;
            uint32_t ev;
            b.sample(rng.uniform3(), &dir, &pdfW, &cosGen, &ev);
            if (pdfW == 0) {
                ++failed;
                continue;
            }
            ++succeeded;
            const bool shadingReflect = dot(dir, ns) * dot(fix, ns) > 0;
            const bool geometricReflect = dot(dir, ng) * dot(fix, ng) > 0;
            ASSERT_EQ(shadingReflect, geometricReflect);
            if (type == MaterialType::Dielectric) ASSERT_EQ(ev == kEventReflect, shadingReflect);
        }
        EXPECT_GT(failed, 0);
        EXPECT_GT(succeeded, 1000);
    }
}

// The same glass with the guard off (ShadingNormals::kShadingOnly, Mitsuba 3): the lobe in
// the shading frame alone decides, so every sample succeeds, reflects iff it stays on
// dirFix's side of the shading normal, and some of them cross the geometric surface the way
// the guarded BSDF refuses (these are what Mitsuba keeps at grazing smooth-shaded hits).
TEST(Bsdf, DielectricWithoutGeometricGuardFollowsTheShadingFrame) {
    const Vec3 ng = kNormal;
    const Frame fg(ng);
    const Vec3 ns = fg.toWorld(Vec3(std::sin(0.52f), 0.0f, std::cos(0.52f)));
    Material m = glass(1.5f);
    Rng rng(32, 4);
    int succeeded = 0, leaks = 0;
    for (int i = 0; i < 4000; ++i) {
        Vec3 fix = sampleUniformSphere(rng.uniform2());
        if (dot(fix, ns) * dot(fix, ng) <= 0.0f) continue;
        Bsdf b;
        b.setGeometricGuard(false);
        if (!b.setup(m, fix, ng, ns, i % 2 == 0)) continue;
        Vec3 dir;
        float pdfW, cosGen;
        uint32_t ev;
        b.sample(rng.uniform3(), &dir, &pdfW, &cosGen, &ev);
        ASSERT_GT(pdfW, 0.0f);
        ++succeeded;
        const bool shadingReflect = dot(dir, ns) * dot(fix, ns) > 0;
        const bool geometricReflect = dot(dir, ng) * dot(fix, ng) > 0;
        ASSERT_EQ(ev == kEventReflect, shadingReflect);
        leaks += shadingReflect != geometricReflect;
    }
    EXPECT_GT(succeeded, 1000);
    EXPECT_GT(leaks, 0);
}
