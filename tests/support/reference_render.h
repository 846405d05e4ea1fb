// Render a scene progressively and compare it with an external reference mean and
// per-sample variance image (core/ztest.h): the per-pixel z-test, and a z-test of the
// image mean per channel, which finds small biases that cover the whole image (a +1%
// light in a Mitsuba scene passed the per-pixel test and failed this one by z = 7).
//
// Image-mean test: pixels are independent (each has its own random streams), so
//   z_c = sum_p (img - ref) / sqrt(sum_p (var_img / n + var_ref / n_ref))
// is a standard normal deviate for an unbiased render (CLT over pixels x iterations).
#pragma once

#include <atomic>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "core/image.h"
#include "core/ztest.h"
#include "render/integrator.h"
#include "render/progressive.h"
#include "scene/scene.h"

namespace ub::test {

struct ReferenceCheck {
    ZTestResult perPixel;
    ZTestOptions options;
    double meanZ[3] = {0, 0, 0};  ///< image-mean z per channel
    double meanRelDiff[3] = {0, 0, 0};
};

/// Renders `scene` with `algorithm` for `iterations` (seed 1, the scene's path length) and
/// tests it against ref/refVar (per-sample variance of a reference of refSamples samples).
inline ReferenceCheck renderAgainstReference(const Scene& scene, const std::string& algorithm,
                                             int iterations, const Image& ref, const Image& refVar,
                                             double refSamples) {
    RenderOptions o;
    o.algorithm = algorithm;
    o.maxPathLength = scene.settings.maxPathLength;
    o.seed = 1;
    std::unique_ptr<Integrator> integrator = makeIntegrator(scene, o);
    ProgressiveOptions po;
    po.iterations = iterations;
    po.computeVariance = true;
    std::atomic<bool> stop{false};
    po.stop = &stop;
    ProgressiveResult r =
        renderProgressive(*integrator, scene.camera.width(), scene.camera.height(), po);

    ReferenceCheck check;
    check.options.alpha = 0.01;
    check.options.samples = r.iterations;
    check.options.referenceSamples = refSamples;
    check.options.varianceRadius = 1;  // heavy tails: see core/ztest.h
    check.perPixel = zTest(r.image, &r.variance, ref, refVar, check.options);
    for (int c = 0; c < 3; ++c) {
        double diff = 0, var = 0, sumRef = 0;
        for (int y = 0; y < ref.height; ++y)
            for (int x = 0; x < ref.width; ++x) {
                diff += double(r.image.at(x, y)[c]) - ref.at(x, y)[c];
                var += std::max(0.0, double(r.variance.at(x, y)[c])) / r.iterations +
                       std::max(0.0, double(refVar.at(x, y)[c])) / refSamples;
                sumRef += ref.at(x, y)[c];
            }
        check.meanZ[c] = var > 0 ? diff / std::sqrt(var) : 0.0;
        check.meanRelDiff[c] = sumRef > 0 ? diff / sumRef : 0.0;
    }
    return check;
}

inline void printReferenceCheck(const std::string& label, const ReferenceCheck& c) {
    std::printf(
        "[ reference] %s: %s\n  image mean z (R, G, B) %.2f %.2f %.2f, relative "
        "difference %.4f %.4f %.4f\n",
        label.c_str(), describeZTest(c.perPixel, c.options).c_str(), c.meanZ[0], c.meanZ[1],
        c.meanZ[2], c.meanRelDiff[0], c.meanRelDiff[1], c.meanRelDiff[2]);
}

}  // namespace ub::test
