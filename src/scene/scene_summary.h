// A human-readable summary of a loaded scene (`unibeam info`): counts of
// shapes, triangles and spheres, lights and materials by type, bounds,
// camera and render settings.
#pragma once

#include <string>

#include "scene/scene.h"

namespace ub {

const char* materialTypeName(MaterialType t);  ///< "diffuse", "phong", ... (scene-format names)
const char* lightTypeName(LightType t);        ///< "area", "point", "directional", ...

/// Multi-line summary, each line "key: value", ending with a newline.
std::string describeScene(const Scene& scene);

}  // namespace ub
