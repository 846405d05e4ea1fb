// make_smoke_vdb: writes the procedural smoke plume that bundled scenes use
// (media/smoke.vdb) with OpenVDB. Deterministic: running it again reproduces
// the committed file's voxels exactly (tests/vdb_grid_test.cpp checks this).
//
//   make_smoke_vdb [output.vdb]      (default: <source dir>/media/smoke.vdb)
//
// The plume: 64^3 voxels over the cube [-0.5, 0.5]^3 (voxel size 1/64), a
// column rising along +y whose radius widens with height and whose axis
// sways, with density falling off quadratically from the axis, faded in at the
// bottom and out at the top, and modulated by 4-octave value-noise fBm (Perlin
// 1985 style lattice noise with smoothstep interpolation). One float grid
// named "density", values in [0, 1], zeros inactive.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>

#include "core/error.h"
#include "scene/vdb_grid.h"

namespace {

// Lattice hash -> [0, 1) (integer mixing from splitmix64).
float latticeValue(int x, int y, int z) {
    uint64_t h = uint64_t(uint32_t(x)) * 0x9E3779B97F4A7C15ull ^
                 uint64_t(uint32_t(y)) * 0xC2B2AE3D27D4EB4Full ^
                 uint64_t(uint32_t(z)) * 0x165667B19E3779F9ull;
    h ^= h >> 31;
    h *= 0xBF58476D1CE4E5B9ull;
    h ^= h >> 29;
    return float(h >> 40) * 0x1p-24f;
}

float smooth(float t) {
    return t * t * (3.0f - 2.0f * t);
}

float valueNoise(float x, float y, float z) {
    int ix = int(std::floor(x)), iy = int(std::floor(y)), iz = int(std::floor(z));
    float fx = smooth(x - ix), fy = smooth(y - iy), fz = smooth(z - iz);
    float v = 0.0f;
    for (int c = 0; c < 8; ++c) {
        int dx = c & 1, dy = (c >> 1) & 1, dz = (c >> 2) & 1;
        float w = (dx ? fx : 1 - fx) * (dy ? fy : 1 - fy) * (dz ? fz : 1 - fz);
        v += w * latticeValue(ix + dx, iy + dy, iz + dz);
    }
    return v;
}

float fbm(float x, float y, float z) {
    float sum = 0.0f, amp = 0.5f, norm = 0.0f;
    for (int o = 0; o < 4; ++o) {
        sum += amp * valueNoise(x, y, z);
        norm += amp;
        x = 2.03f * x + 17.1f;
        y = 2.03f * y + 5.3f;
        z = 2.03f * z - 9.7f;
        amp *= 0.5f;
    }
    return sum / norm;
}

float plumeDensity(float x, float y, float z) {
    const float h = y + 0.5f;  // height in [0, 1]
    const float cx = 0.08f * std::sin(5.0f * h), cz = 0.06f * std::cos(4.0f * h);
    const float radius = 0.08f + 0.25f * h;
    const float d2 = ((x - cx) * (x - cx) + (z - cz) * (z - cz)) / (radius * radius);
    if (d2 >= 1.0f) return 0.0f;
    const float profile = (1.0f - d2) * std::min(1.0f, h / 0.06f) * std::sqrt(1.0f - h);
    const float noise = fbm(6.0f * x, 6.0f * y - 2.0f, 6.0f * z);
    const float density = profile * std::clamp(1.8f * noise - 0.45f, 0.0f, 1.0f);
    return density < 0.02f ? 0.0f : std::min(density, 1.0f);
}

}  // namespace

int main(int argc, char** argv) {
    if (argc > 2 ||
        (argc == 2 && (std::string(argv[1]) == "-h" || std::string(argv[1]) == "--help"))) {
        std::fprintf(stderr, "usage: %s [output.vdb]\n", argv[0]);
        return argc > 2 ? 2 : 0;
    }
    const std::string out =
        argc == 2 ? argv[1] : std::string(UNIBEAM_SOURCE_DIR) + "/media/smoke.vdb";
    const int n = 64;
    ub::DenseFloatGrid dense(n, n, n);
    dense.voxelSize = 1.0f / n;
    dense.origin = ub::Vec3(-0.5f + 0.5f / n);  // voxel centres inside [-0.5, 0.5]^3
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i)
                dense.at(i, j, k) = plumeDensity(dense.origin.x + i * dense.voxelSize,
                                                 dense.origin.y + j * dense.voxelSize,
                                                 dense.origin.z + k * dense.voxelSize);
    try {
        std::filesystem::path dir = std::filesystem::path(out).parent_path();
        if (!dir.empty()) std::filesystem::create_directories(dir);
        ub::writeDenseFloatVdb(out, "density", dense);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "%s\n", e.what());
        return 1;
    }
    size_t active =
        std::count_if(dense.values.begin(), dense.values.end(), [](float v) { return v > 0; });
    std::printf("wrote %s: grid 'density', %dx%dx%d voxels, %zu active\n", out.c_str(), n, n, n,
                active);
    return 0;
}
