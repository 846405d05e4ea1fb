// Shared by the libFuzzer targets in fuzz/ (docs/fuzzing.md).
//
// Each target feeds one loader the way the program does: inputs that a loader takes by path
// are written to files in a private temporary folder (one per process, removed at exit) and
// loaded from there. Bad input must end in the project's documented error, InputError
// (core/error.h; exit status 2 in the CLI): runGuarded catches that and nothing else, so any
// other exception, crash, sanitizer report, leak or hang is a finding.
#pragma once

#include <tbb/global_control.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "core/error.h"

namespace ub::fuzz {

namespace fs = std::filesystem;

/// The process's temporary folder (created on first use; removed at exit).
inline const fs::path& tempDir() {
    static const fs::path dir = [] {
        const char* base = std::getenv("TMPDIR");
        std::string pattern = std::string(base && *base ? base : "/tmp") + "/unibeam-fuzz-XXXXXX";
        std::vector<char> buf(pattern.begin(), pattern.end());
        buf.push_back('\0');
        if (!::mkdtemp(buf.data())) {
            std::perror("unibeam fuzz: mkdtemp");
            std::abort();
        }
        static fs::path made(buf.data());
        std::atexit([] {
            std::error_code ec;
            fs::remove_all(made, ec);
        });
        return made;
    }();
    return dir;
}

/// Writes bytes to tempDir()/name and returns the path.
inline std::string writeTemp(const std::string& name, const uint8_t* data, size_t size) {
    const fs::path p = tempDir() / name;
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
    out.close();
    if (!out) {
        std::fprintf(stderr, "unibeam fuzz: cannot write %s\n", p.c_str());
        std::abort();
    }
    return p.string();
}

inline std::string writeTemp(const std::string& name, const std::string& text) {
    return writeTemp(name, reinterpret_cast<const uint8_t*>(text.data()), text.size());
}

/// Splits the input at NUL bytes into at most `parts` files' contents (missing ones empty;
/// the last part keeps any further NULs). Text formats never contain NUL, so seeds made by
/// scripts/fuzz_corpus.sh join a scene's files with one NUL between each.
inline std::vector<std::string> splitParts(const uint8_t* data, size_t size, size_t parts) {
    std::vector<std::string> out(parts);
    size_t part = 0;
    for (size_t i = 0; i < size; ++i) {
        if (data[i] == 0 && part + 1 < parts) {
            ++part;
            continue;
        }
        out[part].push_back(char(data[i]));
    }
    return out;
}

/// One worker thread: the loaders' parallel parts (Embree's BVH build, TBB loops) run on the
/// fuzzer's thread, so one fuzzer uses one core and reports are reproducible.
inline void limitThreads() {
    static tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
}

/// Runs f, accepting only InputError (the documented error for bad input).
template <typename F>
void runGuarded(F&& f) {
    try {
        f();
    } catch (const InputError&) {
        // Bad input, reported as documented.
    }
}

}  // namespace ub::fuzz
