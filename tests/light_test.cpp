// Light sampling tests: chi-square tests of illuminate() and emit() direction
// sampling against their pdfs, pdf consistency between illuminate()/emit() and
// radianceAlong() (what bidirectional MIS relies on), normalization of the
// environment-map pdf, Monte Carlo irradiance and emitted power against analytic
// values, the documented env-map orientation, and input errors.
#include "scene/light.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <string>

#include "core/error.h"
#include "core/rng.h"
#include "support/chi2.h"

namespace ub {
namespace {

using test::chi2TestSphere;

// Every chi-square test in this file rejects at the Sidak-corrected level, so the
// whole file has a 1% false-rejection rate (fixed seeds make it deterministic).
constexpr int kChi2TestCount = 11;
const double kChi2Alpha = test::sidak(0.01, kChi2TestCount);

SceneSphere testSceneSphere() {
    SceneSphere s;
    s.center = Vec3(0.5f, -0.2f, 0.3f);
    s.radius = 5.0f;
    s.invRadiusSqr = 1.0f / 25.0f;
    return s;
}

Light triangleLight(const Vec3& p0, const Vec3& p1, const Vec3& p2, bool twoSided = false) {
    Light l;
    l.type = LightType::Area;
    l.name = "tri";
    l.radiance = Rgb(2.0f, 1.0f, 0.5f);
    l.triangles = {p0, p1, p2};
    l.twoSided = twoSided;
    l.prepare();
    return l;
}

Light sphereLight(const Vec3& c, float r) {
    Light l;
    l.type = LightType::Area;
    l.name = "ball";
    l.radiance = Rgb(1.5f);
    l.isSphere = true;
    l.position = c;
    l.sphereRadius = r;
    l.prepare();
    return l;
}

/// 64x32 lat-long map: a smooth gradient in u and v plus a 3x3-pixel spot 40x brighter,
/// rotated so the map's +y axis is not a world axis.
Light envMapLight(bool rotated = true, EnvFilter filter = EnvFilter::Nearest) {
    auto img = std::make_shared<Image>(64, 32);
    for (int y = 0; y < img->height; ++y)
        for (int x = 0; x < img->width; ++x) {
            float g = 0.2f + float(x) / 64.0f + 0.5f * float(y) / 32.0f;
            img->at(x, y) = Rgb(g, 0.8f * g, 0.5f + 0.3f * float(y % 4));
        }
    for (int y = 9; y < 12; ++y)
        for (int x = 40; x < 43; ++x) img->at(x, y) = Rgb(40.0f, 30.0f, 20.0f);
    Light l;
    l.type = LightType::EnvMap;
    l.name = "sky";
    l.radiance = Rgb(1.0f, 1.2f, 0.9f);
    l.envMap = img;
    l.envFilter = filter;
    if (rotated) l.envToWorld = Transform::rotate(35.0f, Vec3(1.0f, 0.3f, -0.2f));
    l.prepare();
    return l;
}

Light constantEnvLight() {
    Light l;
    l.type = LightType::ConstantEnv;
    l.name = "const";
    l.radiance = Rgb(0.7f, 0.8f, 0.9f);
    l.prepare();
    return l;
}

Vec3 triangleNormal(const Light& l, size_t tri) {
    const Vec3* p = &l.triangles[3 * tri];
    return normalize(cross(p[1] - p[0], p[2] - p[0]));
}

/// Moller-Trumbore ray/triangle intersection; returns t > 0 or -1.
float intersectTriangle(const Vec3& o, const Vec3& d, const Vec3* p) {
    Vec3 e1 = p[1] - p[0], e2 = p[2] - p[0];
    Vec3 pv = cross(d, e2);
    float det = dot(e1, pv);
    if (std::fabs(det) < 1e-12f) return -1;
    Vec3 tv = o - p[0];
    float u = dot(tv, pv) / det;
    if (u < 0 || u > 1) return -1;
    Vec3 qv = cross(tv, e1);
    float v = dot(d, qv) / det;
    if (v < 0 || u + v > 1) return -1;
    float t = dot(e2, qv) / det;
    return t > 0 ? t : -1;
}

/// Nearest ray/sphere hit distance, or -1.
float intersectSphere(const Vec3& o, const Vec3& d, const Vec3& c, float r) {
    Vec3 oc = o - c;
    float b = dot(oc, d), cc = dot(oc, oc) - r * r;
    float disc = b * b - cc;
    if (disc < 0) return -1;
    float t = -b - std::sqrt(disc);
    return t > 0 ? t : -1;
}

/// Solid-angle density of illuminate() at x for an area light (triangles or a
/// sphere), derived independently of light.cpp: the first hit of the ray from x,
/// converted from the uniform area pdf 1/A by d^2 / cos (0 if the hit faces away).
double areaLightPdfW(const Light& l, const Vec3& x, const Vec3& d) {
    float best = -1;
    Vec3 n;
    for (size_t i = 0; i < l.triangles.size() / 3; ++i) {
        float t = intersectTriangle(x, d, &l.triangles[3 * i]);
        if (t > 0 && (best < 0 || t < best)) {
            best = t;
            n = triangleNormal(l, i);
        }
    }
    if (l.isSphere) {
        float t = intersectSphere(x, d, l.position, l.sphereRadius);
        if (t > 0 && (best < 0 || t < best)) {
            best = t;
            n = normalize(x + t * d - l.position);
        }
    }
    if (best < 0) return 0;
    double c = dot(n, -d);
    if (l.twoSided) c = std::fabs(c);
    if (c <= 0) return 0;
    return double(best) * best / (c * l.totalArea);
}

std::function<Vec3()> illuminateSampler(const Light& l, const Vec3& x, Rng& rng) {
    SceneSphere ss = testSceneSphere();
    return [&l, x, &rng, ss]() {
        Vec3 dir;
        float dist, pdfW, emPdfW, cosL;
        Rgb le = l.illuminate(ss, x, rng.uniform2(), &dir, &dist, &pdfW, &emPdfW, &cosL);
        return (isBlack(le) || pdfW <= 0) ? Vec3(0.0f) : dir;
    };
}

std::function<Vec3()> emitDirectionSampler(const Light& l, Rng& rng) {
    SceneSphere ss = testSceneSphere();
    return [&l, &rng, ss]() {
        Vec3 pos, dir;
        float emPdfW, pdfA, cosL;
        Vec2 rd = rng.uniform2();
        Rgb le = l.emit(ss, rd, rng.uniform2(), &pos, &dir, &emPdfW, &pdfA, &cosL);
        return (isBlack(le) || emPdfW <= 0) ? Vec3(0.0f) : dir;
    };
}

/// Solid-angle pdf of illuminate() for an environment, as reported by radianceAlong().
double envPdfW(const Light& l, const Vec3& d) {
    float pdfW;
    l.radianceAlong(testSceneSphere(), d, Vec3(0.0f), Vec3(0.0f), Vec2(0.0f, 0.0f), &pdfW, nullptr);
    return pdfW;
}

void expectChi2(const test::Chi2Result& r) {
    EXPECT_TRUE(r.message.empty()) << r.message;
    EXPECT_GT(r.pValue, kChi2Alpha) << "chi2 = " << r.statistic << ", dof = " << r.dof;
}

// ---- chi-square: illuminate() ---------------------------------------------------

// Area lights: the pdf is zero outside the light's silhouette, so cells cut by the
// silhouette need fine midpoint integration (otherwise a sliver of a cell that no
// integration point hits holds samples but no expected mass), and a sphere's
// solid-angle pdf d^2 / (A cos) has an integrable 1/cos singularity at its
// silhouette. At 64^2 points per cell the sphere test's expected counts are
// measurably biased (p = 1e-22 at 1M samples); at 128^2 they are not at 200k samples.
constexpr int kAreaIntegrationRes = 128;

TEST(Light, ConstantEnvIlluminateChiSquare) {
    Light l = constantEnvLight();
    Rng rng(1, 1);
    expectChi2(chi2TestSphere(
        illuminateSampler(l, Vec3(0.1f), rng), [&](const Vec3& d) { return envPdfW(l, d); },
        100000));
}

TEST(Light, EnvMapIlluminateChiSquare) {
    Light l = envMapLight();
    Rng rng(2, 1);
    // Fine integration: the pdf is discontinuous at pixel edges that do not align
    // with the chi-square cells.
    expectChi2(chi2TestSphere(
        illuminateSampler(l, Vec3(0.0f), rng), [&](const Vec3& d) { return envPdfW(l, d); }, 200000,
        20, 40, 24));
}

TEST(Light, TriangleIlluminateChiSquare) {
    // Large triangle above the receiver, facing it (normal -z).
    Light l = triangleLight(Vec3(-2, -2, 1), Vec3(0, 2, 1), Vec3(2, -2, 1));
    ASSERT_LT(triangleNormal(l, 0).z, 0.0f);
    Vec3 x(0.1f, -0.2f, 0.0f);
    Rng rng(3, 1);
    expectChi2(chi2TestSphere(
        illuminateSampler(l, x, rng), [&](const Vec3& d) { return areaLightPdfW(l, x, d); }, 200000,
        20, 40, kAreaIntegrationRes));
}

TEST(Light, TwoSidedQuadIlluminateChiSquare) {
    // Two triangles forming a tilted quad whose front faces away from the receiver:
    // only two-sided emission makes it visible.
    Light l;
    l.type = LightType::Area;
    l.name = "quad";
    l.radiance = Rgb(1.0f);
    l.twoSided = true;
    Vec3 a(-1.5f, -1, 0.8f), b(1.5f, -1, 1.4f), c(1.5f, 2, 1.4f), d(-1.5f, 2, 0.8f);
    l.triangles = {a, b, c, a, c, d};
    l.prepare();
    ASSERT_GT(triangleNormal(l, 0).z, 0.0f);
    Vec3 x(0.0f, 0.3f, 0.0f);
    Rng rng(4, 1);
    expectChi2(chi2TestSphere(
        illuminateSampler(l, x, rng), [&](const Vec3& dd) { return areaLightPdfW(l, x, dd); },
        200000, 20, 40, kAreaIntegrationRes));
}

TEST(Light, SphereIlluminateChiSquare) {
    // Sphere on the +x axis (the chi-square equator) subtending a 56 degree
    // half-angle; samples on its far side are invalid (missing mass).
    Light l = sphereLight(Vec3(1.2f, 0, 0), 1.0f);
    Rng rng(5, 1);
    expectChi2(chi2TestSphere(
        illuminateSampler(l, Vec3(0.0f), rng),
        [&](const Vec3& d) { return areaLightPdfW(l, Vec3(0.0f), d); }, 200000, 20, 40,
        kAreaIntegrationRes));
}

// ---- chi-square: emit() directions --------------------------------------------------

TEST(Light, TriangleEmitChiSquare) {
    Light l = triangleLight(Vec3(0, 0, 0), Vec3(1, 0.2f, 0.3f), Vec3(0.1f, 1, -0.4f));
    Vec3 n = triangleNormal(l, 0);
    Rng rng(6, 1);
    // Cosine-weighted around the front normal: cos / pi.
    expectChi2(chi2TestSphere(
        emitDirectionSampler(l, rng),
        [&](const Vec3& d) { return std::max(0.0f, dot(n, d)) * kInvPi; }, 100000));
    Light l2 = triangleLight(Vec3(0, 0, 0), Vec3(1, 0.2f, 0.3f), Vec3(0.1f, 1, -0.4f), true);
    // Two-sided: each side with probability 1/2, |cos| / (2 pi).
    expectChi2(chi2TestSphere(
        emitDirectionSampler(l2, rng),
        [&](const Vec3& d) { return std::fabs(dot(n, d)) * 0.5 * kInvPi; }, 100000));
}

TEST(Light, SphereEmitChiSquare) {
    // Uniform points with cosine-weighted outward directions: by symmetry the
    // marginal direction density is uniform, 1 / (4 pi).
    Light l = sphereLight(Vec3(0.3f, 0.2f, -1), 0.5f);
    Rng rng(7, 1);
    expectChi2(chi2TestSphere(
        emitDirectionSampler(l, rng), [](const Vec3&) { return 0.25 * kInvPi; }, 100000));
}

TEST(Light, EnvironmentEmitChiSquare) {
    // Emitted rays travel along -dirToLight, so their density is pdfW(-d).
    Light env = envMapLight();
    Rng rng(8, 1);
    expectChi2(chi2TestSphere(
        emitDirectionSampler(env, rng), [&](const Vec3& d) { return envPdfW(env, -d); }, 200000, 20,
        40, 24));
    Light cst = constantEnvLight();
    expectChi2(chi2TestSphere(
        emitDirectionSampler(cst, rng), [](const Vec3&) { return 0.25 * kInvPi; }, 100000));
}

TEST(Light, PointEmitChiSquare) {
    Light l;
    l.type = LightType::Point;
    l.intensity = Rgb(3.0f);
    l.position = Vec3(1, 2, 3);
    l.prepare();
    Rng rng(9, 1);
    expectChi2(chi2TestSphere(
        emitDirectionSampler(l, rng), [](const Vec3&) { return 0.25 * kInvPi; }, 100000));
}

// ---- pdf consistency: illuminate() / emit() vs radianceAlong() -----------------------

/// Front normal of an area light at a point on it (what Scene::intersect reports).
Vec3 areaNormalAt(const Light& l, const Vec3& p) {
    if (l.isSphere && std::fabs(length(p - l.position) - l.sphereRadius) < 1e-4f)
        return normalize(p - l.position);
    // Triangles of these tests: pick the one whose plane contains p.
    for (size_t i = 0; i < l.triangles.size() / 3; ++i) {
        Vec3 n = triangleNormal(l, i);
        if (std::fabs(dot(n, p - l.triangles[3 * i])) < 1e-4f) return n;
    }
    ADD_FAILURE() << "point not on the light";
    return Vec3(0.0f);
}

bool relNear(double a, double b, double rel = 1e-4) {
    return std::fabs(a - b) <= rel * std::max(std::fabs(a), std::fabs(b));
}

/// For random samples, radianceAlong() at the sampled point/direction must report
/// the radiance and pdfs illuminate() and emit() used: MIS weights of every
/// bidirectional technique combine pdfs from both (tech. rep. Sec. 5).
void checkConsistency(const Light& l, uint64_t seed) {
    SceneSphere ss = testSceneSphere();
    Rng rng(seed, 7);
    int valid = 0;
    for (int i = 0; i < 2000; ++i) {
        Vec3 x = Vec3(-1.0f) + 2.0f * rng.uniform3();
        Vec3 dir;
        float dist, directPdfW, emPdfW, cosL;
        Rgb le = l.illuminate(ss, x, rng.uniform2(), &dir, &dist, &directPdfW, &emPdfW, &cosL);
        if (isBlack(le)) continue;
        ++valid;
        Vec3 hit = l.isFinite() ? x + dist * dir : Vec3(0.0f);
        Vec3 n = l.type == LightType::Area ? areaNormalAt(l, hit) : Vec3(0.0f);
        float pdfA, emPdfW2;
        Rgb le2 = l.radianceAlong(ss, dir, hit, n, Vec2(0.0f, 0.0f), &pdfA, &emPdfW2);
        float pdfW2 = l.type == LightType::Area ? pdfA * dist * dist / cosL : pdfA;
        // Like an integrator, the test reconstructs the hit point and normal, so the
        // light cosine carries ~1e-6 absolute float error: relative 1e-6 / cos at
        // grazing angles on top of the 1e-4 bound.
        double rel = 1e-4 + 1e-6 / cosL;
        ASSERT_TRUE(relNear(le.x, le2.x) && relNear(le.y, le2.y) && relNear(le.z, le2.z));
        ASSERT_TRUE(relNear(directPdfW, pdfW2, rel)) << directPdfW << " vs " << pdfW2;
        ASSERT_TRUE(relNear(emPdfW, emPdfW2, rel))
            << emPdfW << " vs " << emPdfW2 << " cos " << cosL;
    }
    EXPECT_GT(valid, 100);
    valid = 0;
    for (int i = 0; i < 2000; ++i) {
        Vec3 pos, dir;
        float emPdfW, pdfA, cosL;
        Vec2 rd = rng.uniform2();
        Rgb le = l.emit(ss, rd, rng.uniform2(), &pos, &dir, &emPdfW, &pdfA, &cosL);
        if (isBlack(le)) continue;
        ++valid;
        Vec3 n = l.type == LightType::Area ? areaNormalAt(l, pos) : Vec3(0.0f);
        float pdfA2, emPdfW2;
        Rgb le2 = l.radianceAlong(ss, -dir, pos, n, Vec2(0.0f, 0.0f), &pdfA2, &emPdfW2);
        ASSERT_TRUE(relNear(le.x, le2.x) && relNear(le.y, le2.y) && relNear(le.z, le2.z));
        double rel = 1e-4 + 1e-6 / cosL;  // as above
        ASSERT_TRUE(relNear(pdfA, pdfA2)) << pdfA << " vs " << pdfA2;
        ASSERT_TRUE(relNear(emPdfW, emPdfW2, rel)) << emPdfW << " vs " << emPdfW2;
        if (l.type == LightType::Area) ASSERT_TRUE(relNear(cosL, std::fabs(dot(n, dir))));
        if (l.isEnvironment()) {
            // Emitted rays start on the scene-sphere disk facing -dir (Sec. 5.1).
            Vec3 onDisk = pos - ss.center + ss.radius * dir;
            ASSERT_NEAR(dot(onDisk, dir), 0.0f, 1e-3f * ss.radius);
            ASSERT_LE(length(onDisk), ss.radius * 1.0001f);
        }
    }
    EXPECT_GT(valid, 100);
}

TEST(Light, AreaPdfsMatchRadianceAlong) {
    checkConsistency(triangleLight(Vec3(-2, -2, 1), Vec3(0, 2, 1), Vec3(2, -2, 1)), 11);
    checkConsistency(triangleLight(Vec3(-2, -2, 1), Vec3(0, 2, 1.5f), Vec3(2, -2, 1), true), 12);
    checkConsistency(sphereLight(Vec3(0.5f, 0.5f, 2.5f), 0.7f), 13);
    Light quad;  // two triangles plus a sphere in one light
    quad.type = LightType::Area;
    quad.radiance = Rgb(1.0f);
    quad.triangles = {Vec3(-1, -1, 2), Vec3(1, -1, 2), Vec3(1, 1, 2),
                      Vec3(-1, -1, 2), Vec3(1, 1, 2),  Vec3(-1, 1, 2)};
    quad.isSphere = true;
    quad.position = Vec3(0, 0, -3);
    quad.sphereRadius = 0.5f;
    quad.prepare();
    EXPECT_NEAR(quad.totalArea, 4.0f + 4.0f * kPi * 0.25f, 1e-4f);
    checkConsistency(quad, 14);
}

TEST(Light, EnvironmentPdfsMatchRadianceAlong) {
    checkConsistency(constantEnvLight(), 15);
    checkConsistency(envMapLight(), 16);
    // Bilinear map (Mitsuba 3's envmap); more of its tests are in env_map_test.cpp.
    checkConsistency(envMapLight(true, EnvFilter::Bilinear), 17);
}

TEST(Light, DeltaLightsCannotBeHit) {
    Light p;
    p.type = LightType::Point;
    p.intensity = Rgb(1.0f);
    p.prepare();
    Light d;
    d.type = LightType::Directional;
    d.radiance = Rgb(1.0f);
    d.direction = Vec3(0, 0, -2);
    d.prepare();
    EXPECT_NEAR(length(d.direction), 1.0f, 1e-6f);  // prepare() normalizes
    for (const Light* l : {&p, &d}) {
        float pdfA = -1, emPdfW = -1;
        Rgb le = l->radianceAlong(testSceneSphere(), Vec3(0, 0, 1), Vec3(0.0f), Vec3(0.0f),
                                  Vec2(0.0f, 0.0f), &pdfA, &emPdfW);
        EXPECT_TRUE(isBlack(le));
        EXPECT_EQ(pdfA, 0.0f);
        EXPECT_EQ(emPdfW, 0.0f);
    }
}

// ---- environment map: normalization and orientation --------------------------------

TEST(Light, EnvMapPdfIntegratesToOne) {
    // Midpoint rule over world (theta, phi), d omega = sin(theta) dtheta dphi. The map
    // is rotated so its poles (where pdfW ~ 1 / sin(theta_env), integrable) and pixel
    // edges do not align with the grid; a 1000 x 2000 grid keeps the quadrature error
    // from those edges well below the 1e-3 bound. Both filters.
    for (EnvFilter filter : {EnvFilter::Nearest, EnvFilter::Bilinear}) {
        Light l = envMapLight(true, filter);
        const int nt = 1000, np = 2000;
        double sum = 0;
        for (int i = 0; i < nt; ++i) {
            double theta = (i + 0.5) * M_PI / nt;
            double st = std::sin(theta), ct = std::cos(theta), rowSum = 0;
            for (int j = 0; j < np; ++j) {
                double phi = (j + 0.5) * 2 * M_PI / np;
                rowSum += envPdfW(
                    l, Vec3(float(st * std::cos(phi)), float(st * std::sin(phi)), float(ct)));
            }
            sum += rowSum * st;
        }
        sum *= (M_PI / nt) * (2 * M_PI / np);
        EXPECT_NEAR(sum, 1.0, 1e-3) << envFilterName(filter);
    }
}

TEST(Light, EnvMapMatchesMitsubaOrientation) {
    // Each pixel holds its own index; the documented (Mitsuba 3) mapping
    // u = atan2(x, -z) / 2pi, v = acos(y) / pi must select it. Directions are
    // tilted slightly off pixel edges.
    auto img = std::make_shared<Image>(8, 4);
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 8; ++x) img->at(x, y) = Rgb(float(x + 10 * y + 1));
    Light l;
    l.type = LightType::EnvMap;
    l.radiance = Rgb(1.0f);
    l.envMap = img;
    l.prepare();
    struct Case {
        Vec3 dir;
        int x, y;
    };
    const Case cases[] = {
        {Vec3(0.05f, -0.1f, -1), 0, 2},  // -z: u = 0+, v = 0.5+
        {Vec3(1, -0.1f, 0.05f), 2, 2},   // +x: u = 0.25+
        {Vec3(-0.05f, -0.1f, 1), 4, 2},  // +z: u = 0.5+
        {Vec3(-1, 0.1f, -0.05f), 6, 1},  // -x: u = 0.75+, v = 0.5-
        {Vec3(0.02f, 1, -0.1f), 0, 0},   // near +y: top row
        {Vec3(0.02f, -1, -0.1f), 0, 3},  // near -y: bottom row
    };
    for (const Case& c : cases) {
        float pdfW;
        Rgb le = l.radianceAlong(testSceneSphere(), normalize(c.dir), Vec3(0.0f), Vec3(0.0f),
                                 Vec2(0.0f, 0.0f), &pdfW, nullptr);
        EXPECT_EQ(le.x, float(c.x + 10 * c.y + 1)) << c.dir.x << " " << c.dir.y << " " << c.dir.z;
    }
    // envToWorld rotates the map: the world direction R d sees what d saw before.
    l.envToWorld = Transform::rotate(90.0f, Vec3(0, 1, 0));
    l.prepare();
    for (const Case& c : cases) {
        float pdfW;
        Vec3 w = normalize(l.envToWorld.vector(normalize(c.dir)));
        Rgb le = l.radianceAlong(testSceneSphere(), w, Vec3(0.0f), Vec3(0.0f), Vec2(0.0f, 0.0f),
                                 &pdfW, nullptr);
        EXPECT_EQ(le.x, float(c.x + 10 * c.y + 1));
    }
}

// ---- irradiance via illuminate() ------------------------------------------------------

struct Estimate {
    double mean = 0, stdErr = 0;
};

/// Monte Carlo irradiance E = integral of Le cos over the hemisphere of n at x, from
/// n samples of illuminate(): Le cos / directPdfW per sample (luminance channel x).
Estimate irradiance(const Light& l, const Vec3& x, const Vec3& n, int count, uint64_t seed) {
    SceneSphere ss = testSceneSphere();
    Rng rng(seed, 3);
    double sum = 0, sumSqr = 0;
    for (int i = 0; i < count; ++i) {
        Vec3 dir;
        float dist, pdfW, emPdfW, cosL;
        Rgb le = l.illuminate(ss, x, rng.uniform2(), &dir, &dist, &pdfW, &emPdfW, &cosL);
        double v = 0;
        if (!isBlack(le) && pdfW > 0) v = double(le.x) * std::max(0.0f, dot(n, dir)) / pdfW;
        sum += v;
        sumSqr += v * v;
    }
    Estimate e;
    e.mean = sum / count;
    e.stdErr = std::sqrt(std::max(0.0, sumSqr / count - e.mean * e.mean) / count);
    return e;
}

// Monte Carlo checks below accept |estimate - exact| <= 4 standard errors: with a
// fixed seed, a correct estimator fails with probability < 1e-4 per check.
void expectWithin4Se(const Estimate& e, double exact) {
    EXPECT_NEAR(e.mean, exact, 4 * e.stdErr + 1e-6 * std::fabs(exact)) << "stderr " << e.stdErr;
}

TEST(Light, DeltaLightIrradianceIsAnalytic) {
    Light p;
    p.type = LightType::Point;
    p.intensity = Rgb(5.0f);
    p.position = Vec3(1, 2, 3);
    p.prepare();
    Vec3 x(0.5f, 0.5f, 0.0f), n(0, 0, 1);
    Vec3 toL = p.position - x;
    double exact = 5.0 * dot(n, normalize(toL)) / lengthSqr(toL);  // I cos / d^2
    Estimate e = irradiance(p, x, n, 4, 1);
    EXPECT_NEAR(e.mean, exact, 1e-5 * exact);
    Light d;
    d.type = LightType::Directional;
    d.radiance = Rgb(3.0f);
    d.direction = normalize(Vec3(0.3f, 0.1f, -1));
    d.prepare();
    e = irradiance(d, x, n, 4, 1);
    EXPECT_NEAR(e.mean, 3.0 * dot(n, -d.direction), 1e-5);  // E cos
}

TEST(Light, ConstantEnvIrradianceIsPiL) {
    Light l = constantEnvLight();
    expectWithin4Se(irradiance(l, Vec3(0.0f), normalize(Vec3(0.2f, -0.5f, 1)), 100000, 2),
                    kPi * l.radiance.x);
}

TEST(Light, TriangleIrradianceMatchesLambert) {
    // Lambert's polygon formula (1760; Arvo 1995 eq. 1): E = L/2 sum_i Theta_i (n . g_i),
    // Theta_i the angle subtended by edge i, g_i the unit normal of the plane through
    // the receiver and the edge.
    Light l = triangleLight(Vec3(-1, -0.5f, 1.5f), Vec3(0.3f, 1.2f, 1.0f), Vec3(1.4f, -0.7f, 1.2f));
    Vec3 x(0.2f, 0.1f, 0.0f), n = normalize(Vec3(0.1f, 0.2f, 1));
    ASSERT_LT(dot(triangleNormal(l, 0), l.triangles[0] - x), 0.0f);  // faces the receiver
    double sum = 0;
    for (int i = 0; i < 3; ++i) {
        Vec3 a = normalize(l.triangles[i] - x), b = normalize(l.triangles[(i + 1) % 3] - x);
        double theta = std::acos(std::clamp(double(dot(a, b)), -1.0, 1.0));
        sum += theta * dot(n, normalize(cross(a, b)));
    }
    double exact = 0.5 * l.radiance.x * std::fabs(sum);
    expectWithin4Se(irradiance(l, x, n, 100000, 3), exact);
}

TEST(Light, SphereIrradianceMatchesAnalytic) {
    // A sphere of radius r at distance D on the normal: E = pi L (r / D)^2.
    Light l = sphereLight(Vec3(0, 0, 3), 1.2f);
    expectWithin4Se(irradiance(l, Vec3(0.0f), Vec3(0, 0, 1), 200000, 4),
                    kPi * l.radiance.x * (1.2 * 1.2) / 9.0);
}

/// Integral over the sphere of Le(world dir) * weight(world dir), by quadrature over each
/// pixel of the map in its own (theta, phi) with the documented mapping (exact in Le,
/// which is constant per pixel).
double envQuadrature(const Light& l, const std::function<double(const Vec3&)>& weight) {
    const Image& img = *l.envMap;
    const int sub = 8;
    double sum = 0;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            double le = img.at(x, y).x * l.radiance.x, acc = 0;
            for (int a = 0; a < sub; ++a)
                for (int b = 0; b < sub; ++b) {
                    double theta = M_PI * (y + (a + 0.5) / sub) / img.height;
                    double phi = 2 * M_PI * (x + (b + 0.5) / sub) / img.width;
                    Vec3 local(float(std::sin(phi) * std::sin(theta)), float(std::cos(theta)),
                               float(-std::cos(phi) * std::sin(theta)));
                    acc += weight(normalize(l.envToWorld.vector(local))) * std::sin(theta);
                }
            sum += le * acc * (M_PI / img.height / sub) * (2 * M_PI / img.width / sub);
        }
    return sum;
}

TEST(Light, EnvMapIrradianceMatchesQuadrature) {
    Light l = envMapLight();
    Vec3 n = normalize(Vec3(0.4f, 0.3f, 0.5f));
    double exact = envQuadrature(l, [&](const Vec3& d) { return std::max(0.0f, dot(n, d)); });
    expectWithin4Se(irradiance(l, Vec3(0.3f), n, 200000, 5), exact);
}

// ---- emitted power via emit() ----------------------------------------------------------

/// Monte Carlo power Phi = E[Le cos / emissionPdfW] (channel x).
Estimate power(const Light& l, int count, uint64_t seed) {
    SceneSphere ss = testSceneSphere();
    Rng rng(seed, 5);
    double sum = 0, sumSqr = 0;
    for (int i = 0; i < count; ++i) {
        Vec3 pos, dir;
        float emPdfW, pdfA, cosL;
        Vec2 rd = rng.uniform2();
        Rgb le = l.emit(ss, rd, rng.uniform2(), &pos, &dir, &emPdfW, &pdfA, &cosL);
        double v = 0;
        if (!isBlack(le) && emPdfW > 0) v = double(le.x) * cosL / emPdfW;
        sum += v;
        sumSqr += v * v;
    }
    Estimate e;
    e.mean = sum / count;
    e.stdErr = std::sqrt(std::max(0.0, sumSqr / count - e.mean * e.mean) / count);
    return e;
}

TEST(Light, EmittedPowerMatchesAnalytic) {
    // Lambertian emitter: Phi = pi A Le per emitting side.
    Light tri = triangleLight(Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(0, 1.5f, 0.5f));
    expectWithin4Se(power(tri, 20000, 6), kPi * tri.totalArea * tri.radiance.x);
    Light tri2 = triangleLight(Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(0, 1.5f, 0.5f), true);
    expectWithin4Se(power(tri2, 20000, 7), 2 * kPi * tri2.totalArea * tri2.radiance.x);
    Light ball = sphereLight(Vec3(1, 2, 3), 0.8f);
    expectWithin4Se(power(ball, 20000, 8), kPi * 4 * kPi * 0.64 * ball.radiance.x);
    // Point: 4 pi I. Directional: irradiance times the disk area pi R^2.
    Light p;
    p.type = LightType::Point;
    p.intensity = Rgb(2.0f);
    p.prepare();
    expectWithin4Se(power(p, 1000, 9), 4 * kPi * 2.0);
    Light d;
    d.type = LightType::Directional;
    d.radiance = Rgb(3.0f);
    d.prepare();
    double diskArea = kPi * 25.0;
    expectWithin4Se(power(d, 1000, 10), 3.0 * diskArea);
    // Environments: Phi = pi R^2 * integral of Le over the sphere.
    Light c = constantEnvLight();
    expectWithin4Se(power(c, 1000, 11), diskArea * 4 * kPi * c.radiance.x);
    Light env = envMapLight();
    expectWithin4Se(power(env, 200000, 12),
                    diskArea * envQuadrature(env, [](const Vec3&) { return 1.0; }));
}

// ---- input errors --------------------------------------------------------------------------

std::string prepareError(Light l) {
    try {
        l.prepare();
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

TEST(Light, BadInputThrowsInputError) {
    Light tri;
    tri.type = LightType::Area;
    tri.name = "flat";
    tri.radiance = Rgb(1.0f);
    tri.triangles = {Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(2, 2, 2)};
    std::string msg = prepareError(tri);
    EXPECT_NE(msg.find("light 'flat'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("zero total area"), std::string::npos) << msg;

    tri.triangles = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, std::nanf(""), 0)};
    EXPECT_NE(prepareError(tri).find("non-finite vertex"), std::string::npos);
    tri.triangles = {Vec3(0, 0, 0), Vec3(1, 0, 0)};
    EXPECT_NE(prepareError(tri).find("3 vertices per triangle"), std::string::npos);
    tri.triangles.clear();
    EXPECT_NE(prepareError(tri).find("no geometry"), std::string::npos);

    Light ball = tri;
    ball.isSphere = true;
    ball.sphereRadius = 0.0f;
    EXPECT_NE(prepareError(ball).find("radius must be > 0"), std::string::npos);
    ball.sphereRadius = 1.0f;
    ball.radiance = Rgb(-1.0f);
    EXPECT_NE(prepareError(ball).find("non-negative"), std::string::npos);

    Light d;
    d.type = LightType::Directional;
    d.name = "sun";
    d.radiance = Rgb(1.0f);
    d.direction = Vec3(0.0f);
    EXPECT_NE(prepareError(d).find("direction must be finite and non-zero"), std::string::npos);

    Light env;
    env.type = LightType::EnvMap;
    env.name = "sky";
    env.radiance = Rgb(1.0f);
    EXPECT_NE(prepareError(env).find("has no image"), std::string::npos);
    auto img = std::make_shared<Image>(4, 2);
    img->at(1, 1) = Rgb(0, std::numeric_limits<float>::infinity(), 0);
    env.envMap = img;
    EXPECT_NE(prepareError(env).find("pixel (1, 1) is negative or not finite"), std::string::npos);
    img->at(1, 1) = Rgb(1.0f);
    env.envToWorld = Transform::scale(Vec3(2.0f));
    EXPECT_NE(prepareError(env).find("must be a rotation"), std::string::npos);
    env.envToWorld = Transform::rotate(30.0f, Vec3(0, 0, 1));
    EXPECT_EQ(prepareError(env), "");
}

}  // namespace
}  // namespace ub
