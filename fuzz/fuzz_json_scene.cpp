// Native JSON scene loader (scene/io/json_loader.h), from text, with relative paths resolved
// in the bundled scenes/ folder (so textures, meshes and grids the seeds name are read too).
#include "fuzz/fuzz_common.h"
#include "scene/io/json_loader.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    ub::fuzz::limitThreads();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    ub::fuzz::runGuarded([&] {
        std::vector<ub::Diagnostic> warnings;
        ub::loadJsonSceneFromString(text, "fuzz.json", std::string(UNIBEAM_SOURCE_DIR) + "/scenes",
                                    &warnings);
    });
    return 0;
}
