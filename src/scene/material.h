// Materials as flat data with a type tag (no virtual calls per sample).
// The BSDF built from a material at a hit is in scene/bsdf.h.
#pragma once

#include <cstdint>
#include <string>

#include "core/vec.h"

namespace ub {

enum class MaterialType : uint32_t {
    Diffuse = 0,         ///< Lambertian, reflectance `diffuse`
    Phong = 1,           ///< SmallVCM model: Lambert `diffuse` + modified Phong lobe `glossy`, `exponent`
    Mirror = 2,          ///< perfect specular reflection scaled by `specular`
    Dielectric = 3,      ///< smooth glass: Fresnel reflection + refraction, `ior`, tint `specular`
    RoughConductor = 4,  ///< GGX microfacet conductor: `eta`, `k` (RGB), roughness `alpha`, tint `specular`
    RoughDielectric = 5, ///< GGX microfacet dielectric (Walter et al. 2007): `ior`, `alpha`, tint `specular`
};

struct Material {
    MaterialType type = MaterialType::Diffuse;
    std::string name;
    Rgb diffuse{0.5f, 0.5f, 0.5f};  ///< Diffuse, Phong
    Rgb glossy{0, 0, 0};            ///< Phong lobe reflectance
    float exponent = 1.0f;          ///< Phong exponent (> 0)
    Rgb specular{1, 1, 1};          ///< Mirror / Dielectric / Rough* tint
    float ior = 1.5f;               ///< Dielectric, RoughDielectric: interior / exterior IOR
    Rgb eta{0.2f, 0.92f, 1.1f};     ///< RoughConductor: real part of the complex IOR (default gold)
    Rgb k{3.9f, 2.45f, 2.14f};      ///< RoughConductor: imaginary part
    float alpha = 0.1f;             ///< GGX roughness (alpha = roughness^2 convention NOT used: alpha as given)
    /// Two-sided: if true (default for opaque materials), the back side of a surface
    /// behaves like the front. Dielectrics ignore it: their inside is defined by the normal.
    bool twoSided = true;
};

}  // namespace ub
