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
// irradiance for delta lights), as in SmallVCM.
// Environment lights use the scene bounding sphere (SceneSphere) to place
// emitted rays (Sec. 5.1 of "Implementing VCM").
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/image.h"
#include "core/sampling.h"
#include "core/vec.h"

namespace ub {

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
};

struct Light {
    LightType type = LightType::Area;
    std::string name;
    Rgb radiance{0, 0, 0};   ///< Area: Le; ConstantEnv: Le; EnvMap: scale; Directional: irradiance
    Rgb intensity{0, 0, 0};  ///< Point
    Vec3 position{0, 0, 0};  ///< Point
    Vec3 direction{0, 0, -1};///< Directional: direction light travels (unit)
    bool twoSided = false;   ///< Area: emits from both sides

    // ---- Area light geometry (world space) ----
    std::vector<Vec3> triangles;  ///< 3 vertices per triangle (emits on the side of (p1-p0)x(p2-p0))
    Distribution1D triangleDistribution;  ///< by area
    bool isSphere = false;        ///< Area light is a sphere (center=position, sphereRadius)
    float sphereRadius = 0.0f;
    float totalArea = 0.0f;

    // ---- Environment map ----
    std::shared_ptr<const Image> envMap;      ///< lat-long, u = phi / 2pi, v = theta / pi, +y up
    std::shared_ptr<const Distribution2D> envDistribution;
    Transform envToWorld;                     ///< rotation of the map (identity by default)
    Transform worldToEnv;

    /// Precomputes triangle distribution / area / env-map distribution. Must be called
    /// once after filling the fields; throws InputError (file "") on a zero-area emitter.
    void prepare();

    bool isDelta() const { return type == LightType::Point || type == LightType::Directional; }
    /// False for lights at infinity (directional, environment).
    bool isFinite() const {
        return type == LightType::Area || type == LightType::Point;
    }
    bool isEnvironment() const {
        return type == LightType::ConstantEnv || type == LightType::EnvMap;
    }

    /// Samples a point on the light as seen from receivingPos (next-event estimation).
    /// Returns Le towards receivingPos (black if the sample is invalid).
    Rgb illuminate(const SceneSphere& sphere, const Vec3& receivingPos, const Vec2& rnd,
                   Vec3* dirToLight, float* distance, float* directPdfW, float* emissionPdfW,
                   float* cosAtLight) const;
    /// Samples an emitted ray (light subpath start). Returns emitted radiance
    /// (Area/Env), intensity (Point) or irradiance (Directional) of the sample.
    Rgb emit(const SceneSphere& sphere, const Vec2& rndDir, const Vec2& rndPos, Vec3* position,
             Vec3* direction, float* emissionPdfW, float* directPdfA, float* cosThetaLight) const;
    /// Radiance arriving along rayDir (unit, from the shading point towards the light)
    /// when a ray hits this light: area lights at hitPoint with surface normal
    /// hitNormal (geometric, as stored); environments: hitPoint/hitNormal unused.
    /// Fills the pdfs that illuminate()/emit() would have used for this point.
    Rgb radianceAlong(const SceneSphere& sphere, const Vec3& rayDir, const Vec3& hitPoint,
                      const Vec3& hitNormal, float* directPdfA, float* emissionPdfW) const;
};

}  // namespace ub
