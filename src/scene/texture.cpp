// Texture lookups (conventions: texture.h).
#include "scene/texture.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace ub {

namespace {

/// x - floor(x), in [0, 1).
float frac(float x) {
    float f = x - std::floor(x);
    return f < 1.0f ? f : 0.0f;  // x = -1e-9 rounds to 1.0f
}

int wrapIndex(int i, int n) {
    int r = i % n;
    return r < 0 ? r + n : r;
}

/// Bilinear lookup with repeat wrapping; u, v in [0, 1).
Rgb bilinear(const Image& img, float u, float v) {
    // Continuous pixel coordinates with centres at integer + 1/2.
    const float px = u * float(img.width) - 0.5f, py = v * float(img.height) - 0.5f;
    const float fx = std::floor(px), fy = std::floor(py);
    const float wx = px - fx, wy = py - fy;
    const int x0 = wrapIndex(int(fx), img.width), y0 = wrapIndex(int(fy), img.height);
    const int x1 = wrapIndex(int(fx) + 1, img.width), y1 = wrapIndex(int(fy) + 1, img.height);
    return (img.at(x0, y0) * (1.0f - wx) + img.at(x1, y0) * wx) * (1.0f - wy) +
           (img.at(x0, y1) * (1.0f - wx) + img.at(x1, y1) * wx) * wy;
}

int wrapIndexMode(int i, int n, TextureWrap wrap) {
    switch (wrap) {
        case TextureWrap::Repeat:
            return wrapIndex(i, n);
        case TextureWrap::Clamp:
            return i < 0 ? 0 : (i >= n ? n - 1 : i);
        case TextureWrap::Mirror: {
            const int m = wrapIndex(i, 2 * n);
            return m < n ? m : 2 * n - 1 - m;
        }
    }
    return 0;
}

/// The four texels of a bilinear lookup at continuous pixel coordinates (px, py) (texel
/// centres at half-integers) and the weights wx, wy of the +1 corners.
struct BilinearCell {
    int x0, y0, x1, y1;
    float wx, wy;
};
BilinearCell bilinearCell(const Image& img, float px, float py, TextureWrap wrap) {
    const float qx = px - 0.5f, qy = py - 0.5f;
    const float fx = std::floor(qx), fy = std::floor(qy);
    BilinearCell c;
    c.wx = qx - fx;
    c.wy = qy - fy;
    c.x0 = wrapIndexMode(int(fx), img.width, wrap);
    c.y0 = wrapIndexMode(int(fy), img.height, wrap);
    c.x1 = wrapIndexMode(int(fx) + 1, img.width, wrap);
    c.y1 = wrapIndexMode(int(fy) + 1, img.height, wrap);
    return c;
}

/// Lookup at unwrapped uv' for any filter and wrap mode. Coordinates are clamped to
/// +-2^24 texels first (beyond that float has no fraction and int would overflow).
Rgb lookup(const Image& img, float u, float v, TextureFilter filter, TextureWrap wrap) {
    const float kLimit = 16777216.0f;
    const float px = std::clamp(u * float(img.width), -kLimit, kLimit);
    const float py = std::clamp(v * float(img.height), -kLimit, kLimit);
    if (filter == TextureFilter::Nearest)
        return img.at(wrapIndexMode(int(std::floor(px)), img.width, wrap),
                      wrapIndexMode(int(std::floor(py)), img.height, wrap));
    const BilinearCell c = bilinearCell(img, px, py, wrap);
    return (img.at(c.x0, c.y0) * (1.0f - c.wx) + img.at(c.x1, c.y0) * c.wx) * (1.0f - c.wy) +
           (img.at(c.x0, c.y1) * (1.0f - c.wx) + img.at(c.x1, c.y1) * c.wx) * c.wy;
}

[[noreturn]] void throwTextureError(const Texture& t, const std::string& message) {
    Diagnostic d;
    d.where = "texture '" + t.name + "'";
    d.message = message;
    throw InputError(std::vector<Diagnostic>{d});
}

bool validColor(const Rgb& c) {
    return isFinite(c) && minComponent(c) >= 0.0f;
}

}  // namespace

UvTransform UvTransform::fromMatrix4(const Transform& t) {
    UvTransform r;
    for (int i = 0; i < 2; ++i) {
        r.m[i][0] = t.m[i][0];
        r.m[i][1] = t.m[i][1];
        r.m[i][2] = t.m[i][3];
    }
    return r;
}

Rgb Texture::eval(const Vec2& uvSurface) const {
    if (type == TextureType::Constant) return color0;
    if (type == TextureType::MeshAttribute) return Rgb(0.0f);  // needs the hit's attribute
    const Vec2 uv = toUv.apply(uvSurface);
    if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) return Rgb(0.0f);
    if (type == TextureType::Bitmap &&
        (filter != TextureFilter::Bilinear || wrap != TextureWrap::Repeat))
        return lookup(*image, uv.x, uv.y, filter, wrap);
    const float u = frac(uv.x), v = frac(uv.y);
    if (type == TextureType::Checkerboard) return (u > 0.5f) == (v > 0.5f) ? color0 : color1;
    return bilinear(*image, u, v);
}

Vec2 Texture::luminanceGradient(const Vec2& uvSurface) const {
    if (type != TextureType::Bitmap || filter != TextureFilter::Bilinear || !image)
        return Vec2(0.0f, 0.0f);
    const Vec2 uv = toUv.apply(uvSurface);
    if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) return Vec2(0.0f, 0.0f);
    const Image& img = *image;
    // The cell of lookup()'s bilinear interpolation: f(x, y) = sum of the four corner values
    // times (1 - wx or wx)(1 - wy or wy); its slopes in continuous pixel coordinates.
    const float kLimit = 16777216.0f;
    const BilinearCell c =
        bilinearCell(img, std::clamp(uv.x * float(img.width), -kLimit, kLimit),
                     std::clamp(uv.y * float(img.height), -kLimit, kLimit), wrap);
    const float f00 = luminance(img.at(c.x0, c.y0)), f10 = luminance(img.at(c.x1, c.y0));
    const float f01 = luminance(img.at(c.x0, c.y1)), f11 = luminance(img.at(c.x1, c.y1));
    const float dx = (1.0f - c.wy) * (f10 - f00) + c.wy * (f11 - f01);
    const float dy = (1.0f - c.wx) * (f01 - f00) + c.wx * (f11 - f10);
    // Chain rule through uv' = A uv + b (A^T times the slopes), then Mitsuba's scaling of
    // each component by the resolution (exact for a diagonal A).
    const float du = toUv.m[0][0] * dx + toUv.m[1][0] * dy;
    const float dv = toUv.m[0][1] * dx + toUv.m[1][1] * dy;
    return Vec2(float(img.width) * du, float(img.height) * dv);
}

Rgb Texture::mean() const {
    switch (type) {
        case TextureType::Constant:
            return color0;
        case TextureType::Checkerboard:
            return (color0 + color1) * 0.5f;
        case TextureType::Bitmap:
            return image ? image->mean() : Rgb(0.0f);
        case TextureType::MeshAttribute:
            return color0;  // the scale: the attribute's values belong to each mesh
    }
    return Rgb(0.0f);
}

void Texture::validate() const {
    for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 3; ++j)
            if (!std::isfinite(toUv.m[i][j])) throwTextureError(*this, "to_uv is not finite");
    switch (type) {
        case TextureType::Constant:
            if (!validColor(color0)) throwTextureError(*this, "colour must be finite and >= 0");
            break;
        case TextureType::Checkerboard:
            if (!validColor(color0) || !validColor(color1))
                throwTextureError(*this, "checkerboard colours must be finite and >= 0");
            break;
        case TextureType::Bitmap:
            if (!image || image->width <= 0 || image->height <= 0)
                throwTextureError(*this, "bitmap has no pixels");
            for (const Rgb& p : image->pixels)
                if (!validColor(p))
                    throwTextureError(*this, "bitmap has a negative or non-finite pixel");
            break;
        case TextureType::MeshAttribute:
            if (attributeName.empty()) throwTextureError(*this, "mesh attribute has no name");
            if (!validColor(color0)) throwTextureError(*this, "scale must be finite and >= 0");
            break;
        default:
            throwTextureError(*this, "unknown texture type");
    }
}

}  // namespace ub
