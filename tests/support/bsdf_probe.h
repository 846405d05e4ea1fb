// Test helpers shared by the BSDF tests (bsdf_test.cpp, bsdf_plastic_test.cpp): a frame in
// which chi-square tests see directions, and the directional albedo estimate
// rho(dirFix) = E[f cos / pdf] over Bsdf::sample (delta lobes included), per channel.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/rng.h"
#include "core/vec.h"
#include "scene/bsdf.h"

namespace ub::test {

/// Orthonormal frame with e1 = n and e2 towards dirFix's tangential part.
struct TestFrame {
    Vec3 e1, e2, e3;
    TestFrame(const Vec3& n, const Vec3& dirFix) : e1(n) {
        e2 = normalize(dirFix - dot(dirFix, n) * n);
        e3 = cross(e1, e2);
    }
    Vec3 toTest(const Vec3& d) const { return {dot(d, e1), dot(d, e2), dot(d, e3)}; }
    Vec3 toWorld(const Vec3& t) const { return e1 * t.x + e2 * t.y + e3 * t.z; }
};

struct Albedo {
    Rgb mean, stdErr;  ///< per channel, standard error of the mean over n samples
};

/// Monte Carlo directional albedo with n samples from Rng(seed, 17).
inline Albedo albedo(const Bsdf& bsdf, int n, uint64_t seed) {
    Rng rng(seed, 17);
    double s[3] = {0, 0, 0}, s2[3] = {0, 0, 0};
    for (int i = 0; i < n; ++i) {
        Vec3 dir;
        float pdfW, cosGen;
        Rgb f = bsdf.sample(rng.uniform3(), &dir, &pdfW, &cosGen, nullptr);
        if (pdfW == 0) continue;
        Rgb w = f * (cosGen / pdfW);
        for (int k = 0; k < 3; ++k) {
            s[k] += w[k];
            s2[k] += double(w[k]) * w[k];
        }
    }
    Albedo a;
    for (int k = 0; k < 3; ++k) {
        double m = s[k] / n, var = std::max(0.0, s2[k] / n - m * m);
        a.mean[k] = float(m);
        a.stdErr[k] = float(std::sqrt(var / n));
    }
    return a;
}

}  // namespace ub::test
