// JPEG images (core/image.h) as the loaders read textures: readJpeg by path, sRGB-decoded
// (linearize = true) or raw, chosen by the input's size. libjpeg's memory is capped at 1 GB
// by readJpeg itself (a progressive header announcing a huge image is an error, not an
// allocation).
#include "core/image.h"
#include "fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    ub::fuzz::limitThreads();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string path = ub::fuzz::writeTemp("image.jpg", data, size);
    ub::fuzz::runGuarded([&] { ub::readJpeg(path, size % 2 == 0); });
    return 0;
}
