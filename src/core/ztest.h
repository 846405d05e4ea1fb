// Per-pixel z-test of a rendered image against a reference, as Mitsuba 3's
// render tests do (src/render/tests/test_renders.py), with the image's own
// variance estimate.
//
// For every pixel p and channel c:
//   z = (mean - ref) / sqrt(var_img / n + var_ref / n_ref)
// where `mean` is the average of n independent iterations (one sample per
// pixel each), var_img the per-sample (per-iteration) variance of those
// iterations, ref the reference mean and var_ref its per-sample variance
// (Mitsuba's *_ref_rgb_var.exr: second moment minus squared mean). n_ref = 0
// treats the reference mean as exact (Mitsuba's test). The per-sample
// variances are floored at `varianceFloor` (Mitsuba uses 1e-4) so a pixel
// whose estimate is deterministic cannot fail on round-off.
// Two-sided p-value: p = erfc(|z| / sqrt(2)). For n of a few hundred the
// Student-t correction of an estimated variance is negligible (< 1% on the
// critical value), so the normal distribution is used.
//
// Heavy tails: the per-pixel sample variance of a heavy-tailed estimator (rare
// bright paths) is skewed: for most seeds it falls below the true variance and
// the few pixels where the rare paths did not occur test too small and too
// certain, so a correct image fails far more often than alpha says (measured on
// test_homo_spectral_sigmat: see tests/mitsuba_reference_test.cpp). With
// varianceRadius = r > 0 the image variance of a pixel is the larger of its own
// and the mean of the (floored) per-pixel variances over its (2r+1)^2
// neighbourhood (clipped at the borders). The neighbourhood mean is an estimate
// from ~(2r+1)^2 n samples where the variance is smooth in image space; the
// pixel's own value keeps a high-variance pixel next to low-variance ones (the
// edge of a light seen directly) from being tested with its neighbours' smaller
// variance. Taking the larger makes the test conservative, never more likely to
// reject. It is still the image's own variance, not the reference's, and the
// mean itself is still tested per pixel.
//
// Multiple comparisons: the family of m = pixels x 3 channel tests is held at
// level alpha with Sidak's correction, i.e. each test is rejected when
//   p < 1 - (1 - alpha)^(1/m),
// which bounds the probability of any false rejection by alpha for
// independent tests (Sidak 1967). The image fails if any test is rejected.
#pragma once

#include <string>
#include <vector>

#include "core/image.h"

namespace ub {

struct ZTestOptions {
    double alpha = 0.01;          ///< family-wise significance level, in (0, 1)
    double samples = 1;           ///< n: iterations averaged into the image (>= 2 with var)
    double referenceSamples = 0;  ///< n_ref; 0 = exact reference
    double varianceFloor = 1e-4;  ///< lower bound on per-sample variances
    int varianceRadius = 0;       ///< max(own, mean over (2r+1)^2 pixels); 0 = per pixel
};

struct ZTestFailure {
    int x = 0, y = 0, channel = 0;
    double value = 0, reference = 0, z = 0, pValue = 0;
};

struct ZTestResult {
    bool passed = false;
    size_t tests = 0;         ///< m = pixels x channels
    double perTestLevel = 0;  ///< Sidak-corrected level 1 - (1 - alpha)^(1/m)
    double minPValue = 1;
    int minX = 0, minY = 0, minChannel = 0;
    double maxAbsZ = 0;
    std::vector<ZTestFailure> failures;  ///< every rejected (pixel, channel), worst first
    size_t failingPixels = 0;            ///< pixels with at least one rejected channel
};

/// Two-sided normal p-value of a z statistic.
double zTestPValue(double z);

/// Runs the test. imageVariance may be null: the reference variance then stands for the
/// image's per-sample variance too (Mitsuba's assumption). Throws InputError (file "")
/// when sizes differ, a value is non-finite, or options are out of range. Negative
/// variances (round-off of m2 - m1^2) are raised to the floor like tiny ones.
ZTestResult zTest(const Image& image, const Image* imageVariance, const Image& reference,
                  const Image& referenceVariance, const ZTestOptions& options);

/// One-paragraph human-readable summary (pass/fail, min p-value, level, failing pixels).
std::string describeZTest(const ZTestResult& r, const ZTestOptions& options);

}  // namespace ub
