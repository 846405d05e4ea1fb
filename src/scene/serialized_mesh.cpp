#include "scene/serialized_mesh.h"

#include <zlib.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <vector>

#include "core/file_status.h"

namespace ub {

namespace {

constexpr uint16_t kMagic = 0x041C;
constexpr uint32_t kHasNormals = 0x0001, kHasUvs = 0x0002, kHasTangents = 0x0004,
                   kHasColors = 0x0008, kFaceNormals = 0x0010, kSingle = 0x1000, kDouble = 0x2000;
/// zlib's largest compression ratio is about 1032:1; decompressed sizes beyond this bound
/// of the remaining compressed bytes cannot be real, so they are rejected before allocating.
constexpr double kMaxInflateRatio = 1100.0;

struct Failure {
    std::string message;
};

uint16_t le16(const unsigned char* p) {
    return uint16_t(p[0] | (p[1] << 8));
}
uint32_t le32(const unsigned char* p) {
    return uint32_t(p[0]) | (uint32_t(p[1]) << 8) | (uint32_t(p[2]) << 16) | (uint32_t(p[3]) << 24);
}
uint64_t le64(const unsigned char* p) {
    return uint64_t(le32(p)) | (uint64_t(le32(p + 4)) << 32);
}

std::string hex(uint32_t v) {
    std::ostringstream s;
    s << "0x" << std::hex << v;
    return s.str();
}

/// Reads a zlib stream from memory, exactly as many bytes as asked for.
class Inflater {
  public:
    Inflater(const unsigned char* data, size_t size) {
        std::memset(&z_, 0, sizeof(z_));
        if (inflateInit(&z_) != Z_OK) throw Failure{"cannot initialise zlib"};
        z_.next_in = const_cast<unsigned char*>(data);
        z_.avail_in = uInt(std::min<size_t>(size, std::numeric_limits<uInt>::max()));
    }
    ~Inflater() { inflateEnd(&z_); }
    Inflater(const Inflater&) = delete;
    Inflater& operator=(const Inflater&) = delete;

    /// Compressed bytes not yet read.
    size_t remainingInput() const { return z_.avail_in; }

    void read(void* out, size_t n, const std::string& what) {
        auto* dst = static_cast<unsigned char*>(out);
        while (n > 0) {
            if (ended_)
                throw Failure{"the compressed data end before the " + what +
                              " (the header announces more data than the shape holds)"};
            const size_t chunk = std::min<size_t>(n, size_t(1) << 30);
            z_.next_out = dst;
            z_.avail_out = uInt(chunk);
            while (z_.avail_out > 0) {
                const int ret = inflate(&z_, Z_NO_FLUSH);
                if (ret == Z_STREAM_END) {
                    ended_ = true;
                    break;
                }
                if (ret == Z_BUF_ERROR || (ret == Z_OK && z_.avail_in == 0 && z_.avail_out > 0))
                    throw Failure{"the file ends inside the compressed data, in the " + what +
                                  " (truncated file)"};
                if (ret != Z_OK)
                    throw Failure{"corrupt compressed data in the " + what + " (zlib: " +
                                  (z_.msg ? z_.msg : "error " + std::to_string(ret)) + ")"};
            }
            const size_t got = chunk - z_.avail_out;
            if (got < chunk)
                throw Failure{"the compressed data end before the " + what +
                              " (the header announces more data than the shape holds)"};
            dst += got;
            n -= got;
        }
    }

    /// Throws unless `bytes` more decompressed bytes are plausible from the input left.
    void checkPlausible(double bytes, const std::string& what) const {
        if (bytes > kMaxInflateRatio * double(z_.avail_in) + 65536.0)
            throw Failure{"the header announces " + what + " (" + std::to_string(uint64_t(bytes)) +
                          " bytes), more than the " + std::to_string(z_.avail_in) +
                          " compressed bytes left in the file can hold (corrupt header or "
                          "truncated file)"};
    }

  private:
    z_stream z_;
    bool ended_ = false;
};

/// n x dim values stored as float32 or float64 (dst may be null: read and dropped).
void readReals(Inflater& in, bool isDouble, size_t n, int dim, std::vector<float>* dst,
               const std::string& what) {
    const size_t count = n * size_t(dim);
    if (dst) dst->resize(count);
    const size_t block = 1 << 16;
    std::vector<unsigned char> buf;
    const size_t size = isDouble ? 8 : 4;
    for (size_t done = 0; done < count; done += block) {
        const size_t m = std::min(block, count - done);
        buf.resize(m * size);
        in.read(buf.data(), buf.size(), what);
        if (!dst) continue;
        for (size_t i = 0; i < m; ++i) {
            float v;
            if (isDouble) {
                uint64_t bits = le64(&buf[i * 8]);
                double d;
                std::memcpy(&d, &bits, 8);
                v = float(d);
            } else {
                uint32_t bits = le32(&buf[i * 4]);
                std::memcpy(&v, &bits, 4);
            }
            (*dst)[done + i] = v;
        }
    }
}

TriangleMesh readShape(const std::vector<unsigned char>& file, size_t start, uint16_t version,
                       bool faceNormalsParam, std::vector<std::string>* warnings) {
    Inflater in(file.data() + start + 4, file.size() - start - 4);
    unsigned char word[8];
    in.read(word, 4, "flags");
    const uint32_t flags = le32(word);
    const uint32_t known =
        kHasNormals | kHasUvs | kHasTangents | kHasColors | kFaceNormals | kSingle | kDouble;
    if (flags & ~known)
        throw Failure{"unknown flags " + hex(flags & ~known) + " in the flag word " + hex(flags)};
    if (bool(flags & kSingle) == bool(flags & kDouble))
        throw Failure{"the flag word " + hex(flags) +
                      " must set exactly one of single (0x1000) and double (0x2000) precision"};
    if (version == 4) {  // the shape's name, NUL-terminated
        for (int i = 0;; ++i) {
            if (i == 4096) throw Failure{"the shape name is not NUL-terminated within 4096 bytes"};
            unsigned char c;
            in.read(&c, 1, "shape name");
            if (c == 0) break;
        }
    }
    in.read(word, 8, "vertex count");
    const uint64_t vertexCount = le64(word);
    in.read(word, 8, "triangle count");
    const uint64_t triangleCount = le64(word);
    if (vertexCount == 0 || triangleCount == 0)
        throw Failure{"the shape has " + std::to_string(vertexCount) + " vertices and " +
                      std::to_string(triangleCount) + " triangles (expected at least 1 of each)"};
    if (vertexCount > std::numeric_limits<uint32_t>::max() ||
        triangleCount > std::numeric_limits<uint32_t>::max() / 3)
        throw Failure{"the shape has " + std::to_string(vertexCount) + " vertices and " +
                      std::to_string(triangleCount) +
                      " triangles, more than 32-bit indices can address"};
    const bool isDouble = flags & kDouble;
    const int perVertex = 3 + ((flags & kHasNormals) ? 3 : 0) + ((flags & kHasUvs) ? 2 : 0) +
                          ((flags & kHasColors) ? 3 : 0);
    in.checkPlausible(
        double(vertexCount) * perVertex * (isDouble ? 8 : 4) + double(triangleCount) * 12.0,
        std::to_string(vertexCount) + " vertices and " + std::to_string(triangleCount) +
            " triangles");
    const size_t nv = size_t(vertexCount), nt = size_t(triangleCount);
    TriangleMesh mesh;
    std::vector<float> values;
    readReals(in, isDouble, nv, 3, &values, "vertex positions");
    mesh.positions.resize(nv);
    for (size_t v = 0; v < nv; ++v) {
        mesh.positions[v] = Vec3(values[3 * v], values[3 * v + 1], values[3 * v + 2]);
        if (!isFinite(mesh.positions[v]))
            throw Failure{"non-finite position at vertex " + std::to_string(v)};
    }
    const bool useFaceNormals = faceNormalsParam || (flags & kFaceNormals);
    if (flags & kHasNormals) {
        readReals(in, isDouble, nv, 3, useFaceNormals ? nullptr : &values, "vertex normals");
        if (!useFaceNormals) {
            mesh.normals.resize(nv);
            size_t bad = 0;
            for (size_t v = 0; v < nv; ++v) {
                Vec3 n(values[3 * v], values[3 * v + 1], values[3 * v + 2]);
                if (!isFinite(n) || !(length(n) > 0)) ++bad;
                mesh.normals[v] = n;
            }
            if (bad > 0) {
                warnings->push_back(std::to_string(bad) +
                                    " vertex normals are zero or not finite; the mesh uses face "
                                    "normals");
                mesh.normals.clear();
            } else {
                for (Vec3& n : mesh.normals) n = normalize(n);
            }
        }
    }
    if (flags & kHasUvs) {
        readReals(in, isDouble, nv, 2, &values, "texture coordinates");
        mesh.uvs.resize(nv);
        for (size_t v = 0; v < nv; ++v) {
            mesh.uvs[v] = Vec2(values[2 * v], values[2 * v + 1]);
            if (!std::isfinite(mesh.uvs[v].x) || !std::isfinite(mesh.uvs[v].y))
                throw Failure{"non-finite texture coordinates at vertex " + std::to_string(v)};
        }
    }
    if (flags & kHasColors) readReals(in, isDouble, nv, 3, nullptr, "vertex colours");
    mesh.indices.resize(3 * nt);
    std::vector<unsigned char> buf;
    const size_t block = 1 << 16;
    for (size_t done = 0; done < 3 * nt; done += block) {
        const size_t m = std::min(block, 3 * nt - done);
        buf.resize(4 * m);
        in.read(buf.data(), buf.size(), "triangle indices");
        for (size_t i = 0; i < m; ++i) {
            const uint32_t idx = le32(&buf[4 * i]);
            if (idx >= nv)
                throw Failure{"triangle " + std::to_string((done + i) / 3) + " has vertex index " +
                              std::to_string(idx) + " (the shape has " + std::to_string(nv) +
                              " vertices)"};
            mesh.indices[done + i] = idx;
        }
    }
    // Zero-area triangles are dropped (Embree cannot intersect them meaningfully).
    std::vector<uint32_t> kept;
    kept.reserve(mesh.indices.size());
    size_t dropped = 0;
    for (size_t t = 0; t < nt; ++t) {
        const uint32_t* i = &mesh.indices[3 * t];
        const float a = length(cross(mesh.positions[i[1]] - mesh.positions[i[0]],
                                     mesh.positions[i[2]] - mesh.positions[i[0]]));
        if (!(a > 0.0f) || !std::isfinite(a)) {
            ++dropped;
            continue;
        }
        kept.insert(kept.end(), i, i + 3);
    }
    if (kept.empty())
        throw Failure{"no triangle has a non-zero area (all " + std::to_string(nt) +
                      " are degenerate)"};
    if (dropped > 0)
        warnings->push_back("dropped " + std::to_string(dropped) +
                            " degenerate (zero-area) triangle" + (dropped == 1 ? "" : "s"));
    mesh.indices = std::move(kept);
    return mesh;
}

}  // namespace

TriangleMesh loadSerializedMesh(const std::string& path, int shapeIndex, bool faceNormals,
                                Diagnostics& diags, const std::string& where) {
    auto fail = [&](const std::string& msg) {
        diags.error(Diagnostic{path, 0, 0, where, msg});
        return TriangleMesh();
    };
    if (isDirectory(path)) return fail("cannot open the .serialized file (it is a directory)");
    std::ifstream f(path, std::ios::binary);
    if (!f)
        return fail(std::string("cannot open the .serialized file (") + std::strerror(errno) + ")");
    std::vector<unsigned char> file((std::istreambuf_iterator<char>(f)),
                                    std::istreambuf_iterator<char>());
    if (f.bad()) return fail("cannot read the .serialized file");
    try {
        if (file.size() < 4)
            throw Failure{"the file has " + std::to_string(file.size()) +
                          " bytes, too short for the 4-byte header"};
        const uint16_t magic = le16(file.data()), version = le16(file.data() + 2);
        if (magic != kMagic)
            throw Failure{"not a Mitsuba .serialized file (the first two bytes are " + hex(magic) +
                          ", expected the identifier 0x41c)"};
        if (version != 3 && version != 4)
            throw Failure{"format version " + std::to_string(version) +
                          " is not supported (expected 3 or 4)"};
        size_t start = 0;
        if (shapeIndex < 0) throw Failure{"shape_index must be >= 0"};
        if (shapeIndex > 0) {
            // The dictionary at the end: one offset per shape, then the uint32 shape count.
            if (file.size() < 8) throw Failure{"the file is too short for its shape dictionary"};
            const uint32_t count = le32(&file[file.size() - 4]);
            const size_t entry = version == 4 ? 8 : 4;
            if (uint64_t(count) * entry + 4 + 4 > file.size())
                throw Failure{"the shape dictionary announces " + std::to_string(count) +
                              " shapes, more than the file can hold (corrupt or truncated file)"};
            if (uint32_t(shapeIndex) >= count)
                throw Failure{"shape_index " + std::to_string(shapeIndex) +
                              " is out of range: the file holds " + std::to_string(count) +
                              " shape" + (count == 1 ? "" : "s") +
                              (count > 0 ? " (0.." + std::to_string(count - 1) + ")" : "")};
            const size_t at = file.size() - 4 - entry * (count - uint32_t(shapeIndex));
            const uint64_t offset = version == 4 ? le64(&file[at]) : le32(&file[at]);
            // (offset + 4 would wrap for an offset near 2^64: compared without the sum.)
            if (offset > at || at - offset < 4)
                throw Failure{"the dictionary gives shape " + std::to_string(shapeIndex) +
                              " the offset " + std::to_string(offset) +
                              ", outside the file's shape data"};
            start = size_t(offset);
            if (le16(&file[start]) != kMagic || le16(&file[start + 2]) != version)
                throw Failure{"no shape header at offset " + std::to_string(offset) +
                              " given by the dictionary for shape " + std::to_string(shapeIndex)};
        }
        std::vector<std::string> warnings;
        TriangleMesh mesh;
        try {
            mesh = readShape(file, start, version, faceNormals, &warnings);
        } catch (const Failure& e) {
            throw Failure{"shape " + std::to_string(shapeIndex) + ": " + e.message};
        }
        for (const std::string& w : warnings)
            diags.warning(
                Diagnostic{path, 0, 0, where, "shape " + std::to_string(shapeIndex) + ": " + w});
        return mesh;
    } catch (const Failure& e) {
        return fail("invalid .serialized file: " + e.message);
    } catch (const std::bad_alloc&) {
        return fail("invalid .serialized file: not enough memory for the announced shape");
    }
}

}  // namespace ub
