// Pinhole / thin-lens camera: ray generation against projection, orientation,
// field of view, and the solid-angle pdf integrated over the image.
#include "scene/camera.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/rng.h"

using namespace ub;

namespace {

Camera makeCamera(int w, int h, float fov, float lensRadius = 0.0f, float focus = 1.0f) {
    Camera c;
    c.setup({1, 2, 3}, {-2, 0.5f, -1}, {0.2f, 1, 0.1f}, fov, w, h, lensRadius, focus);
    return c;
}

/// Solid angle of a w x h rectangle centred at distance d on the view axis
/// (e.g. Mathar 2014, "Solid angle of a rectangular plate"):
///     Omega = 4 asin( a b / sqrt((a^2 + d^2) (b^2 + d^2)) ), a = w/2, b = h/2.
double rectangleSolidAngle(double w, double h, double d) {
    double a = 0.5 * w, b = 0.5 * h;
    return 4.0 * std::asin(a * b / std::sqrt((a * a + d * d) * (b * b + d * d)));
}

}  // namespace

TEST(Camera, PixelCentresRoundTripThroughWorldToRaster) {
    for (float fov : {20.0f, 60.0f, 120.0f}) {
        Camera cam = makeCamera(40, 30, fov);
        for (int j = 0; j < cam.height(); ++j)
            for (int i = 0; i < cam.width(); ++i) {
                Vec2 px(i + 0.5f, j + 0.5f);
                Ray r = cam.generateRay(px);
                EXPECT_NEAR(length(r.dir), 1.0f, 1e-6f);
                for (float t : {0.1f, 3.0f, 100.0f}) {
                    Vec2 back;
                    ASSERT_TRUE(cam.worldToRaster(r.org + t * r.dir, &back));
                    EXPECT_NEAR(back.x, px.x, 2e-3f) << fov << " " << i << "," << j;
                    EXPECT_NEAR(back.y, px.y, 2e-3f) << fov << " " << i << "," << j;
                }
            }
    }
}

// Orthographic: worldToRaster inverts generateRay along the whole ray, orthoFilmPoint is the
// ray's origin, points behind the near plane are not seen, and a pixel's near-plane area is
// the region's area over the pixel count (the light-tracing factor's A_pixel).
TEST(Camera, OrthographicRoundTripsThroughWorldToRaster) {
    Camera cam;
    const Vec3 f = normalize(Vec3(0.3f, -0.4f, -1.0f));
    const Vec3 r = normalize(cross(f, Vec3(0, 1, 0)));
    const Vec3 u = cross(r, f);
    cam.setupOrthographic(Vec3(1, 2, 3), f, r, u, 1.5f, 0.75f, 40, 20);
    EXPECT_NEAR(cam.orthoPixelArea(), 3.0f * 1.5f / 800.0f, 1e-7f);
    for (int j = 0; j < cam.height(); ++j)
        for (int i = 0; i < cam.width(); ++i) {
            const Vec2 px(i + 0.25f, j + 0.75f);
            const Ray ray = cam.generateRay(px);
            for (float t : {0.01f, 2.0f, 50.0f}) {
                const Vec3 p = ray.org + t * ray.dir;
                EXPECT_LT(length(cam.orthoFilmPoint(p) - ray.org), 1e-4f);
                Vec2 back;
                ASSERT_TRUE(cam.worldToRaster(p, &back));
                EXPECT_NEAR(back.x, px.x, 1e-3f) << i << "," << j;
                EXPECT_NEAR(back.y, px.y, 1e-3f) << i << "," << j;
            }
            Vec2 back;
            EXPECT_FALSE(cam.worldToRaster(ray.org - 0.1f * ray.dir, &back));
        }
    Vec2 back;
    EXPECT_FALSE(cam.worldToRaster(Vec3(1, 2, 3) + 2.0f * f + 1.6f * r, &back));
    EXPECT_FALSE(cam.worldToRaster(Vec3(1, 2, 3) + 2.0f * f - 0.8f * u, &back));
}

TEST(Camera, OrientationMatchesRasterConvention) {
    Camera cam = makeCamera(64, 48, 50);
    Vec3 fwd = normalize(Vec3(-2, 0.5f, -1) - Vec3(1, 2, 3));
    EXPECT_NEAR(dot(cam.forward(), fwd), 1.0f, 1e-6f);
    // Orthonormal, right-handed (right x up = -forward... i.e. forward x up = right).
    EXPECT_NEAR(dot(cam.right(), cam.up()), 0.0f, 1e-6f);
    EXPECT_NEAR(dot(cam.right(), cam.forward()), 0.0f, 1e-6f);
    EXPECT_NEAR(dot(cam.up(), cam.forward()), 0.0f, 1e-6f);
    EXPECT_NEAR(length(cross(cam.forward(), cam.up()) - cam.right()), 0.0f, 1e-6f);
    EXPECT_GT(dot(cam.up(), Vec3(0.2f, 1, 0.1f)), 0.0f);
    // Image centre looks forward; raster y grows downwards, x to the right.
    EXPECT_NEAR(dot(cam.generateRay({32, 24}).dir, cam.forward()), 1.0f, 1e-6f);
    EXPECT_GT(dot(cam.generateRay({32, 0}).dir, cam.up()), 0.0f);
    EXPECT_LT(dot(cam.generateRay({32, 48}).dir, cam.up()), 0.0f);
    EXPECT_GT(dot(cam.generateRay({64, 24}).dir, cam.right()), 0.0f);
    EXPECT_LT(dot(cam.generateRay({0, 24}).dir, cam.right()), 0.0f);
}

TEST(Camera, VerticalFieldOfView) {
    for (float fov : {10.0f, 45.0f, 90.0f, 150.0f}) {
        Camera cam = makeCamera(50, 20, fov);
        Vec3 top = cam.generateRay({25, 0}).dir, bottom = cam.generateRay({25, 20}).dir;
        float angle = std::acos(std::min(1.0f, dot(top, bottom))) * 180.0f / kPi;
        EXPECT_NEAR(angle, fov, 1e-3f * fov);
        // Unit pixel area on the image plane: its height equals the pixel count.
        EXPECT_NEAR(2.0f * cam.imagePlaneDist() * std::tan(0.5f * fov * kPi / 180.0f), 20.0f,
                    1e-4f * 20.0f);
    }
}

TEST(Camera, WorldToRasterRejectsPointsBehindAndOutside) {
    Camera cam = makeCamera(32, 32, 40);
    Vec2 r;
    EXPECT_FALSE(cam.worldToRaster(cam.position() - cam.forward(), &r));
    EXPECT_FALSE(cam.worldToRaster(cam.position() + cam.forward() + 2.0f * cam.right(), &r));
    EXPECT_FALSE(cam.worldToRaster(cam.position() + cam.forward() - 2.0f * cam.up(), &r));
    EXPECT_TRUE(cam.worldToRaster(cam.position() + cam.forward(), &r));
    EXPECT_NEAR(r.x, 16.0f, 1e-4f);
    EXPECT_NEAR(r.y, 16.0f, 1e-4f);
    EXPECT_EQ(cam.pdfW(-cam.forward()), 0.0f);
}

// pdfW(dir) is the solid-angle density of a ray through a uniformly sampled point of
// one pixel (unit area on the image plane), so 1/pdfW at a pixel centre is that
// pixel's solid angle up to the midpoint rule. Summed over the image it must give the
// analytic solid angle of the image rectangle. Midpoint-rule error per pixel is
// O(1/d^2) relative with d = imagePlaneDist >= 40 here, i.e. well below 1e-3.
TEST(Camera, PdfWIntegratesToImageSolidAngle) {
    struct Case {
        int w, h;
        float fov;
    };
    for (Case c : {Case{64, 48, 60}, Case{48, 64, 90}, Case{100, 20, 30}, Case{64, 64, 120}}) {
        Camera cam = makeCamera(c.w, c.h, c.fov);
        double sum = 0;
        for (int j = 0; j < c.h; ++j)
            for (int i = 0; i < c.w; ++i)
                sum += 1.0 / cam.pdfW(cam.generateRay({i + 0.5f, j + 0.5f}).dir);
        double omega = rectangleSolidAngle(c.w, c.h, cam.imagePlaneDist());
        EXPECT_NEAR(sum / omega, 1.0, 1e-3) << c.w << "x" << c.h << " fov " << c.fov;
    }
}

// Thin lens: every lens sample for one raster point passes through the same point of
// the plane of focus (at focusDistance along the view axis), the pinhole ray's point.
TEST(Camera, ThinLensRaysMeetOnFocusPlane) {
    const float focus = 7.5f;
    Camera lens = makeCamera(32, 24, 45, 0.3f, focus);
    Camera pin = makeCamera(32, 24, 45);
    EXPECT_FALSE(lens.isPinhole());
    Rng rng(4, 4);
    for (int k = 0; k < 200; ++k) {
        Vec2 raster(32 * rng.uniform(), 24 * rng.uniform());
        Ray p = pin.generateRay(raster);
        Vec3 target = p.org + p.dir * (focus / dot(p.dir, pin.forward()));
        Ray r = lens.generateRay(raster, rng.uniform2());
        EXPECT_LE(length(r.org - lens.position()), 0.3f + 1e-5f);
        EXPECT_NEAR(dot(r.org - lens.position(), lens.forward()), 0.0f, 1e-5f);
        float t = dot(target - r.org, lens.forward()) / dot(r.dir, lens.forward());
        EXPECT_NEAR(length(r.org + t * r.dir - target), 0.0f, 1e-4f * focus);
    }
}
