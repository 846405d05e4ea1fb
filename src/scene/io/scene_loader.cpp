#include "scene/io/scene_loader.h"

#include <cctype>
#include <filesystem>

#include "core/file_status.h"
#include "scene/io/json_loader.h"
#include "scene/io/mitsuba_loader.h"
#include "scene/io/smallupbp_loader.h"

namespace ub {

std::vector<std::string> supportedSceneExtensions() {
    return {".json", ".xml", ".obj"};
}

std::unique_ptr<Scene> loadScene(const std::string& path, std::vector<Diagnostic>* warnings) {
    return loadScene(path, {}, warnings);
}

std::unique_ptr<Scene> loadScene(const std::string& path,
                                 const std::map<std::string, std::string>& defines,
                                 std::vector<Diagnostic>* warnings) {
    std::string ext = std::filesystem::path(path).extension().string();
    for (auto& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (ext == ".xml") return loadMitsubaScene(path, defines, warnings);
    if (ext == ".json") {
        if (!defines.empty())
            throw InputError(path, "scene parameters (-D " + defines.begin()->first +
                                       "=...) apply only to Mitsuba .xml scenes");
        return loadJsonScene(path, warnings);
    }
    if (ext == ".obj") {
        if (!defines.empty())
            throw InputError(path, "scene parameters (-D " + defines.begin()->first +
                                       "=...) apply only to Mitsuba .xml scenes");
        // A SmallUPBP scene: X.obj with X.obj.aux beside it (scene/io/smallupbp_loader.h).
        if (isRegularFile(path + ".aux")) return loadSmallUpbpScene(path, warnings);
        throw InputError(path,
                         "an .obj scene is read in SmallUPBP's format, which needs the file '" +
                             std::filesystem::path(path).filename().string() +
                             ".aux' beside it (camera, media and lights; see docs/smallupbp.md), "
                             "and it is missing; to render a plain mesh, reference it from a "
                             ".json scene");
    }

    std::string list;
    for (const auto& e : supportedSceneExtensions()) list += (list.empty() ? "" : ", ") + e;
    throw InputError(path, (ext.empty() ? std::string("the scene file has no extension")
                                        : "unsupported scene file extension '" + ext + "'") +
                               " (supported: " + list + ")");
}

}  // namespace ub
