// Pixel reconstruction filters (box, tent, Gaussian) by filter importance
// sampling (Ernst et al. 2006, "Filter importance sampling").
//
// Pixel (i, j) of a W x H image has its centre at c = (i + 0.5, j + 0.5) in raster
// space. A filter is separable, f(x, y) = f1(x) f1(y), with f1 zero outside
// (-radius, radius). The filtered image is
//     I_ij = integral over the image of  fhat_ij(p) L(p) dp,
//     fhat_ij(p) = f(p - c_ij) / integral over the image of f(q - c_ij) dq,
// i.e. the filter normalised over the part of its footprint that lies inside the
// image. That is the expected value of Mitsuba 3's weighted average
// sum(f L) / sum(f) with its default `sample_border = false` (samples only inside
// the image), at the image borders too.
//
// Camera paths: sampleRaster() draws p from fhat_ij (per axis, by inverting the
// 1D cdf), so a path's estimate is added to its pixel with weight 1 and the image
// equals I_ij in expectation. Light tracing: a path reaching raster position p
// contributes fhat_ij(p) to every pixel whose footprint contains p (splatWeight()).
// The box filter (radius 1/2) samples exactly pixel + u, as without a filter.
//
// Border convention kPartitionOfUnity (Mitsuba 3's particle tracer, `ptracer`, which splats
// each particle with weights normalised to sum to 1 over the whole footprint, pixels outside
// the image included, and drops what falls outside): the filter of pixel ij is
//     w_ij(p) = f(p - c_ij) / S(p),   S(p) = sum over all pixel centres c (unclipped) of f(p - c),
// restricted to the image, so border pixels are not renormalised. Camera paths sample p from
// the normalised f over the whole footprint with weight integral(f) / S(p), 0 outside the
// image; splats use w_ij. For the box and for a tent of radius 1, S = integral(f) = 1.
//
// Profiles (Mitsuba 3's definitions, src/rfilters/*.cpp there):
//   box:      f1(x) = 1 for |x| < 1/2
//   tent:     f1(x) = max(0, 1 - |x| / r), default r = 1
//   gaussian: f1(x) = max(0, exp(-x^2 / (2 s^2)) - exp(-r^2 / (2 s^2))), r = 4 s,
//             default s = 0.5
#pragma once

#include <string>

#include "core/vec.h"

namespace ub {

enum class PixelFilterType : uint8_t { kBox, kTent, kGaussian };

/// How pixels whose footprint leaves the image are normalised (see above).
enum class PixelFilterBorder : uint8_t {
    kRenormalized,      ///< filter normalised over the image (Mitsuba's sampling integrators)
    kPartitionOfUnity,  ///< weights f / S over the whole footprint (Mitsuba's ptracer)
};

class PixelFilter {
  public:
    /// The box filter (unibeam's default).
    PixelFilter() = default;
    static PixelFilter box() { return PixelFilter(); }
    /// Tent of radius r (> 0) pixels.
    static PixelFilter tent(float radius);
    /// Gaussian of standard deviation stddev (> 0) pixels, cut off at 4 stddev.
    static PixelFilter gaussian(float stddev);

    /// The same filter with another border convention.
    PixelFilter withBorder(PixelFilterBorder border) const {
        PixelFilter f = *this;
        f.border_ = border;
        return f;
    }
    PixelFilterBorder border() const { return border_; }
    PixelFilterType type() const { return type_; }
    bool isBox() const { return type_ == PixelFilterType::kBox; }
    float radius() const { return float(radius_); }
    float stddev() const { return float(stddev_); }
    /// "box", "tent (radius 1)", "gaussian (stddev 0.5, radius 2)".
    std::string describe() const;

    /// The 1D profile f1(x), x in pixels from the pixel centre (not normalised).
    double eval1(double x) const;
    /// Its cumulative integral from -radius, normalised: cdf1(-radius) = 0, cdf1(radius) = 1.
    double cdf1(double x) const;

    /// A raster position for pixel (x, y) of a width x height image, u in [0,1)^2, and the
    /// weight of a camera path through it (*weight, may be null). kRenormalized: drawn from
    /// fhat_xy, always inside the image, weight 1 (box: exactly (x + u.x, y + u.y)).
    /// kPartitionOfUnity: drawn from the normalised filter over the whole footprint, weight
    /// integral(f) / S(p), 0 when p is outside the image (then the path adds nothing).
    Vec2 sampleRaster(int x, int y, const Vec2& u, int width, int height,
                      float* weight = nullptr) const;
    /// The filter of pixel (x, y) at raster position p (per unit raster area): fhat_xy(p), or
    /// w_xy(p) with kPartitionOfUnity; 0 outside the footprint or outside the image. The
    /// expected camera-path estimate of the pixel is its integral against the image.
    float splatWeight(int x, int y, const Vec2& p, int width, int height) const;
    /// The pixels whose footprint may contain raster position p, clipped to the image:
    /// [*x0, *x1] x [*y0, *y1] (empty when *x0 > *x1 or *y0 > *y1).
    void footprint(const Vec2& p, int width, int height, int* x0, int* x1, int* y0, int* y1) const;

  private:
    /// Offset in [lo, hi] (within (-r, r)) drawn from f1 restricted to [lo, hi].
    double sample1(double lo, double hi, double u) const;
    /// The filter along one axis at raster coordinate t for pixel i.
    double weight1(int i, double t, int size) const;
    /// S1(t) = sum over all integers k of f1(t - k - 1/2).
    double coverage1(double t) const;

    PixelFilterType type_ = PixelFilterType::kBox;
    PixelFilterBorder border_ = PixelFilterBorder::kRenormalized;
    double radius_ = 0.5, stddev_ = 0.0;
    double norm_ = 1.0;  ///< integral of f1 over (-radius, radius)
};

}  // namespace ub
