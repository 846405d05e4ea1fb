// Media in scenes: the medium stack and its priority rules, nested media
// resolved at points and along rays, shadow transmittance through imaginary
// boundaries, validation (open boundary meshes, conflicting priorities) and
// the JSON "media" errors (docs/scene-format.md).
#include <gtest/gtest.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.h"
#include "render/integrator.h"
#include "scene/io/json_loader.h"
#include "scene/scene.h"
#include "scene/vdb_grid.h"
#include "tests/support/temp_file.h"

namespace ub {
namespace {

namespace fs = std::filesystem;

bool contains(const std::string& s, const std::string& part) {
    return s.find(part) != std::string::npos;
}

/// Temporary folder removed at the end of the test.
struct TempDir {
    fs::path path;
    TempDir() {
        path =
            ub::test::processScratchDir() /
            ("medium_scene_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
             "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::create_directories(path);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path, ec);
    }
};

/// A scene with the given "media", global "medium" (JSON value or empty) and shapes, a
/// point light and a camera at (0, 0.5, 5) looking at the origin.
std::string mediaScene(const std::string& media, const std::string& globalMedium,
                       const std::string& shapes) {
    std::string s =
        "{\n\"camera\": {\"position\": [0, 0.5, 5], \"target\": [0, 0, 0], "
        "\"resolution\": [16, 16]},\n"
        "\"materials\": {\"glass\": {\"type\": \"dielectric\", \"ior\": 1.5},"
        " \"white\": {\"type\": \"diffuse\"}},\n"
        "\"media\": {" +
        media + "},\n";
    if (!globalMedium.empty()) s += "\"medium\": " + globalMedium + ",\n";
    s += "\"shapes\": [" + shapes +
         "],\n"
         "\"lights\": [{\"type\": \"point\", \"position\": [0, 2.5, 0], \"intensity\": 1}]\n}\n";
    return s;
}

const char* kFogMilk =
    R"("fog": {"type": "homogeneous", "sigma_s": 0.05, "sigma_a": 0.01},
       "milk": {"type": "homogeneous", "sigma_t": [4, 5, 6], "albedo": 0.99, "g": 0.3})";

/// Glass of milk in a foggy room: glass = sphere r 1 (priority 1, vacuum inside, dielectric),
/// milk = sphere r 0.9 centred 0.15 lower, so it pokes 0.05 out of the glass bottom
/// (priority 2: milk wins where they overlap).
const char* kGlassOfMilk =
    R"({"type": "sphere", "name": "glass", "material": "glass", "radius": 1,
        "interior_medium": null, "priority": 1},
       {"type": "sphere", "name": "milk", "material": "glass", "center": [0, -0.15, 0],
        "radius": 0.9, "interior_medium": "milk", "priority": 2})";

std::vector<Diagnostic> errorsOf(const std::string& text, const std::string& baseDir = "") {
    try {
        loadJsonSceneFromString(text, "scene.json", baseDir);
    } catch (const InputError& e) {
        return e.diagnostics();
    }
    return {};
}

std::string allErrors(const std::string& text, const std::string& baseDir = "") {
    std::string all;
    for (const auto& d : errorsOf(text, baseDir)) all += d.format() + "\n";
    return all;
}

TEST(MediumStack, HighestPriorityWinsAndPopRemovesAnyEntry) {
    MediumStack s;
    s.reset(7);
    EXPECT_EQ(s.mediumId(), 7);
    EXPECT_TRUE(s.push(/*shape*/ 1, /*medium*/ 10, /*priority*/ 5));
    EXPECT_TRUE(s.push(2, 20, 3));  // lower priority entered later: 10 stays current
    EXPECT_EQ(s.mediumId(), 10);
    EXPECT_TRUE(s.push(3, 30, 5));  // equal priority: the one entered last wins
    EXPECT_EQ(s.mediumId(), 30);
    EXPECT_TRUE(s.pop(1));  // leaving a shape that is not on top
    EXPECT_EQ(s.mediumId(), 30);
    EXPECT_TRUE(s.pop(3));
    EXPECT_EQ(s.mediumId(), 20);
    EXPECT_FALSE(s.pop(3));         // not on the stack any more: no-op
    EXPECT_TRUE(s.push(2, 20, 3));  // already inside: no duplicate
    EXPECT_EQ(s.count, 2);
    EXPECT_TRUE(s.pop(2));
    EXPECT_EQ(s.mediumId(), 7);
}

TEST(MediumStack, OverflowIsReportedNotACrash) {
    MediumStack s;
    s.reset(-1);
    for (int i = 0; i < MediumStack::kCapacity - 1; ++i) EXPECT_TRUE(s.push(i, i, i));
    EXPECT_FALSE(s.push(100, 0, 0));
    EXPECT_EQ(s.count, MediumStack::kCapacity);
}

TEST(NestedMedia, GlassOfMilkInFogHasTheRightMediumEverywhere) {
    auto scene =
        loadJsonSceneFromString(mediaScene(kFogMilk, "\"fog\"", kGlassOfMilk), "milk.json", "");
    ASSERT_EQ(scene->media.size(), 2u);
    const int fog = 0, milk = 1, vacuum = -1;
    EXPECT_EQ(scene->globalMediumId, fog);
    EXPECT_EQ(scene->cameraMediumStack.mediumId(), fog);
    EXPECT_TRUE(scene->hasMedia());
    EXPECT_EQ(scene->mediumStackAt(Vec3(2, 0, 0)).mediumId(), fog);         // room
    EXPECT_EQ(scene->mediumStackAt(Vec3(0, 0.85f, 0)).mediumId(), vacuum);  // glass, above milk
    EXPECT_EQ(scene->mediumStackAt(Vec3(0, 0.0f, 0)).mediumId(), milk);     // milk in the glass
    // Milk poking out below the glass (y in (-1.05, -1)): milk, priority 2 beats the fog.
    EXPECT_EQ(scene->mediumStackAt(Vec3(0, -1.02f, 0)).mediumId(), milk);
    EXPECT_EQ(scene->mediumStackAt(Vec3(0, -1.2f, 0)).mediumId(), fog);

    // Straight down the axis from the camera: real hits are the glass top (y = 1), the milk
    // top (y = 0.75) and the milk bottom (y = -1.05); the glass bottom (y = -1), met from
    // inside the higher-priority milk, is skipped: a crossing inside one trace.
    MediumStack stack = scene->cameraMediumStack;
    Ray ray;
    ray.org = Vec3(0, 3, 0);
    ray.dir = Vec3(0, -1, 0);
    struct Expected {
        float hitY;
        std::vector<int> media;  // of the trace's segments
    };
    const Expected expected[] = {{1.0f, {fog}}, {0.75f, {vacuum}}, {-1.05f, {milk, milk}}};
    for (const Expected& e : expected) {
        MediumTrace trace;
        Hit hit;
        scene->traceMedia(ray, &stack, &trace, &hit);
        ASSERT_TRUE(trace.hitSurface);
        ASSERT_FALSE(trace.overflow);
        // The real hit comes back to be completed where a path reaches it.
        EXPECT_TRUE(hit.detailPending);
        EXPECT_NEAR(hit.pos.y, e.hitY, 1e-4f);
        scene->completeHit(trace.hitRay, &hit);
        EXPECT_FALSE(hit.detailPending);
        EXPECT_NEAR(hit.pos.y, e.hitY, 1e-4f);
        ASSERT_EQ(trace.count, int(e.media.size()));
        for (int k = 0; k < trace.count; ++k) EXPECT_EQ(trace.segments[k].mediumId, e.media[k]);
        // Continue straight through the real surface (as a refraction would).
        ASSERT_TRUE(scene->crossSurface(hit, -ray.dir, ray.dir, &stack));
        ray = scene->spawnRay(hit, ray.dir);
    }
    EXPECT_EQ(stack.mediumId(), fog);
    // The skipped crossing was the glass (shape 0), leaving it.
    MediumTrace trace;
    Hit hit;
    Ray inMilk;
    inMilk.org = Vec3(0, -0.5f, 0);
    inMilk.dir = Vec3(0, -1, 0);
    MediumStack s = scene->mediumStackAt(inMilk.org);
    scene->traceMedia(inMilk, &s, &trace, &hit);
    ASSERT_EQ(trace.count, 2);
    EXPECT_EQ(trace.segments[0].crossingShape, 0);
    EXPECT_EQ(trace.segments[0].crossingEntering, 0);
}

TEST(NestedMedia, PtRejectsScenesWithMedia) {
    auto scene =
        loadJsonSceneFromString(mediaScene(kFogMilk, "\"fog\"", kGlassOfMilk), "milk.json", "");
    RenderOptions opt;
    opt.algorithm = "pt";
    try {
        makeIntegrator(*scene, opt);
        FAIL() << "pt accepted a scene with media";
    } catch (const InputError& e) {
        EXPECT_TRUE(contains(e.what(), "participating media")) << e.what();
        EXPECT_TRUE(contains(e.what(), "vpt")) << e.what();
    }
    opt.algorithm = "vpt";
    EXPECT_NO_THROW(makeIntegrator(*scene, opt));
}

TEST(NestedMedia, ShadowRaysPassImaginaryBoundariesWithTransmittance) {
    // An imaginary cube [-1, 1]^3 of sigma_t = (1, 2, 3) in vacuum: a shadow ray along x from
    // -3 to 3 crosses 2 units of it; T = exp(-2 sigma_t), pass probability = mean of T.
    const char* media =
        R"("m": {"type": "homogeneous", "sigma_a": [0.5, 1, 1.5], "sigma_s": [0.5, 1, 1.5]})";
    const char* shapes =
        R"({"type": "cube", "name": "box", "interior_medium": "m", "imaginary": true})";
    auto scene = loadJsonSceneFromString(mediaScene(media, "", shapes), "imag.json", "");
    MediumStack stack = scene->mediumStackAt(Vec3(-3, 0.1f, 0.2f));
    EXPECT_EQ(stack.mediumId(), -1);
    MediumShadow sh = scene->shadowTransmittance(Vec3(-3, 0.1f, 0.2f), Vec3(0.0f), stack,
                                                 Vec3(3, 0.1f, 0.2f), Vec3(0.0f));
    ASSERT_FALSE(sh.blocked);
    EXPECT_EQ(sh.segmentCount, 3);
    const float T[3] = {std::exp(-2.0f), std::exp(-4.0f), std::exp(-6.0f)};
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(sh.transmittance[c], T[c], 1e-4f * T[c] + 1e-6f);
    EXPECT_NEAR(sh.probPass, (T[0] + T[1] + T[2]) / 3.0f, 1e-5f);
    // Both ends in vacuum: no stopping density at either end.
    EXPECT_EQ(sh.pdfScatterFwdL, 0.0f);
    EXPECT_EQ(sh.pdfScatterRevL, 0.0f);
    // From inside the box to outside: stopping at a (reverse) has density sigma_t(a) T.
    MediumStack inside = scene->mediumStackAt(Vec3(0, 0.1f, 0.2f));
    EXPECT_EQ(inside.mediumId(), 0);
    MediumShadow half = scene->shadowTransmittance(Vec3(0, 0.1f, 0.2f), Vec3(0.0f), inside,
                                                   Vec3(3, 0.1f, 0.2f), Vec3(0.0f));
    const float Th[3] = {std::exp(-1.0f), std::exp(-2.0f), std::exp(-3.0f)};
    EXPECT_NEAR(half.pdfScatterRevL, (1 * Th[0] + 2 * Th[1] + 3 * Th[2]) / 3.0f, 1e-5f);
    // A real (non-boundary) wall blocks.
    const char* wall =
        R"({"type": "cube", "name": "box", "interior_medium": "m", "imaginary": true},
        {"type": "rectangle", "material": "white", "transform": {"rotate": {"axis": [0, 1, 0], "angle": 90}, "translate": [2, 0, 0]}})";
    auto walled = loadJsonSceneFromString(mediaScene(media, "", wall), "wall.json", "");
    MediumShadow blocked = walled->shadowTransmittance(Vec3(-3, 0.1f, 0.2f), Vec3(0.0f),
                                                       walled->mediumStackAt(Vec3(-3, 0.1f, 0.2f)),
                                                       Vec3(3, 0.1f, 0.2f), Vec3(0.0f));
    EXPECT_TRUE(blocked.blocked);
    EXPECT_TRUE(isBlack(blocked.transmittance));
}

TEST(NestedMedia, ShadowRaysThroughEdgesAndCornersCrossOnce) {
    // The imaginary cube [-1, 1]^3 of the test above. Rays that leave it through the centre
    // of a face (on the diagonal of its two triangles), through an edge (four triangles) and
    // through a corner meet several triangles at one point; the one-traversal shadow query
    // (Scene::shadowCrossings) reports each such crossing once, so the stack leaves the cube
    // once and the transmittance is that of the chord.
    const char* media =
        R"("m": {"type": "homogeneous", "sigma_a": [0.5, 1, 1.5], "sigma_s": [0.5, 1, 1.5]})";
    const char* shapes =
        R"({"type": "cube", "name": "box", "interior_medium": "m", "imaginary": true})";
    auto scene = loadJsonSceneFromString(mediaScene(media, "", shapes), "imag.json", "");
    const Vec3 exits[6] = {Vec3(0, 0, 1), Vec3(0, 0, -1), Vec3(1, 0, 0),
                           Vec3(1, 1, 0), Vec3(-1, 0, 1), Vec3(1, 1, 1)};
    for (const Vec3& e : exits) {
        const float chord = length(e);
        const Vec3 dir = e / chord;
        Scene::ShadowCrossing crossings[8];
        int count = -1;
        ASSERT_EQ(scene->shadowCrossings(Vec3(0.0f), dir, 3.0f * chord, crossings, 8, &count),
                  Scene::ShadowQuery::kOpen);
        ASSERT_EQ(count, 1) << "exit " << e.x << " " << e.y << " " << e.z;
        EXPECT_NEAR(crossings[0].t, chord, 1e-5f);
        EXPECT_FALSE(crossings[0].entering);
        const MediumStack inside = scene->mediumStackAt(Vec3(0.0f));
        ASSERT_EQ(inside.mediumId(), 0);
        const MediumShadow sh =
            scene->shadowTransmittance(Vec3(0.0f), Vec3(0.0f), inside, e * 3.0f, Vec3(0.0f));
        ASSERT_FALSE(sh.blocked);
        EXPECT_EQ(sh.segmentCount, 2);
        for (int c = 0; c < 3; ++c) {
            const float T = std::exp(-float(c + 1) * chord);
            EXPECT_NEAR(sh.transmittance[c], T, 1e-4f * T);
        }
    }
    // In and out through the centres of two opposite faces.
    Scene::ShadowCrossing crossings[8];
    int count = -1;
    ASSERT_EQ(scene->shadowCrossings(Vec3(-3, 0, 0), Vec3(1, 0, 0), 6.0f, crossings, 8, &count),
              Scene::ShadowQuery::kOpen);
    ASSERT_EQ(count, 2);
    EXPECT_TRUE(crossings[0].entering);
    EXPECT_FALSE(crossings[1].entering);
    // Fewer entries than crossings: the caller walks instead.
    EXPECT_EQ(scene->shadowCrossings(Vec3(-3, 0, 0), Vec3(1, 0, 0), 6.0f, crossings, 1, &count),
              Scene::ShadowQuery::kUnavailable);
}

TEST(MediumValidation, OpenMeshBoundaryIsAnError) {
    const char* shapes =
        R"({"type": "rectangle", "name": "sheet", "material": "white", "interior_medium": "fog"})";
    std::string err = allErrors(mediaScene(kFogMilk, "", shapes));
    EXPECT_TRUE(contains(err, "scene.json:")) << err;
    EXPECT_TRUE(contains(err, "/shapes/0")) << err;
    EXPECT_TRUE(contains(err, "shape 'sheet' is a medium boundary but its mesh is not closed"))
        << err;
    // A cube (closed after welding its 24 vertices by position) is accepted.
    const char* cube =
        R"({"type": "cube", "name": "box", "material": "white", "interior_medium": "fog"})";
    EXPECT_EQ(allErrors(mediaScene(kFogMilk, "", cube)), "");
}

TEST(MediumValidation, ConflictingPrioritiesAreAnError) {
    const char* shapes =
        R"({"type": "sphere", "name": "a", "material": "glass", "radius": 1, "interior_medium": "fog", "priority": 3},
           {"type": "sphere", "name": "b", "material": "glass", "center": [1, 0, 0], "radius": 1, "interior_medium": "milk", "priority": 3},
           {"type": "sphere", "name": "far", "material": "glass", "center": [5, 0, 0], "radius": 1, "interior_medium": "milk", "priority": 3})";
    auto d = errorsOf(mediaScene(kFogMilk, "", shapes));
    ASSERT_EQ(d.size(), 1u);  // 'far' does not overlap 'a'
    std::string err = d[0].format();
    EXPECT_TRUE(contains(err, "/shapes/1")) << err;
    EXPECT_TRUE(contains(err,
                         "conflicting medium priorities: shapes 'a' and 'b' overlap, have "
                         "the same priority 3"))
        << err;
}

TEST(MediumValidation, SceneCommitRejectsBadBoundariesWithoutTheLoader) {
    Scene scene;
    scene.sourceFile = "code.json";
    scene.addMedium(Medium::homogeneous(Rgb(0.1f), Rgb(0.1f), 0.0f), "fog");
    Material white;
    int mat = scene.addMaterial(white);
    TriangleMesh tri;
    tri.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
    tri.indices = {0, 1, 2};
    uint32_t id = scene.addMesh(tri, mat, -1, "triangle");
    scene.setMediumBoundary(id, 0, 0, false);
    try {
        scene.commit();
        FAIL() << "an open boundary was accepted";
    } catch (const InputError& e) {
        ASSERT_EQ(e.diagnostics().size(), 1u);
        EXPECT_EQ(e.diagnostics()[0].file, "code.json");
        EXPECT_EQ(e.diagnostics()[0].where, "shape 'triangle'");
        EXPECT_TRUE(contains(e.diagnostics()[0].message, "3 edges are not shared"));
    }
}

TEST(MediaJson, BadCoefficientsGAndNamesAreReported) {
    const char* media =
        R"("neg": {"type": "homogeneous", "sigma_a": [0.1, -0.2, 0.1], "sigma_s": 1},
           "hg": {"type": "homogeneous", "sigma_s": 1, "g": 1},
           "both": {"type": "homogeneous", "sigma_s": 1, "sigma_t": 2, "albedo": 0.5},
           "vdbg": {"type": "heterogeneous", "file": "x.vdb", "g": -1.5})";
    const char* shapes =
        R"({"type": "sphere", "material": "white", "radius": 1, "interior_medium": "mlik"})";
    std::string err = allErrors(mediaScene(media, "\"nowhere\"", shapes));
    EXPECT_TRUE(contains(err, "at /media/neg/sigma_a/1:")) << err;
    EXPECT_TRUE(contains(err, "at /media/hg/g:")) << err;
    EXPECT_TRUE(contains(err, "(-1, 1)")) << err;
    EXPECT_TRUE(contains(err, "at /media/vdbg/g:")) << err;
    EXPECT_TRUE(contains(err, "not both forms")) << err;
    EXPECT_TRUE(contains(err, "at /medium: unknown medium 'nowhere'")) << err;
    EXPECT_TRUE(contains(err, "at /shapes/0/interior_medium: unknown medium 'mlik'")) << err;
    EXPECT_TRUE(contains(err, "VDB file 'x.vdb' not found")) << err;
    // Every error has a line and column.
    for (const auto& d : errorsOf(mediaScene(media, "\"nowhere\"", shapes))) {
        EXPECT_GT(d.line, 0) << d.format();
        EXPECT_GT(d.column, 0) << d.format();
    }
}

TEST(MediaJson, VdbFileErrorsNameFileAndGrid) {
    TempDir tmp;
    DenseFloatGrid dense(4, 4, 4, 1.0f);
    writeDenseFloatVdb((tmp.path / "ok.vdb").string(), "density", dense);
    {
        std::ofstream bad(tmp.path / "corrupt.vdb", std::ios::binary);
        bad << "this is not a VDB file";
    }
    {
        openvdb::initialize();
        auto vec = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
        vec->setName("velocity");
        vec->tree().setValue(openvdb::Coord(0, 0, 0), openvdb::Vec3s(1.0f));
        auto labels = openvdb::Int32Grid::create(0);
        labels->setName("labels");
        labels->tree().setValue(openvdb::Coord(0, 0, 0), 7);
        openvdb::GridPtrVec grids{vec, labels};
        openvdb::io::File((tmp.path / "vector.vdb").string()).write(grids);
    }
    auto scene = [](const std::string& file, const std::string& grid) {
        return mediaScene("\"smoke\": {\"type\": \"heterogeneous\", \"file\": \"" + file +
                              "\", \"grid\": \"" + grid + "\", \"density_scale\": 2}",
                          "", R"({"type": "cube", "interior_medium": "smoke", "imaginary": true})");
    };
    const std::string base = tmp.path.string();
    EXPECT_EQ(allErrors(scene("ok.vdb", "density"), base), "");
    std::string err = allErrors(scene("corrupt.vdb", "density"), base);
    EXPECT_TRUE(contains(err, "at /media/smoke/file: cannot use VDB file 'corrupt.vdb'")) << err;
    EXPECT_TRUE(contains(err, "not a readable OpenVDB file")) << err;
    err = allErrors(scene("ok.vdb", "smoke"), base);
    EXPECT_TRUE(contains(err, "no grid of that name in the file; grids present: 'density'")) << err;
    // A vec3 grid is a chromatic density (one per channel); an int grid is neither.
    EXPECT_EQ(allErrors(scene("vector.vdb", "velocity"), base), "");
    err = allErrors(scene("vector.vdb", "labels"), base);
    EXPECT_TRUE(contains(err, "expected a float (1 channel) or vec3s (3 channels) density grid"))
        << err;
    err = allErrors(scene("missing.vdb", "density"), base);
    EXPECT_TRUE(contains(err, "VDB file 'missing.vdb' not found")) << err;
}

TEST(MediaJson, ImaginaryShapesNeedAMediumAndNoSurface) {
    const char* shapes =
        R"({"type": "cube", "imaginary": true},
           {"type": "cube", "interior_medium": "fog", "imaginary": true, "material": "white"},
           {"type": "sphere", "radius": 1, "material": "white", "priority": 2})";
    std::string err = allErrors(mediaScene(kFogMilk, "", shapes));
    EXPECT_TRUE(contains(err, "at /shapes/0/imaginary: \"imaginary\" needs an \"interior_medium\""))
        << err;
    EXPECT_TRUE(contains(err, "at /shapes/1/material: an imaginary shape has no surface")) << err;
    EXPECT_TRUE(contains(err, "at /shapes/2/priority: \"priority\" needs an \"interior_medium\""))
        << err;
}

TEST(MediaJson, HomogeneousFormsGiveTheSameCoefficients) {
    const char* media =
        R"("a": {"type": "homogeneous", "sigma_a": [0.1, 0.2, 0.3], "sigma_s": [0.9, 0.8, 0.7], "scale": 2, "g": 0.5, "emission": [1, 2, 3]},
           "b": {"type": "homogeneous", "sigma_t": 1, "albedo": [0.9, 0.8, 0.7], "scale": 2})";
    auto scene = loadJsonSceneFromString(mediaScene(media, "\"a\"", ""), "forms.json", "");
    ASSERT_EQ(scene->media.size(), 2u);
    const Medium& a = scene->media[0];
    const Medium& b = scene->media[1];
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(a.sigmaA[c], b.sigmaA[c], 1e-6f);
        EXPECT_NEAR(a.sigmaS[c], b.sigmaS[c], 1e-6f);
    }
    EXPECT_FLOAT_EQ(a.sigmaS[0], 1.8f);
    EXPECT_FLOAT_EQ(a.g, 0.5f);
    EXPECT_FLOAT_EQ(a.Le[2], 3.0f);
    EXPECT_EQ(scene->mediumNames[1], "b");
}

TEST(BundledMediaScenes, LoadWithTheirMediaAndNeedVpt) {
    struct Expect {
        const char* file;
        size_t media;
        int cameraMedium;  // the camera is outside every boundary in all five
    };
    const Expect scenes[] = {{"cornell-fog.json", 1, -1},
                             {"cornell-smoke.json", 1, -1},
                             {"glass-medium-caustics.json", 2, -1},
                             {"forward-scattering.json", 1, -1},
                             {"medium-specular-light.json", 1, -1}};
    for (const Expect& e : scenes) {
        auto scene = loadJsonScene(std::string(UNIBEAM_SOURCE_DIR) + "/scenes/" + e.file);
        EXPECT_EQ(scene->media.size(), e.media) << e.file;
        EXPECT_EQ(scene->cameraMediumStack.mediumId(), e.cameraMedium) << e.file;
        EXPECT_EQ(scene->camera.width(), 256) << e.file;
        EXPECT_TRUE(scene->hasMedia()) << e.file;
        RenderOptions opt;
        EXPECT_THROW(makeIntegrator(*scene, opt), InputError) << e.file;  // pt
    }
    // Inside the fog of the Cornell box, and inside the glass sphere (vacuum, priority 1).
    auto fog = loadJsonScene(std::string(UNIBEAM_SOURCE_DIR) + "/scenes/cornell-fog.json");
    EXPECT_EQ(fog->mediumStackAt(Vec3(0, 0, 0.5f)).mediumId(), 0);
    EXPECT_EQ(fog->mediumStackAt(Vec3(0.55831f, 0.02453f, -0.78002f)).mediumId(), -1);
}

}  // namespace
}  // namespace ub
