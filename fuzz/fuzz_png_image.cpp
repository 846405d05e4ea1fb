// PNG images (core/image.h) as the loaders read textures: readPng by path, sRGB-decoded
// (linearize = true) or raw, chosen by the input's size.
//
// Inputs whose IHDR announces more than 2^22 pixels are not decoded: readPng bounds what it
// allocates by the file size (deflate's 1032:1), but within that bound a 4 KB 1-bit image may
// still decode to a few hundred MB of float pixels, legitimately, and ASan's allocator keeps
// such memory across inputs until the process passes libFuzzer's 2 GB limit (live heap at the
// time: 24 MB). Large headers themselves are covered by the regression test
// (tests/data/fuzz-regressions/fuzz_png_image/).
#include "core/image.h"
#include "fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    ub::fuzz::limitThreads();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size >= 24) {
        auto be32 = [&](size_t o) {
            return uint64_t(data[o]) << 24 | uint64_t(data[o + 1]) << 16 |
                   uint64_t(data[o + 2]) << 8 | uint64_t(data[o + 3]);
        };
        if (be32(16) * be32(20) > (uint64_t(1) << 22)) return 0;
    }
    const std::string path = ub::fuzz::writeTemp("image.png", data, size);
    ub::fuzz::runGuarded([&] { ub::readPng(path, size % 2 == 0); });
    return 0;
}
