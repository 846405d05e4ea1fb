// Grid media with trilinear density (GridFilter::kTrilinear in scene/medium.h),
// with exact transmittance.
//
// Dual space: q = worldToCell(p) - 1/2 puts voxel v's centre at the integer
// point v. Inside the dual cell [k, k+1)^3 the density is the trilinear
// interpolation of the eight voxels k + {0,1}^3, each index clamped to the
// domain [lo, hi] (clamp-to-edge); outside the box [lo - 1/2, hi + 1/2] (the
// domain's cells) it is 0. Along a ray q(t) = Q + D t every coordinate is
// linear in t, so inside one dual cell the density is a product of three
// linear factors summed over corners: a cubic polynomial in t. Its integral
// (the optical depth) is a quartic evaluated exactly, and free-flight
// sampling solves tau(t) = -ln(1 - u) inside the cell where the target is
// crossed by Newton's method safeguarded by bisection (tau is monotone, its
// derivative is the density). Everything else (pdfs, spectral MIS over the
// channels, throughput weights) follows the conventions of scene/medium.h.
#pragma once

#include "scene/medium.h"

namespace ub {

/// Interpolated density (before densityScale) of channel `channel` (0, 1, 2; grey media
/// have one) at world point p.
float trilinearDensityAt(const Medium& m, const Vec3& p, int channel = 0);
/// The interpolated density of every channel at p (grey media: channel 0 replicated).
Rgb trilinearDensityRgbAt(const Medium& m, const Vec3& p);
Rgb trilinearTransmittance(const Medium& m, const Vec3& origin, const Vec3& dir, float length);
MediumSegment trilinearSegment(const Medium& m, const Vec3& origin, const Vec3& dir, float length);
FreeFlightSample trilinearFreeFlight(const Medium& m, const Vec3& origin, const Vec3& dir,
                                     float tMax, float uChannel, float uDistance);

}  // namespace ub
