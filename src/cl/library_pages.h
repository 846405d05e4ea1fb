// Giving back the pages of a shared library that loading it read and nothing will write.
//
// PoCL (libpocl) links LLVM and Clang. Loading them (clGetPlatformIDs) applies 9 MB of
// relocations read from libLLVM's first segment and runs LLVM's static constructors, whose code
// is spread over its 50 MB of text; with the kernel's fault-around, about 52 MB of libLLVM's and
// libclang-cpp's read-only, executable segments become resident in the process (Debian 12,
// LLVM 15, measured from /proc/self/smaps: docs/performance.md, session 45). Once the program is
// built (or read from the program cache) the estimate passes run PoCL's compiled kernels and do
// not call LLVM again, yet those pages stay in the process's resident set, which is what a user
// sees as its memory: a render of the candle with the OpenCL backend peaked at 94 MB, 74 of them
// PoCL's, against 20 MB on the host backend.
//
// The pages are clean and backed by the library file: madvise(MADV_DONTNEED) unmaps them from
// the process. They stay in the page cache (shared with any other process using LLVM), and a
// later call into LLVM (a kernel built for a new local size) maps them again on a minor fault;
// nothing is lost. Only mappings that are private, readable and executable, never writable,
// with no dirty or anonymous page in them, are released: releasing a private page that was
// written (a text relocation) would discard the write.
//
// Linux only (/proc/self/smaps); elsewhere the call releases nothing.
#pragma once

#include <cstddef>
#include <istream>
#include <string>
#include <vector>

namespace ub {

/// One mapping of /proc/self/smaps, what releaseLibraryText needs of it.
struct SmapsMapping {
    unsigned long begin = 0, end = 0;  // [begin, end)
    std::string perms;                 // "r-xp"
    std::string path;                  // empty for anonymous mappings
    long privateDirtyKb = -1, sharedDirtyKb = -1, anonymousKb = -1, rssKb = -1;
};

/// Parses the text of /proc/PID/smaps (a mapping's header line, then its "Key: value kB"
/// lines). Lines of another form are ignored.
std::vector<SmapsMapping> parseSmaps(std::istream& in);

/// Whether a mapping is of one of `libraries`: its file name contains one of them.
bool mapsLibrary(const SmapsMapping& m, const std::vector<std::string>& libraries);

/// Whether a mapping may be released: its file name contains one of `libraries`, it is
/// private, readable and executable and not writable, and it holds no dirty or anonymous page.
bool releasableLibraryText(const SmapsMapping& m, const std::vector<std::string>& libraries);

/// Releases the resident pages of this process's releasable mappings of `libraries`
/// (madvise MADV_DONTNEED); returns the resident kilobytes they held.
size_t releaseLibraryText(const std::vector<std::string>& libraries);

/// The libraries an OpenCL driver may have loaded whose text is released after set-up:
/// LLVM and Clang (PoCL, Mesa).
const std::vector<std::string>& openClCompilerLibraries();

}  // namespace ub
