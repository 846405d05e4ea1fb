// Lat-long environment map lookup and sampling; conventions and the choice of the
// bilinear sampling density are explained in env_map.h.
#include "scene/env_map.h"

#include <algorithm>
#include <cmath>

namespace ub {

namespace {

constexpr float kOneMinusEpsilon = 0.99999994f;

float lerp(float t, float a, float b) {
    return (1.0f - t) * a + t * b;
}

/// max of sin over [lo, hi] within [0, pi]: 1 if the interval holds pi/2.
float maxSin(float lo, float hi) {
    lo = std::max(lo, 0.0f);
    hi = std::min(hi, kPi);
    if (lo <= 0.5f * kPi && hi >= 0.5f * kPi) return 1.0f;
    return std::max(std::sin(lo), std::sin(hi));
}

}  // namespace

const char* envFilterName(EnvFilter f) {
    return f == EnvFilter::Bilinear ? "bilinear" : "nearest";
}

float sampleLinear(float xi, float a, float b) {
    if (a == b || !(a + b > 0.0f)) return xi;  // uniform (or degenerate): the CDF is xi
    if (xi <= 0.0f) return 0.0f;
    // Scale to max(a, b) = 1 so that the squares cannot overflow.
    const float m = std::max(a, b);
    a /= m;
    b /= m;
    // CDF(x) = (a x + (b - a) x^2 / 2) / ((a + b) / 2) = xi; the root in [0, 1], written
    // without the cancellation of (-a + sqrt(.)) / (b - a).
    const float x = xi * (a + b) / (a + std::sqrt(lerp(xi, a * a, b * b)));
    return std::min(std::max(x, 0.0f), kOneMinusEpsilon);
}

float linearPdf(float x, float a, float b) {
    const float sum = a + b;
    return sum > 0.0f ? 2.0f * lerp(x, a, b) / sum : 0.0f;
}

LatLongMap::LatLongMap(std::shared_ptr<const Image> img, const Rgb& scale, EnvFilter filter)
    : img_(std::move(img)), scale_(scale), filter_(filter) {
    const Image& im = *img_;
    if (filter_ == EnvFilter::Nearest) {
        cellsU_ = im.width;
        cellsV_ = im.height;
        std::vector<float> f(size_t(cellsU_) * cellsV_);
        for (int y = 0; y < cellsV_; ++y) {
            // sin(theta) at the row centre: the Jacobian of the lat-long map.
            const float sinTheta = std::sin(kPi * (float(y) + 0.5f) / float(cellsV_));
            for (int x = 0; x < cellsU_; ++x)
                f[size_t(y) * cellsU_ + x] = std::max(0.0f, luminance(texel(x, y))) * sinTheta;
        }
        cells_ = Distribution2D(f, cellsU_, cellsV_);
        return;
    }
    // Bilinear: vertex grid padded as Mitsuba's Bitmap::pad_to(2, 3).
    gridU_ = std::max(im.width, 2);
    gridV_ = std::max(im.height, 3);
    cellsU_ = gridU_;      // periodic in phi: cell x spans columns x and x+1 mod W'
    cellsV_ = gridV_ - 1;  // rows 0 .. H'-1 bound H'-1 cells
    const float dTheta = kPi / float(gridV_ - 1);
    g_.resize(size_t(gridU_) * gridV_);
    for (int y = 0; y < gridV_; ++y) {
        const float sMax = maxSin(float(y - 1) * dTheta, float(y + 1) * dTheta);
        for (int x = 0; x < gridU_; ++x)
            g_[size_t(y) * gridU_ + x] = std::max(0.0f, luminance(texel(x, y))) * sMax;
    }
    std::vector<float> f(size_t(cellsU_) * cellsV_);
    for (int y = 0; y < cellsV_; ++y)
        for (int x = 0; x < cellsU_; ++x) {
            const int x1 = x + 1 == gridU_ ? 0 : x + 1;
            // Integral of the bilinear patch over the cell / cell area.
            f[size_t(y) * cellsU_ + x] = 0.25f * (vertexWeight(x, y) + vertexWeight(x1, y) +
                                                  vertexWeight(x, y + 1) + vertexWeight(x1, y + 1));
        }
    cells_ = Distribution2D(f, cellsU_, cellsV_);
}

Rgb LatLongMap::texel(int x, int y) const {
    const Image& im = *img_;
    return im.at(std::min(x, im.width - 1), std::min(y, im.height - 1)) * scale_;
}

void LatLongMap::locate(const Vec2& uv, int* x, int* y, float* fx, float* fy) const {
    // s = u W' - 1/2 wrapped into [0, W'): column x sits at u = (x + 1/2) / W'.
    float s = uv.x * float(gridU_) - 0.5f;
    s -= std::floor(s / float(gridU_)) * float(gridU_);
    const float t = std::min(std::max(uv.y, 0.0f), 1.0f) * float(gridV_ - 1);
    *x = std::min(std::max(int(s), 0), gridU_ - 1);
    *y = std::min(std::max(int(t), 0), gridV_ - 2);
    *fx = std::min(std::max(s - float(*x), 0.0f), 1.0f);
    *fy = std::min(std::max(t - float(*y), 0.0f), 1.0f);
}

Rgb LatLongMap::eval(const Vec2& uv) const {
    if (filter_ == EnvFilter::Nearest) {
        const Image& im = *img_;
        float u = uv.x - std::floor(uv.x);
        int x = std::min(std::max(int(u * float(im.width)), 0), im.width - 1);
        int y = std::min(std::max(int(uv.y * float(im.height)), 0), im.height - 1);
        return texel(x, y);
    }
    int x, y;
    float fx, fy;
    locate(uv, &x, &y, &fx, &fy);
    const int x1 = x + 1 == gridU_ ? 0 : x + 1;
    const Rgb top = (1.0f - fx) * texel(x, y) + fx * texel(x1, y);
    const Rgb bottom = (1.0f - fx) * texel(x, y + 1) + fx * texel(x1, y + 1);
    return (1.0f - fy) * top + fy * bottom;
}

float LatLongMap::cellPdf(int x, int y, float fx, float fy) const {
    const int x1 = x + 1 == gridU_ ? 0 : x + 1;
    const float g00 = vertexWeight(x, y), g10 = vertexWeight(x1, y);
    const float g01 = vertexWeight(x, y + 1), g11 = vertexWeight(x1, y + 1);
    const float mean = 0.25f * (g00 + g10 + g01 + g11);
    if (!(mean > 0.0f)) return 0.0f;
    const float bilinear = lerp(fy, lerp(fx, g00, g10), lerp(fx, g01, g11));
    // P(cell) * #cells, read back from the distribution the sampler draws from.
    const float cellPdf =
        cells_.pdf(Vec2((float(x) + 0.5f) / float(cellsU_), (float(y) + 0.5f) / float(cellsV_)));
    return cellPdf * bilinear / mean;
}

float LatLongMap::pdfUv(const Vec2& uv) const {
    if (filter_ == EnvFilter::Nearest) {
        Vec2 p(uv.x - std::floor(uv.x), std::min(std::max(uv.y, 0.0f), kOneMinusEpsilon));
        return cells_.pdf(p);
    }
    int x, y;
    float fx, fy;
    locate(uv, &x, &y, &fx, &fy);
    return cellPdf(x, y, fx, fy);
}

Vec2 LatLongMap::sample(const Vec2& rnd, float* pdfUv) const {
    if (filter_ == EnvFilter::Nearest) return cells_.sampleContinuous(rnd, pdfUv);
    float cellPdfUv;
    const Vec2 c = cells_.sampleContinuous(rnd, &cellPdfUv);
    // Cell and the (uniform) position of the sample inside it.
    const float cs = c.x * float(cellsU_), ct = c.y * float(cellsV_);
    const int x = std::min(int(cs), cellsU_ - 1), y = std::min(int(ct), cellsV_ - 1);
    const float ux = std::min(std::max(cs - float(x), 0.0f), kOneMinusEpsilon);
    const float uy = std::min(std::max(ct - float(y), 0.0f), kOneMinusEpsilon);
    const int x1 = x + 1 == gridU_ ? 0 : x + 1;
    const float g00 = vertexWeight(x, y), g10 = vertexWeight(x1, y);
    const float g01 = vertexWeight(x, y + 1), g11 = vertexWeight(x1, y + 1);
    // Bilinear patch: linear v-marginal, then the linear u-conditional at that v.
    const float fy = sampleLinear(uy, g00 + g10, g01 + g11);
    const float fx = sampleLinear(ux, lerp(fy, g00, g01), lerp(fy, g10, g11));
    *pdfUv = cellPdf(x, y, fx, fy);
    float u = (float(x) + fx + 0.5f) / float(gridU_);
    if (u >= 1.0f) u -= 1.0f;
    const float v = (float(y) + fy) / float(gridV_ - 1);
    return {std::min(std::max(u, 0.0f), kOneMinusEpsilon), std::min(v, kOneMinusEpsilon)};
}

}  // namespace ub
