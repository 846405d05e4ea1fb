#include "app/scene_access.h"

#include <cstdio>
#include <vector>

#include "core/error.h"
#include "scene/io/scene_loader.h"
#include "scene/scene_summary.h"

namespace ub::app {

std::unique_ptr<Scene> loadSceneFile(const std::string& path,
                                     const std::map<std::string, std::string>& defines) {
    std::vector<Diagnostic> warnings;
    std::unique_ptr<Scene> scene = loadScene(path, defines, &warnings);
    for (const auto& w : warnings) std::fprintf(stderr, "%s\n", w.format().c_str());
    return scene;
}

std::string sceneDescription(const Scene& scene) {
    return describeScene(scene);
}

}  // namespace ub::app
