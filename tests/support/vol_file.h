// Bytes of a Mitsuba .vol file (format in src/scene/vol_grid.h), for tests that
// write small grids: header fields as given (so tests can also write invalid
// files), then the float32 values in file order (x fastest, channels innermost).
#pragma once

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

namespace ub::test {

inline std::string volBytes(int nx, int ny, int nz, int channels, const std::vector<float>& data,
                            uint8_t version = 3, int32_t encoding = 1) {
    std::string s = "VOL";
    s += char(version);
    auto i32 = [&](int32_t v) { s.append(reinterpret_cast<const char*>(&v), 4); };
    auto f32 = [&](float v) { s.append(reinterpret_cast<const char*>(&v), 4); };
    i32(encoding);
    i32(nx);
    i32(ny);
    i32(nz);
    i32(channels);
    for (float v : {0.f, 0.f, 0.f, 1.f, 1.f, 1.f}) f32(v);
    for (float v : data) f32(v);
    return s;
}

inline void writeBinaryFile(const std::string& path, const std::string& bytes) {
    std::ofstream(path, std::ios::binary) << bytes;
}

}  // namespace ub::test
