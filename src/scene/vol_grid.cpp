#include "scene/vol_grid.h"

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.h"

namespace ub {

namespace {

constexpr size_t kHeaderBytes = 48;

int32_t readI32(const unsigned char* p) {
    uint32_t v = uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
    int32_t r;
    std::memcpy(&r, &v, 4);
    return r;
}

float readF32(const unsigned char* p) {
    uint32_t v = uint32_t(readI32(p));
    float f;
    std::memcpy(&f, &v, 4);
    return f;
}

}  // namespace

VolGrid readVolFile(const std::string& path) {
    auto fail = [&](const std::string& what) {
        throw InputError(path, "invalid .vol file: " + what);
    };
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
        throw InputError(path, "cannot open the .vol file (not found or not a file)");
    std::ifstream in(path, std::ios::binary);
    const uintmax_t fileBytes = std::filesystem::file_size(path, ec);
    if (!in || ec) throw InputError(path, "cannot open the .vol file (not readable)");
    // The header is validated before the voxels are read: a file whose header is garbage is
    // not read whole into memory.
    std::vector<unsigned char> bytes(kHeaderBytes);
    in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(kHeaderBytes));
    if (size_t(in.gcount()) < kHeaderBytes)
        fail("the file has " + std::to_string(in.gcount()) + " bytes, shorter than the " +
             std::to_string(kHeaderBytes) + "-byte header");
    const unsigned char* h = bytes.data();
    if (h[0] != 'V' || h[1] != 'O' || h[2] != 'L')
        fail("missing the 'VOL' magic at the start (not a Mitsuba volume file)");
    if (h[3] != 3) fail("version " + std::to_string(int(h[3])) + " (expected 3)");
    int32_t encoding = readI32(h + 4);
    if (encoding != 1)
        fail("encoding " + std::to_string(encoding) +
             " (expected 1 = float32; Mitsuba 3 reads no other encoding)");
    VolGrid v;
    v.nx = readI32(h + 8);
    v.ny = readI32(h + 12);
    v.nz = readI32(h + 16);
    v.channels = readI32(h + 20);
    if (v.nx <= 0 || v.ny <= 0 || v.nz <= 0)
        fail("resolution " + std::to_string(v.nx) + " x " + std::to_string(v.ny) + " x " +
             std::to_string(v.nz) + " (expected positive sizes)");
    if (v.channels != 1 && v.channels != 3)
        fail(std::to_string(v.channels) + " channels (expected 1: density, or 3: RGB albedo)");
    for (int a = 0; a < 3; ++a) {
        v.bboxMin[a] = readF32(h + 24 + 4 * a);
        v.bboxMax[a] = readF32(h + 36 + 4 * a);
    }
    if (!isFinite(v.bboxMin) || !isFinite(v.bboxMax) || !(v.bboxMin.x < v.bboxMax.x) ||
        !(v.bboxMin.y < v.bboxMax.y) || !(v.bboxMin.z < v.bboxMax.z))
        fail("empty, inverted or non-finite bounding box in the header");
    const uint64_t count = uint64_t(v.nx) * uint64_t(v.ny) * uint64_t(v.nz) * uint64_t(v.channels);
    if (count > (uint64_t(1) << 32)) fail("more than 2^32 values (a corrupt header?)");
    const uint64_t expected = kHeaderBytes + count * 4;
    if (fileBytes != expected) {
        std::ostringstream os;
        os << "the header announces " << v.nx << " x " << v.ny << " x " << v.nz << " x "
           << v.channels << " float32 values (" << expected << " bytes with the header), but "
           << "the file has " << fileBytes << " bytes";
        fail(os.str());
    }
    bytes.resize(size_t(expected));
    in.read(reinterpret_cast<char*>(bytes.data() + kHeaderBytes),
            std::streamsize(expected - kHeaderBytes));
    if (uint64_t(in.gcount()) != expected - kHeaderBytes)
        fail("reading the voxels failed after " + std::to_string(in.gcount()) + " bytes");
    h = bytes.data();
    v.values.resize(size_t(count));
    for (size_t i = 0; i < count; ++i) {
        float f = readF32(h + kHeaderBytes + 4 * i);
        if (!std::isfinite(f)) {
            size_t voxel = i / size_t(v.channels);
            size_t x = voxel % size_t(v.nx), y = (voxel / size_t(v.nx)) % size_t(v.ny),
                   z = voxel / (size_t(v.nx) * size_t(v.ny));
            fail("non-finite value at voxel (" + std::to_string(x) + ", " + std::to_string(y) +
                 ", " + std::to_string(z) + "), channel " + std::to_string(i % size_t(v.channels)));
        }
        v.values[i] = f;
    }
    return v;
}

DenseFloatGrid volChannelToDense(const VolGrid& vol, int channel) {
    DenseFloatGrid d(vol.nx, vol.ny, vol.nz);
    for (int z = 0; z < vol.nz; ++z)
        for (int y = 0; y < vol.ny; ++y)
            for (int x = 0; x < vol.nx; ++x) d.at(x, y, z) = vol.at(x, y, z, channel);
    return d;
}

Transform volCellToUnitCube(const VolGrid& vol) {
    return Transform::scale(Vec3(1.0f / float(vol.nx), 1.0f / float(vol.ny), 1.0f / float(vol.nz)));
}

}  // namespace ub
