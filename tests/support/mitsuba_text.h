// Mitsuba 3 scenes given as text in tests: load one (relative paths from the working
// directory) and the message of the error it fails with.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "scene/io/mitsuba_loader.h"

namespace ub::test {

inline std::unique_ptr<Scene> loadMitsubaText(const std::string& text,
                                              std::vector<Diagnostic>* warnings = nullptr) {
    return loadMitsubaSceneFromString(text, "scene.xml", ".", {}, warnings);
}

/// The InputError's message of loading text, or "" if it loads.
inline std::string mitsubaErrorsOf(const std::string& text) {
    try {
        loadMitsubaText(text);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

}  // namespace ub::test
