// Mitsuba .serialized meshes (scene/serialized_mesh.h) and the XML `serialized` shape:
// versions 3 and 4, float32/float64, normals, uvs, colours, face normals, shape_index through
// the end-of-file dictionary, to_world; every kind of truncated or corrupt file is an error
// naming the file and what is wrong. Files are written here from the format description
// (tests/data/mitsuba/meshes/quads.serialized is made by tools/make_serialized_mesh.py).
#include "scene/serialized_mesh.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "scene/io/mitsuba_loader.h"
#include "tests/support/temp_file.h"

using namespace ub;
namespace fs = std::filesystem;

namespace {

using Bytes = std::string;

void put16(Bytes& b, uint16_t v) {
    b.append(reinterpret_cast<const char*>(&v), 2);
}
void put32(Bytes& b, uint32_t v) {
    b.append(reinterpret_cast<const char*>(&v), 4);
}
void put64(Bytes& b, uint64_t v) {
    b.append(reinterpret_cast<const char*>(&v), 8);
}
void putReal(Bytes& b, double v, bool isDouble) {
    if (isDouble) {
        b.append(reinterpret_cast<const char*>(&v), 8);
    } else {
        float f = float(v);
        b.append(reinterpret_cast<const char*>(&f), 4);
    }
}

Bytes compress(const Bytes& raw) {
    uLongf size = compressBound(uLong(raw.size()));
    Bytes out(size, '\0');
    EXPECT_EQ(::compress(reinterpret_cast<Bytef*>(&out[0]), &size,
                         reinterpret_cast<const Bytef*>(raw.data()), uLong(raw.size())),
              Z_OK);
    out.resize(size);
    return out;
}

struct ShapeSpec {
    uint16_t version = 3;
    bool isDouble = false, normals = false, uvs = false, colors = false, faceNormalsFlag = false;
    float shiftX = 0;
    std::vector<uint32_t> faces = {0, 1, 2, 0, 2, 3};
    uint64_t vertexCountOverride = 0;  ///< announce another count (corrupt header)
};

/// The uncompressed body of one shape (a unit quad in z = 0, shifted by shiftX).
Bytes body(const ShapeSpec& s) {
    Bytes b;
    uint32_t flags = (s.isDouble ? 0x2000 : 0x1000) | (s.normals ? 1 : 0) | (s.uvs ? 2 : 0) |
                     (s.colors ? 8 : 0) | (s.faceNormalsFlag ? 0x10 : 0);
    put32(b, flags);
    if (s.version == 4) b += std::string("quad") + '\0';
    put64(b, s.vertexCountOverride ? s.vertexCountOverride : 4);
    put64(b, s.faces.size() / 3);
    const double p[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    for (const auto& v : p) {
        putReal(b, v[0] + s.shiftX, s.isDouble);
        putReal(b, v[1], s.isDouble);
        putReal(b, v[2], s.isDouble);
    }
    if (s.normals)
        for (int i = 0; i < 4; ++i)
            for (double c : {0.0, 0.0, 2.0}) putReal(b, c, s.isDouble);  // normalised on load
    if (s.uvs)
        for (const auto& v : p) {
            putReal(b, v[0], s.isDouble);
            putReal(b, v[1], s.isDouble);
        }
    if (s.colors)
        for (int i = 0; i < 12; ++i) putReal(b, 0.5, s.isDouble);
    for (uint32_t i : s.faces) put32(b, i);
    return b;
}

Bytes shapeBytes(const ShapeSpec& s) {
    Bytes b;
    put16(b, 0x041C);
    put16(b, s.version);
    return b + compress(body(s));
}

/// Shapes concatenated, then the dictionary (offsets, count).
Bytes file(const std::vector<ShapeSpec>& shapes) {
    Bytes b;
    std::vector<uint64_t> offsets;
    for (const ShapeSpec& s : shapes) {
        offsets.push_back(b.size());
        b += shapeBytes(s);
    }
    for (uint64_t o : offsets) {
        if (shapes[0].version == 4)
            put64(b, o);
        else
            put32(b, uint32_t(o));
    }
    put32(b, uint32_t(shapes.size()));
    return b;
}

std::string writeTemp(const std::string& name, const Bytes& data) {
    const fs::path d = ub::test::scratchFolder("serialized_test");
    std::string path = (d / name).string();
    std::ofstream(path, std::ios::binary) << data;
    return path;
}

/// The first error of loading shape `index` ("" if it loads).
std::string errorOf(const Bytes& data, int index = 0) {
    const std::string path = writeTemp("e.serialized", data);
    Diagnostics diags;
    TriangleMesh m = loadSerializedMesh(path, index, false, diags, "shape");
    for (const Diagnostic& d : diags.all())
        if (!d.warning) return d.message;
    EXPECT_FALSE(m.indices.empty());
    return "";
}

bool contains(const std::string& s, const std::string& part) {
    return s.find(part) != std::string::npos;
}

}  // namespace

TEST(SerializedMesh, ReadsVersionsPrecisionsAndAttributes) {
    ShapeSpec a;
    a.normals = a.uvs = a.colors = true;
    ShapeSpec b;
    b.isDouble = true;
    b.shiftX = 2;
    b.normals = true;
    b.faceNormalsFlag = true;
    for (uint16_t version : {uint16_t(3), uint16_t(4)}) {
        a.version = b.version = version;
        const std::string path = writeTemp("ok.serialized", file({a, b}));
        Diagnostics diags;
        TriangleMesh m0 = loadSerializedMesh(path, 0, false, diags, "shape");
        ASSERT_FALSE(diags.hasErrors()) << diags.all()[0].message;
        ASSERT_EQ(m0.positions.size(), 4u);
        ASSERT_EQ(m0.indices.size(), 6u);
        ASSERT_EQ(m0.normals.size(), 4u);
        EXPECT_FLOAT_EQ(m0.normals[1].z, 1.0f);
        ASSERT_EQ(m0.uvs.size(), 4u);
        EXPECT_FLOAT_EQ(m0.uvs[2].x, 1.0f);
        TriangleMesh m1 = loadSerializedMesh(path, 1, false, diags, "shape");
        ASSERT_FALSE(diags.hasErrors()) << diags.all()[0].message;
        EXPECT_FLOAT_EQ(m1.positions[1].x, 3.0f);  // shape 1 found through the dictionary
        EXPECT_TRUE(m1.normals.empty());           // the file's face-normals flag
        TriangleMesh f = loadSerializedMesh(path, 0, true, diags, "shape");
        EXPECT_TRUE(f.normals.empty());  // face_normals = true
    }
}

TEST(SerializedMesh, TruncatedAndCorruptFilesAreErrors) {
    ShapeSpec s;
    s.normals = true;
    const Bytes good = file({s, s});
    EXPECT_EQ(errorOf(good), "");
    EXPECT_TRUE(contains(errorOf(""), "too short for the 4-byte header")) << errorOf("");
    Bytes badMagic = good;
    badMagic[0] = 'X';
    EXPECT_TRUE(contains(errorOf(badMagic), "not a Mitsuba .serialized file")) << errorOf(badMagic);
    Bytes v5 = good;
    v5[2] = 5;
    EXPECT_TRUE(contains(errorOf(v5), "format version 5 is not supported (expected 3 or 4)"))
        << errorOf(v5);
    // Truncated inside the compressed data of shape 0.
    const Bytes cut = shapeBytes(s).substr(0, 30);
    EXPECT_TRUE(contains(errorOf(cut), "the file ends inside the compressed data")) << errorOf(cut);
    // Corrupt compressed bytes.
    Bytes corrupt = good;
    for (size_t i = 8; i < 24; ++i) corrupt[i] = char(0xA5);
    EXPECT_TRUE(contains(errorOf(corrupt), "corrupt compressed data")) << errorOf(corrupt);
    // An index beyond the vertices.
    ShapeSpec badIndex = s;
    badIndex.faces = {0, 1, 7};
    EXPECT_TRUE(contains(errorOf(file({badIndex})),
                         "triangle 0 has vertex index 7 (the shape has 4 "
                         "vertices)"))
        << errorOf(file({badIndex}));
    // A vertex count the data cannot hold, and one beyond what the file could ever decompress.
    ShapeSpec more = s;
    more.vertexCountOverride = 5;
    EXPECT_TRUE(contains(errorOf(file({more})), "the compressed data end before the"))
        << errorOf(file({more}));
    ShapeSpec huge = s;
    huge.vertexCountOverride = uint64_t(1) << 31;
    EXPECT_TRUE(contains(errorOf(file({huge})), "more than the")) << errorOf(file({huge}));
    // shape_index beyond the dictionary, a dictionary beyond the file, a bad offset.
    EXPECT_TRUE(contains(errorOf(good, 2),
                         "shape_index 2 is out of range: the file holds 2 shapes "
                         "(0..1)"))
        << errorOf(good, 2);
    Bytes badCount = good;
    badCount[badCount.size() - 1] = char(0x7f);
    EXPECT_TRUE(contains(errorOf(badCount, 1), "the shape dictionary announces"))
        << errorOf(badCount, 1);
    Bytes badOffset = good;
    badOffset[badOffset.size() - 8] = char(0x01);  // offset of shape 1 moved by one byte
    EXPECT_TRUE(contains(errorOf(badOffset, 1), "no shape header at offset"))
        << errorOf(badOffset, 1);
    // Flags without a precision.
    Bytes noPrecision;
    put16(noPrecision, 0x041C);
    put16(noPrecision, 3);
    Bytes raw = body(s);
    raw[1] = 0;  // clears 0x1000
    noPrecision += compress(raw);
    EXPECT_TRUE(contains(errorOf(noPrecision), "must set exactly one of single"))
        << errorOf(noPrecision);
}

TEST(SerializedMesh, XmlShapeWithShapeIndexAndToWorld) {
    const std::string dir = std::string(UNIBEAM_SOURCE_DIR) + "/tests/data/mitsuba";
    const std::string text = R"(<scene version="3.0.0">
<sensor type="perspective"><film type="hdrfilm"><integer name="width" value="8"/>
<integer name="height" value="8"/></film></sensor>
<shape type="serialized"><string name="filename" value="meshes/quads.serialized"/>
  <integer name="shape_index" value="1"/>
  <transform name="to_world"><translate y="5"/></transform></shape>
<shape type="serialized"><string name="filename" value="meshes/quads.serialized"/>
  <boolean name="face_normals" value="true"/></shape>
<emitter type="constant"/>
</scene>
)";
    auto scene = loadMitsubaSceneFromString(text, "scene.xml", dir);
    ASSERT_EQ(scene->shapes.size(), 2u);
    EXPECT_FLOAT_EQ(scene->shapes[0].bounds.lo.x, 2.0f);
    EXPECT_FLOAT_EQ(scene->shapes[0].bounds.lo.y, 5.0f);
    EXPECT_FLOAT_EQ(scene->shapes[1].bounds.hi.x, 1.0f);
    std::string bad = text;
    bad.replace(bad.find("value=\"1\""), 9, "value=\"4\"");
    try {
        loadMitsubaSceneFromString(bad, "scene.xml", dir);
        ADD_FAILURE() << "expected an error";
    } catch (const InputError& e) {
        EXPECT_TRUE(contains(e.what(), "scene.xml:4:26: error: <shape type=\"serialized\">: "))
            << e.what();
        EXPECT_TRUE(contains(e.what(),
                             "quads.serialized: error: at <shape type=\"serialized\">: invalid "
                             ".serialized file: shape_index 4 is out of range: the file "
                             "holds 2 shapes (0..1)"))
            << e.what();
    }
}
