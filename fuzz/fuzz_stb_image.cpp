// BMP, TGA, RGBE and PNM images (core/image_stb.cpp, stb_image) as the loaders read
// textures: readBitmapFile by path. The input's first byte chooses the format (the file's
// extension: % 4 = 0 bmp, 1 tga, 2 hdr, 3 ppm), the rest is the file; sRGB-decoded or raw by
// the input's size. Headers announcing more pixels than
// the file can hold are errors before stb allocates.
#include "core/image.h"
#include "fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    ub::fuzz::limitThreads();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const char* const kNames[4] = {"image.bmp", "image.tga", "image.hdr", "image.ppm"};
    if (size == 0) return 0;
    const std::string path = ub::fuzz::writeTemp(kNames[data[0] % 4], data + 1, size - 1);
    ub::fuzz::runGuarded([&] { ub::readBitmapFile(path, size % 2 == 0); });
    return 0;
}
