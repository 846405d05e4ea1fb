// Chi-square goodness-of-fit test for direction samplers (after Mitsuba 3's
// and pbrt-v4's sampler tests): the sphere is divided into thetaBins x phiBins
// cells in (cos(theta), phi); observed sample counts are compared with counts
// expected from numerically integrating the sampler's pdf over each cell.
// Cells with small expectation are pooled (expected < 5). Returns the p-value;
// tests reject at a stated significance level.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "core/vec.h"

namespace ub::test {

/// Regularised upper incomplete gamma Q(a, x) (Numerical Recipes-style series /
/// continued fraction), used for the chi-square survival function.
inline double gammaQ(double a, double x) {
    if (x <= 0) return 1.0;
    double gln = std::lgamma(a);
    if (x < a + 1) {
        double ap = a, sum = 1.0 / a, del = sum;
        for (int n = 0; n < 10000; ++n) {
            ap += 1;
            del *= x / ap;
            sum += del;
            if (std::fabs(del) < std::fabs(sum) * 1e-15) break;
        }
        return 1.0 - sum * std::exp(-x + a * std::log(x) - gln);
    }
    double b = x + 1 - a, c = 1.0 / 1e-300, d = 1.0 / b, h = d;
    for (int i = 1; i < 10000; ++i) {
        double an = -i * (i - a);
        b += 2;
        d = an * d + b;
        if (std::fabs(d) < 1e-300) d = 1e-300;
        c = b + an / c;
        if (std::fabs(c) < 1e-300) c = 1e-300;
        d = 1.0 / d;
        double del = d * c;
        h *= del;
        if (std::fabs(del - 1) < 1e-15) break;
    }
    return std::exp(-x + a * std::log(x) - gln) * h;
}

struct Chi2Result {
    double pValue = 0;
    double statistic = 0;
    int dof = 0;
    std::string message;  ///< filled when the test fails structurally
};

/// sample(): returns a unit direction, or a zero vector if sampling failed (such
/// samples count as missing mass, which the test detects if pdf integrates to 1).
/// pdf(dir): solid-angle density of sample(), for dir on the unit sphere.
/// Directions are expressed in the frame in which (theta, phi) are binned (+z pole).
inline Chi2Result chi2TestSphere(const std::function<Vec3()>& sample,
                                 const std::function<double(const Vec3&)>& pdf, int sampleCount,
                                 int thetaBins = 20, int phiBins = 40, int integrationRes = 8) {
    const int nb = thetaBins * phiBins;
    std::vector<double> observed(nb, 0.0), expected(nb, 0.0);
    for (int i = 0; i < sampleCount; ++i) {
        Vec3 d = sample();
        if (lengthSqr(d) == 0) continue;
        d = normalize(d);
        double cz = std::clamp(double(d.z), -1.0, 1.0);
        double phi = std::atan2(double(d.y), double(d.x));
        if (phi < 0) phi += 2 * M_PI;
        int ti = std::min(thetaBins - 1, int((1 - cz) * 0.5 * thetaBins));
        int pi = std::min(phiBins - 1, int(phi / (2 * M_PI) * phiBins));
        observed[ti * phiBins + pi] += 1;
    }
    // Integrate pdf over each cell in (z, phi) with a midpoint rule; the cell
    // measure dz dphi equals solid angle.
    double dz = 2.0 / thetaBins, dphi = 2 * M_PI / phiBins;
    for (int ti = 0; ti < thetaBins; ++ti)
        for (int pi = 0; pi < phiBins; ++pi) {
            double z0 = 1 - ti * dz, p0 = pi * dphi, acc = 0;
            for (int a = 0; a < integrationRes; ++a)
                for (int b = 0; b < integrationRes; ++b) {
                    double z = z0 - (a + 0.5) * dz / integrationRes;
                    double ph = p0 + (b + 0.5) * dphi / integrationRes;
                    double r = std::sqrt(std::max(0.0, 1 - z * z));
                    acc += pdf(Vec3(float(r * std::cos(ph)), float(r * std::sin(ph)), float(z)));
                }
            expected[ti * phiBins + pi] =
                acc * dz * dphi / (integrationRes * integrationRes) * sampleCount;
        }
    // Sort cells by expected count and pool the small ones (Mitsuba's approach).
    std::vector<int> idx(nb);
    for (int i = 0; i < nb; ++i) idx[i] = i;
    std::sort(idx.begin(), idx.end(), [&](int a, int b) { return expected[a] < expected[b]; });
    double pooledE = 0, pooledO = 0, stat = 0;
    int dof = 0;
    Chi2Result res;
    for (int i : idx) {
        if (expected[i] == 0) {
            if (observed[i] > sampleCount * 1e-5) {
                res.message = "samples fall into a cell where the pdf is zero";
                return res;
            }
            continue;
        }
        if (expected[i] < 5) {
            pooledE += expected[i];
            pooledO += observed[i];
        } else {
            stat += (observed[i] - expected[i]) * (observed[i] - expected[i]) / expected[i];
            ++dof;
        }
    }
    if (pooledE > 0) {
        stat += (pooledO - pooledE) * (pooledO - pooledE) / pooledE;
        ++dof;
    }
    dof -= 1;
    res.statistic = stat;
    res.dof = dof;
    if (dof < 1) {
        res.message = "too few cells for a chi-square test";
        return res;
    }
    res.pValue = gammaQ(0.5 * dof, 0.5 * stat);
    return res;
}

/// p-value of binned counts against their expectations: cells expected below 5 are pooled
/// into one; dof = cells - 1 (the total is fixed by the sample count).
inline double chi2PooledPValue(const std::vector<double>& observed,
                               const std::vector<double>& expected) {
    double stat = 0, pooledE = 0, pooledO = 0;
    int cells = 0;
    for (size_t b = 0; b < expected.size(); ++b) {
        if (expected[b] < 5) {
            pooledE += expected[b];
            pooledO += observed[b];
            continue;
        }
        stat += (observed[b] - expected[b]) * (observed[b] - expected[b]) / expected[b];
        ++cells;
    }
    if (pooledE > 0) {
        stat += (pooledO - pooledE) * (pooledO - pooledE) / pooledE;
        ++cells;
    }
    return gammaQ(0.5 * (cells - 1), 0.5 * stat);
}

/// Significance level for one of `testCount` independent tests at overall level alpha
/// (Šidák correction).
inline double sidak(double alpha, int testCount) {
    return 1.0 - std::pow(1.0 - alpha, 1.0 / testCount);
}

}  // namespace ub::test
