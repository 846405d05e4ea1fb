// Projected-texture emitters: Mitsuba 3's `spot` with a `texture` and its `projector`
// (src/emitters/spot.cpp and projector.cpp of Mitsuba 3.9.1, read for the conventions; the
// code here is unibeam's). Both are delta-position lights whose intensity depends on the
// direction through a texture lookup at uv(direction), in the light's frame (frameX, frameY,
// direction) = Mitsuba's to_world axes (x, y, z), with l = the unit direction in that frame:
//
//   spot:      uv = (1/2 + l.x / (2 l.z tan c), 1/2 + l.y / (2 l.z tan c)), c = the cutoff;
//              I(l) = intensity * falloff(l.z) * T(uv). emit() keeps the untextured
//              spot's uniform cone sampling (as Mitsuba does): pdfW = 1 / (2 pi (1 - cos c)).
//   projector: the pinhole camera of Mitsuba's `perspective` sensor run backwards. The image
//              plane z = 1 spans x in [-t, t], y in [-t / a, t / a] (t = tan(fov_x / 2),
//              a = width / height of the texture), area A = 4 t^2 / a, and
//              uv = (1/2 - l.x / (2 t l.z), 1/2 - a l.y / (2 t l.z)), valid for l.z > 0 and
//              uv in [0, 1]^2. The irradiance on the plane z = 1 is pi * scale * E(uv)
//              (Mitsuba's normalisation), so with dA = dw / cos^3 (plane at distance 1):
//                I(l) = pi scale E(uv) / cos^3,  cos = l.z.
//              emit() samples uv with the piecewise-constant density pdfUv of
//              projDistribution, so pdfW = pdfUv / (A cos^3), and the emitted weight
//              I / pdfW = pi scale A E(uv) / pdfUv (Mitsuba's sample_ray weight).
//
// The sampling density: for a bitmap with an identity to_uv, one cell per pixel, weighted by
// the pixel's luminance (nearest filter: exactly proportional to E), or for the bilinear
// filter by the mean of the pixel's luminance and the largest luminance of its 3 x 3
// neighbourhood (under every wrap mode): a bilinear lookup inside the pixel mixes only those
// pixels, so the density is positive wherever E is. Any other texture: uniform over
// [0, 1]^2. Either way the estimate is unbiased; the density only moves the noise.
#include "scene/light_projected.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "scene/light.h"

namespace ub {

namespace {

[[noreturn]] void projectedError(const Light& l, const std::string& message) {
    Diagnostic d;
    d.where = "light '" + l.name + "'";
    d.message = message;
    throw InputError(std::vector<Diagnostic>{d});
}

Vec3 toLocal(const Light& l, const Vec3& d) {
    return {dot(d, l.frameX), dot(d, l.frameY), dot(d, l.direction)};
}

float luminanceOf(const Rgb& c) {
    return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
}

bool isIdentity(const UvTransform& t) {
    return t.m[0][0] == 1 && t.m[0][1] == 0 && t.m[0][2] == 0 && t.m[1][0] == 0 && t.m[1][1] == 1 &&
           t.m[1][2] == 0;
}

/// Cell weights of the projector's sampling density (see the banner).
std::shared_ptr<const Distribution2D> projectorDistribution(const Texture& tex) {
    if (tex.type != TextureType::Bitmap || !tex.image || !isIdentity(tex.toUv))
        return std::make_shared<Distribution2D>(std::vector<float>{1.0f}, 1, 1);
    const Image& img = *tex.image;
    const int w = img.width, h = img.height;
    std::vector<float> lum(size_t(w) * size_t(h));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) lum[size_t(y) * w + x] = luminanceOf(img.at(x, y));
    std::vector<float> f(lum.size());
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const float own = lum[size_t(y) * w + x];
            if (tex.filter == TextureFilter::Nearest) {
                f[size_t(y) * w + x] = own;
                continue;
            }
            float mx = own;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    // Neighbours as repeat wraps them and as clamp (and mirror) keeps them.
                    const int xs[2] = {((x + dx) % w + w) % w, std::clamp(x + dx, 0, w - 1)};
                    const int ys[2] = {((y + dy) % h + h) % h, std::clamp(y + dy, 0, h - 1)};
                    for (int i = 0; i < 2; ++i)
                        for (int j = 0; j < 2; ++j)
                            mx = std::max(mx, lum[size_t(ys[j]) * w + size_t(xs[i])]);
                }
            f[size_t(y) * w + x] = 0.5f * (own + mx);
        }
    return std::make_shared<Distribution2D>(f, w, h);
}

/// Projector: uv of the local unit direction l; false outside the frustum.
bool projectorUv(const Light& l, const Vec3& local, Vec2* uv) {
    if (!(local.z > 0.0f)) return false;
    const float k = 0.5f / (l.projTan * local.z);
    *uv = Vec2(0.5f - k * local.x, 0.5f - k * l.projAspect * local.y);
    return uv->x >= 0.0f && uv->x <= 1.0f && uv->y >= 0.0f && uv->y <= 1.0f;
}

/// Projector: area of the image plane z = 1.
float projectorPlaneArea(const Light& l) {
    return 4.0f * l.projTan * l.projTan / l.projAspect;
}

}  // namespace

void prepareProjected(Light& l) {
    if (l.type == LightType::Projector) {
        if (!l.projTexture) projectedError(l, "projector light has no irradiance texture");
        if (!isFinite(l.intensity) || minComponent(l.intensity) < 0.0f)
            projectedError(l, "projector scale must be finite and non-negative");
        if (!(l.projFovXDeg > 0.0f && l.projFovXDeg < 180.0f))
            projectedError(l, "projector field of view must be in (0, 180) degrees (got " +
                                  std::to_string(l.projFovXDeg) + ")");
        if (!(l.projAspect > 0.0f) || !std::isfinite(l.projAspect))
            projectedError(l, "projector aspect ratio must be positive and finite");
        if (!isFinite(l.position)) projectedError(l, "projector position is not finite");
        l.projTan = std::tan(0.5f * l.projFovXDeg * (kPi / 180.0f));
    } else if (l.projTexture) {  // a textured spot (prepare() checked the rest)
        if (!(l.cutoffAngleDeg < 90.0f))
            projectedError(l,
                           "a spot light with a texture needs cutoff_angle < 90 degrees "
                           "(got " +
                               std::to_string(l.cutoffAngleDeg) + ")");
        l.projTan = std::tan(l.cutoffAngleDeg * (kPi / 180.0f));
    }
    if (!l.projTexture) return;
    l.projTexture->validate();
    const float len = length(l.direction);
    if (!std::isfinite(len) || !(len > 0.0f))
        projectedError(l, "light direction must be finite and non-zero");
    l.direction = l.direction / len;
    if (lengthSqr(l.frameX) == 0.0f && lengthSqr(l.frameY) == 0.0f) {
        const Frame f(l.direction);
        l.frameX = f.s;
        l.frameY = f.t;
    } else {
        const float lx = length(l.frameX), ly = length(l.frameY);
        if (!(lx > 0.0f) || !(ly > 0.0f) || !std::isfinite(lx) || !std::isfinite(ly))
            projectedError(l, "light frame axes must be finite and non-zero");
        l.frameX = l.frameX / lx;
        l.frameY = l.frameY / ly;
        const float eps = 1e-3f;
        if (std::fabs(dot(l.frameX, l.frameY)) > eps ||
            std::fabs(dot(l.frameX, l.direction)) > eps ||
            std::fabs(dot(l.frameY, l.direction)) > eps)
            projectedError(l,
                           "light frame must be orthogonal (to_world a rotation and "
                           "translation)");
    }
    if (l.type == LightType::Projector) l.projDistribution = projectorDistribution(*l.projTexture);
}

Rgb Light::projectedIntensity(const Vec3& dirOut, float* projectorPdfW) const {
    if (projectorPdfW) *projectorPdfW = 0.0f;
    if (type == LightType::Spot) {
        const float falloff = spotFalloff(dot(direction, dirOut));
        if (!(falloff > 0.0f)) return Rgb(0.0f);
        if (!projTexture) return intensity * falloff;
        const Vec3 local = toLocal(*this, dirOut);
        const float k = 0.5f / (projTan * local.z);
        const Vec2 uv(0.5f + k * local.x, 0.5f + k * local.y);
        return intensity * falloff * projTexture->eval(uv);
    }
    if (type != LightType::Projector) return Rgb(0.0f);
    const Vec3 local = toLocal(*this, dirOut);
    Vec2 uv;
    if (!projectorUv(*this, local, &uv)) return Rgb(0.0f);
    const float cos3 = local.z * local.z * local.z;
    if (projectorPdfW)
        *projectorPdfW = projDistribution->pdf(uv) / (projectorPlaneArea(*this) * cos3);
    return intensity * projTexture->eval(uv) * (kPi / cos3);
}

Vec3 sampleProjectorDirection(const Light& l, const Vec2& rnd) {
    float pdfUv;
    const Vec2 uv = l.projDistribution->sampleContinuous(rnd, &pdfUv);
    const float x = (0.5f - uv.x) * 2.0f * l.projTan;
    const float y = (0.5f - uv.y) * 2.0f * l.projTan / l.projAspect;
    const Vec3 local = normalize(Vec3(x, y, 1.0f));
    return normalize(local.x * l.frameX + local.y * l.frameY + local.z * l.direction);
}

}  // namespace ub
