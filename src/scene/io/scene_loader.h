// Entry point for reading a scene file of any supported format, chosen by the
// file extension: .json (native, docs/scene-format.md), .xml (Mitsuba 3
// subset, docs/mitsuba.md) and .obj with a sibling .obj.aux (SmallUPBP,
// docs/smallupbp.md).
#pragma once

#include <map>
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

/// Same with scene parameters (`-D name=value`): overrides of a Mitsuba XML scene's
/// <default> parameters. Non-empty `defines` for a format without parameters is an error.
std::unique_ptr<Scene> loadScene(const std::string& path,
                                 const std::map<std::string, std::string>& defines,
                                 std::vector<Diagnostic>* warnings = nullptr);

}  // namespace ub
