// Bilinear lat-long environment map (Mitsuba 3's `envmap` convention, scene/env_map.h):
// the lookup against an independent transcription of the convention and hand-checked
// values, the linear-density inversion, chi-square tests of illuminate()/emit() against
// the pdf that radianceAlong() reports (the pdf MIS uses), a strictly positive pdf where
// the radiance is positive (poles included), and irradiance against quadrature.
// Consistency of illuminate()/emit() with radianceAlong() and the normalization of the
// pdf are checked for both filters in light_test.cpp.
#include "scene/env_map.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>

#include "core/rng.h"
#include "scene/light.h"
#include "support/chi2.h"

namespace ub {
namespace {

// The chi-square tests of this file form one family at 1% (Sidak), fixed seeds.
constexpr int kChi2TestCount = 3;
const double kChi2Alpha = test::sidak(0.01, kChi2TestCount);

SceneSphere testSceneSphere() {
    SceneSphere s;
    s.center = Vec3(0.5f, -0.2f, 0.3f);
    s.radius = 5.0f;
    s.invRadiusSqr = 1.0f / 25.0f;
    return s;
}

Light bilinearLight(std::shared_ptr<Image> img, const Transform& envToWorld = Transform()) {
    Light l;
    l.type = LightType::EnvMap;
    l.name = "sky";
    l.radiance = Rgb(1.0f, 1.2f, 0.9f);
    l.envMap = std::move(img);
    l.envFilter = EnvFilter::Bilinear;
    l.envToWorld = envToWorld;
    l.prepare();
    return l;
}

/// 64x32 map: gradients, a 3x3 spot 40x brighter, distinct seam columns (x = 0 and 63)
/// and pole rows, rotated so that the map's +y axis is no world axis.
Light detailedLight() {
    auto img = std::make_shared<Image>(64, 32);
    for (int y = 0; y < img->height; ++y)
        for (int x = 0; x < img->width; ++x) {
            float g = 0.2f + float(x) / 64.0f + 0.5f * float(y) / 32.0f;
            img->at(x, y) = Rgb(g, 0.8f * g, 0.5f + 0.3f * float(y % 4));
        }
    for (int y = 9; y < 12; ++y)
        for (int x = 40; x < 43; ++x) img->at(x, y) = Rgb(40.0f, 30.0f, 20.0f);
    for (int y = 0; y < img->height; ++y) {
        img->at(0, y) = Rgb(6.0f, 1.0f, 0.2f);
        img->at(img->width - 1, y) = Rgb(0.1f, 0.2f, 3.0f);
    }
    for (int x = 0; x < img->width; ++x) {
        img->at(x, 0) = Rgb(0.05f + 0.1f * float(x % 5));
        img->at(x, img->height - 1) = Rgb(2.0f, 0.5f * float(x % 3), 1.0f);
    }
    return bilinearLight(img, Transform::rotate(35.0f, Vec3(1.0f, 0.3f, -0.2f)));
}

/// 6x4 map: cells of 60 x 60 degrees, so the chi-square cells resolve the bilinear
/// density inside each cell; one black pixel and non-black poles.
Light coarseLight() {
    auto img = std::make_shared<Image>(6, 4);
    const float values[4][6] = {{0.5f, 2.0f, 0.2f, 1.0f, 3.0f, 0.7f},
                                {4.0f, 0.1f, 1.5f, 0.0f, 0.6f, 2.5f},
                                {0.3f, 1.2f, 5.0f, 0.8f, 0.4f, 1.1f},
                                {1.0f, 0.2f, 0.9f, 3.0f, 0.5f, 2.0f}};
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 6; ++x) img->at(x, y) = Rgb(values[y][x], 0.5f * values[y][x], 1.0f);
    img->at(3, 1) = Rgb(0.0f);
    return bilinearLight(img);
}

/// Direction in the map's frame of (u, v) (Mitsuba 3's envmap, +y up).
Vec3 mapDirection(double u, double v) {
    double phi = 2 * M_PI * u, theta = M_PI * v;
    return Vec3(float(std::sin(phi) * std::sin(theta)), float(std::cos(theta)),
                float(-std::cos(phi) * std::sin(theta)));
}

/// Independent transcription of Mitsuba 3's envmap lookup (emitters/envmap.cpp,
/// eval_spectrum), in double: texel x centred at u = (x + 1/2) / W and periodic in u,
/// row y at v = y / (H - 1), bilinear in between. Red channel, unscaled.
double mitsubaLookup(const Image& img, double u, double v) {
    const int w = img.width, h = img.height;
    double s = u * w - 0.5;
    s -= w * std::floor(s / w);
    double t = std::clamp(v, 0.0, 1.0) * (h - 1);
    int x0 = std::min(int(std::floor(s)), w - 1), y0 = std::min(int(std::floor(t)), h - 2);
    double a = s - x0, b = t - y0;
    int x1 = (x0 + 1) % w;
    double top = (1 - a) * img.at(x0, y0).x + a * img.at(x1, y0).x;
    double bottom = (1 - a) * img.at(x0, y0 + 1).x + a * img.at(x1, y0 + 1).x;
    return (1 - b) * top + b * bottom;
}

Rgb radianceAt(const Light& l, const Vec3& worldDir, float* pdfW = nullptr) {
    float pdf;
    Rgb le = l.radianceAlong(testSceneSphere(), normalize(worldDir), Vec3(0.0f), Vec3(0.0f),
                             Vec2(0.0f, 0.0f), &pdf, nullptr);
    if (pdfW) *pdfW = pdf;
    return le;
}

double envPdfW(const Light& l, const Vec3& d) {
    float pdfW;
    radianceAt(l, d, &pdfW);
    return pdfW;
}

void expectChi2(const test::Chi2Result& r) {
    EXPECT_TRUE(r.message.empty()) << r.message;
    EXPECT_GT(r.pValue, kChi2Alpha) << "chi2 = " << r.statistic << ", dof = " << r.dof;
}

// ---- the linear density -------------------------------------------------------------

TEST(LatLongMap, SampleLinearInvertsItsCdf) {
    // CDF(x) = (a x + (b - a) x^2 / 2) / ((a + b) / 2); sampleLinear(CDF(x)) must return x
    // (float rounding: 1e-5), and linearPdf must be the CDF's derivative.
    const float ends[][2] = {{1, 1},     {0, 1},           {1, 0},        {0.2f, 5},
                             {7, 0.01f}, {1e-20f, 1e-19f}, {3e30f, 1e30f}};
    for (const auto& e : ends) {
        const double a = e[0], b = e[1];
        for (int i = 0; i <= 100; ++i) {
            const double x = i / 100.0;
            const double cdf = (a * x + 0.5 * (b - a) * x * x) / (0.5 * (a + b));
            EXPECT_NEAR(sampleLinear(float(cdf), e[0], e[1]), std::min(x, 0.99999994), 1e-5)
                << a << " " << b << " x " << x;
            const double pdf = (a + (b - a) * x) / (0.5 * (a + b));
            EXPECT_NEAR(linearPdf(float(x), e[0], e[1]), pdf, 1e-5 * std::max(1.0, pdf));
        }
    }
}

// ---- lookup: Mitsuba 3's convention ---------------------------------------------------

TEST(LatLongMap, BilinearMatchesMitsubaConvention) {
    // Pixel (x, y) holds x + 10 y + 1 (red).
    auto img = std::make_shared<Image>(8, 5);
    for (int y = 0; y < 5; ++y)
        for (int x = 0; x < 8; ++x) img->at(x, y) = Rgb(float(x + 10 * y + 1), 1.0f, 2.0f);
    Light l = bilinearLight(img);
    auto value = [](double x, double y) { return x + 10 * y + 1; };
    auto lookup = [&](double u, double v) {
        return double(radianceAt(l, mapDirection(u, v)).x) / l.radiance.x;
    };
    // Pixel centres: column x at u = (x + 1/2) / 8, row y at v = y / 4 (rows 1..3; the pole
    // rows are single directions).
    for (int y = 1; y < 4; ++y)
        for (int x = 0; x < 8; ++x)
            EXPECT_NEAR(lookup((x + 0.5) / 8, y / 4.0), value(x, y), 1e-3) << x << " " << y;
    // Between pixels: the mean of the neighbours, across the seam u = 0 too (-z).
    EXPECT_NEAR(lookup(2.0 / 8, 0.5), 0.5 * (value(1, 2) + value(2, 2)), 1e-3);
    EXPECT_NEAR(lookup(1e-6, 0.5), 0.5 * (value(7, 2) + value(0, 2)), 1e-3);
    EXPECT_NEAR(lookup(1 - 1e-6, 0.5), 0.5 * (value(7, 2) + value(0, 2)), 1e-3);
    EXPECT_NEAR(lookup(3.5 / 8, 0.375), 0.5 * (value(3, 1) + value(3, 2)), 1e-3);
    // Near the poles the first and last rows are reached (bilinear in u).
    EXPECT_NEAR(lookup(5.5 / 8, 1e-5), value(5, 0), 1e-2);
    EXPECT_NEAR(lookup(5.5 / 8, 1 - 1e-5), value(5, 4), 1e-2);
    // Everywhere: the independent transcription, and envToWorld rotates the map.
    Light rotated = bilinearLight(img, Transform::rotate(70.0f, Vec3(0.2f, 1.0f, 0.5f)));
    Rng rng(21, 1);
    for (int i = 0; i < 2000; ++i) {
        const Vec2 uv = rng.uniform2();
        const double ref = mitsubaLookup(*img, uv.x, uv.y);
        const Vec3 d = mapDirection(uv.x, uv.y);
        EXPECT_NEAR(lookup(uv.x, uv.y), ref, 2e-3 * ref) << uv.x << " " << uv.y;
        const Vec3 w = rotated.envToWorld.vector(d);
        EXPECT_NEAR(radianceAt(rotated, w).x / rotated.radiance.x, ref, 2e-3 * ref);
    }
}

TEST(LatLongMap, SmallMapsArePaddedAsMitsuba) {
    // Mitsuba pads maps to at least 2 x 3 by repeating the last column / row: a 4 x 2 map
    // has rows 0, 1, 1 at v = 0, 1/2, 1.
    auto img = std::make_shared<Image>(4, 2);
    for (int x = 0; x < 4; ++x) {
        img->at(x, 0) = Rgb(1.0f);
        img->at(x, 1) = Rgb(3.0f);
    }
    Light l = bilinearLight(img);
    EXPECT_NEAR(radianceAt(l, mapDirection(0.3, 0.25)).x, 2.0f * l.radiance.x, 1e-4);
    EXPECT_NEAR(radianceAt(l, mapDirection(0.3, 0.75)).x, 3.0f * l.radiance.x, 1e-4);
    // A single pixel is a constant environment.
    auto px = std::make_shared<Image>(1, 1);
    px->at(0, 0) = Rgb(0.5f, 1.0f, 2.0f);
    Light one = bilinearLight(px);
    Rng rng(22, 1);
    for (int i = 0; i < 100; ++i) {
        Rgb le = radianceAt(one, sampleUniformSphere(rng.uniform2()));
        EXPECT_NEAR(le.z, 2.0f * one.radiance.z, 1e-5);
    }
}

// ---- sampling -------------------------------------------------------------------------

std::function<Vec3()> illuminateSampler(const Light& l, Rng& rng) {
    return [&l, &rng]() {
        Vec3 dir;
        float dist, pdfW, emPdfW, cosL;
        Rgb le = l.illuminate(testSceneSphere(), Vec3(0.2f), rng.uniform2(), &dir, &dist, &pdfW,
                              &emPdfW, &cosL);
        return (isBlack(le) || pdfW <= 0) ? Vec3(0.0f) : dir;
    };
}

TEST(Light, BilinearEnvMapIlluminateChiSquare) {
    // The pdf is continuous (bilinear inside cells), so the default integration suffices;
    // 200k samples resolve the 3x3-pixel spot and the seam columns.
    Light l = detailedLight();
    Rng rng(31, 1);
    expectChi2(test::chi2TestSphere(
        illuminateSampler(l, rng), [&](const Vec3& d) { return envPdfW(l, d); }, 200000));
}

TEST(Light, CoarseBilinearEnvMapIlluminateChiSquare) {
    // 60-degree cells against 9-degree chi-square cells: the bilinear density inside each
    // map cell, the seam and the polar cells are tested directly.
    Light l = coarseLight();
    Rng rng(32, 1);
    expectChi2(test::chi2TestSphere(
        illuminateSampler(l, rng), [&](const Vec3& d) { return envPdfW(l, d); }, 200000));
}

TEST(Light, BilinearEnvMapEmitChiSquare) {
    // Emitted rays travel along -dirToLight: density pdfW(-d).
    Light l = detailedLight();
    Rng rng(33, 1);
    auto sampler = [&]() {
        Vec3 pos, dir;
        float emPdfW, pdfA, cosL;
        Vec2 rd = rng.uniform2();
        Rgb le = l.emit(testSceneSphere(), rd, rng.uniform2(), &pos, &dir, &emPdfW, &pdfA, &cosL);
        return (isBlack(le) || emPdfW <= 0) ? Vec3(0.0f) : dir;
    };
    expectChi2(test::chi2TestSphere(
        sampler, [&](const Vec3& d) { return envPdfW(l, -d); }, 200000));
}

TEST(LatLongMap, SamplerPdfEqualsPdfUv) {
    // The pdf sample() reports is pdfUv at the sample (what radianceAlong converts for MIS),
    // and every sample has non-zero radiance.
    Light l = detailedLight();
    const LatLongMap& map = *l.envLatLong;
    Rng rng(34, 1);
    for (int i = 0; i < 20000; ++i) {
        float pdf;
        Vec2 uv = map.sample(rng.uniform2(), &pdf);
        ASSERT_GT(pdf, 0.0f);
        ASSERT_NEAR(pdf, map.pdfUv(uv), 1e-4f * pdf) << uv.x << " " << uv.y;
        ASSERT_GT(maxComponent(map.eval(uv)), 0.0f);
    }
}

TEST(LatLongMap, BilinearPdfIsPositiveWhereRadianceIs) {
    // A black map with one lit pixel in the top (pole) row and one inside: Mitsuba's
    // sin(theta_row) weighting would give the polar cells pdf 0 below the lit pole pixel;
    // here pdf > 0 exactly where the bilinear radiance is > 0.
    auto img = std::make_shared<Image>(16, 8);
    img->at(5, 0) = Rgb(1.0f, 2.0f, 0.5f);
    img->at(11, 4) = Rgb(0.0f, 0.0f, 3.0f);
    Light l = bilinearLight(img);
    const LatLongMap& map = *l.envLatLong;
    int lit = 0;
    for (int i = 0; i < 400; ++i)
        for (int j = 0; j < 800; ++j) {
            Vec2 uv((j + 0.5f) / 800, (i + 0.5f) / 400);
            const bool radiant = maxComponent(map.eval(uv)) > 0.0f;
            const float pdf = map.pdfUv(uv);
            ASSERT_EQ(radiant, pdf > 0.0f) << uv.x << " " << uv.y << " pdf " << pdf;
            lit += radiant;
            float pdfW;
            if (radiant && uv.y > 0.01f && uv.y < 0.99f) {
                // Same through the light's solid-angle pdf (away from the pole singularity).
                radianceAt(l, mapDirection(uv.x, uv.y), &pdfW);
                ASSERT_GT(pdfW, 0.0f);
            }
        }
    EXPECT_GT(lit, 0);
}

// ---- irradiance -----------------------------------------------------------------------

TEST(Light, BilinearEnvMapIrradianceMatchesQuadrature) {
    // E = integral of L cos over the hemisphere of n, by midpoint quadrature of the
    // independent Mitsuba lookup over the map's (theta, phi) (1024 x 2048: the integrand is
    // continuous, quadrature error << the Monte Carlo error), against 200k samples of
    // illuminate(); 4 standard errors (fixed seed, a correct estimator fails w.p. < 1e-4).
    Light l = detailedLight();
    const Vec3 n = normalize(Vec3(0.4f, 0.3f, 0.5f));
    const int nt = 1024, np = 2048;
    double exact = 0;
    for (int i = 0; i < nt; ++i) {
        const double v = (i + 0.5) / nt;
        for (int j = 0; j < np; ++j) {
            const double u = (j + 0.5) / np;
            const Vec3 w = l.envToWorld.vector(mapDirection(u, v));
            exact +=
                mitsubaLookup(*l.envMap, u, v) * std::max(0.0f, dot(n, w)) * std::sin(M_PI * v);
        }
    }
    exact *= l.radiance.x * (M_PI / nt) * (2 * M_PI / np);

    Rng rng(35, 3);
    double sum = 0, sumSqr = 0;
    const int count = 200000;
    for (int k = 0; k < count; ++k) {
        Vec3 dir;
        float dist, pdfW, emPdfW, cosL;
        Rgb le = l.illuminate(testSceneSphere(), Vec3(0.3f), rng.uniform2(), &dir, &dist, &pdfW,
                              &emPdfW, &cosL);
        double x = 0;
        if (!isBlack(le) && pdfW > 0) x = double(le.x) * std::max(0.0f, dot(n, dir)) / pdfW;
        sum += x;
        sumSqr += x * x;
    }
    const double mean = sum / count;
    const double se = std::sqrt(std::max(0.0, sumSqr / count - mean * mean) / count);
    EXPECT_NEAR(mean, exact, 4 * se) << "stderr " << se;
}

}  // namespace
}  // namespace ub
