#include "scene/pixel_filter.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace ub {

PixelFilter PixelFilter::tent(float radius) {
    if (!(radius > 0.0f) || !std::isfinite(radius))
        throw std::invalid_argument("PixelFilter::tent: the radius must be > 0");
    PixelFilter f;
    f.type_ = PixelFilterType::kTent;
    f.radius_ = radius;
    f.norm_ = radius;  // integral of max(0, 1 - |x|/r)
    return f;
}

PixelFilter PixelFilter::gaussian(float stddev) {
    if (!(stddev > 0.0f) || !std::isfinite(stddev))
        throw std::invalid_argument("PixelFilter::gaussian: the standard deviation must be > 0");
    PixelFilter f;
    f.type_ = PixelFilterType::kGaussian;
    f.stddev_ = stddev;
    f.radius_ = 4.0 * double(stddev);
    // integral over (-r, r) of exp(-x^2 / (2 s^2)) - exp(-r^2 / (2 s^2))
    const double s = f.stddev_, r = f.radius_;
    f.norm_ = s * std::sqrt(2.0 * M_PI) * std::erf(r / (s * std::sqrt(2.0))) -
              2.0 * r * std::exp(-r * r / (2.0 * s * s));
    return f;
}

std::string PixelFilter::describe() const {
    std::ostringstream s;
    switch (type_) {
        case PixelFilterType::kBox:
            return "box";
        case PixelFilterType::kTent:
            s << "tent (radius " << radius_ << ")";
            break;
        case PixelFilterType::kGaussian:
            s << "gaussian (stddev " << stddev_ << ", radius " << radius_ << ")";
            break;
    }
    if (border_ == PixelFilterBorder::kPartitionOfUnity) s << ", borders as Mitsuba's ptracer";
    return s.str();
}

double PixelFilter::eval1(double x) const {
    const double ax = std::fabs(x);
    if (!(ax < radius_)) return 0.0;
    switch (type_) {
        case PixelFilterType::kBox:
            return 1.0;
        case PixelFilterType::kTent:
            return 1.0 - ax / radius_;
        case PixelFilterType::kGaussian: {
            const double k = -1.0 / (2.0 * stddev_ * stddev_);
            return std::max(0.0, std::exp(k * x * x) - std::exp(k * radius_ * radius_));
        }
    }
    return 0.0;
}

double PixelFilter::cdf1(double x) const {
    const double r = radius_;
    if (x <= -r) return 0.0;
    if (x >= r) return 1.0;
    switch (type_) {
        case PixelFilterType::kBox:
            return (x + r) / (2.0 * r);
        case PixelFilterType::kTent: {
            // Integral of the tent from -r, divided by its area r.
            if (x <= 0.0) return (x + r) * (x + r) / (2.0 * r * r);
            return 1.0 - (r - x) * (r - x) / (2.0 * r * r);
        }
        case PixelFilterType::kGaussian: {
            const double s = stddev_, a = 1.0 / (s * std::sqrt(2.0));
            const double bias = std::exp(-r * r / (2.0 * s * s));
            const double integral =
                s * std::sqrt(0.5 * M_PI) * (std::erf(a * x) + std::erf(a * r)) - bias * (x + r);
            return std::clamp(integral / norm_, 0.0, 1.0);
        }
    }
    return 0.0;
}

double PixelFilter::sample1(double lo, double hi, double u) const {
    const double fLo = cdf1(lo), fHi = cdf1(hi);
    const double target = fLo + u * (fHi - fLo);
    // Safeguarded Newton iteration on the (monotone) cdf within the bracket [a, b].
    double a = lo, b = hi, x = 0.5 * (lo + hi);
    for (int it = 0; it < 100; ++it) {
        const double g = cdf1(x) - target;
        if (g > 0.0)
            b = x;
        else
            a = x;
        if (std::fabs(g) < 1e-14 || b - a < 1e-12) break;
        const double pdf = eval1(x) / norm_;
        double next = pdf > 0.0 ? x - g / pdf : 0.5 * (a + b);
        if (!(next > a && next < b)) next = 0.5 * (a + b);
        x = next;
    }
    return std::clamp(x, lo, hi);
}

Vec2 PixelFilter::sampleRaster(int x, int y, const Vec2& u, int width, int height,
                               float* weight) const {
    if (weight) *weight = 1.0f;
    if (type_ == PixelFilterType::kBox) return Vec2(float(x) + u.x, float(y) + u.y);
    if (border_ == PixelFilterBorder::kPartitionOfUnity) {
        const double tx = x + 0.5 + sample1(-radius_, radius_, double(u.x));
        const double ty = y + 0.5 + sample1(-radius_, radius_, double(u.y));
        const Vec2 p{float(tx), float(ty)};
        if (weight) {
            const bool inside =
                p.x >= 0.0f && p.x < float(width) && p.y >= 0.0f && p.y < float(height);
            *weight = inside ? float(norm_ / coverage1(tx) * norm_ / coverage1(ty)) : 0.0f;
        }
        return p;
    }
    auto axis = [&](int i, double ui, int size) {
        const double c = double(i) + 0.5;
        // The footprint restricted to the image [0, size].
        const double lo = std::max(-radius_, -c), hi = std::min(radius_, double(size) - c);
        const double t = c + sample1(lo, hi, ui);
        // Stay inside the image (float rounding at the image's edges).
        return std::clamp(float(t), 0.0f, std::nextafter(float(size), 0.0f));
    };
    return Vec2(axis(x, double(u.x), width), axis(y, double(u.y), height));
}

double PixelFilter::coverage1(double t) const {
    // Pixel centres k + 1/2 within the radius of t.
    double s = 0.0;
    const int k0 = int(std::floor(t - 0.5 - radius_)), k1 = int(std::ceil(t - 0.5 + radius_));
    for (int k = k0; k <= k1; ++k) s += eval1(t - (double(k) + 0.5));
    return s;
}

double PixelFilter::weight1(int i, double t, int size) const {
    const double c = double(i) + 0.5;
    const double f = eval1(t - c);
    if (f <= 0.0) return 0.0;
    if (border_ == PixelFilterBorder::kPartitionOfUnity) {
        const double s = coverage1(t);
        return s > 0.0 ? f / s : 0.0;
    }
    const double mass = cdf1(double(size) - c) - cdf1(-c);  // part of the footprint in the image
    return mass > 0.0 ? f / (norm_ * mass) : 0.0;
}

float PixelFilter::splatWeight(int x, int y, const Vec2& p, int width, int height) const {
    if (!(p.x >= 0.0f && p.x < float(width) && p.y >= 0.0f && p.y < float(height))) return 0.0f;
    if (type_ == PixelFilterType::kBox) return int(p.x) == x && int(p.y) == y ? 1.0f : 0.0f;
    return float(weight1(x, double(p.x), width) * weight1(y, double(p.y), height));
}

void PixelFilter::footprint(const Vec2& p, int width, int height, int* x0, int* x1, int* y0,
                            int* y1) const {
    if (type_ == PixelFilterType::kBox) {
        *x0 = *x1 = int(std::floor(p.x));
        *y0 = *y1 = int(std::floor(p.y));
    } else {
        // Pixel i can contain p when |p - (i + 0.5)| < radius.
        *x0 = int(std::floor(double(p.x) - 0.5 - radius_));
        *x1 = int(std::ceil(double(p.x) - 0.5 + radius_));
        *y0 = int(std::floor(double(p.y) - 0.5 - radius_));
        *y1 = int(std::ceil(double(p.y) - 0.5 + radius_));
    }
    *x0 = std::max(*x0, 0);
    *y0 = std::max(*y0, 0);
    *x1 = std::min(*x1, width - 1);
    *y1 = std::min(*y1, height - 1);
}

}  // namespace ub
