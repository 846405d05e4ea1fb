// Tests of the spot light (LightType::Spot, Mitsuba 3's `spot`): emit() direction
// sampling (chi-square), emitted power against the analytic integral of the falloff,
// illuminate() irradiance, falloff values, pdf agreement and input errors.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/error.h"
#include "core/rng.h"
#include "scene/light.h"
#include "tests/support/chi2.h"

using namespace ub;

namespace {

const Vec3 kAxis = normalize(Vec3(0.3f, -0.5f, -0.8f));

Light spot(float cutoffDeg, float beamDeg) {
    Light l;
    l.type = LightType::Spot;
    l.name = "spot";
    l.position = Vec3(1, 2, 3);
    l.direction = kAxis * 3.0f;  // prepare() normalises
    l.intensity = Rgb(2.0f, 1.0f, 0.5f);
    l.cutoffAngleDeg = cutoffDeg;
    l.beamWidthDeg = beamDeg;
    l.prepare();
    return l;
}

SceneSphere sceneSphere() {
    SceneSphere s;
    s.radius = 5.0f;
    s.invRadiusSqr = 1.0f / 25.0f;
    return s;
}

/// Direction at angle thetaDeg from the axis.
Vec3 offAxis(float thetaDeg, float phiDeg = 40.0f) {
    const float t = thetaDeg * kPi / 180, p = phiDeg * kPi / 180;
    return Frame(kAxis).toWorld(
        Vec3(std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)));
}

}  // namespace

// emit() samples directions uniformly in the cutoff cone: pdf 1 / (2 pi (1 - cos c))
// inside, 0 outside. Binned in a frame where the axis lies on the equator (so the cone
// covers many (z, phi) cells), 200k samples, 40 x 80 cells with 16 x 16 quadrature (the
// cone's edge cuts cells), significance 1% over the two tests (Sidak).
TEST(SpotLight, EmitChiSquare) {
    for (float cutoff : {30.0f, 100.0f}) {
        const Light l = spot(cutoff, 0.5f * cutoff);
        const Frame f(kAxis);  // f.n = axis; test frame: (axis, s, t) -> (x, y, z)
        Rng rng(uint64_t(cutoff), 3);
        const float conePdf = 1.0f / (2 * kPi * (1 - std::cos(cutoff * kPi / 180)));
        auto sample = [&]() {
            Vec3 pos, dir;
            float emPdfW, pdfA, cosL;
            l.emit(sceneSphere(), rng.uniform2(), rng.uniform2(), &pos, &dir, &emPdfW, &pdfA,
                   &cosL);
            if (!(emPdfW > 0)) return Vec3(0.0f);
            return Vec3(dot(dir, f.n), dot(dir, f.s), dot(dir, f.t));
        };
        auto pdf = [&](const Vec3& d) {
            return d.x > std::cos(cutoff * kPi / 180) ? conePdf : 0.0;
        };
        auto r = ub::test::chi2TestSphere(sample, pdf, 200000, 40, 80, 16);
        EXPECT_TRUE(r.message.empty()) << r.message;
        EXPECT_GT(r.pValue, ub::test::sidak(0.01, 2))
            << cutoff << ": chi2 = " << r.statistic << ", dof = " << r.dof;
    }
}

// Every emit() sample: position = the light, pdf the cone pdf, value = intensity times
// the falloff of its angle, directPdfA = cos = 1; and illuminate() from a point on that
// ray reports the same emissionPdfW and intensity.
TEST(SpotLight, EmitAndIlluminateAgree) {
    const Light l = spot(30.0f, 20.0f);
    Rng rng(5, 1);
    for (int i = 0; i < 1000; ++i) {
        Vec3 pos, dir;
        float emPdfW, pdfA, cosL;
        Rgb le = l.emit(sceneSphere(), rng.uniform2(), rng.uniform2(), &pos, &dir, &emPdfW, &pdfA,
                        &cosL);
        ASSERT_EQ(pos.x, l.position.x);
        ASSERT_NEAR(emPdfW, 1.0f / (2 * kPi * (1 - std::cos(30 * kPi / 180))), 1e-4f);
        ASSERT_EQ(pdfA, 1.0f);
        ASSERT_EQ(cosL, 1.0f);
        const float falloff = l.spotFalloff(dot(dir, l.direction));
        ASSERT_NEAR(le.x, 2.0f * falloff, 1e-4f);
        if (falloff <= 0.0f) continue;
        const Vec3 receiver = pos + 2.5f * dir;
        Vec3 toLight;
        float dist, pdfW, emPdfW2, cosAt;
        Rgb li = l.illuminate(sceneSphere(), receiver, rng.uniform2(), &toLight, &dist, &pdfW,
                              &emPdfW2, &cosAt);
        // Same falloff up to the float error of the direction (~1e-7 rad), which the
        // ramp's slope I / (c - b) = 11.5 per radian turns into ~2e-6 absolute.
        ASSERT_NEAR(li.x, le.x, 1e-4f * le.x + 2e-5f);
        ASSERT_NEAR(emPdfW2, emPdfW, 1e-6f);
        ASSERT_NEAR(dist, 2.5f, 1e-5f);
        ASSERT_NEAR(pdfW, 6.25f, 1e-4f);
        ASSERT_EQ(cosAt, 1.0f);
    }
}

// Mitsuba 3's falloff: 1 within the beam width, linear in the angle down to 0 at the
// cutoff, 0 beyond; beam width = cutoff gives a hard edge.
TEST(SpotLight, FalloffProfile) {
    const Light l = spot(30.0f, 20.0f);
    auto at = [&](float deg) { return l.spotFalloff(std::cos(deg * kPi / 180)); };
    EXPECT_EQ(at(0.0f), 1.0f);
    EXPECT_EQ(at(19.9f), 1.0f);
    EXPECT_NEAR(at(25.0f), 0.5f, 1e-4f);
    EXPECT_NEAR(at(22.5f), 0.75f, 1e-4f);
    EXPECT_NEAR(at(29.9f), 0.01f, 1e-3f);
    EXPECT_EQ(at(30.5f), 0.0f);
    EXPECT_EQ(at(170.0f), 0.0f);
    const Light hard = spot(30.0f, 30.0f);
    EXPECT_EQ(hard.spotFalloff(std::cos(29.9f * kPi / 180)), 1.0f);
    EXPECT_EQ(hard.spotFalloff(std::cos(30.1f * kPi / 180)), 0.0f);
    // Mitsuba's default beam width is 3/4 of the cutoff (the JSON loader applies it).
    Light def;
    EXPECT_EQ(def.cutoffAngleDeg, 20.0f);
    EXPECT_EQ(def.beamWidthDeg, 15.0f);
}

// Power: Phi = I * 2 pi [1 - (sin c - sin b) / (c - b)] (integral of the falloff over the
// sphere, spotPowerPerIntensity). Checked (1) against a midpoint quadrature in theta
// (100k cells: relative error < 1e-6) and (2) against the Monte Carlo estimate
// E[emit() * cos / emissionPdfW] from 100k samples, within 4 standard errors.
TEST(SpotLight, EmittedPowerMatchesAnalyticIntegral) {
    for (auto cb : {std::pair<float, float>{30.0f, 20.0f},
                    {20.0f, 15.0f},
                    {60.0f, 0.0f},
                    {45.0f, 45.0f},
                    {150.0f, 90.0f}}) {
        const Light l = spot(cb.first, cb.second);
        const double analytic = l.spotPowerPerIntensity();
        const int n = 100000;
        double quad = 0;
        for (int i = 0; i < n; ++i) {
            const double theta = (i + 0.5) / n * kPi;
            quad += l.spotFalloff(float(std::cos(theta))) * std::sin(theta);
        }
        quad *= 2 * kPi * kPi / n;
        EXPECT_NEAR(analytic, quad, 2e-4 * analytic) << cb.first << " " << cb.second;
        Rng rng(uint64_t(cb.first * 10 + cb.second), 2);
        double s = 0, s2 = 0;
        for (int i = 0; i < n; ++i) {
            Vec3 pos, dir;
            float emPdfW, pdfA, cosL;
            Rgb le = l.emit(sceneSphere(), rng.uniform2(), rng.uniform2(), &pos, &dir, &emPdfW,
                            &pdfA, &cosL);
            const double w = emPdfW > 0 ? le.y * cosL / emPdfW : 0.0;
            s += w;
            s2 += w * w;
        }
        const double mean = s / n, se = std::sqrt(std::max(0.0, s2 / n - mean * mean) / n);
        // (+ float rounding: with beam = cutoff every sample weighs the same, se = 0.)
        EXPECT_NEAR(mean, analytic * l.intensity.y, 4 * se + 1e-6 * analytic)
            << cb.first << " " << cb.second;
    }
}

// illuminate(): irradiance at a receiver with normal n is E = I falloff(theta) cos / d^2,
// i.e. le * cos / directPdfW with directPdfW = d^2; zero (black, zero pdf) outside the
// cone. Spot lights are delta lights: radianceAlong() is black.
TEST(SpotLight, IlluminateIrradiance) {
    const Light l = spot(30.0f, 20.0f);
    for (float theta : {0.0f, 10.0f, 25.0f, 29.0f, 31.0f, 90.0f}) {
        const float d = 1.7f;
        const Vec3 x = l.position + d * offAxis(theta);
        const Vec3 n = normalize(-offAxis(theta) + Vec3(0.1f, 0.2f, 0.0f));
        Vec3 toLight;
        float dist, pdfW, emPdfW, cosAt;
        Rgb le = l.illuminate(sceneSphere(), x, Vec2(0.3f, 0.7f), &toLight, &dist, &pdfW, &emPdfW,
                              &cosAt);
        const float falloff = theta < 20 ? 1.0f : theta < 30 ? (30 - theta) / 10 : 0.0f;
        const double exact = l.intensity.x * falloff * dot(n, -offAxis(theta)) / (d * d);
        if (falloff == 0.0f) {
            EXPECT_TRUE(isBlack(le)) << theta;
            EXPECT_EQ(pdfW, 0.0f) << theta;
            continue;
        }
        EXPECT_NEAR(le.x * dot(n, toLight) / pdfW, exact, 1e-3 * exact) << theta;
        EXPECT_NEAR(dist, d, 1e-5f);
    }
    float pdfA = 1, emPdfW = 1;
    EXPECT_TRUE(isBlack(l.radianceAlong(sceneSphere(), -kAxis, l.position, Vec3(0.0f),
                                        Vec2(0.0f, 0.0f), &pdfA, &emPdfW)));
    EXPECT_EQ(pdfA, 0.0f);
    EXPECT_TRUE(l.isDelta() && l.isDeltaPosition() && l.isFinite());
}

TEST(SpotLight, BadInputThrowsInputError) {
    auto message = [](Light l) -> std::string {
        try {
            l.prepare();
        } catch (const InputError& e) {
            return e.what();
        }
        return "";
    };
    Light l;
    l.type = LightType::Spot;
    l.name = "lamp";
    l.intensity = Rgb(1.0f);
    l.direction = Vec3(0.0f);
    EXPECT_NE(message(l).find("direction must be finite and non-zero"), std::string::npos);
    l.direction = Vec3(0, 0, 1);
    l.beamWidthDeg = 25.0f;  // cutoff 20
    EXPECT_NE(message(l).find("beam_width must be in [0, cutoff_angle]"), std::string::npos)
        << message(l);
    l.beamWidthDeg = 10.0f;
    l.cutoffAngleDeg = 0.0f;
    EXPECT_NE(message(l).find("cutoff_angle must be in (0, 180]"), std::string::npos);
    l.cutoffAngleDeg = 20.0f;
    l.intensity = Rgb(-1.0f);
    EXPECT_NE(message(l).find("light 'lamp'"), std::string::npos);
    l.intensity = Rgb(1.0f);
    EXPECT_EQ(message(l), "");
}
