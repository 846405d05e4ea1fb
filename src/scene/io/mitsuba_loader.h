// Mitsuba 3 XML scenes (a subset; docs/mitsuba.md lists every supported plugin
// and parameter and how it maps onto unibeam).
//
// Reading is strict: an unsupported plugin, an unsupported or unused parameter,
// a wrong type, a missing file or a bad value is an error naming the file, the
// line and column and the plugin. All problems are collected and thrown as one
// InputError. Semantics that differ slightly and cannot be represented exactly
// (e.g. Mitsuba's sampler, replaced by unibeam's own) are warnings.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "scene/scene.h"

namespace ub {

/// Loads and commits the Mitsuba XML scene at `path`. `defines` are -D name=value
/// overrides of the scene's <default> parameters (an override of a parameter the scene does
/// not declare is an error). Throws InputError listing every error.
std::unique_ptr<Scene> loadMitsubaScene(const std::string& path,
                                        const std::map<std::string, std::string>& defines = {},
                                        std::vector<Diagnostic>* warnings = nullptr);

/// Same from text in memory (`fileName` for messages, relative paths start at baseDir).
std::unique_ptr<Scene> loadMitsubaSceneFromString(
    const std::string& text, const std::string& fileName, const std::string& baseDir,
    const std::map<std::string, std::string>& defines = {},
    std::vector<Diagnostic>* warnings = nullptr);

}  // namespace ub
