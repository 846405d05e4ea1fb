// Whether a path names a regular file or a folder or exists, without throwing: std::filesystem's
// one-argument queries throw filesystem_error when the system call fails for another reason
// than a missing file (a name too long, a component that is not a folder, no permission),
// which a scene file's reference to another file must turn into the loader's clear error,
// not an uncaught exception (fuzz_smallupbp_scene found it with a 300-byte mtllib name).
#pragma once

#include <filesystem>
#include <string>
#include <system_error>

namespace ub {

/// True when `path` is a regular file (after symlinks); false when it is not or cannot be
/// examined.
inline bool isRegularFile(const std::filesystem::path& path) {
    std::error_code ec;
    return std::filesystem::is_regular_file(path, ec);
}

/// True when `path` is a folder (after symlinks); false when it is not or cannot be examined.
inline bool isDirectory(const std::filesystem::path& path) {
    std::error_code ec;
    return std::filesystem::is_directory(path, ec);
}

/// True when `path` exists; false when it does not or cannot be examined.
inline bool pathExists(const std::filesystem::path& path) {
    std::error_code ec;
    return std::filesystem::exists(path, ec);
}

}  // namespace ub
