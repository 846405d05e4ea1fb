// Mitsuba .serialized meshes (scene/serialized_mesh.h): loadSerializedMesh by path, shape
// index size % 3 (0 reads the first shape, 1 and 2 go through the end-of-file dictionary),
// face normals by the input's parity. Bad contents are diagnostics, never exceptions.
#include "core/error.h"
#include "fuzz/fuzz_common.h"
#include "scene/serialized_mesh.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    ub::fuzz::limitThreads();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string path = ub::fuzz::writeTemp("mesh.serialized", data, size);
    ub::fuzz::runGuarded([&] {
        ub::Diagnostics diags;
        ub::loadSerializedMesh(path, int(size % 3), size % 2 == 1, diags, "shape");
    });
    return 0;
}
