// Error metrics between a rendered image and a reference, and a false-colour
// picture of the per-pixel error with a colour bar (unibeam compare, study).
//
// Per channel c over the N pixels (a = image, r = reference):
//   RMSE_c   = sqrt(1/N sum (a - r)^2)
//   relMSE_c = 1/N sum (a - r)^2 / (r^2 + eps),  eps = 1e-2   (Rousselle et al. 2011's
//              relative MSE, the usual measure of rendering studies: dark pixels do not
//              dominate, and eps keeps black reference pixels finite)
//   MAE_c    = 1/N sum |a - r|
// "overall" is the same over all 3N values. Sums are in double precision.
#pragma once

#include <string>

#include "core/image.h"

namespace ub {

struct ImageError {
    double rmse[3] = {0, 0, 0}, relMse[3] = {0, 0, 0}, mae[3] = {0, 0, 0};
    double rmseAll = 0, relMseAll = 0, maeAll = 0;
    /// Value of the named metric ("rmse", "relmse", "mae"), overall.
    double overall(const std::string& metric) const;
};

constexpr double kRelMseEpsilon = 1e-2;

/// Errors of image against reference (same size, else std::invalid_argument). Non-finite
/// image values count as an infinite error.
ImageError imageError(const Image& image, const Image& reference);

/// One line per channel and one overall, for logs and `unibeam compare`.
std::string describeImageError(const ImageError& e);

/// False-colour map of the per-pixel relative error |a - r| / (r + 0.01) (mean over the
/// channels), from black (0) through purple, red and yellow to white (>= maxError), with a
/// colour bar and its end values drawn below the image. maxError <= 0: the 99th percentile
/// of the error (at least 1e-6). Returns an image whose PNG (writePng, exposure 0) shows
/// exactly these colours; *usedMax receives the top of the scale.
Image falseColourError(const Image& image, const Image& reference, float maxError = 0.0f,
                       float* usedMax = nullptr);

}  // namespace ub
