// Scene::setupBsdf and texture lookups: every integrator builds its BSDFs here, so
// textured parameters (scene/texture.h) reach all of them in the same way.
#include <string>

#include "core/error.h"
#include "scene/bsdf.h"
#include "scene/scene.h"

namespace ub {

int Scene::addTexture(const Texture& t) {
    t.validate();
    textures.push_back(t);
    return int(textures.size()) - 1;
}

SurfaceColors Scene::surfaceColors(const Material& m, const Vec2& uv, const Rgb& attribute) const {
    SurfaceColors c = SurfaceColors::of(m);
    auto lookup = [&](int index, Rgb* value) {
        if (index >= 0) *value = textures[size_t(index)].eval(uv, attribute);
    };
    lookup(m.textures.diffuse, &c.diffuse);
    lookup(m.textures.glossy, &c.glossy);
    lookup(m.textures.specular, &c.specular);
    lookup(m.textures.transmittance, &c.transmittance);
    for (int i = 0; i < PrincipledParams::kWeights; ++i)
        if (const int t = m.textures.principled[size_t(i)]; t >= 0)
            c.principled.weight(i) = luminance(textures[size_t(t)].eval(uv, attribute));
    // Roughness: Mitsuba's float textures, the luminance of an RGB one (as blend weights);
    // alpha_v follows alpha_u where only one is given (isotropic).
    if (m.textures.alpha >= 0) {
        c.alphaU = luminance(textures[size_t(m.textures.alpha)].eval(uv, attribute));
        if (m.alphaV < 0.0f && m.textures.alphaV < 0) c.alphaV = c.alphaU;
    }
    if (m.textures.alphaV >= 0)
        c.alphaV = luminance(textures[size_t(m.textures.alphaV)].eval(uv, attribute));
    return c;
}

bool Scene::setupBsdf(Bsdf* bsdf, int materialId, const Vec2& uv, const Rgb& attribute,
                      const Vec3& dirFix, const Vec3& geoNormal, const Vec3& shadingNormal,
                      const Vec3& tangent, bool fromLight) const {
    if (materialId < 0 || size_t(materialId) >= materials.size()) {
        *bsdf = Bsdf();
        return false;
    }
    const Material& m = materials[size_t(materialId)];
    bsdf->setGeometricGuard(settings.shadingNormals == ShadingNormals::kGeometricGuard);
    if (m.type == MaterialType::Blend) {
        // The parts at the same point (Scene::addMaterial checked that they precede m), and
        // the weight: the constant, or the weight texture's luminance at uv (Mitsuba reads a
        // float texture; its grey value is the luminance of an RGB one).
        Bsdf parts[2];
        for (int i = 0; i < 2; ++i)
            setupBsdf(&parts[i], m.blendParts[i], uv, attribute, dirFix, geoNormal, shadingNormal,
                      tangent, fromLight);
        float w = m.blendWeight;
        if (m.textures.weight >= 0)
            w = luminance(textures[size_t(m.textures.weight)].eval(uv, attribute));
        return bsdf->setupBlend(m, w, parts[0], parts[1]);
    }
    return bsdf->setup(m, surfaceColors(m, uv, attribute), dirFix, geoNormal, shadingNormal,
                       fromLight, tangent);
}

bool Scene::setupBsdf(Bsdf* bsdf, const Hit& hit, const Vec3& dirFix, bool fromLight) const {
    return setupBsdf(bsdf, hit.materialId, hit.uv, hit.attribute, dirFix, hit.geoNormal,
                     hit.shadingNormal, hit.tangent, fromLight);
}

}  // namespace ub
