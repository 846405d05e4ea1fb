// unibeam's native JSON scene format, specified in docs/scene-format.md.
//
// Reading is strict: unknown keys, wrong types, out-of-range or non-finite
// numbers, unknown type or material names, missing files, zero-area emitters,
// several environment lights, a scene without light or camera are errors. All
// problems of a file are collected and thrown together as one InputError whose
// diagnostics name file:line:column and the JSON pointer of the bad value.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "scene/scene.h"

namespace ub {

/// Loads and commits the scene at `path`. Warnings (e.g. a black emission) go to
/// *warnings when given. Throws InputError listing every error found.
std::unique_ptr<Scene> loadJsonScene(const std::string& path,
                                     std::vector<Diagnostic>* warnings = nullptr);

/// Same, from text in memory: `fileName` is used in messages and as Scene::sourceFile,
/// relative file paths start at `baseDir`.
std::unique_ptr<Scene> loadJsonSceneFromString(const std::string& text, const std::string& fileName,
                                               const std::string& baseDir,
                                               std::vector<Diagnostic>* warnings = nullptr);

}  // namespace ub
