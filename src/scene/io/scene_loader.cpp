#include "scene/io/scene_loader.h"

#include <cctype>
#include <filesystem>

#include "scene/io/json_loader.h"

namespace ub {

std::vector<std::string> supportedSceneExtensions() {
    return {".json"};
}

std::unique_ptr<Scene> loadScene(const std::string& path, std::vector<Diagnostic>* warnings) {
    std::string ext = std::filesystem::path(path).extension().string();
    for (auto& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (ext == ".json") return loadJsonScene(path, warnings);

    std::string list;
    for (const auto& e : supportedSceneExtensions()) list += (list.empty() ? "" : ", ") + e;
    throw InputError(path, (ext.empty() ? std::string("the scene file has no extension")
                                        : "unsupported scene file extension '" + ext + "'") +
                               " (supported: " + list + ")");
}

}  // namespace ub
