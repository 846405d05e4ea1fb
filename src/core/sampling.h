// Sampling warps and tabulated distributions (host). Every warp has its pdf
// next to it; tests/sampling_test.cpp checks each against the other.
#pragma once

#include <vector>

#include "core/vec.h"

namespace ub {

/// Cosine-weighted hemisphere around +z; pdf = cos(theta)/pi (solid angle).
inline Vec3 sampleCosineHemisphere(const Vec2& u, float* pdfW = nullptr) {
    float phi = 2.0f * kPi * u.x;
    float r = std::sqrt(u.y);
    float z = std::sqrt(std::max(0.0f, 1.0f - u.y));
    if (pdfW) *pdfW = z * kInvPi;
    return {r * std::cos(phi), r * std::sin(phi), z};
}
inline float cosineHemispherePdfW(const Vec3& local) {
    return std::max(0.0f, local.z) * kInvPi;
}

/// Uniform direction on the unit sphere; pdf = 1/(4 pi).
inline Vec3 sampleUniformSphere(const Vec2& u, float* pdfW = nullptr) {
    float z = 1.0f - 2.0f * u.x;
    float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    float phi = 2.0f * kPi * u.y;
    if (pdfW) *pdfW = 0.25f * kInvPi;
    return {r * std::cos(phi), r * std::sin(phi), z};
}
inline float uniformSpherePdfW() {
    return 0.25f * kInvPi;
}

/// Direction inside the cone cos(theta) >= cosThetaMax around +z, uniform in solid angle.
inline Vec3 sampleUniformCone(const Vec2& u, float cosThetaMax) {
    float z = 1.0f - u.x * (1.0f - cosThetaMax);
    float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    float phi = 2.0f * kPi * u.y;
    return {r * std::cos(phi), r * std::sin(phi), z};
}

/// Concentric disk mapping (Shirley & Chiu 1997), unit disk.
inline Vec2 sampleConcentricDisk(const Vec2& u) {
    float a = 2.0f * u.x - 1.0f, b = 2.0f * u.y - 1.0f;
    if (a == 0 && b == 0) return {0, 0};
    float r, phi;
    if (std::fabs(a) > std::fabs(b)) {
        r = a;
        phi = (kPi / 4.0f) * (b / a);
    } else {
        r = b;
        phi = kPi / 2.0f - (kPi / 4.0f) * (a / b);
    }
    return {r * std::cos(phi), r * std::sin(phi)};
}

/// Uniform barycentrics on a triangle: returns (b1, b2), point = p0 + b1 (p1-p0) + b2 (p2-p0).
inline Vec2 sampleUniformTriangle(const Vec2& u) {
    float su = std::sqrt(u.x);
    return {1.0f - su, u.y * su};
}

/// Piecewise-constant 1D distribution over n bins on [0,1).
class Distribution1D {
  public:
    Distribution1D() = default;
    explicit Distribution1D(const std::vector<float>& f);
    /// Continuous sample in [0,1); pdf is the density in [0,1) measure.
    float sampleContinuous(float u, float* pdf, int* bin = nullptr) const;
    /// Discrete sample of a bin; pmf is its probability.
    int sampleDiscrete(float u, float* pmf = nullptr) const;
    float pmf(int bin) const { return funcInt_ > 0 ? func_[bin] / (funcInt_ * count()) : 0.0f; }
    float pdf(float x) const;
    int count() const { return int(func_.size()); }
    float integral() const { return funcInt_; }

  private:
    std::vector<float> func_, cdf_;
    float funcInt_ = 0;
};

/// Piecewise-constant 2D distribution on [0,1)^2 (marginal in v, conditional in u).
class Distribution2D {
  public:
    Distribution2D() = default;
    /// f has nv rows of nu values, row-major.
    Distribution2D(const std::vector<float>& f, int nu, int nv);
    Vec2 sampleContinuous(const Vec2& u, float* pdf) const;
    float pdf(const Vec2& p) const;

  private:
    std::vector<Distribution1D> conditional_;
    Distribution1D marginal_;
};

}  // namespace ub
