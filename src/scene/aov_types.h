// The AOV types of Mitsuba 3's `aov` integrator that unibeam renders (render/aov.h); here, in
// scene/, so that the loaders can check a scene's list without the renderer.
#pragma once

#include <string>
#include <vector>

namespace ub {

inline const std::vector<std::string>& aovTypes() {
    static const std::vector<std::string> types = {
        "depth", "position", "uv", "geo_normal", "sh_normal", "prim_index", "shape_index"};
    return types;
}

}  // namespace ub
