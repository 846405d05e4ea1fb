// Light sampling and evaluation: SmallVCM's Illuminate / Emit / GetRadiance
// (Georgiev 2012, "Implementing Vertex Connection and Merging", Sec. 5) for
// area, point, spot, projector, directional, constant and image-based environment lights.
//
// Invariant the bidirectional estimators rely on: for every light and every
// (point, direction) that illuminate() or emit() can produce, radianceAlong()
// returns the same radiance, directPdfA (solid angle for environments) and
// emissionPdfW. All three paths therefore share the helpers below
// (areaPdfs(), envEval()) instead of recomputing the pdfs in three places.
#include "scene/light.h"

#include <cmath>

#include "core/error.h"
#include "kernels/shared/ub_light_pdf.h"
#include "scene/light_projected.h"

namespace ub {

namespace {

/// Below this cosine a light point is treated as seen edge-on (no contribution),
/// as SmallVCM's EPS_COSINE; the same threshold in illuminate() and radianceAlong().
constexpr float kEpsCosine = 1e-6f;

[[noreturn]] void throwLightError(const Light& l, const std::string& message) {
    Diagnostic d;
    d.where = "light '" + l.name + "'";
    d.message = message;
    throw InputError(std::vector<Diagnostic>{d});
}

bool isFiniteNonNegative(const Rgb& c) {
    return isFinite(c) && minComponent(c) >= 0.0f;
}

// ---- area lights -------------------------------------------------------------

/// Picks a point uniformly by area over all triangles and the sphere (the sphere,
/// if any, is the last bin of triangleDistribution). Returns the point, its
/// front-side unit normal and its uv (for a radiance texture; computed only with one).
/// rnd is reused for the discrete choice (rescaled).
Vec3 sampleAreaPoint(const Light& l, const Vec2& rnd, Vec3* normal, Vec2* uv) {
    int bin = 0;
    float binPdf;
    float x = l.triangleDistribution.sampleContinuous(rnd.x, &binPdf, &bin);
    int count = l.triangleDistribution.count();
    // Position of rnd.x inside its bin, uniform in [0,1) again.
    float u0 = std::min(std::max(x * float(count) - float(bin), 0.0f), 0.99999994f);
    size_t triCount = l.triangles.size() / 3;
    if (size_t(bin) >= triCount) {  // the sphere
        Vec3 n = sampleUniformSphere(Vec2(u0, rnd.y));
        *normal = n;
        if (l.radianceTexture) *uv = sphereUv(n);
        return l.position + l.sphereRadius * n;
    }
    const size_t t = 3 * size_t(bin);
    const Vec3& p0 = l.triangles[t];
    Vec3 e1 = l.triangles[t + 1] - p0;
    Vec3 e2 = l.triangles[t + 2] - p0;
    Vec2 b = sampleUniformTriangle(Vec2(u0, rnd.y));
    *normal = normalize(cross(e1, e2));
    if (l.radianceTexture) {
        // Scene::intersect's uv at the same barycentrics (b.x on p1, b.y on p2).
        if (l.triangleUvs.empty()) {
            *uv = b;
        } else {
            const Vec2 &t0 = l.triangleUvs[t], &t1 = l.triangleUvs[t + 1],
                       &t2 = l.triangleUvs[t + 2];
            const float b0 = 1.0f - b.x - b.y;
            *uv = Vec2(b0 * t0.x + b.x * t1.x + b.y * t2.x, b0 * t0.y + b.x * t1.y + b.y * t2.y);
        }
    }
    return p0 + b.x * e1 + b.y * e2;
}

/// Probability of each emitting side: 1/2 for two-sided emitters (emit() picks a
/// side with a coin flip), 1 otherwise.
float sideProbability(const Light& l) {
    return l.twoSided ? 0.5f : 1.0f;
}

/// Emission cosine for a point with front normal n seen along dirOut (leaving the
/// light). Negative for the back of one-sided lights.
float emissionCosine(const Light& l, const Vec3& n, const Vec3& dirOut) {
    float c = dot(n, dirOut);
    return l.twoSided ? std::fabs(c) : c;
}

/// Pdfs of an area-light point emitting with cosine cosOut (> 0):
/// directPdfA = 1/A (uniform area sampling) and
/// emissionPdfW = 1/A * P(side) * cos/pi (cosine-weighted emission, tech. rep. Sec. 5.1).
void areaPdfs(const Light& l, float cosOut, float* directPdfA, float* emissionPdfW) {
    float invArea = 1.0f / l.totalArea;
    if (directPdfA) *directPdfA = invArea;
    if (emissionPdfW)
        *emissionPdfW = invArea * sideProbability(l) * ub_cos_hemisphere_pdf_w(cosOut);
}

// ---- environment lights --------------------------------------------------------

/// Lat-long direction in the map's frame (Mitsuba 3 `envmap` convention, +y up):
/// d = (sin(phi) sin(theta), cos(theta), -cos(phi) sin(theta)), phi = 2 pi u, theta = pi v.
Vec3 latLongDirection(const Vec2& uv) {
    float phi = 2.0f * kPi * uv.x, theta = kPi * uv.y;
    float sinTheta = std::sin(theta);
    return {std::sin(phi) * sinTheta, std::cos(theta), -std::cos(phi) * sinTheta};
}

/// Inverse of latLongDirection for a unit direction in the map's frame.
Vec2 latLongUv(const Vec3& d, float* sinTheta) {
    float cosTheta = std::min(std::max(d.y, -1.0f), 1.0f);
    *sinTheta = std::sqrt(std::max(0.0f, 1.0f - cosTheta * cosTheta));
    float u = std::atan2(d.x, -d.z) * (0.5f * kInvPi);
    if (u < 0.0f) u += 1.0f;
    float v = std::acos(cosTheta) * kInvPi;
    return {std::min(u, 0.99999994f), std::min(v, 0.99999994f)};
}

/// Radiance towards the environment direction dirToLight (world, unit) and the
/// solid-angle pdf with which illuminate() samples it. Constant environments sample
/// the uniform sphere; maps sample (u, v) with LatLongMap (env_map.h), and
/// pdfW = pdfUv / (2 pi^2 sin theta) (ub_latlong_pdf_w).
Rgb envEval(const Light& l, const Vec3& dirToLight, float* pdfW) {
    if (l.type == LightType::ConstantEnv) {
        *pdfW = uniformSpherePdfW();
        return l.radiance;
    }
    Vec3 local = normalize(l.worldToEnv.vector(dirToLight));
    float sinTheta;
    Vec2 uv = latLongUv(local, &sinTheta);
    *pdfW = ub_latlong_pdf_w(l.envLatLong->pdfUv(uv), sinTheta);
    return l.envLatLong->eval(uv);
}

/// Samples a direction towards the environment (world, unit).
Vec3 envSampleDirection(const Light& l, const Vec2& rnd) {
    if (l.type == LightType::ConstantEnv) return sampleUniformSphere(rnd);
    float pdfUv;
    Vec2 uv = l.envLatLong->sample(rnd, &pdfUv);
    return normalize(l.envToWorld.vector(latLongDirection(uv)));
}

/// Point on the disk of the scene sphere perpendicular to axis, centred at
/// center + radius * axis (tech. rep. Sec. 5.1); its area pdf is ub_disk_pdf_a.
Vec3 sceneDiskPoint(const SceneSphere& sphere, const Vec3& axis, const Vec2& rnd) {
    Vec2 xy = sampleConcentricDisk(rnd);
    Frame f(axis);
    return sphere.center + sphere.radius * (axis + f.s * xy.x + f.t * xy.y);
}

bool isRotation(const Transform& t) {
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            float d = 0;
            for (int k = 0; k < 3; ++k) d += t.m[k][i] * t.m[k][j];
            if (!std::isfinite(d) || std::fabs(d - (i == j ? 1.0f : 0.0f)) > 1e-3f) return false;
        }
    return true;
}

}  // namespace

// ---- prepare -------------------------------------------------------------------

void Light::prepare() {
    switch (type) {
        case LightType::Area: {
            if (!isFiniteNonNegative(radiance))
                throwLightError(*this, "area light radiance must be finite and non-negative");
            if (triangles.size() % 3 != 0)
                throwLightError(*this,
                                "area light triangle list must hold 3 vertices per triangle");
            if (triangles.empty() && !isSphere)
                throwLightError(*this, "area light has no geometry (no triangles and no sphere)");
            if (!triangleUvs.empty() && triangleUvs.size() != triangles.size())
                throwLightError(*this, "area light has " + std::to_string(triangleUvs.size()) +
                                           " vertex uvs for " + std::to_string(triangles.size()) +
                                           " triangle vertices");
            if (radianceTexture) {
                if (radianceTexture->type == TextureType::MeshAttribute)
                    throwLightError(*this,
                                    "a mesh_attribute cannot be an area light's radiance "
                                    "(not supported)");
                radianceTexture->validate();
            }
            std::vector<float> areas;
            areas.reserve(triangles.size() / 3 + 1);
            double total = 0;
            for (size_t i = 0; i < triangles.size(); i += 3) {
                const Vec3 &p0 = triangles[i], &p1 = triangles[i + 1], &p2 = triangles[i + 2];
                if (!ub::isFinite(p0) || !ub::isFinite(p1) || !ub::isFinite(p2))
                    throwLightError(*this, "area light triangle " + std::to_string(i / 3) +
                                               " has a non-finite vertex");
                float a = 0.5f * length(cross(p1 - p0, p2 - p0));
                areas.push_back(a);
                total += a;
            }
            if (isSphere) {
                if (!ub::isFinite(position) || !std::isfinite(sphereRadius))
                    throwLightError(*this, "area light sphere has a non-finite centre or radius");
                if (sphereRadius <= 0)
                    throwLightError(*this, "area light sphere radius must be > 0 (got " +
                                               std::to_string(sphereRadius) + ")");
                float a = 4.0f * kPi * sphereRadius * sphereRadius;
                areas.push_back(a);
                total += a;
            }
            if (!(total > 0) || !std::isfinite(total))
                throwLightError(*this, "area light has zero total area (degenerate triangles)");
            totalArea = float(total);
            triangleDistribution = Distribution1D(areas);
            break;
        }
        case LightType::Point:
            if (!isFiniteNonNegative(intensity))
                throwLightError(*this, "point light intensity must be finite and non-negative");
            if (!ub::isFinite(position))
                throwLightError(*this, "point light position is not finite");
            break;
        case LightType::Spot: {
            if (!isFiniteNonNegative(intensity))
                throwLightError(*this, "spot light intensity must be finite and non-negative");
            if (!ub::isFinite(position))
                throwLightError(*this, "spot light position is not finite");
            float len = length(direction);
            if (!std::isfinite(len) || !(len > 0))
                throwLightError(*this, "spot light direction must be finite and non-zero");
            direction = direction / len;
            if (!(cutoffAngleDeg > 0.0f && cutoffAngleDeg <= 180.0f))
                throwLightError(*this, "spot light cutoff_angle must be in (0, 180] degrees (got " +
                                           std::to_string(cutoffAngleDeg) + ")");
            if (!(beamWidthDeg >= 0.0f && beamWidthDeg <= cutoffAngleDeg))
                throwLightError(*this, "spot light beam_width must be in [0, cutoff_angle] (got " +
                                           std::to_string(beamWidthDeg) + ")");
            cutoffRad = cutoffAngleDeg * (kPi / 180.0f);
            const float beamRad = beamWidthDeg * (kPi / 180.0f);
            cosCutoff = std::cos(cutoffRad);
            cosBeamWidth = std::cos(beamRad);
            invTransitionRad = cutoffRad > beamRad ? 1.0f / (cutoffRad - beamRad) : 0.0f;
            prepareProjected(*this);  // the optional texture
            break;
        }
        case LightType::Projector:
            prepareProjected(*this);
            break;
        case LightType::Directional: {
            if (!isFiniteNonNegative(radiance))
                throwLightError(*this,
                                "directional light irradiance must be finite and non-negative");
            float len = length(direction);
            if (!std::isfinite(len) || !(len > 0))
                throwLightError(*this, "directional light direction must be finite and non-zero");
            direction = direction / len;
            break;
        }
        case LightType::ConstantEnv:
            if (!isFiniteNonNegative(radiance))
                throwLightError(*this, "environment radiance must be finite and non-negative");
            break;
        case LightType::EnvMap: {
            if (!isFiniteNonNegative(radiance))
                throwLightError(*this, "environment map scale must be finite and non-negative");
            if (!envMap || envMap->width <= 0 || envMap->height <= 0)
                throwLightError(*this, "environment map has no image");
            if (!isRotation(envToWorld))
                throwLightError(*this, "environment map transform must be a rotation");
            if (envFilter != EnvFilter::Nearest && envFilter != EnvFilter::Bilinear)
                throwLightError(
                    *this, "unknown environment map filter " + std::to_string(uint32_t(envFilter)));
            worldToEnv = envToWorld.inverse();
            const Image& img = *envMap;
            for (int y = 0; y < img.height; ++y)
                for (int x = 0; x < img.width; ++x)
                    if (!isFiniteNonNegative(img.at(x, y)))
                        throwLightError(*this, "environment map pixel (" + std::to_string(x) +
                                                   ", " + std::to_string(y) +
                                                   ") is negative or not finite");
            envLatLong = std::make_shared<LatLongMap>(envMap, radiance, envFilter);
            // Aliasing pointer: envDistribution lives as long as envLatLong.
            envDistribution =
                std::shared_ptr<const Distribution2D>(envLatLong, &envLatLong->cellDistribution());
            break;
        }
        default:
            throwLightError(*this, "unknown light type");
    }
    prepared = true;
}

// ---- spot ------------------------------------------------------------------------

float Light::spotFalloff(float cosTheta) const {
    // Mitsuba 3 spot.cpp: 0 outside the cutoff cone, 1 inside the beam, in between linear
    // in the angle from the cutoff.
    if (!(cosTheta > cosCutoff)) return 0.0f;
    if (cosTheta >= cosBeamWidth || invTransitionRad == 0.0f) return 1.0f;
    const float theta = std::acos(std::min(1.0f, cosTheta));
    return std::min(1.0f, std::max(0.0f, (cutoffRad - theta) * invTransitionRad));
}

float Light::spotPowerPerIntensity() const {
    // int_0^b sin + int_b^c (c - t)/(c - b) sin dt = 1 - (sin c - sin b) / (c - b).
    const double c = double(cutoffAngleDeg) * kPi / 180.0, b = double(beamWidthDeg) * kPi / 180.0;
    const double inner = c > b ? 1.0 - (std::sin(c) - std::sin(b)) / (c - b) : 1.0 - std::cos(c);
    return float(2.0 * kPi * inner);
}

namespace {

/// Solid-angle pdf of emit()'s uniform cone sampling for a spot light.
float spotConePdfW(const Light& l) {
    return 1.0f / (2.0f * kPi * (1.0f - l.cosCutoff));
}

}  // namespace

// ---- illuminate ------------------------------------------------------------------

Rgb Light::illuminate(const SceneSphere& sphere, const Vec3& receivingPos, const Vec2& rnd,
                      Vec3* dirToLight, float* distance, float* directPdfW, float* emissionPdfW,
                      float* cosAtLight) const {
    // Invalid samples return black with zero pdfs.
    *directPdfW = 0;
    if (emissionPdfW) *emissionPdfW = 0;
    if (cosAtLight) *cosAtLight = 0;
    switch (type) {
        case LightType::Area: {
            Vec3 n;
            Vec2 uv;
            Vec3 p = sampleAreaPoint(*this, rnd, &n, &uv);
            Vec3 toLight = p - receivingPos;
            float distSqr = lengthSqr(toLight);
            if (!(distSqr > 0)) return Rgb(0);
            float dist = std::sqrt(distSqr);
            Vec3 dir = toLight / dist;
            float cosOut = emissionCosine(*this, n, -dir);
            if (cosOut <= kEpsCosine) return Rgb(0);
            float directPdfA;
            areaPdfs(*this, cosOut, &directPdfA, emissionPdfW);
            *dirToLight = dir;
            *distance = dist;
            *directPdfW = ub_pdf_a_to_w(directPdfA, distSqr, cosOut);
            if (cosAtLight) *cosAtLight = cosOut;
            return areaRadiance(uv);
        }
        case LightType::Point: {
            Vec3 toLight = position - receivingPos;
            float distSqr = lengthSqr(toLight);
            if (!(distSqr > 0)) return Rgb(0);
            float dist = std::sqrt(distSqr);
            *dirToLight = toLight / dist;
            *distance = dist;
            // directPdfA = 1 (delta position), cos = 1: pdfW = d^2 gives I / d^2.
            *directPdfW = distSqr;
            if (emissionPdfW) *emissionPdfW = uniformSpherePdfW();
            if (cosAtLight) *cosAtLight = 1.0f;
            return intensity;
        }
        case LightType::Spot:
        case LightType::Projector: {
            // A point emitter whose intensity depends on the direction (falloff, texture):
            // I(dir) / d^2 as for a point light. The emission pdf is emit()'s: uniform in the
            // spot's cone, the projector's texture-proportional density.
            Vec3 toLight = position - receivingPos;
            float distSqr = lengthSqr(toLight);
            if (!(distSqr > 0)) return Rgb(0);
            float dist = std::sqrt(distSqr);
            Vec3 dir = toLight / dist;
            const bool projector = type == LightType::Projector;
            float pdfW = projector ? 0.0f : spotConePdfW(*this);
            Rgb value = projectedIntensity(-dir, projector ? &pdfW : nullptr);
            if (isBlack(value) || !(pdfW > 0)) return Rgb(0);
            *dirToLight = dir;
            *distance = dist;
            *directPdfW = distSqr;  // directPdfA = 1 (delta position), cos = 1
            if (emissionPdfW) *emissionPdfW = pdfW;
            if (cosAtLight) *cosAtLight = 1.0f;
            return value;
        }
        case LightType::Directional:
            *dirToLight = -direction;
            *distance = kInf;
            *directPdfW = 1.0f;
            if (emissionPdfW) *emissionPdfW = ub_disk_pdf_a(sphere.invRadiusSqr);
            if (cosAtLight) *cosAtLight = 1.0f;
            return radiance;
        case LightType::ConstantEnv:
        case LightType::EnvMap: {
            Vec3 dir = envSampleDirection(*this, rnd);
            float pdfW;
            Rgb le = envEval(*this, dir, &pdfW);
            if (!(pdfW > 0)) return Rgb(0);
            *dirToLight = dir;
            *distance = kInf;
            *directPdfW = pdfW;
            if (emissionPdfW) *emissionPdfW = pdfW * ub_disk_pdf_a(sphere.invRadiusSqr);
            if (cosAtLight) *cosAtLight = 1.0f;
            return le;
        }
    }
    return Rgb(0);
}

// ---- emit ------------------------------------------------------------------------

Rgb Light::emit(const SceneSphere& sphere, const Vec2& rndDir, const Vec2& rndPos,
                Vec3* positionOut, Vec3* directionOut, float* emissionPdfW, float* directPdfA,
                float* cosThetaLight) const {
    *emissionPdfW = 0;
    if (directPdfA) *directPdfA = 0;
    if (cosThetaLight) *cosThetaLight = 0;
    switch (type) {
        case LightType::Area: {
            Vec3 n;
            Vec2 uv;
            *positionOut = sampleAreaPoint(*this, rndPos, &n, &uv);
            Vec2 u = rndDir;
            if (twoSided) {  // coin flip for the side, rndDir.x rescaled to [0,1)
                if (u.x < 0.5f) {
                    u.x = 2.0f * u.x;
                } else {
                    u.x = std::min(2.0f * u.x - 1.0f, 0.99999994f);
                    n = -n;
                }
            }
            Vec3 local = sampleCosineHemisphere(u);
            if (!(local.z > 0)) return Rgb(0);
            *directionOut = Frame(n).toWorld(local);
            // Same formula as radianceAlong(): emissionPdfW = 1/A * P(side) * cos/pi.
            areaPdfs(*this, local.z, directPdfA, emissionPdfW);
            if (cosThetaLight) *cosThetaLight = local.z;
            return areaRadiance(uv);
        }
        case LightType::Point:
            *positionOut = position;
            *directionOut = sampleUniformSphere(rndDir);
            *emissionPdfW = uniformSpherePdfW();
            if (directPdfA) *directPdfA = 1.0f;
            if (cosThetaLight) *cosThetaLight = 1.0f;
            return intensity;
        case LightType::Spot: {
            // Uniform in the cutoff cone: cos theta uniform in [cos c, 1].
            const float cosTheta = 1.0f - rndDir.x * (1.0f - cosCutoff);
            const float sinTheta = std::sqrt(std::max(0.0f, 1.0f - cosTheta * cosTheta));
            const float phi = 2.0f * kPi * rndDir.y;
            const Vec3 local(sinTheta * std::cos(phi), sinTheta * std::sin(phi), cosTheta);
            *positionOut = position;
            *directionOut = Frame(direction).toWorld(local);
            *emissionPdfW = spotConePdfW(*this);
            if (directPdfA) *directPdfA = 1.0f;
            if (cosThetaLight) *cosThetaLight = 1.0f;
            return projTexture ? projectedIntensity(*directionOut)
                               : intensity * spotFalloff(cosTheta);
        }
        case LightType::Projector: {
            *positionOut = position;
            *directionOut = sampleProjectorDirection(*this, rndDir);
            float pdfW;
            Rgb value = projectedIntensity(*directionOut, &pdfW);
            if (isBlack(value) || !(pdfW > 0)) return Rgb(0);
            *emissionPdfW = pdfW;
            if (directPdfA) *directPdfA = 1.0f;
            if (cosThetaLight) *cosThetaLight = 1.0f;
            return value;
        }
        case LightType::Directional:
            // Parallel rays through the scene-sphere disk on the side the light comes from.
            *positionOut = sceneDiskPoint(sphere, -direction, rndPos);
            *directionOut = direction;
            *emissionPdfW = ub_disk_pdf_a(sphere.invRadiusSqr);
            if (directPdfA) *directPdfA = 1.0f;
            if (cosThetaLight) *cosThetaLight = 1.0f;
            return radiance;
        case LightType::ConstantEnv:
        case LightType::EnvMap: {
            // Direction as in illuminate(), then a point on the disk facing it (tech. rep.
            // Sec. 5.1); the ray starts outside the scene sphere and travels inwards.
            Vec3 dirToLight = envSampleDirection(*this, rndDir);
            float pdfW;
            Rgb le = envEval(*this, dirToLight, &pdfW);
            if (!(pdfW > 0)) return Rgb(0);
            *positionOut = sceneDiskPoint(sphere, dirToLight, rndPos);
            *directionOut = -dirToLight;
            *emissionPdfW = pdfW * ub_disk_pdf_a(sphere.invRadiusSqr);
            // SmallVCM convention: for lights at infinity directPdfA holds the solid-angle pdf.
            if (directPdfA) *directPdfA = pdfW;
            if (cosThetaLight) *cosThetaLight = 1.0f;
            return le;
        }
    }
    return Rgb(0);
}

// ---- radianceAlong ---------------------------------------------------------------

Rgb Light::radianceAlong(const SceneSphere& sphere, const Vec3& rayDir, const Vec3& /*hitPoint*/,
                         const Vec3& hitNormal, const Vec2& hitUv, float* directPdfA,
                         float* emissionPdfW) const {
    if (directPdfA) *directPdfA = 0;
    if (emissionPdfW) *emissionPdfW = 0;
    switch (type) {
        case LightType::Area: {
            float cosOut = emissionCosine(*this, hitNormal, -rayDir);
            if (cosOut <= kEpsCosine) return Rgb(0);
            areaPdfs(*this, cosOut, directPdfA, emissionPdfW);
            return areaRadiance(hitUv);
        }
        case LightType::Point:
        case LightType::Spot:
        case LightType::Projector:
        case LightType::Directional:
            return Rgb(0);  // delta lights cannot be hit
        case LightType::ConstantEnv:
        case LightType::EnvMap: {
            float pdfW;
            Rgb le = envEval(*this, rayDir, &pdfW);
            if (directPdfA) *directPdfA = pdfW;
            if (emissionPdfW) *emissionPdfW = pdfW * ub_disk_pdf_a(sphere.invRadiusSqr);
            return le;
        }
    }
    return Rgb(0);
}

}  // namespace ub
