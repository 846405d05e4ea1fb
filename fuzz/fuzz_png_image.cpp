// PNG images (core/image.h) as the loaders read textures: readPng by path, sRGB-decoded
// (linearize = true) or raw, chosen by the input's size.
#include "core/image.h"
#include "fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    ub::fuzz::limitThreads();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string path = ub::fuzz::writeTemp("image.png", data, size);
    ub::fuzz::runGuarded([&] { ub::readPng(path, size % 2 == 0); });
    return 0;
}
