// PLY meshes (scene/mesh_io.h) as the scene loaders read them: loadMeshFile, which reports
// bad contents as diagnostics and never throws for them: here any exception is a finding.
#include "fuzz/fuzz_common.h"
#include "scene/mesh_io.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    ub::fuzz::limitThreads();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string path = ub::fuzz::writeTemp("mesh.ply", data, size);
    ub::Diagnostics diags;
    ub::loadMeshFile(path, diags, "/shapes/0");
    return 0;
}
