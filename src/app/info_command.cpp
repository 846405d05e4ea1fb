// `unibeam info`: load a scene and print its summary.
#include <cstdio>
#include <filesystem>

#include "app/commands.h"
#include "app/scene_access.h"
#include "core/file_status.h"

namespace ub::app {

int runInfo(const std::string& scenePath, const std::map<std::string, std::string>& defines) {
    if (!pathExists(scenePath)) throw UsageError("scene file '" + scenePath + "' does not exist");
    std::unique_ptr<Scene> scene = loadSceneFile(scenePath, defines);
    std::string text = sceneDescription(*scene);
    std::fputs(text.c_str(), stdout);
    if (!text.empty() && text.back() != '\n') std::fputc('\n', stdout);
    return 0;
}

}  // namespace ub::app
