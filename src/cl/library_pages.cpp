// Giving back the clean text pages of LLVM after OpenCL set-up (cl/library_pages.h).
#include "cl/library_pages.h"

#include <cstdio>
#include <fstream>
#include <sstream>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace ub {

std::vector<SmapsMapping> parseSmaps(std::istream& in) {
    std::vector<SmapsMapping> out;
    std::string line;
    while (std::getline(in, line)) {
        unsigned long b = 0, e = 0;
        char perms[8] = {};
        int consumed = 0;
        // A header: "begin-end perms offset dev inode [path]".
        if (std::sscanf(line.c_str(), "%lx-%lx %7s %*s %*s %*s%n", &b, &e, perms, &consumed) == 3 &&
            consumed > 0) {
            SmapsMapping m;
            m.begin = b;
            m.end = e;
            m.perms = perms;
            const size_t slash = line.find('/', size_t(consumed));
            if (slash != std::string::npos) m.path = line.substr(slash);
            out.push_back(m);
            continue;
        }
        if (out.empty()) continue;
        const size_t colon = line.find(':');
        if (colon == std::string::npos) continue;
        const std::string key = line.substr(0, colon);
        long* field = key == "Private_Dirty"  ? &out.back().privateDirtyKb
                      : key == "Shared_Dirty" ? &out.back().sharedDirtyKb
                      : key == "Anonymous"    ? &out.back().anonymousKb
                      : key == "Rss"          ? &out.back().rssKb
                                              : nullptr;
        if (!field) continue;
        std::istringstream value(line.substr(colon + 1));
        long kb = -1;
        if (value >> kb) *field = kb;
    }
    return out;
}

bool mapsLibrary(const SmapsMapping& m, const std::vector<std::string>& libraries) {
    const std::string name = m.path.substr(m.path.rfind('/') + 1);  // whole path if no '/'
    for (const std::string& lib : libraries)
        if (!name.empty() && name.find(lib) != std::string::npos) return true;
    return false;
}

bool releasableLibraryText(const SmapsMapping& m, const std::vector<std::string>& libraries) {
    if (m.end <= m.begin) return false;
    // Every count must have been read, and be zero: a private page that was ever written
    // (Private_Dirty, Anonymous) would lose the write.
    return mapsLibrary(m, libraries) && m.perms == "r-xp" && m.privateDirtyKb == 0 &&
           m.sharedDirtyKb == 0 && m.anonymousKb == 0;
}

size_t releaseLibraryText(const std::vector<std::string>& libraries) {
#if defined(__linux__)
    std::ifstream in("/proc/self/smaps");
    if (!in) return 0;
    size_t releasedKb = 0;
    for (const SmapsMapping& m : parseSmaps(in))
        if (releasableLibraryText(m, libraries) && m.rssKb > 0 &&
            madvise(reinterpret_cast<void*>(m.begin), m.end - m.begin, MADV_DONTNEED) == 0)
            releasedKb += size_t(m.rssKb);
    return releasedKb;
#else
    (void)libraries;
    return 0;
#endif
}

const std::vector<std::string>& openClCompilerLibraries() {
    static const std::vector<std::string> names = {"libLLVM", "libclang-cpp"};
    return names;
}

}  // namespace ub
