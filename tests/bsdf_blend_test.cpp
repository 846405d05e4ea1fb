// Tests of the Blend BSDF (scene/bsdf.cpp, "Blend": Mitsuba 3's blendbsdf and mask):
// sample() against pdf() by chi-square, evaluate() and both pdfs as the weighted sums of the
// parts, the delta lobes of a part inside a mixture, a mask's null lobe, and the albedo.
//
// Parts: diffuse, Phong 20, GGX conductor alpha 0.3, GGX rough glass alpha 0.3 (IOR 1.5), a
// perfect mirror (delta) and the null interface of a mask (ThinDielectric of ior 1). Blend
// weights 0.3, 0.6, 0.7; incidence 5, 45, 80 degrees, dirFix on both sides of a tilted
// normal.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/rng.h"
#include "core/sampling.h"
#include "scene/bsdf.h"
#include "tests/support/bsdf_probe.h"
#include "tests/support/chi2.h"

using namespace ub;

namespace {

const Vec3 kNormal = normalize(Vec3(0.2f, -0.3f, 0.9f));
const float kAnglesDeg[] = {5.0f, 45.0f, 80.0f};
const float kSides[] = {1.0f, -1.0f};

Vec3 directionAt(const Vec3& n, float thetaDeg, float side, float phiDeg = 30.0f) {
    const float t = thetaDeg * kPi / 180.0f, p = phiDeg * kPi / 180.0f;
    return Frame(n).toWorld(
        Vec3(std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), side * std::cos(t)));
}

/// The materials outlive every Bsdf (a Bsdf keeps a pointer to its material).
struct Materials {
    Material diffuse, phong, conductor, glass, mirror, null, blend;
    Materials() {
        diffuse.type = MaterialType::Diffuse;
        diffuse.diffuse = Rgb(0.7f, 0.5f, 0.3f);
        diffuse.twoSided = true;
        phong.type = MaterialType::Phong;
        phong.diffuse = Rgb(0.2f, 0.25f, 0.3f);
        phong.glossy = Rgb(0.7f, 0.6f, 0.5f);
        phong.exponent = 20.0f;
        phong.twoSided = true;
        conductor.type = MaterialType::RoughConductor;
        conductor.alpha = 0.3f;
        conductor.twoSided = true;
        glass.type = MaterialType::RoughDielectric;
        glass.alpha = 0.3f;
        glass.ior = 1.5f;
        mirror.type = MaterialType::Mirror;
        mirror.specular = Rgb(0.9f, 0.8f, 0.7f);
        mirror.twoSided = true;
        null.type = MaterialType::ThinDielectric;  // the loader's nullPassMaterial
        null.ior = 1.0f;
        null.specular = Rgb(0.0f);
        null.transmittance = Rgb(1.0f);
        blend.type = MaterialType::Blend;
        for (Material* m : {&diffuse, &phong, &conductor, &glass, &mirror, &null})
            prepareMaterial(*m);
    }
};
const Materials& mats() {
    static const Materials m;
    return m;
}

struct BlendCase {
    std::string name;
    const Material* a;
    const Material* b;
    float weight;
};

std::vector<BlendCase> cases() {
    const Materials& m = mats();
    return {{"diffuse+conductor", &m.diffuse, &m.conductor, 0.3f},
            {"phong+glass", &m.phong, &m.glass, 0.6f},
            {"diffuse+mirror", &m.diffuse, &m.mirror, 0.6f},
            {"mask(conductor)", &m.null, &m.conductor, 0.7f}};
}

Bsdf part(const Material& m, const Vec3& dirFix, bool fromLight) {
    Bsdf b;
    b.setup(m, dirFix, kNormal, kNormal, fromLight);
    return b;
}

Bsdf blend(const BlendCase& c, const Vec3& dirFix, bool fromLight, Bsdf* a = nullptr,
           Bsdf* b = nullptr) {
    const Bsdf pa = part(*c.a, dirFix, fromLight), pb = part(*c.b, dirFix, fromLight);
    if (a) *a = pa;
    if (b) *b = pb;
    Bsdf out;
    out.setupBlend(mats().blend, c.weight, pa, pb);
    return out;
}

std::string label(const BlendCase& c, float theta, float side) {
    return c.name + " theta=" + std::to_string(int(theta)) + (side > 0 ? " front" : " back");
}

bool nearRel(float x, float y, float rel = 1e-4f) {
    return std::fabs(x - y) <= rel * std::max(std::fabs(x), std::fabs(y)) + 1e-20f;
}

}  // namespace

// Chi-square of the non-delta samples against pdf() (binning as bsdf_test.cpp: 40 x 80 cells
// around the normal, 10x10 midpoint rule, 200k samples); delta samples (the mirror part, the
// mask's null lobe) count as missing mass, which pdf() leaves out too. 24 tests at overall
// significance 1% (Sidak).
TEST(BsdfBlend, ChiSquare) {
    const std::vector<BlendCase> all = cases();
    const double alpha = test::sidak(0.01, int(all.size() * 6));
    uint64_t seed = 9100;
    for (const BlendCase& c : all)
        for (float theta : kAnglesDeg)
            for (float side : kSides) {
                const Vec3 dirFix = directionAt(kNormal, theta, side);
                const Bsdf bsdf = blend(c, dirFix, false);
                ASSERT_TRUE(bsdf.isValid()) << label(c, theta, side);
                const test::TestFrame tf(kNormal, dirFix);
                Rng rng(seed++, 7);
                auto sample = [&]() {
                    Vec3 dir;
                    float pdfW, cosGen;
                    uint32_t event;
                    bsdf.sample(rng.uniform3(), &dir, &pdfW, &cosGen, &event);
                    return pdfW > 0 && !(event & kEventSpecular) ? tf.toTest(dir) : Vec3(0.0f);
                };
                auto pdf = [&](const Vec3& d) { return double(bsdf.pdf(tf.toWorld(d))); };
                auto res = test::chi2TestSphere(sample, pdf, 200000, 40, 80, 10);
                EXPECT_TRUE(res.message.empty()) << label(c, theta, side) << ": " << res.message;
                EXPECT_GT(res.pValue, alpha)
                    << label(c, theta, side) << ": chi2 = " << res.statistic
                    << ", dof = " << res.dof;
            }
}

// evaluate() and both pdfs are (1 - w) part a + w part b at every direction, in both transport
// modes; the reverse pdf is the forward pdf of the blend set up at dirGen (bidirectional MIS).
TEST(BsdfBlend, EvaluateAndPdfsAreTheMixture) {
    uint64_t seed = 9200;
    for (const BlendCase& c : cases())
        for (float theta : kAnglesDeg)
            for (float side : kSides)
                for (bool fromLight : {false, true}) {
                    const Vec3 dirFix = directionAt(kNormal, theta, side);
                    Bsdf a, b;
                    const Bsdf bsdf = blend(c, dirFix, fromLight, &a, &b);
                    Rng rng(seed++, 3);
                    const float w = c.weight;
                    for (int i = 0; i < 300; ++i) {
                        const Vec3 d = sampleUniformSphere(rng.uniform2());
                        float cs, pd, pr, ca, pda, pra, cb, pdb, prb;
                        const Rgb f = bsdf.evaluate(d, &cs, &pd, &pr);
                        const Rgb fa = a.evaluate(d, &ca, &pda, &pra);
                        const Rgb fb = b.evaluate(d, &cb, &pdb, &prb);
                        const Rgb mix = fa * (1.0f - w) + fb * w;
                        for (int k = 0; k < 3; ++k) ASSERT_TRUE(nearRel(f[k], mix[k]));
                        ASSERT_TRUE(nearRel(pd, (1.0f - w) * pda + w * pdb));
                        ASSERT_TRUE(nearRel(pr, (1.0f - w) * pra + w * prb));
                        ASSERT_NEAR(cs, std::fabs(dot(d, kNormal)), 1e-5f);
                        if (pd > 0.0f && std::fabs(dot(d, kNormal)) > 0.05f) {
                            const Bsdf back = blend(c, d, fromLight);
                            ASSERT_TRUE(back.isValid());
                            ASSERT_TRUE(nearRel(back.pdf(dirFix), pr, 2e-4f))
                                << label(c, theta, side) << ": " << back.pdf(dirFix) << " vs "
                                << pr;
                        }
                    }
                }
}

// sample(): a non-delta sample returns the mixture's value and pdf there; a delta sample of
// a part keeps that part's throughput, with pdf = selection probability x the part's pdf.
TEST(BsdfBlend, SampleAgreesWithEvaluateAndDeltaParts) {
    uint64_t seed = 9300;
    for (const BlendCase& c : cases())
        for (float theta : kAnglesDeg) {
            const Vec3 dirFix = directionAt(kNormal, theta, 1.0f);
            const Bsdf bsdf = blend(c, dirFix, false);
            Rng rng(seed++, 11);
            int deltas = 0;
            for (int i = 0; i < 2000; ++i) {
                Vec3 dir;
                float pdfW, cosGen;
                uint32_t event;
                const Rgb f = bsdf.sample(rng.uniform3(), &dir, &pdfW, &cosGen, &event);
                if (pdfW == 0) {
                    ASSERT_TRUE(isBlack(f));
                    continue;
                }
                if (event & kEventSpecular) {
                    ++deltas;
                    const bool null = c.a->type == MaterialType::ThinDielectric;
                    const float select = null ? 1.0f - c.weight : c.weight;
                    ASSERT_TRUE(nearRel(pdfW, select)) << c.name << " " << pdfW;
                    const Rgb t = f * (cosGen / pdfW);
                    const Rgb expect = null ? Rgb(1.0f) : c.b->specular;
                    for (int k = 0; k < 3; ++k) ASSERT_TRUE(nearRel(t[k], expect[k])) << c.name;
                    ASSERT_EQ(bsdf.isNullEvent(event), null) << c.name;
                    if (null) ASSERT_NEAR(dot(dir, -dirFix), 1.0f, 1e-5f);
                    continue;
                }
                float cs, pd, pr;
                const Rgb fe = bsdf.evaluate(dir, &cs, &pd, &pr);
                for (int k = 0; k < 3; ++k) ASSERT_TRUE(nearRel(f[k], fe[k])) << c.name;
                ASSERT_TRUE(nearRel(pdfW, pd)) << c.name;
                ASSERT_TRUE(nearRel(cosGen, cs)) << c.name;
                ASSERT_FALSE(bsdf.isNullEvent(event)) << c.name;
            }
            const bool hasDelta =
                c.a->type == MaterialType::ThinDielectric || c.b->type == MaterialType::Mirror;
            EXPECT_EQ(deltas > 0, hasDelta) << c.name;
            EXPECT_EQ(bsdf.hasNullLobe(), c.a->type == MaterialType::ThinDielectric);
            EXPECT_FALSE(bsdf.isDelta());
        }
}

// The directional albedo E[f cos / pdf] of the blend is (1 - w) rho_a + w rho_b (each part's
// own estimate; 4 standard errors of the difference), and a blend of two delta parts is delta.
TEST(BsdfBlend, AlbedoIsTheWeightedSumAndDeltaOfDeltas) {
    uint64_t seed = 9400;
    for (const BlendCase& c : cases())
        for (float theta : kAnglesDeg) {
            const Vec3 dirFix = directionAt(kNormal, theta, 1.0f);
            Bsdf a, b;
            const Bsdf bsdf = blend(c, dirFix, false, &a, &b);
            const test::Albedo ab = test::albedo(bsdf, 400000, seed++);
            const test::Albedo aa = test::albedo(a, 400000, seed++);
            const test::Albedo abb = test::albedo(b, 400000, seed++);
            const float w = c.weight;
            for (int k = 0; k < 3; ++k) {
                const float expect = (1.0f - w) * aa.mean[k] + w * abb.mean[k];
                const float err = std::sqrt(ab.stdErr[k] * ab.stdErr[k] +
                                            (1 - w) * (1 - w) * aa.stdErr[k] * aa.stdErr[k] +
                                            w * w * abb.stdErr[k] * abb.stdErr[k]);
                EXPECT_NEAR(ab.mean[k], expect, 4.0f * err + 1e-6f)
                    << c.name << " theta " << theta << " channel " << k;
            }
        }
    const Materials& m = mats();
    const Vec3 dirFix = directionAt(kNormal, 30.0f, 1.0f);
    Bsdf both;
    both.setupBlend(m.blend, 0.4f, part(m.null, dirFix, false), part(m.mirror, dirFix, false));
    EXPECT_TRUE(both.isDelta());
    EXPECT_TRUE(both.hasNullLobe());
    EXPECT_NEAR(both.continuationProb(), 0.6f * 1.0f + 0.4f * 0.9f, 1e-6f);
}
