// Visible-normal sampling (banner in microfacet_sampling.h).
//
// Beckmann, alpha = 1, view direction at polar angle theta in the xz-plane: a slope
// (x, y) (normal m ~ (-x, -y, 1)) is visible with density proportional to
//   (cos theta - x sin theta) exp(-x^2 - y^2)   for x < cot theta
// (the P22 slope density times v.m / m.z; Heitz & d'Eon 2014, eq. 10 with the Beckmann P22).
// The y part is a Gaussian of variance 1/2, inverted through erf. The x marginal has CDF
//   F(x) = cos theta sqrt(pi) / 2 (1 + erf x) + sin theta exp(-x^2) / 2,
// increasing from 0 to F(cot theta); it is inverted with Newton steps kept inside a
// bisection bracket.
#include "scene/microfacet_sampling.h"

#include <algorithm>
#include <cmath>

#include "kernels/shared/ub_microfacet.h"

namespace ub {

namespace {

constexpr double kSqrtPi = 1.7724538509055160273;

/// Solves f(x) = target for x in [lo, hi], f increasing with derivative df, from the guess
/// x0: Newton steps, bisection when a step leaves the bracket, to |dx| < 1e-11.
template <class F, class DF>
double solveIncreasing(F f, DF df, double target, double lo, double hi, double x0) {
    double x = x0 > lo && x0 < hi ? x0 : 0.5 * (lo + hi);
    for (int i = 0; i < 200; ++i) {
        const double v = f(x) - target;
        if (v > 0.0)
            hi = x;
        else
            lo = x;
        const double d = df(x);
        if (v == 0.0) return x;
        double next = d > 0.0 ? x - v / d : 0.5 * (lo + hi);
        if (std::fabs(next - x) < 1e-11)
            return next;  // converged (before the bracket test:
                          // a last step may touch its ends)
        if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
        if (hi - lo < 1e-11) return next;
        x = next;
    }
    return x;
}

/// A starting point for Newton: Winitzki's closed-form approximation of erfinv(t), relative
/// error below 2e-3 (S. Winitzki 2008, "A handy approximation for the error function and its
/// inverse", eq. 7 inverted, a = 0.147).
double erfinvGuess(double t) {
    t = std::min(std::max(t, -1.0 + 1e-15), 1.0 - 1e-15);
    const double a = 0.147, ln = std::log(1.0 - t * t);
    const double b = 2.0 / (3.14159265358979323846 * a) + 0.5 * ln;
    return std::copysign(std::sqrt(std::sqrt(b * b - ln / a) - b), t);
}

}  // namespace

double inverseNormalCdfErf(double u) {
    const double target = 2.0 * u - 1.0;
    return solveIncreasing([](double x) { return std::erf(x); },
                           [](double x) { return 2.0 / kSqrtPi * std::exp(-x * x); }, target, -9.0,
                           9.0, erfinvGuess(target));
}

Vec3 sampleVisibleNormal(uint32_t dist, const Vec3& v, float alpha, float u1, float u2) {
    return sampleVisibleNormal(dist, v, alpha, alpha, u1, u2);
}

Vec3 sampleVisibleNormal(uint32_t dist, const Vec3& v, float alphaU, float alphaV, float u1,
                         float u2) {
    if (dist != UB_MF_BECKMANN) {
        Vec3 m;
        ub_ggx_sample_visible(v.x, v.y, v.z, alphaU, alphaV, u1, u2, &m.x, &m.y, &m.z);
        return m;
    }
    // Stretch to alpha = 1 (Heitz & d'Eon 2014, Sec. 4, step 1; x by alphaU, y by alphaV).
    double sx = double(alphaU) * v.x, sy = double(alphaV) * v.y, sz = v.z;
    const double len = std::sqrt(sx * sx + sy * sy + sz * sz);
    sx /= len;
    sy /= len;
    sz /= len;
    const double sinTheta = std::sqrt(std::max(0.0, 1.0 - sz * sz));
    const double cosTheta = sz;
    double cosPhi = 1.0, sinPhi = 0.0;
    if (sinTheta > 1e-12) {
        const double h = std::sqrt(sx * sx + sy * sy);
        cosPhi = sx / h;
        sinPhi = sy / h;
    }
    // Step 2: visible slopes for the view at theta in the xz-plane.
    const double xMax = sinTheta > 1e-12 ? std::min(cosTheta / sinTheta, 9.0) : 9.0;
    auto cdf = [&](double x) {
        return cosTheta * kSqrtPi * 0.5 * (1.0 + std::erf(x)) + sinTheta * 0.5 * std::exp(-x * x);
    };
    auto pdf = [&](double x) { return (cosTheta - x * sinTheta) * std::exp(-x * x); };
    const double lo = -9.0, total = cdf(xMax), base = cdf(lo);
    const double target = base + double(u1) * (total - base);
    // Guess: the Gaussian the slopes follow at normal incidence.
    const double slopeX = solveIncreasing(
        cdf, pdf, target, lo, xMax, std::min(erfinvGuess(2.0 * double(u1) - 1.0), xMax - 1e-3));
    const double slopeY = inverseNormalCdfErf(std::min(std::max(double(u2), 1e-300), 1.0 - 1e-16));
    // Steps 3-4: rotate by phi, unstretch, and turn the slope into a normal.
    const double rx = cosPhi * slopeX - sinPhi * slopeY;
    const double ry = sinPhi * slopeX + cosPhi * slopeY;
    const double nx = -double(alphaU) * rx, ny = -double(alphaV) * ry;
    const double n = std::sqrt(nx * nx + ny * ny + 1.0);
    return Vec3(float(nx / n), float(ny / n), float(1.0 / n));
}

}  // namespace ub
