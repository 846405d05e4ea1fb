// Lat-long environment map on the unit square (u, v) = (phi / 2 pi, theta / pi):
// radiance lookup and importance sampling for two reconstruction filters. The
// direction <-> (u, v) mapping (Mitsuba 3's `envmap`: +y up, u = atan2(x, -z) / 2 pi)
// and the conversion to solid angle live in light.cpp; this file only sees (u, v).
//
// Nearest (SmallUPBP's EnvMap, unibeam's original map): pixel (x, y) covers
//   [x / W, (x + 1) / W) x [y / H, (y + 1) / H)  and the map is constant on it.
//   Sampling: piecewise-constant over pixels, weight luminance * sin(theta at the row
//   centre); pdfUv is that piecewise-constant density.
//
// Bilinear (Mitsuba 3's `envmap`, src/emitters/envmap.cpp): pixel values sit on the
// vertices of a grid, periodic in phi and "align-corners" in theta:
//   column x at u = (x + 1/2) / W  (wrapping across the seam u = 0 = 1),
//   row y at v = y / (H - 1)       (row 0 is the +y pole, row H-1 the -y pole),
// and the map is bilinear between them: with s = u W - 1/2 (mod W) and t = v (H - 1),
//   L(u, v) = sum over the 4 corners of cell (floor s, floor t) of the bilinear weights.
// Like Mitsuba, an image narrower than 2 or lower than 3 pixels is padded by repeating
// its last column / row (Bitmap::pad_to).
//   Sampling draws from the bilinear patch itself (as Mitsuba's Hierarchical2D warp):
// pdfUv(u, v) is proportional to the bilinear interpolation of vertex weights
//   g(x, y) = luminance(pixel(x, y) * scale) * sMax(y),
//   sMax(y) = max of sin(theta) over the rows y-1 .. y+1  (theta_y = pi y / (H - 1)).
// Mitsuba uses sin(theta_y) itself, which is 0 on the pole rows, so its pdf vanishes in
// the polar cells wherever row 1 (or H-2) is black even if the pole row is not.
// sMax(y) > 0 for every row, so here pdfUv > 0 exactly where the interpolated radiance
// is non-zero (the bilinear weights are non-negative and g(x, y) > 0 iff the pixel is
// non-black), which every estimator that samples the map relies on. Moreover sMax(y) >=
// sin(theta) for every theta in the two cells next to row y, so g >= L sin(theta)
// corner-wise: the sampling weight luminance(L) 2 pi^2 sin(theta) / pdfUv is bounded by
// 2 pi^2 times the mean cell weight, even near the poles.
//   Sampling is exact: a cell is picked with the piecewise-constant Distribution2D over
// cell weights (mean of its 4 corner g: the integral of the bilinear patch), then the
// point inside it by inverting the patch's CDF (its v-marginal is linear, and so is the
// u-conditional given v). pdfUv = P(cell) * (W (H - 1)) * bilinear(g) / mean corner g
// uses the very probabilities the sampler uses.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "core/image.h"
#include "core/sampling.h"
#include "core/vec.h"

namespace ub {

enum class EnvFilter : uint32_t {
    Nearest = 0,   ///< piecewise constant per pixel, pixel (floor(u W), floor(v H))
    Bilinear = 1,  ///< Mitsuba 3's envmap: bilinear, phi periodic, theta align-corners
};

/// Name used in scene files and messages: "nearest" or "bilinear".
const char* envFilterName(EnvFilter f);

class LatLongMap {
  public:
    LatLongMap() = default;
    /// img must be non-empty with finite, non-negative pixels (checked by Light::prepare);
    /// scale multiplies every pixel (the light's `radiance`).
    LatLongMap(std::shared_ptr<const Image> img, const Rgb& scale, EnvFilter filter);

    EnvFilter filter() const { return filter_; }
    /// Radiance * scale at (u, v) in [0, 1]^2 (u wraps, v clamps).
    Rgb eval(const Vec2& uv) const;
    /// Density on the unit square with which sample() produces (u, v).
    float pdfUv(const Vec2& uv) const;
    /// Samples (u, v) in [0, 1)^2 with density *pdfUv (0 if the map is black).
    Vec2 sample(const Vec2& rnd, float* pdfUv) const;
    /// The piecewise-constant distribution over pixels (nearest) or grid cells (bilinear).
    const Distribution2D& cellDistribution() const { return cells_; }
    /// Number of cells of cellDistribution(): W x H (nearest), W' x (H' - 1) (bilinear,
    /// W' = max(W, 2), H' = max(H, 3)).
    int cellsU() const { return cellsU_; }
    int cellsV() const { return cellsV_; }

  private:
    /// Pixel (x, y) of the (padded) grid, times scale_.
    Rgb texel(int x, int y) const;
    /// Bilinear: the cell containing (u, v) and the position (fx, fy) in [0, 1]^2 inside it.
    void locate(const Vec2& uv, int* x, int* y, float* fx, float* fy) const;
    float vertexWeight(int x, int y) const { return g_[size_t(y) * gridU_ + size_t(x)]; }
    /// Bilinear: pdfUv of the point (fx, fy) of cell (x, y).
    float cellPdf(int x, int y, float fx, float fy) const;

    std::shared_ptr<const Image> img_;
    Rgb scale_{1, 1, 1};
    EnvFilter filter_ = EnvFilter::Nearest;
    int gridU_ = 0, gridV_ = 0;    ///< bilinear: vertex grid W' x H'
    int cellsU_ = 0, cellsV_ = 0;  ///< cells of cells_
    std::vector<float> g_;         ///< bilinear: vertex weights g(x, y), row-major
    Distribution2D cells_;
};

/// Samples x in [0, 1) with density proportional to (1 - x) a + x b (a, b >= 0, not both
/// zero) by inverting its quadratic CDF: x = xi (a + b) / (a + sqrt((1 - xi) a^2 + xi b^2)).
float sampleLinear(float xi, float a, float b);
/// Density of sampleLinear at x: ((1 - x) a + x b) / ((a + b) / 2) (0 if a = b = 0).
float linearPdf(float x, float a, float b);

}  // namespace ub
