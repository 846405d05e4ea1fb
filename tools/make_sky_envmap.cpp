// Writes the procedural sky used by scenes/envmap-spheres.json:
//     make_sky_envmap [output.exr]      (default scenes/textures/sky.exr)
// A 256x128 latitude-longitude map in the layout of Light::envMap
// (u = phi / 2pi, v = theta / pi, theta measured from +y, row 0 = zenith):
//   - sky above the horizon: blend from a pale horizon colour to a deeper blue
//     zenith with weight sqrt(cos theta);
//   - ground below the horizon: constant dull brown, blended over 3 degrees so
//     the horizon is not a hard step;
//   - a sun of angular radius 2.5 degrees (radiance 1000) at elevation 35 degrees
//     and u = 1/3 (direction (0.71, 0.57, 0.41): front right of the envmap-spheres
//     camera), with a soft glow around it (Gaussian, 6 degrees).
// Each pixel averages 4x4 stratified directions so the sun disc is antialiased.
// Everything is deterministic: re-running the tool reproduces the committed file.
#include <cmath>
#include <cstdio>
#include <string>

#include "core/image.h"
#include "core/vec.h"

using namespace ub;

namespace {

constexpr int kWidth = 256, kHeight = 128, kSuper = 4;
constexpr float kDeg = kPi / 180.0f;

/// Direction of lat-long coordinates (u, v), as src/scene/light.cpp maps them:
/// phi = 2 pi u, theta = pi v, d = (sin phi sin theta, cos theta, -cos phi sin theta).
Vec3 directionOf(float u, float v) {
    float phi = 2.0f * kPi * u, theta = kPi * v;
    return {std::sin(phi) * std::sin(theta), std::cos(theta), -std::cos(phi) * std::sin(theta)};
}

Rgb skyRadiance(const Vec3& d, const Vec3& sunDir) {
    const Rgb horizon(0.85f, 0.90f, 1.00f), zenith(0.20f, 0.38f, 0.85f);
    const Rgb ground(0.22f, 0.19f, 0.16f);
    float up = std::max(d.y, 0.0f);
    float w = std::sqrt(up);
    Rgb sky = horizon * (1.0f - w) + zenith * w;
    // Smooth transition to the ground over 3 degrees below the horizon.
    float g = std::min(1.0f, std::max(0.0f, -d.y / std::sin(3.0f * kDeg)));
    Rgb c = sky * (1.0f - g) + ground * g;

    float angle = std::acos(std::min(1.0f, std::max(-1.0f, dot(d, sunDir))));
    const float glowSigma = 6.0f * kDeg;
    c +=
        Rgb(1.0f, 0.85f, 0.6f) * (2.0f * std::exp(-0.5f * angle * angle / (glowSigma * glowSigma)));
    if (angle < 2.5f * kDeg) c += Rgb(1000.0f, 950.0f, 850.0f);
    return c;
}

}  // namespace

int main(int argc, char** argv) {
    std::string out = argc > 1 ? argv[1] : "scenes/textures/sky.exr";
    const float sunElevation = 35.0f * kDeg;
    Vec3 sunDir = directionOf(1.0f / 3.0f, 0.5f - sunElevation / kPi);

    Image img(kWidth, kHeight);
    for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < kWidth; ++x) {
            Rgb sum(0.0f);
            for (int sy = 0; sy < kSuper; ++sy)
                for (int sx = 0; sx < kSuper; ++sx) {
                    float u = (x + (sx + 0.5f) / kSuper) / kWidth;
                    float v = (y + (sy + 0.5f) / kSuper) / kHeight;
                    sum += skyRadiance(directionOf(u, v), sunDir);
                }
            img.at(x, y) = sum / float(kSuper * kSuper);
        }
    try {
        writeExr(out, img,
                 {{"generator", "tools/make_sky_envmap.cpp"},
                  {"layout", "lat-long, u = phi/2pi, v = theta/pi from +y, row 0 = zenith"}});
    } catch (const std::exception& e) {
        std::fprintf(stderr, "make_sky_envmap: %s\n", e.what());
        return 1;
    }
    std::printf("wrote %s (%dx%d, mean radiance %.4f)\n", out.c_str(), kWidth, kHeight,
                double(average(img.mean())));
    return 0;
}
