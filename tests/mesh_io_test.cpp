// Mesh file loading: OBJ (tinyobjloader) and PLY (Assimp), and every error the
// loader reports, with its message text.
#include "scene/mesh_io.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include "core/error.h"
#include "scene/shapes.h"

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
    std::string copy = testing::TempDir() + "ub_mesh_io_TRIANGLE.OBJ";
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
    EXPECT_TRUE(contains(d.message, "cannot read PLY file: ")) << d.message;
    EXPECT_TRUE(contains(d.message, "magic number")) << d.message;  // Assimp's reason
    // Assimp does not notice the missing bytes itself; the garbage it reads for the
    // last face is caught by the index check.
    d = loadError(meshPath("truncated_binary.ply"));
    EXPECT_TRUE(contains(d.message, "out of range (mesh has 4 vertices)")) << d.message;
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

// Assimp reserves memory for every element a PLY header announces before reading any: a header
// claiming 4e9 vertices ended in std::bad_alloc (or the OOM killer). Counts are checked against
// the bytes the file has first; a negative count is not a count.
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
