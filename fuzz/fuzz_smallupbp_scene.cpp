// SmallUPBP loader (scene/io/smallupbp_loader.h): the input is scene.obj, NUL, scene.obj.aux,
// NUL, scene.mtl (the seeds' OBJ says "mtllib scene.mtl"), written to files and loaded by
// path.
#include "fuzz/fuzz_common.h"
#include "scene/io/smallupbp_loader.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    ub::fuzz::limitThreads();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::vector<std::string> parts = ub::fuzz::splitParts(data, size, 3);
    const std::string obj = ub::fuzz::writeTemp("scene.obj", parts[0]);
    ub::fuzz::writeTemp("scene.obj.aux", parts[1]);
    ub::fuzz::writeTemp("scene.mtl", parts[2]);
    ub::fuzz::runGuarded([&] {
        std::vector<ub::Diagnostic> warnings;
        ub::loadSmallUpbpScene(obj, &warnings);
    });
    return 0;
}
