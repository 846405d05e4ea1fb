// Perturbed shading normals (definitions: normal_perturbation.h).
#include "scene/normal_perturbation.h"

#include <algorithm>
#include <cmath>

namespace ub {

namespace {

bool finiteNonZero(const Vec3& v, float* len) {
    *len = length(v);
    return *len > 0.0f && std::isfinite(*len);
}

/// v on the side of unit ng (v itself where it already is).
Vec3 toSideOf(const Vec3& v, const Vec3& ng) {
    return dot(v, ng) < 0.0f ? -v : v;
}

}  // namespace

Vec3 shadingTangent(const Vec3& n, const Vec3& dpdu) {
    const Vec3 s = dpdu - dot(n, dpdu) * n;
    float len;
    if (finiteNonZero(s, &len)) return s / len;
    return Frame(n).s;
}

Vec3 normalMapNormal(const Rgb& texel, const Vec3& n, const Vec3& dpdu) {
    const Vec3 local(2.0f * texel.x - 1.0f, 2.0f * texel.y - 1.0f, 2.0f * texel.z - 1.0f);
    const Vec3 s = shadingTangent(n, dpdu), t = cross(n, s);
    const Vec3 world = s * local.x + t * local.y + n * local.z;
    float len;
    return finiteNonZero(world, &len) ? world / len : n;
}

Vec3 bumpMapNormal(const Vec2& heightGradient, const Vec3& n, const Vec3& dpdu, const Vec3& dpdv,
                   const Vec3& ng) {
    const Vec3 du = dpdu + (heightGradient.x - dot(n, dpdu)) * n;
    const Vec3 dv = dpdv + (heightGradient.y - dot(n, dpdv)) * n;
    const Vec3 c = cross(du, dv);
    float len;
    if (!finiteNonZero(c, &len)) return n;
    return toSideOf(c / len, ng);
}

Vec3 perturbedShadingNormal(const Material& m, const Texture& texture, const Vec2& uv,
                            const Vec3& n, const Vec3& ng, const Vec3& dpdu, const Vec3& dpdv) {
    switch (m.perturbation) {
        case NormalPerturbation::kNormalMap:
            return toSideOf(normalMapNormal(texture.eval(uv), n, dpdu), ng);
        case NormalPerturbation::kBumpMap: {
            const Vec2 g = texture.luminanceGradient(uv);
            return bumpMapNormal(Vec2(m.bumpScale * g.x, m.bumpScale * g.y), n, dpdu, dpdv, ng);
        }
        case NormalPerturbation::kNone:
            break;
    }
    return n;
}

float shadowTerminatorAlpha2(const Vec3& perturbed, const Vec3& unperturbed) {
    const float c = dot(perturbed, unperturbed), c2 = c * c;
    if (!(c2 > 0.0f)) return 1.0f;
    const float tan2 = std::max(0.0f, 1.0f - c2) / c2;
    return std::min(0.125f * tan2, 1.0f);
}

}  // namespace ub
