// Tests of the projected-texture emitters (scene/light_projected.cpp): Mitsuba 3's
// `projector` and the `spot` with a `texture`. The projector's emit() direction sampling
// (chi-square against the pdf illuminate() reports), emit()/illuminate() agreement, the
// irradiance on the image plane z = 1 (pi scale E(uv), Mitsuba's normalisation), the emitted
// power against a quadrature of the texture, the uv conventions of both lights, the sampling
// density's support next to black pixels, and input errors.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "core/error.h"
#include "core/rng.h"
#include "scene/light.h"
#include "tests/support/chi2.h"

using namespace ub;

namespace {

SceneSphere sceneSphere() {
    SceneSphere s;
    s.radius = 5.0f;
    s.invRadiusSqr = 1.0f / 25.0f;
    return s;
}

/// 6 x 3 bitmap with distinct colours and one black pixel (x = 2, y = 1).
std::shared_ptr<Texture> slide(TextureFilter filter) {
    auto img = std::make_shared<Image>(6, 3);
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 6; ++x)
            img->at(x, y) = Rgb(0.2f + 0.3f * x, 1.0f + 0.5f * y, 0.1f + 0.2f * ((x + y) % 3));
    img->at(2, 1) = Rgb(0.0f);
    auto t = std::make_shared<Texture>();
    t->type = TextureType::Bitmap;
    t->name = "slide";
    t->image = img;
    t->filter = filter;
    t->wrap = TextureWrap::Clamp;
    return t;
}

/// Projector at `pos` looking along -z with x = (1, 0, 0)... in a tilted frame.
Light projector(float fovDeg, TextureFilter filter = TextureFilter::Bilinear) {
    Light l;
    l.type = LightType::Projector;
    l.name = "projector";
    l.position = Vec3(0.5f, 1.0f, -0.3f);
    const Frame f(normalize(Vec3(0.2f, -0.3f, 1.0f)));
    l.direction = f.n;
    l.frameX = f.s;
    l.frameY = f.t;
    l.intensity = Rgb(1.5f);
    l.projTexture = slide(filter);
    l.projAspect = 2.0f;  // 6 x 3
    l.projFovXDeg = fovDeg;
    l.prepare();
    return l;
}

Vec3 localOf(const Light& l, const Vec3& d) {
    return {dot(d, l.frameX), dot(d, l.frameY), dot(d, l.direction)};
}

}  // namespace

// emit() draws directions with the density illuminate() and projectedIntensity() report:
// 200k samples binned in the light's frame (axis = the bin sphere's pole), 20 x 40 cells of
// 16 x 16 quadrature; a wide frustum (fov 150) so that it covers many cells. Nearest and
// bilinear sampling weights, 1% over the two tests (Sidak).
TEST(ProjectorLight, EmitChiSquare) {
    for (TextureFilter filter : {TextureFilter::Nearest, TextureFilter::Bilinear}) {
        const Light l = projector(150.0f, filter);
        Rng rng(filter == TextureFilter::Nearest ? 3 : 4, 1);
        auto sample = [&]() {
            Vec3 pos, dir;
            float emPdfW, pdfA, cosL;
            Rgb v = l.emit(sceneSphere(), rng.uniform2(), rng.uniform2(), &pos, &dir, &emPdfW,
                           &pdfA, &cosL);
            if (!(emPdfW > 0) || isBlack(v)) return Vec3(0.0f);
            return localOf(l, dir);
        };
        auto pdf = [&](const Vec3& local) {
            float pdfW;
            const Vec3 d = local.x * l.frameX + local.y * l.frameY + local.z * l.direction;
            l.projectedIntensity(normalize(d), &pdfW);
            return double(pdfW);
        };
        auto r = ub::test::chi2TestSphere(sample, pdf, 200000, 20, 40, 16);
        EXPECT_TRUE(r.message.empty()) << r.message;
        EXPECT_GT(r.pValue, ub::test::sidak(0.01, 2))
            << "chi2 = " << r.statistic << ", dof = " << r.dof;
    }
}

// Every emit() sample: the position is the light's, the value the intensity towards the
// direction, and illuminate() from a point on the ray reports the same value and
// emissionPdfW (what bidirectional MIS combines), directPdfW = d^2.
TEST(ProjectorLight, EmitAndIlluminateAgree) {
    const Light l = projector(60.0f);
    Rng rng(5, 1);
    int valid = 0;
    for (int i = 0; i < 2000; ++i) {
        Vec3 pos, dir;
        float emPdfW, pdfA, cosL;
        Rgb le = l.emit(sceneSphere(), rng.uniform2(), rng.uniform2(), &pos, &dir, &emPdfW, &pdfA,
                        &cosL);
        if (isBlack(le)) continue;
        ++valid;
        ASSERT_EQ(pos.x, l.position.x);
        ASSERT_EQ(pdfA, 1.0f);
        ASSERT_EQ(cosL, 1.0f);
        const Vec3 receiver = pos + 1.7f * dir;
        Vec3 toLight;
        float dist, pdfW, emPdfW2, cosAt;
        Rgb li = l.illuminate(sceneSphere(), receiver, rng.uniform2(), &toLight, &dist, &pdfW,
                              &emPdfW2, &cosAt);
        ASSERT_NEAR(li.x, le.x, 1e-4f * le.x);
        ASSERT_NEAR(li.z, le.z, 1e-4f * le.z);
        ASSERT_NEAR(emPdfW2, emPdfW, 1e-4f * emPdfW);
        ASSERT_NEAR(dist, 1.7f, 1e-5f);
        ASSERT_NEAR(pdfW, 1.7f * 1.7f, 1e-4f);
    }
    // The black pixel's own cell keeps a sampling weight (its lit neighbours bleed into it
    // through the bilinear lookup), so nearly every sample carries light.
    EXPECT_GT(valid, 1990);
}

// The irradiance on the plane z = 1 of the light's frame, facing the projector, is
// pi * scale * E(uv) (Mitsuba's projector.cpp normalisation): uv = 1/2 - (x, a y) / (2 t).
// Outside the frustum and behind the light: black.
TEST(ProjectorLight, IrradianceOnTheImagePlane) {
    const Light l = projector(50.0f, TextureFilter::Nearest);
    const float t = std::tan(25.0f * kPi / 180.0f);
    for (Vec2 uv : {Vec2(0.5f, 0.5f), Vec2(0.1f, 0.2f), Vec2(0.9f, 0.8f), Vec2(0.3f, 0.5f)}) {
        const float x = (0.5f - uv.x) * 2.0f * t, y = (0.5f - uv.y) * 2.0f * t / 2.0f;
        const Vec3 p = l.position + x * l.frameX + y * l.frameY + l.direction;
        Vec3 toLight;
        float dist, pdfW, emPdfW, cosAt;
        Rgb le = l.illuminate(sceneSphere(), p, Vec2(0.5f, 0.5f), &toLight, &dist, &pdfW, &emPdfW,
                              &cosAt);
        const float cosPlane = dot(toLight, -l.direction);
        const Rgb e = l.projTexture->eval(uv);
        EXPECT_NEAR(le.y * cosPlane / pdfW, kPi * 1.5f * e.y, 1e-4f * e.y) << uv.x << " " << uv.y;
    }
    Vec3 toLight;
    float dist, pdfW, emPdfW, cosAt;
    const Vec3 outside = l.position + 2.0f * t * l.frameX + l.direction;  // uv.x = -1/2
    EXPECT_TRUE(isBlack(l.illuminate(sceneSphere(), outside, Vec2(0.5f, 0.5f), &toLight, &dist,
                                     &pdfW, &emPdfW, &cosAt)));
    const Vec3 behind = l.position - l.direction;
    EXPECT_TRUE(isBlack(l.illuminate(sceneSphere(), behind, Vec2(0.5f, 0.5f), &toLight, &dist,
                                     &pdfW, &emPdfW, &cosAt)));
    EXPECT_TRUE(l.isDelta() && l.isDeltaPosition() && l.isFinite());
    float pdfA = 1, em = 1;
    EXPECT_TRUE(isBlack(l.radianceAlong(sceneSphere(), -l.direction, l.position, Vec3(0.0f),
                                        Vec2(0.0f, 0.0f), &pdfA, &em)));
}

// Power: Phi = pi scale A integral of E over [0, 1]^2 (A = 4 t^2 / a, the plane's area):
// the Monte Carlo estimate E[emit() / emissionPdfW] of 100k samples within 4 standard
// errors of a 400 x 400 midpoint quadrature of the texture.
TEST(ProjectorLight, EmittedPowerMatchesQuadrature) {
    const Light l = projector(70.0f);
    const double t = std::tan(35.0 * kPi / 180.0), area = 4 * t * t / 2.0;
    double quad = 0;
    const int n = 400;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i)
            quad += l.projTexture->eval(Vec2((i + 0.5f) / n, (j + 0.5f) / n)).y;
    const double exact = kPi * 1.5 * area * quad / (double(n) * n);
    Rng rng(7, 2);
    double s = 0, s2 = 0;
    const int m = 100000;
    for (int i = 0; i < m; ++i) {
        Vec3 pos, dir;
        float emPdfW, pdfA, cosL;
        Rgb le = l.emit(sceneSphere(), rng.uniform2(), rng.uniform2(), &pos, &dir, &emPdfW, &pdfA,
                        &cosL);
        const double w = emPdfW > 0 ? le.y / emPdfW : 0.0;
        s += w;
        s2 += w * w;
    }
    const double mean = s / m, se = std::sqrt(std::max(0.0, s2 / m - mean * mean) / m);
    EXPECT_NEAR(mean, exact, 4 * se + 1e-3 * exact);
}

// A spot with a texture: intensity * falloff * T(uv), uv = 1/2 + (x, y) / (2 z tan c) in the
// light's frame (Mitsuba's spot.cpp); the axis looks up the texture's centre; emit() keeps the
// uniform cone and returns the same textured intensity illuminate() sees.
TEST(ProjectorLight, TexturedSpotLooksUpItsUv) {
    Light l;
    l.type = LightType::Spot;
    l.name = "spot";
    l.position = Vec3(0.0f, 2.0f, 0.0f);
    l.direction = Vec3(0.0f, -1.0f, 0.0f);
    l.frameX = Vec3(1.0f, 0.0f, 0.0f);
    l.frameY = Vec3(0.0f, 0.0f, 1.0f);
    l.intensity = Rgb(2.0f);
    l.cutoffAngleDeg = 30.0f;
    l.beamWidthDeg = 30.0f;
    l.projTexture = slide(TextureFilter::Nearest);
    l.prepare();
    const float tc = std::tan(30.0f * kPi / 180.0f);
    for (Vec2 xy : {Vec2(0.0f, 0.0f), Vec2(0.3f, 0.1f), Vec2(-0.4f, -0.2f), Vec2(0.1f, 0.45f)}) {
        const Vec3 local = normalize(Vec3(xy.x * tc, xy.y * tc, 1.0f));
        const Vec3 d = local.x * l.frameX + local.y * l.frameY + local.z * l.direction;
        const Rgb e = l.projTexture->eval(Vec2(0.5f + 0.5f * xy.x, 0.5f + 0.5f * xy.y));
        const Rgb v = l.projectedIntensity(d);
        EXPECT_NEAR(v.x, 2.0f * e.x, 1e-5f) << xy.x << " " << xy.y;
        EXPECT_NEAR(v.z, 2.0f * e.z, 1e-5f);
    }
    Rng rng(9, 1);
    for (int i = 0; i < 500; ++i) {
        Vec3 pos, dir;
        float emPdfW, pdfA, cosL;
        Rgb le = l.emit(sceneSphere(), rng.uniform2(), rng.uniform2(), &pos, &dir, &emPdfW, &pdfA,
                        &cosL);
        ASSERT_NEAR(emPdfW, 1.0f / (2 * kPi * (1 - std::cos(30 * kPi / 180))), 1e-4f);
        Vec3 toLight;
        float dist, pdfW, emPdfW2, cosAt;
        Rgb li = l.illuminate(sceneSphere(), pos + 1.3f * dir, rng.uniform2(), &toLight, &dist,
                              &pdfW, &emPdfW2, &cosAt);
        ASSERT_NEAR(li.y, le.y, 1e-4f * le.y + 1e-6f);
    }
}

TEST(ProjectorLight, BadInputThrowsInputError) {
    auto message = [](Light l) -> std::string {
        try {
            l.prepare();
        } catch (const InputError& e) {
            return e.what();
        }
        return "";
    };
    Light base;
    base.type = LightType::Projector;
    base.name = "p";
    base.intensity = Rgb(1.0f);
    base.projTexture = slide(TextureFilter::Bilinear);
    base.projFovXDeg = 40.0f;
    EXPECT_EQ(message(base), "");
    Light l = base;
    l.projTexture = nullptr;
    EXPECT_NE(message(l).find("no irradiance texture"), std::string::npos) << message(l);
    l = base;
    l.projFovXDeg = 180.0f;
    EXPECT_NE(message(l).find("field of view"), std::string::npos) << message(l);
    l = base;
    l.intensity = Rgb(-1.0f);
    EXPECT_NE(message(l).find("scale"), std::string::npos) << message(l);
    l = base;
    l.frameX = Vec3(1, 0, 0);
    l.frameY = Vec3(1, 1, 0);
    EXPECT_NE(message(l).find("orthogonal"), std::string::npos) << message(l);
    Light spot;
    spot.type = LightType::Spot;
    spot.name = "s";
    spot.intensity = Rgb(1.0f);
    spot.cutoffAngleDeg = 100.0f;
    spot.beamWidthDeg = 50.0f;
    spot.projTexture = slide(TextureFilter::Bilinear);
    EXPECT_NE(message(spot).find("cutoff_angle < 90"), std::string::npos) << message(spot);
}
