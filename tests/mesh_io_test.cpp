// Mesh file loading: OBJ (tinyobjloader) and PLY (scene/ply_reader.h), and every error the
// loader reports, with its message text.
#include "scene/mesh_io.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>

#include "core/error.h"
#include "scene/shapes.h"
#include "tests/support/temp_file.h"

using namespace ub;

namespace {

std::string meshPath(const std::string& name) {
    return std::string(UNIBEAM_TEST_DATA_DIR) + "/meshes/" + name;
}

/// Loads a test mesh that must load without errors.
TriangleMesh loadOk(const std::string& name, Diagnostics* diagsOut = nullptr) {
    Diagnostics diags;
    TriangleMesh m = loadMeshFile(meshPath(name), diags, "/shapes/0");
    EXPECT_FALSE(diags.hasErrors())
        << name << ": " << (diags.all().empty() ? "" : diags.all()[0].format());
    if (diagsOut) *diagsOut = diags;
    return m;
}

/// Loads a broken mesh: exactly one error, empty mesh. Returns the diagnostic.
Diagnostic loadError(const std::string& file) {
    Diagnostics diags;
    TriangleMesh m = loadMeshFile(file, diags, "/shapes/3");
    EXPECT_TRUE(diags.hasErrors()) << file;
    EXPECT_EQ(m.triangleCount(), 0u);
    EXPECT_TRUE(m.positions.empty());
    for (const Diagnostic& d : diags.all())
        if (!d.warning) {
            EXPECT_EQ(d.file, file);
            EXPECT_EQ(d.where, "/shapes/3");
            return d;
        }
    return {};
}

bool contains(const std::string& s, const std::string& part) {
    return s.find(part) != std::string::npos;
}

}  // namespace

TEST(MeshIo, ObjTriangleWithNormalsAndUvs) {
    TriangleMesh m = loadOk("triangle.obj");
    ASSERT_EQ(m.triangleCount(), 1u);
    ASSERT_EQ(m.positions.size(), 3u);
    ASSERT_EQ(m.normals.size(), 3u);
    ASSERT_EQ(m.uvs.size(), 3u);
    EXPECT_FLOAT_EQ(m.positions[m.indices[1]].x, 2.0f);
    EXPECT_FLOAT_EQ(m.uvs[m.indices[1]].x, 1.0f);
    EXPECT_FLOAT_EQ(m.uvs[m.indices[2]].y, 1.0f);
    EXPECT_FLOAT_EQ(m.normals[m.indices[0]].z, 1.0f);
    EXPECT_FLOAT_EQ(meshArea(m), 2.0f);
}

TEST(MeshIo, ObjQuadsAreTriangulatedAndDeindexed) {
    TriangleMesh m = loadOk("cube_quads.obj");
    ASSERT_EQ(m.triangleCount(), 12u);
    // 8 positions x 6 normals used as 24 distinct (v, vt, vn) corners.
    EXPECT_EQ(m.positions.size(), 24u);
    ASSERT_EQ(m.normals.size(), 24u);
    ASSERT_EQ(m.uvs.size(), 24u);
    EXPECT_NEAR(meshArea(m), 6.0f, 1e-6f);
    // Winding kept: geometric normal of each triangle equals its vertex normals,
    // and points out of the unit cube.
    for (size_t t = 0; t < 12; ++t) {
        const uint32_t* i = &m.indices[3 * t];
        Vec3 ng = normalize(
            cross(m.positions[i[1]] - m.positions[i[0]], m.positions[i[2]] - m.positions[i[0]]));
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(dot(ng, m.normals[i[k]]), 1.0f, 1e-6f) << t;
        Vec3 centroid = (m.positions[i[0]] + m.positions[i[1]] + m.positions[i[2]]) / 3.0f;
        EXPECT_GT(dot(ng, centroid - Vec3(0.5f)), 0.0f);
    }
}

TEST(MeshIo, ObjRelativeIndicesAndPolygon) {
    TriangleMesh m = loadOk("relative_indices.obj");
    EXPECT_EQ(m.triangleCount(), 3u);
    EXPECT_TRUE(m.normals.empty());
    EXPECT_TRUE(m.uvs.empty());
    // Pentagon (0,0) (1,0) (1.5,1) (0.5,1.8) (-0.5,1), shoelace area 2.3.
    EXPECT_NEAR(meshArea(m), 2.3f, 1e-5f);
}

TEST(MeshIo, ObjNormalsDroppedUnlessEveryCornerHasOne) {
    TriangleMesh m = loadOk("mixed_normals.obj");
    EXPECT_EQ(m.triangleCount(), 2u);
    EXPECT_TRUE(m.normals.empty());
}

TEST(MeshIo, DegenerateTrianglesDroppedWithOneWarning) {
    Diagnostics diags;
    TriangleMesh m = loadOk("degenerate.obj", &diags);
    EXPECT_EQ(m.triangleCount(), 1u);
    ASSERT_EQ(diags.warnings().size(), 1u);
    EXPECT_EQ(diags.warnings()[0].message, "dropped 1 degenerate (zero-area) triangle");
}

TEST(MeshIo, PlyAsciiQuadWithNormalsAndUvs) {
    TriangleMesh m = loadOk("square.ply");
    ASSERT_EQ(m.triangleCount(), 2u);
    EXPECT_NEAR(meshArea(m), 1.0f, 1e-6f);
    ASSERT_EQ(m.normals.size(), m.positions.size());
    ASSERT_EQ(m.uvs.size(), m.positions.size());
    for (size_t i = 0; i < m.positions.size(); ++i) {
        EXPECT_FLOAT_EQ(m.normals[i].z, 1.0f);
        // uv (s, t) equals (x, y) in this file.
        EXPECT_FLOAT_EQ(m.uvs[i].x, m.positions[i].x);
        EXPECT_FLOAT_EQ(m.uvs[i].y, m.positions[i].y);
    }
    for (size_t t = 0; t < 2; ++t) {
        const uint32_t* i = &m.indices[3 * t];
        EXPECT_GT(
            cross(m.positions[i[1]] - m.positions[i[0]], m.positions[i[2]] - m.positions[i[0]]).z,
            0.0f);
    }
}

TEST(MeshIo, PlyBinaryTetrahedron) {
    TriangleMesh m = loadOk("tetra_binary.ply");
    ASSERT_EQ(m.triangleCount(), 4u);
    // Three right triangles of area 1/2 and an equilateral one of side sqrt(2).
    EXPECT_NEAR(meshArea(m), 1.5f + std::sqrt(3.0f) / 2.0f, 1e-6f);
    Vec3 c(0.25f, 0.25f, 0.25f);
    for (size_t t = 0; t < 4; ++t) {
        const uint32_t* i = &m.indices[3 * t];
        Vec3 ng =
            cross(m.positions[i[1]] - m.positions[i[0]], m.positions[i[2]] - m.positions[i[0]]);
        EXPECT_GT(dot(ng, m.positions[i[0]] - c), 0.0f) << "face " << t << " not outward";
    }
}

TEST(MeshIo, ExtensionIsCaseInsensitive) {
    std::ifstream src(meshPath("triangle.obj"));
    std::string copy = (ub::test::processScratchDir() / "ub_mesh_io_TRIANGLE.OBJ").string();
    {
        std::ofstream dst(copy);
        dst << src.rdbuf();
    }
    Diagnostics diags;
    TriangleMesh m = loadMeshFile(copy, diags, "");
    EXPECT_FALSE(diags.hasErrors());
    EXPECT_EQ(m.triangleCount(), 1u);
    std::remove(copy.c_str());
}

TEST(MeshIo, ErrorUnsupportedExtension) {
    Diagnostic d = loadError(meshPath("model.stl"));
    EXPECT_EQ(d.message, "unsupported mesh file extension '.stl' (expected .obj or .ply)");
    d = loadError(meshPath("noextension"));
    EXPECT_EQ(d.message, "mesh file name has no extension (expected .obj or .ply)");
}

TEST(MeshIo, ErrorCannotOpen) {
    Diagnostic d = loadError(meshPath("does_not_exist.obj"));
    EXPECT_EQ(d.message, "cannot open mesh file (No such file or directory)");
    d = loadError(meshPath("does_not_exist.ply"));
    EXPECT_TRUE(contains(d.message, "cannot open mesh file")) << d.message;
}

TEST(MeshIo, ErrorObjIndexOutOfRangeWithLine) {
    Diagnostic d = loadError(meshPath("bad_index.obj"));
    EXPECT_EQ(d.message, "vertex index 17 out of range (mesh has 12 vertices)");
    EXPECT_EQ(d.line, 15);
    EXPECT_EQ(d.column, 7);
    EXPECT_TRUE(contains(d.format(), "bad_index.obj:15:7: error: at /shapes/3: vertex index 17"))
        << d.format();
}

TEST(MeshIo, ErrorObjNonFinitePosition) {
    Diagnostic d = loadError(meshPath("nonfinite.obj"));
    EXPECT_EQ(d.message, "non-finite vertex position at vertex 3");
    EXPECT_EQ(d.line, 3);
}

TEST(MeshIo, ErrorObjInvalidNumber) {
    Diagnostic d = loadError(meshPath("bad_number.obj"));
    EXPECT_EQ(d.message, "invalid number 'zero' in vertex position (expected 3 numbers)");
    EXPECT_EQ(d.line, 2);
    EXPECT_EQ(d.column, 5);
}

TEST(MeshIo, ErrorObjNoTriangles) {
    Diagnostic d = loadError(meshPath("no_faces.obj"));
    EXPECT_EQ(d.message, "OBJ file has no triangles (expected faces: 'f' lines)");
}

TEST(MeshIo, ErrorObjAllTrianglesDegenerate) {
    Diagnostic d = loadError(meshPath("all_degenerate.obj"));
    EXPECT_EQ(d.message, "OBJ file has no triangles with non-zero area (all 2 are degenerate)");
}

TEST(MeshIo, ErrorObjFaceWithTwoVertices) {
    Diagnostic d = loadError(meshPath("short_face.obj"));
    EXPECT_EQ(d.message, "face has 2 vertices (expected at least 3)");
    EXPECT_EQ(d.line, 4);
}

TEST(MeshIo, ErrorPlyIndexOutOfRange) {
    Diagnostic d = loadError(meshPath("bad_index.ply"));
    EXPECT_EQ(d.message, "vertex index 17 out of range (mesh has 3 vertices)");
}

TEST(MeshIo, ErrorPlyNonFinitePosition) {
    Diagnostic d = loadError(meshPath("nonfinite.ply"));
    EXPECT_EQ(d.message, "non-finite vertex position at vertex 2");
}

TEST(MeshIo, ErrorPlyNoTriangles) {
    Diagnostic d = loadError(meshPath("no_faces.ply"));
    EXPECT_EQ(d.message, "PLY file has no triangles (expected a 'face' element)");
}

TEST(MeshIo, ErrorPlyGarbageAndTruncated) {
    Diagnostic d = loadError(meshPath("garbage.ply"));
    EXPECT_EQ(d.line, 1);
    EXPECT_EQ(d.message,
              "not a PLY file: the first line is 'this is not a ply fi' (expected 'ply')");
    // The last face's list announces 3 indices where fewer bytes are left.
    d = loadError(meshPath("truncated_binary.ply"));
    EXPECT_TRUE(contains(d.message, "PLY list 'vertex_indices' of 'face' element ")) << d.message;
    EXPECT_TRUE(contains(d.message, "more than the rest of the file holds (at byte offset "))
        << d.message;
}

namespace {

/// Writes `text` (binary) as a temporary .ply file and returns its path.
std::string tempPly(const std::string& name, const std::string& text) {
    const std::string path =
        (ub::test::processScratchDir() / ("ub_mesh_io_" + name + ".ply")).string();
    std::ofstream out(path, std::ios::binary);
    out << text;
    return path;
}

const char* kTriangleHeader =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
    "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";

}  // namespace

// The same tetrahedron in big-endian binary, with double positions, an extra per-vertex
// property, an element the reader skips (edges, with a list), and a face as one quad plus
// one triangle: what the reader must read and what it must step over.
TEST(MeshIo, PlyBigEndianDoublesExtraElementsAndPolygons) {
    std::string body;
    auto be = [&](const void* p, int n) {
        const unsigned char* b = static_cast<const unsigned char*>(p);
        for (int i = n - 1; i >= 0; --i) body.push_back(char(b[i]));
    };
    const double pos[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    for (const auto& p : pos) {
        for (double c : p) be(&c, 8);
        const unsigned short quality = 7;
        be(&quality, 2);
    }
    // element edge 1: list uchar int, then a uchar
    body.push_back(char(2));
    for (int v : {0, 1}) be(&v, 4);
    body.push_back(char(9));
    // element face 2: the quad as one face, then a degenerate 2-vertex "face" (a line)
    body.push_back(char(4));
    for (int v : {0, 1, 2, 3}) be(&v, 4);
    body.push_back(char(2));
    for (int v : {0, 2}) be(&v, 4);
    const std::string path =
        tempPly("bigendian",
                "ply\nformat binary_big_endian 1.0\nelement vertex 4\nproperty double x\n"
                "property double y\nproperty double z\nproperty ushort quality\n"
                "element edge 1\nproperty list uchar int vertex_indices\nproperty uchar "
                "flags\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n" +
                    body);
    Diagnostics diags;
    TriangleMesh m = loadMeshFile(path, diags, "/shapes/0");
    ASSERT_FALSE(diags.hasErrors()) << diags.all()[0].format();
    ASSERT_EQ(m.positions.size(), 4u);
    ASSERT_EQ(m.triangleCount(), 2u);  // the quad as a fan
    EXPECT_NEAR(meshArea(m), 1.0f, 1e-6f);
    EXPECT_EQ(m.positions[2].x, 1.0f);
    EXPECT_EQ(m.positions[2].y, 1.0f);
    ASSERT_EQ(diags.warnings().size(), 1u);
    EXPECT_EQ(diags.warnings()[0].message, "ignored 1 point and line primitives");
}

// Values that are no number of their type, list counts out of their type's range or beyond
// what the file holds, negative indices, a missing coordinate: each an error with its line
// and column (ASCII), never an allocation of what a count announces.
TEST(MeshIo, ErrorPlyBadValuesAndCounts) {
    const std::string vertices = "0 0 0\n1 0 0\n0 1 0\n";
    struct Case {
        std::string name, text, message;
        int line, column;
    };
    const std::vector<Case> cases = {
        {"letter", std::string(kTriangleHeader) + "0 0 0\n1 x 0\n0 1 0\n3 0 1 2\n",
         "PLY value 'x' of property 'y' of 'vertex' element 1 (expected a float number)", 11, 3},
        {"count300", std::string(kTriangleHeader) + vertices + "300 0 1 2\n",
         "PLY list count '300' of property 'vertex_indices' of 'face' element 0 (expected a "
         "uchar integer in its range)",
         13, 1},
        {"countdigits", std::string(kTriangleHeader) + vertices + "41015555555555555555 0 1 2\n",
         "PLY list count '41015555555555555555' of property 'vertex_indices' of 'face' element 0 "
         "(expected a uchar integer in its range)",
         13, 1},
        {"negative", std::string(kTriangleHeader) + vertices + "3 0 -1 2\n",
         "vertex index -1 out of range (mesh has 3 vertices)", 13, 5},
        {"fraction", std::string(kTriangleHeader) + vertices + "3 0 1.5 2\n",
         "PLY list entry '1.5' of property 'vertex_indices' of 'face' element 0 (expected a int "
         "integer in its range)",
         13, 5},
        {"negativecount",
         "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
         "property float z\nelement face 1\nproperty list int int vertex_indices\nend_header\n" +
             vertices + "-5 0 1 2\n",
         "PLY list 'vertex_indices' of 'face' element 0 has count -5 (expected a non-negative "
         "count; at line 13)",
         13, 1},
        {"noz",
         "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
         "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0\n1 0\n0 "
         "1\n3 0 1 2\n",
         "PLY element 'vertex' has no 'z' property (expected float properties x, y and z)", 3, 0},
        {"noformat", "ply\nelement vertex 0\nproperty float x\nend_header\n",
         "PLY header has no 'format' line (expected 'format ascii 1.0' or a binary format)", 2, 0},
        {"propfirst", "ply\nformat ascii 1.0\nproperty float x\nend_header\n",
         "PLY property 'x' before any element line", 3, 0},
    };
    for (const Case& c : cases) {
        Diagnostic d = loadError(tempPly(c.name, c.text));
        EXPECT_EQ(d.message, c.message) << c.name;
        EXPECT_EQ(d.line, c.line) << c.name;
        EXPECT_EQ(d.column, c.column) << c.name;
    }
    // A uint count of 4e9 in a binary file of a few bytes: refused before any allocation.
    std::string body(36, '\0');
    body += std::string("\x00\x28\x6b\xee", 4);  // 4,000,000,000 (little endian) entries
    Diagnostic d = loadError(
        tempPly("hugelist",
                "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
                "property float y\nproperty float z\nelement face 1\nproperty list uint "
                "int vertex_indices\nend_header\n" +
                    body));
    EXPECT_EQ(d.message,
              "PLY list 'vertex_indices' of 'face' element 0 has 4000000000 entries, more than the "
              "rest of the file holds (at byte offset 204; truncated or corrupt file?)");
    // A last value without a newline after it is still a value.
    Diagnostics diags;
    TriangleMesh m = loadMeshFile(
        tempPly("nonewline", std::string(kTriangleHeader) + vertices + "3 0 1 2"), diags, "");
    EXPECT_FALSE(diags.hasErrors()) << diags.all()[0].format();
    EXPECT_EQ(m.triangleCount(), 1u);
}

// CRLF line endings, groups, smoothing groups and material statements: materials
// come from the scene file, so a missing .mtl is neither an error nor a warning.
TEST(MeshIo, ObjWithCrlfAndMaterialStatements) {
    Diagnostics diags;
    TriangleMesh m = loadOk("crlf_with_mtllib.obj", &diags);
    EXPECT_EQ(m.triangleCount(), 1u);
    ASSERT_EQ(m.uvs.size(), 3u);
    EXPECT_TRUE(m.normals.empty());
    EXPECT_TRUE(diags.all().empty()) << diags.all()[0].format();
}

// A header claiming 4e9 vertices must not end in std::bad_alloc (or the OOM killer): counts
// are checked against the bytes the file has first; a negative count is not a count.
TEST(MeshIo, ErrorPlyCountsTheFileCannotHold) {
    Diagnostic d = loadError(meshPath("huge_count.ply"));
    EXPECT_EQ(d.line, 4);
    EXPECT_EQ(d.message,
              "PLY header announces 4000000000 'vertex' elements (at least 12 bytes each), but "
              "the file has only 0 bytes after the header (truncated or corrupt file?)");
    d = loadError(meshPath("negative_count.ply"));
    EXPECT_EQ(d.line, 3);
    EXPECT_EQ(d.message, "PLY element 'vertex' has count '-5' (expected a non-negative integer)");
}

// Mesh attributes (Mitsuba 3's naming): red/green/blue as "color" (uchar / 255), NAME_k as
// channel k of "NAME", other scalars as 1-channel attributes; face values are repeated for
// every triangle of a polygon's fan and follow the triangles when degenerate ones are dropped.
TEST(MeshIo, PlyMeshAttributesFollowMitsubasNaming) {
    const std::string path = (ub::test::processScratchDir() / "unibeam_attributes.ply").string();
    std::ofstream(path) << "ply\nformat ascii 1.0\nelement vertex 5\n"
                           "property float x\nproperty float y\nproperty float z\n"
                           "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                           "property float quality\n"
                           "element face 2\nproperty list uchar int vertex_indices\n"
                           "property float color_0\nproperty float color_1\n"
                           "property float color_2\nproperty float weight_0\nend_header\n"
                           "0 0 0 255 0 0 0.5\n1 0 0 0 255 0 1.5\n1 1 0 0 0 255 2.5\n"
                           "0 1 0 51 102 153 3.5\n2 0 0 0 0 0 4.5\n"
                           "4 0 1 2 3 0.1 0.2 0.3 0.25\n"
                           "3 0 1 4 0.7 0.8 0.9 0.75\n";
    Diagnostics diags;
    TriangleMesh m = loadMeshFile(path, diags, "/shapes/0");
    ASSERT_FALSE(diags.hasErrors()) << diags.all()[0].format();
    ASSERT_EQ(m.triangleCount(), 2u);  // the quad's fan; the collinear triangle is dropped
    std::map<std::string, const MeshAttribute*> byName;
    for (const MeshAttribute& a : m.attributes) byName[a.name] = &a;
    ASSERT_EQ(byName.size(), 4u);
    const MeshAttribute* vc = byName["vertex_color"];
    ASSERT_TRUE(vc);
    EXPECT_FALSE(vc->perFace);
    EXPECT_EQ(vc->channels, 3);
    ASSERT_EQ(vc->values.size(), 15u);
    EXPECT_FLOAT_EQ(vc->values[0], 1.0f);
    EXPECT_FLOAT_EQ(vc->values[9], 0.2f);  // 51 / 255
    EXPECT_FLOAT_EQ(vc->values[11], 0.6f);
    const MeshAttribute* q = byName["vertex_quality"];
    ASSERT_TRUE(q);
    EXPECT_EQ(q->channels, 1);
    ASSERT_EQ(q->values.size(), 5u);
    EXPECT_FLOAT_EQ(q->values[3], 3.5f);
    const MeshAttribute* fc = byName["face_color"];
    ASSERT_TRUE(fc);
    EXPECT_TRUE(fc->perFace);
    ASSERT_EQ(fc->values.size(), 6u);  // both triangles of the quad, the degenerate one gone
    for (int t = 0; t < 2; ++t) {
        EXPECT_FLOAT_EQ(fc->values[3 * t + 0], 0.1f);
        EXPECT_FLOAT_EQ(fc->values[3 * t + 2], 0.3f);
    }
    const MeshAttribute* w = byName["face_weight"];
    ASSERT_TRUE(w);
    EXPECT_EQ(w->channels, 1);
    ASSERT_EQ(w->values.size(), 2u);
    EXPECT_FLOAT_EQ(w->values[1], 0.25f);
    std::remove(path.c_str());
}
