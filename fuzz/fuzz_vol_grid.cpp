// Mitsuba .vol grids (scene/vol_grid.h) as the Mitsuba loader reads them: readVolFile, then
// every channel to a dense grid and its cell-to-unit-cube transform.
#include "fuzz/fuzz_common.h"
#include "scene/vol_grid.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    ub::fuzz::limitThreads();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string path = ub::fuzz::writeTemp("grid.vol", data, size);
    ub::fuzz::runGuarded([&] {
        ub::VolGrid vol = ub::readVolFile(path);
        for (int c = 0; c < vol.channels; ++c) ub::volChannelToDense(vol, c);
        ub::volCellToUnitCube(vol);
    });
    return 0;
}
