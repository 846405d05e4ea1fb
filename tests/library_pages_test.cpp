// Giving back LLVM's clean text pages after OpenCL set-up (src/cl/library_pages.h): the smaps
// parser, which mappings may be released, and, on the first OpenCL device (PoCL in CI, which
// links LLVM), that set-up leaves LLVM's text out of the resident set while the kernels still
// run afterwards.
#include "cl/library_pages.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <memory>
#include <sstream>

#include "cl/cl_runtime.h"

using namespace ub;

namespace {

const char* kSmaps =
    "7f0000000000-7f0000100000 r-xp 00000000 08:01 42        /usr/lib/libLLVM-15.so.1\n"
    "Size:               1024 kB\n"
    "Rss:                 512 kB\n"
    "Shared_Dirty:          0 kB\n"
    "Private_Clean:       512 kB\n"
    "Private_Dirty:         0 kB\n"
    "Anonymous:             0 kB\n"
    "VmFlags: rd ex mr mw me sd\n"
    "7f0000100000-7f0000110000 r--p 00100000 08:01 42        /usr/lib/libLLVM-15.so.1\n"
    "Rss:                  64 kB\n"
    "Shared_Dirty:          0 kB\n"
    "Private_Dirty:        64 kB\n"
    "Anonymous:            64 kB\n"
    "7f0000200000-7f0000300000 rw-p 00000000 00:00 0 \n"
    "Rss:                 100 kB\n"
    "Shared_Dirty:          0 kB\n"
    "Private_Dirty:       100 kB\n"
    "Anonymous:           100 kB\n"
    "7f0000400000-7f0000500000 r-xp 00000000 08:01 43        /usr/lib/libc.so.6\n"
    "Rss:                 300 kB\n"
    "Shared_Dirty:          0 kB\n"
    "Private_Dirty:         0 kB\n"
    "Anonymous:             0 kB\n"
    "7f0000600000-7f0000700000 r-xp 00000000 08:01 44        /usr/lib/libclang-cpp.so.15\n"
    "Rss:                 200 kB\n"
    "Shared_Dirty:          0 kB\n"
    "Private_Dirty:         4 kB\n"
    "Anonymous:             4 kB\n"
    "7f0000800000-7f0000900000 r-xp 00000000 08:01 44        /usr/lib/libclang-cpp.so.15\n"
    "Rss:                 200 kB\n";

/// Resident kilobytes of this process's mappings of LLVM and Clang, split into the text that
/// may be released and the rest; `mapped` counts the mappings.
struct CompilerPages {
    long releasableKb = 0, otherKb = 0;
    int mapped = 0;
};

CompilerPages compilerPages() {
    std::ifstream in("/proc/self/smaps");
    EXPECT_TRUE(in.good());
    CompilerPages c;
    for (const SmapsMapping& m : parseSmaps(in)) {
        if (!mapsLibrary(m, openClCompilerLibraries())) continue;
        ++c.mapped;
        (releasableLibraryText(m, openClCompilerLibraries()) ? c.releasableKb : c.otherKb) +=
            std::max(0L, m.rssKb);
    }
    return c;
}

}  // namespace

TEST(LibraryPages, ParsesSmaps) {
    std::istringstream in(kSmaps);
    const std::vector<SmapsMapping> m = parseSmaps(in);
    ASSERT_EQ(m.size(), 6u);
    EXPECT_EQ(m[0].begin, 0x7f0000000000ul);
    EXPECT_EQ(m[0].end, 0x7f0000100000ul);
    EXPECT_EQ(m[0].perms, "r-xp");
    EXPECT_EQ(m[0].path, "/usr/lib/libLLVM-15.so.1");
    EXPECT_EQ(m[0].rssKb, 512);
    EXPECT_EQ(m[0].privateDirtyKb, 0);
    EXPECT_EQ(m[1].privateDirtyKb, 64);
    EXPECT_EQ(m[2].path, "");  // anonymous
    EXPECT_EQ(m[2].rssKb, 100);
    EXPECT_EQ(m[5].rssKb, 200);
    EXPECT_EQ(m[5].privateDirtyKb, -1);  // not given
}

TEST(LibraryPages, ReleasesOnlyCleanTextOfTheListedLibraries) {
    std::istringstream in(kSmaps);
    const std::vector<SmapsMapping> m = parseSmaps(in);
    const std::vector<std::string>& libs = openClCompilerLibraries();
    EXPECT_TRUE(releasableLibraryText(m[0], libs));   // LLVM's clean text
    EXPECT_FALSE(releasableLibraryText(m[1], libs));  // relocated read-only data: written
    EXPECT_FALSE(releasableLibraryText(m[2], libs));  // anonymous
    EXPECT_FALSE(releasableLibraryText(m[3], libs));  // not listed
    EXPECT_FALSE(releasableLibraryText(m[4], libs));  // a written page in the text
    EXPECT_FALSE(releasableLibraryText(m[5], libs));  // counts not read: not known clean
    EXPECT_TRUE(releasableLibraryText(m[3], {"libc.so"}));
}

TEST(LibraryPages, OpenClSetUpLeavesLlvmTextOutOfTheResidentSet) {
    // Built from source (no program cache): the build runs LLVM, whose text is then resident.
    std::unique_ptr<ClRuntime> cl;
    ASSERT_NO_THROW(cl = std::make_unique<ClRuntime>(-1, -1, "-"));
    const CompilerPages after = compilerPages();
    // PoCL, the CI device, links LLVM and Clang: the check below is not vacuous.
    ASSERT_GT(after.mapped, 0) << "no LLVM or Clang mapping: the driver does not use them";
    EXPECT_GT(cl->releasedLibraryKb(), 1024u) << "the build made more than 1 MB of LLVM resident";
    // What remains of the text is what ran between the release and this line (none of LLVM).
    EXPECT_LT(after.releasableKb, 1024) << "LLVM's text is still resident after set-up";
    // Every test of tests/opencl_estimate_test.cpp runs its kernels after this release (the
    // constructor's), and PoCL builds each kernel's work-group function at its first launch,
    // calling LLVM on the released pages.
}
