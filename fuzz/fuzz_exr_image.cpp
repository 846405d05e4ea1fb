// OpenEXR images (core/image.h) as the loaders read textures and environment maps: readExr by
// path, with its metadata.
#include "core/image.h"
#include "fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    ub::fuzz::limitThreads();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string path = ub::fuzz::writeTemp("image.exr", data, size);
    ub::fuzz::runGuarded([&] {
        ub::ImageMetadata meta;
        ub::readExr(path, &meta);
    });
    return 0;
}
