// Pinhole camera with optional thin lens. Raster space: x right in [0,W),
// y down in [0,H); pixel (i,j) covers [i,i+1)x[j,j+1).
//
// The image plane sits at distance imagePlaneDist() from the eye, chosen so
// that one pixel has unit area on it. Then the solid-angle pdf of a camera
// ray through a uniformly sampled pixel point is
//     p_cam,W = imagePlaneDist^2 / cos^3(theta)        (SmallVCM, TR Sec. 5.2)
// and light tracing divides by the "surface to image" factor built from it.
#pragma once

#include "core/vec.h"

namespace ub {

struct Ray {
    Vec3 org;
    Vec3 dir;  ///< unit length
    float tMin = 0.0f;
    float tMax = kInf;
};

class Camera {
  public:
    /// fovYDeg: vertical field of view in degrees, in (0, 180).
    /// lensRadius 0 means pinhole; focusDistance must be > 0 when lensRadius > 0.
    void setup(const Vec3& position, const Vec3& target, const Vec3& up, float fovYDeg, int width,
               int height, float lensRadius = 0.0f, float focusDistance = 1.0f);

    /// An orthographic camera (Mitsuba 3's `orthographic`): parallel rays along `forward`
    /// from the near plane, the point nearCentre + right x + up y for the raster position
    /// with x in [-halfWidth, halfWidth] (left to right) and y in [-halfHeight, halfHeight]
    /// (bottom to top), world units. forward, right and up must be orthonormal.
    void setupOrthographic(const Vec3& nearCentre, const Vec3& forward, const Vec3& right,
                           const Vec3& up, float halfWidth, float halfHeight, int width,
                           int height);

    /// The same camera with a width x height image: the vertical field of view is kept,
    /// or the horizontal one if keepHorizontalFov (orthographic: the width of the viewed
    /// region, or its height).
    Camera resized(int width, int height, bool keepHorizontalFov = false) const;

    /// Primary ray through raster position `raster` (e.g. pixel + jitter); lensU in [0,1)^2
    /// picks the lens point (ignored for a pinhole).
    Ray generateRay(const Vec2& raster, const Vec2& lensU = Vec2(0.5f, 0.5f)) const;
    /// Projects world point p to raster coordinates; false if behind the camera (for an
    /// orthographic camera: behind its near plane) or outside the image.
    bool worldToRaster(const Vec3& p, Vec2* raster) const;
    /// Thin lens: the raster position whose rays through lens point `lens` reach p (the line
    /// from lens to p crosses the focus plane where the pinhole ray of that raster position
    /// does, as generateRay builds them); a pinhole ignores `lens`.
    bool worldToRaster(const Vec3& p, const Vec3& lens, Vec2* raster) const;
    /// The lens point generateRay uses for lensU (the eye for a pinhole).
    Vec3 lensPoint(const Vec2& lensU) const;
    /// Orthographic: the point of the near plane whose ray (along forward) reaches p.
    Vec3 orthoFilmPoint(const Vec3& p) const;
    /// Solid-angle pdf of sampling direction `dir` (unit, world) from the eye, or for a thin
    /// lens from the lens point the ray starts at: the same d_img^2 / cos^3 (the raster maps to
    /// the focus plane, dA_focus = (f / d_img)^2 dA_raster, and d omega = dA_focus cos^3 / f^2).
    /// Not for an orthographic camera (its direction is a delta: orthoPixelArea()).
    float pdfW(const Vec3& dir) const;
    /// Orthographic: the near-plane area of one pixel (world units^2). The camera samples the
    /// ray's origin with the area pdf 1 / orthoPixelArea() per pixel and its direction as a
    /// delta, so the first vertex x_1 has the area pdf |cos x_1| / orthoPixelArea() with no
    /// 1/d^2 (the delta counted as 1 on both sides of every MIS ratio, as for a directional
    /// light [TR Sec. 5.1]).
    float orthoPixelArea() const;

    bool isPinhole() const { return lensRadius_ <= 0.0f && !orthographic_; }
    bool isOrthographic() const { return orthographic_; }
    /// Orthographic: half the width and height of the viewed region (world units).
    float orthoHalfWidth() const { return orthoHalfWidth_; }
    float orthoHalfHeight() const { return orthoHalfHeight_; }
    int width() const { return width_; }
    int height() const { return height_; }
    const Vec3& position() const { return position_; }
    const Vec3& forward() const { return forward_; }
    const Vec3& up() const { return up_; }
    const Vec3& right() const { return right_; }
    float fovYDeg() const { return fovYDeg_; }
    float lensRadius() const { return lensRadius_; }
    float focusDistance() const { return focusDistance_; }
    /// Distance of the unit-pixel-area image plane from the eye.
    float imagePlaneDist() const { return imagePlaneDist_; }

  private:
    Vec3 position_, forward_, up_, right_;
    float fovYDeg_ = 45.0f, imagePlaneDist_ = 1.0f;
    float lensRadius_ = 0.0f, focusDistance_ = 1.0f;
    int width_ = 0, height_ = 0;
    bool orthographic_ = false;
    float orthoHalfWidth_ = 0.0f, orthoHalfHeight_ = 0.0f;
};

}  // namespace ub
