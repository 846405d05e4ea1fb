// Lights as flat data with a type tag, SmallVCM's interface (Illuminate /
// Emit / GetRadiance) with pdfs named by measure:
//   directPdfW  - solid-angle pdf (at the receiving point) with which illuminate()
//                 samples this light point; for area lights = directPdfA * d^2 / cosAtLight.
//   directPdfA  - area pdf of the light point used by illuminate() (area lights),
//                 1 for delta-position lights. Environment lights: solid-angle pdf.
//   emissionPdfW - pdf of emit() generating this (point, direction) pair:
//                 position pdf (area, or 1/(pi R^2) of the scene disk for
//                 directional/environment lights) * direction pdf (solid angle).
//   cosAtLight / cosThetaLight - cosine at the light surface (1 for point,
//                 directional and environment lights).
// None of these includes the light selection probability (1/#lights), which
// the integrators apply. Returned radiance / energy values are NOT divided by
// any pdf: illuminate() returns Le(dir) and emit() returns Le (or intensity /
// irradiance for delta lights). Unlike SmallVCM's Emit(), emit() does NOT multiply
// by the emission cosine: a light subpath starts with throughput
//   emit() * cosThetaLight / (emissionPdfW * lightPickProb)
// (cosThetaLight = 1 for point, directional and environment lights).
// Environment lights use the scene bounding sphere (SceneSphere) to place
// emitted rays (Sec. 5.1 of "Implementing VCM"): emit() picks a direction
// exactly as illuminate() does, then a point on the disk of radius R facing it,
// centred at center + R * dirToLight (directional lights: center - R * direction).
//
// Area lights: every triangle emits on the side of normalize((p1-p0)x(p2-p0)) (both
// sides if twoSided, where emit() picks each side with probability 1/2 and
// emissionPdfW includes that 1/2); a sphere emits outward. A point is picked
// uniformly by area over all triangles and the sphere (the sphere is the last bin
// of triangleDistribution), so directPdfA = 1 / totalArea. radianceAlong() trusts
// hitNormal as that front-side normal. A textured area light (Mitsuba 3's `area` with a
// `radiance` texture) emits radiance x radianceTexture(uv), uv being the shape's own
// (Hit::uv): the triangles' `triangleUvs` interpolated at the sampled point (barycentrics
// when the mesh has none), the sphere's spherical uv. Points are still sampled uniformly by
// area, so every pdf is the untextured one.
//
// Environment map orientation (same as Mitsuba 3's `envmap`): a direction
// d = (dx, dy, dz) in the map's frame (d = worldToEnv(dirToLight)) looks up
//   u = atan2(dx, -dz) / (2 pi)  (wrapped to [0,1)),   v = acos(dy) / pi.
// Inverse: d = (sin(phi) sin(theta), cos(theta), -cos(phi) sin(theta)) with
// phi = 2 pi u, theta = pi v; row 0 of the image is at the top (v = 0 is +y).
// envFilter picks the reconstruction (scene/env_map.h): Bilinear is Mitsuba 3's
// (pixel centres at u = (x + 1/2) / W, rows at v = y / (H - 1), bilinear between
// them, periodic in phi), Nearest is piecewise constant on pixel (floor(u W), floor(v H))
// (SmallUPBP's). Unlike Mitsuba, envToWorld must be a rotation.
// Sampling: LatLongMap::sample (a cell by luminance, then the bilinear patch inside it
// for Bilinear), pdfW = pdfUv / (2 pi^2 sin theta) (0 at the poles).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/image.h"
#include "core/sampling.h"
#include "core/vec.h"
#include "scene/env_map.h"
#include "scene/texture.h"

namespace ub {

/// The uv of a sphere shape at the point with unit outward normal n (Scene::intersect's and
/// Mitsuba's spherical coordinates about +z): u = phi / 2 pi in [0, 1), v = theta / pi.
inline Vec2 sphereUv(double nx, double ny, double nz) {
    constexpr double kTwoPi = 6.283185307179586476925;
    double phi = std::atan2(ny, nx);
    if (phi < 0.0) phi += kTwoPi;
    const double theta = std::acos(std::max(-1.0, std::min(1.0, nz)));
    return Vec2(float(phi / kTwoPi), float(theta / (0.5 * kTwoPi)));
}
inline Vec2 sphereUv(const Vec3& n) {
    return sphereUv(n.x, n.y, n.z);
}

struct SceneSphere {
    Vec3 center{0, 0, 0};
    float radius = 1.0f;
    float invRadiusSqr = 1.0f;
};

enum class LightType : uint32_t {
    Area = 0,         ///< emissive triangles and/or one sphere; uniform area sampling
    Point = 1,        ///< isotropic point, `intensity` [W/sr]
    Directional = 2,  ///< `direction` (travel direction of light), irradiance `radiance`
    ConstantEnv = 3,  ///< constant environment radiance
    EnvMap = 4,       ///< lat-long environment map, importance sampled
    Spot = 5,         ///< Mitsuba 3 `spot`: `intensity` [W/sr] at `position`, axis `direction`
    Projector = 6,    ///< Mitsuba 3 `projector`: a texture projected through a pinhole
};

struct Light {
    LightType type = LightType::Area;
    std::string name;
    Rgb radiance{0, 0, 0};   ///< Area: Le; ConstantEnv: Le; EnvMap: scale; Directional: irradiance
    Rgb intensity{0, 0, 0};  ///< Point
    Vec3 position{0, 0, 0};  ///< Point
    Vec3 direction{0, 0, -1};  ///< Directional: direction light travels (unit)
    bool twoSided = false;     ///< Area: emits from both sides
    // ---- Spot (Mitsuba 3's `spot`): intensity(theta) = intensity * falloff(theta) with
    // theta the angle to `direction`: 1 inside beamWidthDeg, a linear ramp in theta down to
    // 0 at cutoffAngleDeg, 0 beyond. Mitsuba's defaults: cutoff 20, beam width 3/4 cutoff.
    float cutoffAngleDeg = 20.0f;  ///< Spot: half-angle of the lit cone, in (0, 180]
    float beamWidthDeg = 15.0f;    ///< Spot: half-angle of full intensity, in [0, cutoff]
    float cosCutoff = 0.0f, cosBeamWidth = 0.0f;      ///< Spot: set by prepare()
    float cutoffRad = 0.0f, invTransitionRad = 0.0f;  ///< Spot: set by prepare() (0: no ramp)

    // ---- Projected textures (light_projected.cpp): a spot's optional `texture` and a
    // projector's `irradiance`, looked up at uv of the direction in the light's frame
    // (frameX, frameY, direction: the unit axes of Mitsuba's to_world, a rigid transform).
    //   Spot: uv = 1/2 + (x, y) / (2 z tan(cutoff)), intensity * falloff * texture(uv).
    //   Projector (`intensity` = Mitsuba's `scale`): uv = 1/2 - (x, aspect y) / (2 z t) with
    //   t = tan(fov_x / 2), inside [0, 1]^2 and z > 0; intensity pi scale E(uv) / cos^3
    //   (Mitsuba's projector.cpp, so that the irradiance on the plane z = 1 is E(uv)).
    std::shared_ptr<const Texture> projTexture;  ///< Spot: optional; Projector: required
    Vec3 frameX{0, 0, 0}, frameY{0, 0, 0};       ///< Spot, Projector: local x, y (0: built)
    float projFovXDeg = 0.0f;                    ///< Projector: horizontal field of view
    float projAspect = 1.0f;                     ///< Projector: width / height of the texture
    float projTan = 0.0f;  ///< set by prepare(): tan(fov_x / 2) or tan(cutoff)
    std::shared_ptr<const Distribution2D> projDistribution;  ///< Projector: set by prepare()

    // ---- Area light geometry (world space) ----
    std::vector<Vec3>
        triangles;  ///< 3 vertices per triangle (emits on the side of (p1-p0)x(p2-p0))
    /// Area: uv of each triangle vertex (3 per triangle, as `triangles`; empty: barycentric
    /// uvs, as Scene::intersect gives a mesh without them). Used by radianceTexture only.
    std::vector<Vec2> triangleUvs;
    /// Area: the emitted radiance is `radiance` x this texture at the point's uv (null:
    /// constant). Mitsuba's `radiance` bitmap; its `scale` folds into `radiance`.
    std::shared_ptr<const Texture> radianceTexture;
    Distribution1D triangleDistribution;  ///< by area
    bool isSphere = false;  ///< Area light is a sphere (center=position, sphereRadius)
    float sphereRadius = 0.0f;
    float totalArea = 0.0f;

    // ---- Environment map ----
    std::shared_ptr<const Image> envMap;       ///< lat-long, u = phi / 2pi, v = theta / pi, +y up
    EnvFilter envFilter = EnvFilter::Nearest;  ///< lookup (Mitsuba and JSON loaders: Bilinear)
    std::shared_ptr<const LatLongMap> envLatLong;  ///< set by prepare(): lookup and sampling
    std::shared_ptr<const Distribution2D> envDistribution;  ///< set by prepare(): its cells
    Transform envToWorld;  ///< rotation of the map (identity by default)
    Transform worldToEnv;  ///< set by prepare()

    bool prepared = false;  ///< set by prepare()

    /// Precomputes triangle distribution / area / env-map distribution and normalizes
    /// `direction`. Must be called after filling the fields (calling it again is
    /// harmless). Throws InputError (file "", where = "light '<name>'") on a zero-area
    /// emitter, non-finite geometry, negative or non-finite radiance, a zero direction,
    /// a missing or invalid env map, or a non-rotation envToWorld.
    void prepare();

    bool isDelta() const { return isDeltaPosition() || type == LightType::Directional; }
    /// A single emitting point in free space (point, spot and projector lights): shadow rays
    /// to it need no offset at the light end.
    bool isDeltaPosition() const {
        return type == LightType::Point || type == LightType::Spot || type == LightType::Projector;
    }
    /// False for lights at infinity (directional, environment).
    bool isFinite() const { return type == LightType::Area || isDeltaPosition(); }
    /// Spot: the falloff factor in [0, 1] for cos(theta) to the axis (Mitsuba 3's spot).
    float spotFalloff(float cosTheta) const;
    /// Spot: total emitted power per unit intensity, 2 pi [1 - (sin c - sin b) / (c - b)]
    /// for cutoff c and beam width b in radians (2 pi (1 - cos c) when b = c): the
    /// integral of the falloff over the sphere.
    float spotPowerPerIntensity() const;
    /// Spot and projector: the intensity towards the unit world direction dirOut (leaving
    /// the light), falloff and texture included; for a projector also the solid-angle pdf
    /// with which emit() samples dirOut (light_projected.cpp).
    Rgb projectedIntensity(const Vec3& dirOut, float* projectorPdfW = nullptr) const;
    bool isEnvironment() const {
        return type == LightType::ConstantEnv || type == LightType::EnvMap;
    }

    /// Samples a point on the light as seen from receivingPos (next-event estimation).
    /// Returns Le towards receivingPos (black if the sample is invalid).
    Rgb illuminate(const SceneSphere& sphere, const Vec3& receivingPos, const Vec2& rnd,
                   Vec3* dirToLight, float* distance, float* directPdfW, float* emissionPdfW,
                   float* cosAtLight) const;
    /// Samples an emitted ray (light subpath start). Returns emitted radiance
    /// (Area/Env), intensity (Point; Spot: times the falloff) or irradiance (Directional)
    /// of the sample. Spot lights sample directions uniformly in the cutoff cone,
    /// emissionPdfW = 1 / (2 pi (1 - cos cutoff)) (illuminate() reports the same).
    Rgb emit(const SceneSphere& sphere, const Vec2& rndDir, const Vec2& rndPos, Vec3* position,
             Vec3* direction, float* emissionPdfW, float* directPdfA, float* cosThetaLight) const;
    /// Radiance arriving along rayDir (unit, from the shading point towards the light)
    /// when a ray hits this light: area lights at hitPoint with surface normal
    /// hitNormal (geometric, as stored) and uv hitUv (Hit::uv, where a radiance texture is
    /// looked up); environments: hitPoint, hitNormal and hitUv unused.
    /// Fills the pdfs that illuminate()/emit() would have used for this point.
    Rgb radianceAlong(const SceneSphere& sphere, const Vec3& rayDir, const Vec3& hitPoint,
                      const Vec3& hitNormal, const Vec2& hitUv, float* directPdfA,
                      float* emissionPdfW) const;
    /// Area: the radiance at a point with uv (radiance x radianceTexture(uv)).
    Rgb areaRadiance(const Vec2& uv) const {
        return radianceTexture ? radiance * radianceTexture->eval(uv, Rgb(0.0f)) : radiance;
    }
};

}  // namespace ub
