// Entry point for reading a scene file of any supported format, chosen by the
// file extension: .json (native, docs/scene-format.md). Later: Mitsuba .xml and
// SmallUPBP .obj + .obj.aux.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "scene/scene.h"

namespace ub {

/// File extensions loadScene accepts, with their dot (".json").
std::vector<std::string> supportedSceneExtensions();

/// Loads and commits the scene at `path`, dispatching on its extension
/// (case-insensitive). Warnings go to *warnings when given. Throws InputError on an
/// unsupported extension (listing the supported ones) and on any error in the file.
std::unique_ptr<Scene> loadScene(const std::string& path,
                                 std::vector<Diagnostic>* warnings = nullptr);

}  // namespace ub
