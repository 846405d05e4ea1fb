// Mitsuba 3 XML loader (scene/io/mitsuba_loader.h), by path. The input is main.xml, then
// after a NUL byte inc.xml, which main.xml may <include filename="inc.xml"/> (and which may
// include itself or main.xml: include cycles must be errors). The folder also has
// textures/ and volumes/, links to tests/data/mitsuba/, for the files the seeds name.
#include "fuzz/fuzz_common.h"
#include "scene/io/mitsuba_loader.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    ub::fuzz::limitThreads();
    namespace fs = std::filesystem;
    const fs::path data = fs::path(UNIBEAM_SOURCE_DIR) / "tests/data/mitsuba";
    for (const char* sub : {"textures", "volumes"}) {
        std::error_code ec;
        fs::create_directory_symlink(data / sub, ub::fuzz::tempDir() / sub, ec);
    }
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::vector<std::string> parts = ub::fuzz::splitParts(data, size, 2);
    const std::string main = ub::fuzz::writeTemp("main.xml", parts[0]);
    ub::fuzz::writeTemp("inc.xml", parts[1]);
    ub::fuzz::runGuarded([&] {
        std::vector<ub::Diagnostic> warnings;
        ub::loadMitsubaScene(main, {}, &warnings);
    });
    return 0;
}
