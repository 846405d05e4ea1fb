// Scene::addLight lives apart from scene.cpp so that code using only the geometry
// (tests, tools) does not need the light implementation (Light::prepare) at link time.
#include "scene/scene.h"

namespace ub {

int Scene::addLight(Light l) {
    // prepare() fills totalArea (area lights) and envDistribution (maps); a light that
    // has them was prepared by the caller. Other types are cheap to prepare again.
    bool prepared = false;
    if (l.type == LightType::Area) prepared = l.totalArea > 0.0f;
    if (l.type == LightType::EnvMap) prepared = l.envDistribution != nullptr;
    if (!prepared) l.prepare();
    lights.push_back(std::move(l));
    return int(lights.size()) - 1;
}

}  // namespace ub
