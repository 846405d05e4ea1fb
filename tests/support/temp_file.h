// A file with the given bytes in a per-test-suite folder of the system's temporary
// directory, for tests that feed readers small files they write themselves.
#pragma once

#include <filesystem>
#include <fstream>
#include <string>

namespace ub::test {

/// Writes data to <tmp>/<folder>/<name> (folder created) and returns the path.
inline std::string writeTempFile(const std::string& folder, const std::string& name,
                                 const std::string& data) {
    const std::filesystem::path d = std::filesystem::temp_directory_path() / folder;
    std::filesystem::create_directories(d);
    const std::string path = (d / name).string();
    std::ofstream(path, std::ios::binary) << data;
    return path;
}

}  // namespace ub::test
