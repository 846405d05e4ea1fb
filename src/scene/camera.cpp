#include "scene/camera.h"

#include <cmath>

#include "core/sampling.h"

namespace ub {

void Camera::setup(const Vec3& position, const Vec3& target, const Vec3& up, float fovYDeg,
                   int width, int height, float lensRadius, float focusDistance) {
    position_ = position;
    forward_ = normalize(target - position);
    right_ = normalize(cross(forward_, up));
    up_ = cross(right_, forward_);
    fovYDeg_ = fovYDeg;
    width_ = width;
    height_ = height;
    lensRadius_ = lensRadius;
    focusDistance_ = focusDistance;
    orthographic_ = false;
    orthoHalfWidth_ = orthoHalfHeight_ = 0.0f;
    float tanHalf = std::tan(0.5f * fovYDeg * kPi / 180.0f);
    imagePlaneDist_ = float(height) / (2.0f * tanHalf);
}

void Camera::setupOrthographic(const Vec3& nearCentre, const Vec3& forward, const Vec3& right,
                               const Vec3& up, float halfWidth, float halfHeight, int width,
                               int height) {
    position_ = nearCentre;
    forward_ = forward;
    right_ = right;
    up_ = up;
    width_ = width;
    height_ = height;
    lensRadius_ = 0.0f;
    focusDistance_ = 1.0f;
    orthographic_ = true;
    orthoHalfWidth_ = halfWidth;
    orthoHalfHeight_ = halfHeight;
    // Not used by an orthographic camera (orthoPixelArea() instead); kept finite.
    fovYDeg_ = 0.0f;
    imagePlaneDist_ = 1.0f;
}

Camera Camera::resized(int width, int height, bool keepHorizontalFov) const {
    if (orthographic_) {
        // Square pixels: keep the region's width (or height), the other follows the aspect.
        Camera c = *this;
        c.width_ = width;
        c.height_ = height;
        if (keepHorizontalFov)
            c.orthoHalfHeight_ = orthoHalfWidth_ * float(height) / float(width);
        else
            c.orthoHalfWidth_ = orthoHalfHeight_ * float(width) / float(height);
        return c;
    }
    float fovY = fovYDeg_;
    if (keepHorizontalFov && width_ > 0 && height_ > 0) {
        // tan(fovX / 2) = tan(fovY / 2) * width / height, kept across the two sizes.
        const float tanHalfX =
            std::tan(0.5f * fovYDeg_ * kPi / 180.0f) * float(width_) / float(height_);
        fovY = 2.0f * std::atan(tanHalfX * float(height) / float(width)) * 180.0f / kPi;
    }
    Camera c;
    c.setup(position_, position_ + forward_, up_, fovY, width, height, lensRadius_, focusDistance_);
    return c;
}

Ray Camera::generateRay(const Vec2& raster, const Vec2& lensU) const {
    if (orthographic_) {
        // Mitsuba's orthographic sensor: the raster position on the near plane, along forward.
        const float x = (2.0f * raster.x / float(width_) - 1.0f) * orthoHalfWidth_;
        const float y = (1.0f - 2.0f * raster.y / float(height_)) * orthoHalfHeight_;
        Ray ray;
        ray.org = position_ + right_ * x + up_ * y;
        ray.dir = forward_;
        return ray;
    }
    float px = raster.x - 0.5f * float(width_);
    float py = 0.5f * float(height_) - raster.y;
    Vec3 d = normalize(forward_ * imagePlaneDist_ + right_ * px + up_ * py);
    Ray ray;
    ray.org = position_;
    ray.dir = d;
    if (lensRadius_ > 0.0f) {
        // Thin lens: all rays through the pinhole direction meet at the focus plane.
        float ft = focusDistance_ / dot(d, forward_);
        Vec3 focus = position_ + d * ft;
        ray.org = lensPoint(lensU);
        ray.dir = normalize(focus - ray.org);
    }
    return ray;
}

Vec3 Camera::lensPoint(const Vec2& lensU) const {
    if (!(lensRadius_ > 0.0f)) return position_;
    const Vec2 l = sampleConcentricDisk(lensU);
    return position_ + right_ * (l.x * lensRadius_) + up_ * (l.y * lensRadius_);
}

bool Camera::worldToRaster(const Vec3& p, const Vec3& lens, Vec2* raster) const {
    if (!(lensRadius_ > 0.0f) || orthographic_) return worldToRaster(p, raster);
    const Vec3 w = p - lens;
    const float z = dot(w, forward_);
    if (z <= 0.0f) return false;
    // Where the line from the lens point to p meets the focus plane, seen through the eye.
    return worldToRaster(lens + w * (focusDistance_ / z), raster);
}

Vec3 Camera::orthoFilmPoint(const Vec3& p) const {
    return p - forward_ * dot(p - position_, forward_);
}

float Camera::orthoPixelArea() const {
    return (2.0f * orthoHalfWidth_ / float(width_)) * (2.0f * orthoHalfHeight_ / float(height_));
}

bool Camera::worldToRaster(const Vec3& p, Vec2* raster) const {
    Vec3 v = p - position_;
    float z = dot(v, forward_);
    if (z <= 0.0f) return false;
    float x, y;
    if (orthographic_) {
        // generateRay's map inverted: x_world = (2 x / W - 1) hw, y_world = (1 - 2 y / H) hh.
        x = (dot(v, right_) / orthoHalfWidth_ + 1.0f) * 0.5f * float(width_);
        y = (1.0f - dot(v, up_) / orthoHalfHeight_) * 0.5f * float(height_);
    } else {
        float s = imagePlaneDist_ / z;
        x = dot(v, right_) * s + 0.5f * float(width_);
        y = 0.5f * float(height_) - dot(v, up_) * s;
    }
    if (!(x >= 0.0f && x < float(width_) && y >= 0.0f && y < float(height_))) return false;
    *raster = Vec2(x, y);
    return true;
}

float Camera::pdfW(const Vec3& dir) const {
    float c = dot(dir, forward_);
    if (c <= 0.0f) return 0.0f;
    return imagePlaneDist_ * imagePlaneDist_ / (c * c * c);
}

}  // namespace ub
