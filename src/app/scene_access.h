// The CLI's one entry to the scene loaders (scene/io/) and the scene summary.
#pragma once

#include <map>
#include <memory>
#include <string>

#include "scene/scene.h"

namespace ub::app {

/// Loads a scene file (any supported format); prints loader warnings to stderr.
/// Throws InputError with every problem found.
std::unique_ptr<Scene> loadSceneFile(const std::string& path,
                                     const std::map<std::string, std::string>& defines = {});
/// Human-readable description for `unibeam info`.
std::string sceneDescription(const Scene& scene);

}  // namespace ub::app
