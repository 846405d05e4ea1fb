// Scratch files of the tests: one folder per test process in the system's temporary
// directory, so that two test runs at once (a Release and a sanitizer build, say) never write
// the same file, and removed when the process exits, so that nothing is left behind.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

namespace ub::test {

/// <tmp>/unibeam_test_<pid>/: this process's scratch folder, created on first use and removed
/// with its contents at exit.
inline const std::filesystem::path& processScratchDir() {
    struct Dir {
        std::filesystem::path path =
            std::filesystem::temp_directory_path() / ("unibeam_test_" + std::to_string(::getpid()));
        Dir() { std::filesystem::create_directories(path); }
        ~Dir() {
            std::error_code ec;
            std::filesystem::remove_all(path, ec);
        }
    };
    static const Dir dir;
    return dir.path;
}

/// processScratchDir() / name, created as a folder.
inline std::filesystem::path scratchFolder(const std::string& name) {
    const std::filesystem::path d = processScratchDir() / name;
    std::filesystem::create_directories(d);
    return d;
}

/// Writes data to <scratch>/<folder>/<name> (folder created) and returns the path.
inline std::string writeTempFile(const std::string& folder, const std::string& name,
                                 const std::string& data) {
    const std::filesystem::path d = processScratchDir() / folder;
    std::filesystem::create_directories(d);
    const std::string path = (d / name).string();
    std::ofstream(path, std::ios::binary) << data;
    return path;
}

}  // namespace ub::test
