// Native JSON scene format (src/scene/io/json_loader.*, docs/scene-format.md):
// valid scenes load with the expected contents, and every kind of bad input
// gives the documented message at the right file:line:column and JSON pointer.
// Positions in the expected messages were counted by hand in the test texts.
#include "scene/io/scene_loader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/image.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "scene/io/json_loader.h"
#include "scene/io/json_positions.h"
#include "scene/scene_summary.h"
#include "tests/support/temp_file.h"

using namespace ub;
namespace fs = std::filesystem;

namespace {

const std::string kDataDir = std::string(UNIBEAM_TEST_DATA_DIR) + "/scenes";
const std::string kScenesDir = std::string(UNIBEAM_SOURCE_DIR) + "/scenes";

/// Loads `text` as "scene.json" (relative paths from baseDir); returns the errors
/// (empty if the scene loaded).
std::vector<Diagnostic> errorsOf(const std::string& text, const std::string& baseDir = kDataDir) {
    try {
        loadJsonSceneFromString(text, "scene.json", baseDir);
    } catch (const InputError& e) {
        return e.diagnostics();
    }
    return {};
}

/// The single error of `text`, formatted ("scene.json:3:9: error: at /x: ..."); fails
/// the test if there is not exactly one.
std::string onlyError(const std::string& text, const std::string& baseDir = kDataDir) {
    auto d = errorsOf(text, baseDir);
    EXPECT_EQ(d.size(), 1u);
    std::string all;
    for (const auto& x : d) all += x.format() + "\n";
    if (d.size() != 1) return all;
    return d[0].format();
}

bool contains(const std::string& s, const std::string& part) {
    return s.find(part) != std::string::npos;
}

/// A valid scene with a placeholder where each test inserts its piece.
const char* kCamera =
    R"json("camera": {"position": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0], "fov": 40, "resolution": [32, 24]})json";

std::string sceneWith(const std::string& materials, const std::string& shapes,
                      const std::string& lights) {
    return std::string("{\n") + kCamera + ",\n\"materials\": {" + materials + "},\n\"shapes\": [" +
           shapes + "],\n\"lights\": [" + lights + "]\n}\n";
}

const char* kWhite = R"json("white": {"type": "diffuse", "reflectance": 0.8})json";
const char* kRect = R"json({"type": "rectangle", "material": "white"})json";
const char* kPoint = R"json({"type": "point", "position": [0, 0, 3], "intensity": 10})json";

struct TempDir {
    fs::path path;
    TempDir() {
        path = ub::test::processScratchDir() /
               ("loader_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
                "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::create_directories(path);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path, ec);
    }
};

}  // namespace

// ---------------------------------------------------------------- position index

TEST(JsonPositions, PointersMapToValueAndKeyPositions) {
    const std::string text = "{\n  \"a\": [1, {\"b/c\": true}],\n\t\"d\": \"x\" // note\n}";
    JsonPositionIndex idx(text);
    EXPECT_EQ(idx.value("/a").line, 2);
    EXPECT_EQ(idx.value("/a").column, 8);
    EXPECT_EQ(idx.value("/a/1").column, 12);
    EXPECT_EQ(idx.key("/a/1/b~1c").column, 13);  // '/' escaped as ~1 (RFC 6901)
    EXPECT_EQ(idx.value("/a/1/b~1c").column, 20);
    EXPECT_EQ(idx.value("/d").line, 3);
    EXPECT_EQ(idx.value("/d").column, 7);  // a tab is one column
    // A missing pointer falls back to its nearest ancestor.
    EXPECT_EQ(idx.value("/a/1/missing").column, 12);
    EXPECT_TRUE(idx.duplicates().empty());
}

TEST(JsonPositions, ColumnsCountCodePointsAndDuplicatesAreFound) {
    const std::string text = "{\"\xC3\xA9t\xC3\xA9\": 1, \"x\": 2, \"x\": 3}";
    JsonPositionIndex idx(text);
    EXPECT_EQ(idx.value("/\xC3\xA9t\xC3\xA9").column, 9);
    ASSERT_EQ(idx.duplicates().size(), 1u);
    EXPECT_EQ(idx.duplicates()[0].pointer, "/x");
    EXPECT_EQ(idx.duplicates()[0].first.column, 12);
    EXPECT_EQ(idx.duplicates()[0].again.column, 20);
}

TEST(JsonPositions, DeepNestingDoesNotExhaustTheStack) {
    const int depth = 200000;
    std::string text = "{\"x\": " + std::string(depth, '[') + std::string(depth, ']') + "}";
    JsonPositionIndex idx(text);
    EXPECT_EQ(idx.value("/x").column, 7);
    EXPECT_EQ(idx.value("/x/0/0/0").column, 10);
    // The loader reports the document as a scene error, without crashing.
    auto d = errorsOf(text);
    EXPECT_FALSE(d.empty());
}

// ---------------------------------------------------------------- valid scenes

TEST(JsonLoader, MinimalSceneHasExpectedContents) {
    auto scene = loadJsonSceneFromString(sceneWith(kWhite, kRect, kPoint), "scene.json", kDataDir);
    EXPECT_EQ(scene->camera.width(), 32);
    EXPECT_EQ(scene->camera.height(), 24);
    EXPECT_FLOAT_EQ(scene->camera.fovYDeg(), 40.0f);
    EXPECT_TRUE(scene->camera.isPinhole());
    EXPECT_EQ(scene->settings.maxPathLength, 10);  // documented defaults
    EXPECT_EQ(scene->settings.seed, 1u);
    ASSERT_EQ(scene->materials.size(), 1u);
    EXPECT_EQ(scene->materials[0].name, "white");
    EXPECT_FLOAT_EQ(scene->materials[0].diffuse.y, 0.8f);
    ASSERT_EQ(scene->shapes.size(), 1u);
    EXPECT_EQ(scene->shapes[0].triangleCount, 2u);
    ASSERT_EQ(scene->lights.size(), 1u);
    EXPECT_EQ(scene->lights[0].type, LightType::Point);
    EXPECT_FLOAT_EQ(scene->lights[0].intensity.x, 10.0f);
    EXPECT_EQ(scene->backgroundLightId, -1);
    EXPECT_EQ(scene->sourceFile, "scene.json");
}

TEST(JsonLoader, TransformsApplyScaleThenRotateThenTranslate) {
    const std::string shapes =
        R"json({"type": "rectangle", "material": "white", "transform": {"scale": [2, 3, 1], "rotate": {"axis": [0, 0, 1], "angle": 90}, "translate": [10, 0, 0]}},
        {"type": "rectangle", "material": "white", "transform": {"matrix": [[0, -3, 0, 10], [2, 0, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}},
        {"type": "sphere", "material": "white", "center": [1, 0, 0], "radius": 0.5, "transform": {"scale": 2, "translate": [0, 5, 0]}})json";
    auto scene = loadJsonSceneFromString(sceneWith(kWhite, shapes, kPoint), "scene.json", kDataDir);
    ASSERT_EQ(scene->shapes.size(), 3u);
    // [-1,1]^2 scaled to [-2,2]x[-3,3], rotated 90 deg about z to [-3,3]x[-2,2], moved by +10 in x.
    for (int s = 0; s < 2; ++s) {
        const Bounds3& b = scene->shapes[size_t(s)].bounds;
        EXPECT_NEAR(b.lo.x, 7.0f, 1e-5f);
        EXPECT_NEAR(b.hi.x, 13.0f, 1e-5f);
        EXPECT_NEAR(b.lo.y, -2.0f, 1e-5f);
        EXPECT_NEAR(b.hi.y, 2.0f, 1e-5f);
    }
    // Sphere: centre (1,0,0) -> scaled (2,0,0) -> (2,5,0); radius 0.5 * 2.
    const Bounds3& sb = scene->shapes[2].bounds;
    EXPECT_TRUE(scene->shapes[2].isSphere);
    EXPECT_NEAR(sb.center().x, 2.0f, 1e-5f);
    EXPECT_NEAR(sb.center().y, 5.0f, 1e-5f);
    EXPECT_NEAR(sb.hi.x - sb.lo.x, 2.0f, 1e-5f);
}

TEST(JsonLoader, MaterialsOfEveryTypeKeepTheirParameters) {
    const std::string materials = R"json(
        "white": {"type": "diffuse", "reflectance": [0.1, 0.2, 0.3], "two_sided": false},
        "plastic": {"type": "phong", "diffuse_reflectance": 0.2, "glossy_reflectance": 0.7, "exponent": 50},
        "mirror": {"type": "mirror", "reflectance": 0.9},
        "glass": {"type": "dielectric", "ior": 1.33},
        "gold": {"type": "rough_conductor", "metal": "gold", "alpha": 0.2},
        "custom": {"type": "rough_conductor", "eta": [1, 2, 3], "k": 4, "alpha": 0.5, "tint": 0.5},
        "frosted": {"type": "rough_dielectric", "ior": 1.5, "alpha": 0.3, "masking": "separable"})json";
    auto scene =
        loadJsonSceneFromString(sceneWith(materials, kRect, kPoint), "scene.json", kDataDir);
    const auto& m = scene->materials;
    ASSERT_EQ(m.size(), 7u);
    EXPECT_EQ(m[0].type, MaterialType::Diffuse);
    EXPECT_FLOAT_EQ(m[0].diffuse.z, 0.3f);
    EXPECT_FALSE(m[0].twoSided);
    EXPECT_EQ(m[1].type, MaterialType::Phong);
    EXPECT_FLOAT_EQ(m[1].glossy.x, 0.7f);
    EXPECT_FLOAT_EQ(m[1].exponent, 50.0f);
    EXPECT_TRUE(m[1].twoSided);
    EXPECT_EQ(m[2].type, MaterialType::Mirror);
    EXPECT_FLOAT_EQ(m[2].specular.y, 0.9f);
    EXPECT_EQ(m[3].type, MaterialType::Dielectric);
    EXPECT_FLOAT_EQ(m[3].ior, 1.33f);
    EXPECT_FALSE(m[3].twoSided);
    EXPECT_EQ(m[4].type, MaterialType::RoughConductor);
    EXPECT_FLOAT_EQ(m[4].eta.x, 0.1830f);  // the documented gold preset
    EXPECT_FLOAT_EQ(m[4].k.z, 1.7704f);
    EXPECT_FLOAT_EQ(m[4].alpha, 0.2f);
    EXPECT_FLOAT_EQ(m[5].eta.z, 3.0f);
    EXPECT_FLOAT_EQ(m[5].k.x, 4.0f);
    EXPECT_FLOAT_EQ(m[5].specular.x, 0.5f);
    EXPECT_EQ(m[6].type, MaterialType::RoughDielectric);
    EXPECT_FLOAT_EQ(m[6].alpha, 0.3f);
    EXPECT_FALSE(m[4].separableMasking);  // default: height-correlated
    EXPECT_TRUE(m[6].separableMasking);
}

TEST(JsonLoader, LightsOfEveryType) {
    TempDir tmp;
    Image sky(8, 4);
    for (auto& p : sky.pixels) p = Rgb(0.5f, 1.0f, 2.0f);
    writeExr((tmp.path / "sky.exr").string(), sky);
    const std::string lights =
        R"json({"type": "directional", "direction": [0, 0, -2], "irradiance": [1, 2, 3]},
        {"type": "envmap", "file": "sky.exr", "scale": 2, "rotate": {"axis": [0, 1, 0], "angle": 90}})json";
    const std::string shapes =
        R"json({"type": "sphere", "radius": 0.25, "emission": 4, "emission_two_sided": true})json";
    auto scene =
        loadJsonSceneFromString(sceneWith(kWhite, shapes, lights), "scene.json", tmp.path.string());
    ASSERT_EQ(scene->lights.size(), 3u);
    const Light& area = scene->lights[0];  // emissive shapes first
    EXPECT_EQ(area.type, LightType::Area);
    EXPECT_TRUE(area.isSphere);
    EXPECT_TRUE(area.twoSided);
    EXPECT_NEAR(area.totalArea, 4.0f * kPi * 0.0625f, 1e-5f);
    EXPECT_EQ(scene->shapes[0].lightId, 0);
    // The emitter without a material gets a black one.
    EXPECT_TRUE(isBlack(scene->materials[size_t(scene->shapes[0].materialId)].diffuse));
    EXPECT_EQ(scene->lights[1].type, LightType::Directional);
    EXPECT_NEAR(scene->lights[1].direction.z, -1.0f, 1e-6f);  // normalized
    EXPECT_FLOAT_EQ(scene->lights[1].radiance.z, 3.0f);
    const Light& env = scene->lights[2];
    EXPECT_EQ(env.type, LightType::EnvMap);
    ASSERT_TRUE(env.envMap);
    EXPECT_EQ(env.envMap->width, 8);
    EXPECT_FLOAT_EQ(env.radiance.x, 2.0f);
    Vec3 x = env.envToWorld.vector(Vec3(1, 0, 0));  // +90 deg about y: x -> -z
    EXPECT_NEAR(x.z, -1.0f, 1e-5f);
    EXPECT_EQ(scene->backgroundLightId, 2);
    EXPECT_EQ(env.envFilter, EnvFilter::Bilinear);  // the default
}

TEST(JsonLoader, EnvMapFilterIsBilinearOrNearest) {
    TempDir tmp;
    Image sky(8, 4);
    for (auto& p : sky.pixels) p = Rgb(0.5f, 1.0f, 2.0f);
    writeExr((tmp.path / "sky.exr").string(), sky);
    for (const char* name : {"bilinear", "nearest"}) {
        const std::string light =
            std::string(R"json({"type": "envmap", "file": "sky.exr", "filter": ")json") + name +
            R"json("})json";
        auto scene = loadJsonSceneFromString(sceneWith(kWhite, kRect, light), "scene.json",
                                             tmp.path.string());
        ASSERT_EQ(scene->lights.size(), 1u);
        EXPECT_STREQ(envFilterName(scene->lights[0].envFilter), name);
    }
}

TEST(JsonLoader, ObjMeshPathIsRelativeToTheSceneFile) {
    auto scene = loadScene(kDataDir + "/mesh-scene.json");
    ASSERT_EQ(scene->shapes.size(), 2u);
    EXPECT_EQ(scene->shapes[0].triangleCount, 1u);
    EXPECT_EQ(scene->shapes[1].triangleCount, 12u);
    ASSERT_EQ(scene->lights.size(), 1u);
    const Light& l = scene->lights[0];
    EXPECT_NEAR(l.totalArea, 2.0f, 1e-5f);
    // Rotated 180 deg about x and lifted to z = 2: emits downwards, towards the cube.
    ASSERT_EQ(l.triangles.size(), 3u);
    Vec3 n = cross(l.triangles[1] - l.triangles[0], l.triangles[2] - l.triangles[0]);
    EXPECT_LT(n.z, 0.0f);
    EXPECT_NEAR(l.triangles[0].z, 2.0f, 1e-5f);
}

TEST(JsonLoader, CommentsAreAllowed) {
    std::string text =
        "// a comment\n" + sceneWith(kWhite, kRect, "/* here */" + std::string(kPoint));
    EXPECT_TRUE(errorsOf(text).empty());
}

// ---------------------------------------------------------------- bundled scenes

TEST(BundledScenes, CornellLargeLightMatchesSmallVcm) {
    auto scene = loadScene(kScenesDir + "/cornell-large-light.json");
    EXPECT_EQ(scene->camera.width(), 256);
    EXPECT_EQ(scene->camera.height(), 256);
    EXPECT_EQ(scene->shapes.size(), 7u);  // floor, ceiling, 3 walls, 2 spheres
    ASSERT_EQ(scene->lights.size(), 1u);
    const Light& l = scene->lights[0];
    EXPECT_EQ(l.type, LightType::Area);
    // The whole ceiling, 2.56004^2 m^2, emitting 3/pi downwards (SmallVCM: 0.95492965).
    EXPECT_NEAR(l.totalArea, 2.56004f * 2.56004f, 1e-4f);
    EXPECT_NEAR(l.radiance.x, 0.95492965f, 1e-7f);
    Vec3 n = cross(l.triangles[1] - l.triangles[0], l.triangles[2] - l.triangles[0]);
    EXPECT_LT(n.z, 0.0f);
    // Box bounds as SmallVCM's cb[] corners.
    EXPECT_NEAR(scene->bounds.lo.x, -1.27029f, 1e-4f);
    EXPECT_NEAR(scene->bounds.hi.y, 1.30455f, 1e-4f);
    EXPECT_NEAR(scene->bounds.hi.z, 1.28002f, 1e-4f);
    int mirrors = 0, glass = 0, phong = 0;
    for (const auto& m : scene->materials) {
        mirrors += m.type == MaterialType::Mirror;
        glass += m.type == MaterialType::Dielectric && std::fabs(m.ior - 1.6f) < 1e-6f;
        phong += m.type == MaterialType::Phong && m.exponent == 90.0f;
    }
    EXPECT_EQ(mirrors, 1);
    EXPECT_EQ(glass, 1);
    EXPECT_EQ(phong, 1);
}

TEST(BundledScenes, EveryBundledSceneLoadsWithItsLight) {
    struct Expect {
        const char* file;
        LightType type;
        float areaOrZero;
    };
    const Expect expected[] = {
        {"cornell-large-light.json", LightType::Area, 2.56004f * 2.56004f},
        {"cornell-small-light.json", LightType::Area, 0.25f},
        {"cornell-point-light.json", LightType::Point, 0.0f},
        {"cornell-background.json", LightType::ConstantEnv, 0.0f},
        {"envmap-spheres.json", LightType::EnvMap, 0.0f},
    };
    for (const auto& e : expected) {
        SCOPED_TRACE(e.file);
        std::vector<Diagnostic> warnings;
        auto scene = loadScene(kScenesDir + "/" + e.file, &warnings);
        EXPECT_TRUE(warnings.empty());
        ASSERT_EQ(scene->lights.size(), 1u);
        EXPECT_EQ(scene->lights[0].type, e.type);
        if (e.areaOrZero > 0) EXPECT_NEAR(scene->lights[0].totalArea, e.areaOrZero, 1e-4f);
        EXPECT_EQ(scene->backgroundLightId, scene->lights[0].isEnvironment() ? 0 : -1);
    }
}

TEST(BundledScenes, SkyMapIsTheGeneratedOne) {
    Image sky = readExr(kScenesDir + "/textures/sky.exr");
    EXPECT_EQ(sky.width, 256);
    EXPECT_EQ(sky.height, 128);
    float maxLum = 0;
    for (const auto& p : sky.pixels) maxLum = std::max(maxLum, luminance(p));
    EXPECT_GT(maxLum, 100.0f);  // the sun
}

TEST(SceneFormatDoc, OpeningExampleLoads) {
    // The complete scene at the top of docs/scene-format.md must stay valid.
    std::ifstream in(std::string(UNIBEAM_SOURCE_DIR) + "/docs/scene-format.md");
    std::stringstream ss;
    ss << in.rdbuf();
    std::string doc = ss.str();
    size_t begin = doc.find("```json\n");
    ASSERT_NE(begin, std::string::npos);
    begin += 8;
    size_t end = doc.find("```", begin);
    ASSERT_NE(end, std::string::npos);
    auto scene = loadJsonSceneFromString(doc.substr(begin, end - begin), "doc.json", kDataDir);
    EXPECT_EQ(scene->shapes.size(), 2u);
    EXPECT_EQ(scene->lights.size(), 1u);
}

TEST(SceneSummary, DescribesCountsBoundsCameraAndSettings) {
    auto scene = loadScene(kScenesDir + "/cornell-point-light.json");
    std::string s = describeScene(*scene);
    EXPECT_TRUE(contains(s, "shapes: 7 (5 meshes with 10 triangles, 2 spheres)")) << s;
    EXPECT_TRUE(contains(s, "materials: 7 (diffuse 4, phong 1, mirror 1, dielectric 1)")) << s;
    EXPECT_TRUE(contains(s, "lights: 1 (point 1)")) << s;
    EXPECT_TRUE(
        contains(s, "bounds: (-1.27029, -1.25549, -1.28002) to (1.28975, 1.30455, 1.28002)"))
        << s;
    EXPECT_TRUE(contains(s, "camera: 256x256")) << s;
    EXPECT_TRUE(contains(s, "fov 45 deg (vertical), pinhole")) << s;
    EXPECT_TRUE(contains(s, "settings: max_path_length 10, min_path_length 0, seed 1234")) << s;
}

// ---------------------------------------------------------------- errors

TEST(JsonLoaderErrors, SyntaxErrorNamesLineAndColumn) {
    std::string e = onlyError("{\n  \"camera\": {\"fov\": 45,, \"x\": 1}\n}");
    EXPECT_TRUE(contains(e,
                         "scene.json:2:24: error: invalid JSON: syntax error while parsing "
                         "object key - unexpected ','; expected string literal"))
        << e;
}

TEST(JsonLoaderErrors, UnexpectedEndOfInputPointsAtTheLastToken) {
    std::string e = onlyError("{\n  \"camera\": {\"fov\": 45}\n");
    EXPECT_TRUE(contains(e,
                         "scene.json:2:23: error: invalid JSON: syntax error while parsing "
                         "object - unexpected end of input; expected '}'"))
        << e;
}

TEST(JsonLoaderErrors, NumberOverflowIsFound) {
    std::string e = onlyError("{\n  \"camera\": {\"fov\": 1e999}\n}");
    EXPECT_TRUE(contains(e,
                         "scene.json:2:21: error: invalid number: number overflow parsing "
                         "'1e999' (expected a finite number)"))
        << e;
}

TEST(JsonLoaderErrors, FloatOverflowIsNotFinite) {
    std::string text = sceneWith(kWhite, kRect, kPoint);
    text.replace(text.find("\"intensity\": 10"), 15, "\"intensity\": 1e39");
    std::string e = onlyError(text);
    EXPECT_TRUE(contains(e, "at /lights/0/intensity: expected a finite number, got 1e+39")) << e;
}

TEST(JsonLoaderErrors, UnknownKeyListsValidKeys) {
    std::string text = sceneWith(kWhite, kRect, kPoint);
    text.replace(text.find("\"fov\""), 5, "\"fvo\"");
    std::string e = onlyError(text);
    EXPECT_EQ(e,
              "scene.json:2:73: error: at /camera/fvo: unknown key 'fvo' in camera (did you "
              "mean 'fov'?); valid keys: position, target, up, fov, resolution, lens_radius, "
              "focus_distance");
}

TEST(JsonLoaderErrors, WrongTypeSaysWhatWasExpected) {
    std::string text = sceneWith(kWhite, kRect, kPoint);
    text.replace(text.find("\"fov\": 40"), 9, "\"fov\": \"40\"");
    std::string e = onlyError(text);
    EXPECT_EQ(e,
              "scene.json:2:80: error: at /camera/fov: expected a number in (0, 180), got a "
              "string (\"40\")");
}

TEST(JsonLoaderErrors, MissingRequiredKey) {
    std::string e =
        onlyError(sceneWith(kWhite, kRect, R"json({"type": "point", "position": [0, 0, 3]})json"));
    EXPECT_TRUE(contains(e,
                         "scene.json:5:12: error: at /lights/0/intensity: missing required key "
                         "'intensity' (expected an RGB colour: one number or [r, g, b], each "
                         "a number >= 0)"))
        << e;
}

TEST(JsonLoaderErrors, UnknownTypesListValidTypes) {
    auto d = errorsOf(sceneWith(R"json("white": {"type": "difuse"})json",
                                R"json({"type": "cone", "material": "white"})json",
                                R"json({"type": "laser"})json"));
    ASSERT_EQ(d.size(), 3u);
    EXPECT_EQ(d[0].where, "/materials/white/type");
    EXPECT_EQ(d[0].message,
              "unknown material type 'difuse' (did you mean 'diffuse'?); valid types: "
              "diffuse, phong, mirror, dielectric, rough_conductor, rough_dielectric, plastic, "
              "rough_plastic, thin_dielectric, multi_lobe, principled, principled_thin");
    EXPECT_EQ(d[1].message,
              "unknown shape type 'cone' (did you mean 'cube'?); valid types: obj, ply, "
              "rectangle, cube, sphere, disk, cylinder");
    EXPECT_EQ(d[2].message,
              "unknown light type 'laser'; valid types: point, spot, directional, "
              "constant, envmap (area lights are shapes with an \"emission\")");
}

TEST(JsonLoaderErrors, UnknownMaterialReferenceListsDefinedOnes) {
    const std::string materials =
        R"json("white": {"type": "diffuse"}, "red": {"type": "diffuse"}, "glass": {"type": "dielectric", "ior": 1.5})json";
    std::string e =
        onlyError(sceneWith(materials, R"json({"type": "cube", "material": "glas"})json", kPoint));
    EXPECT_EQ(e,
              "scene.json:4:41: error: at /shapes/0/material: unknown material 'glas' (did you "
              "mean 'glass'?) (defined: white, red, glass)");
}

TEST(JsonLoaderErrors, UnknownMaterialWhenNoneAreDefined) {
    std::string e = onlyError(sceneWith("", kRect, kPoint));
    EXPECT_TRUE(contains(e,
                         "at /shapes/0/material: unknown material 'white' (no materials are "
                         "defined in \"materials\")"))
        << e;
}

TEST(JsonLoaderErrors, NegativeAndOutOfRangeValues) {
    struct Case {
        std::string from, to, expected;
    };
    const Case cases[] = {
        {"\"fov\": 40", "\"fov\": 180", "at /camera/fov: expected a number in (0, 180), got 180"},
        {"\"resolution\": [32, 24]", "\"resolution\": [0, 24]",
         "at /camera/resolution/0: expected an integer in [1, 16384], got 0"},
        {"\"resolution\": [32, 24]", "\"resolution\": [32, 100000]",
         "at /camera/resolution/1: expected an integer in [1, 16384], got 100000"},
        {"\"resolution\": [32, 24]", "\"resolution\": [32.5, 24]",
         "at /camera/resolution/0: expected an integer in [1, 16384], got 32.5 (not an integer)"},
        {"\"reflectance\": 0.8", "\"reflectance\": -0.1",
         "at /materials/white/reflectance: expected a number in [0, 1], got -0.1"},
        {"\"reflectance\": 0.8", "\"reflectance\": [0.5, 1.2, 0.5]",
         "at /materials/white/reflectance/1: expected a number in [0, 1], got 1.2"},
        {"\"intensity\": 10", "\"intensity\": [1, -1, 1]",
         "at /lights/0/intensity/1: expected a number >= 0, got -1"},
    };
    for (const auto& c : cases) {
        std::string text = sceneWith(kWhite, kRect, kPoint);
        ASSERT_NE(text.find(c.from), std::string::npos) << c.from;
        text.replace(text.find(c.from), c.from.size(), c.to);
        std::string e = onlyError(text);
        EXPECT_TRUE(contains(e, c.expected)) << e;
    }
}

TEST(JsonLoaderErrors, MaterialParametersOutOfRange) {
    auto d = errorsOf(sceneWith(
        R"json("white": {"type": "diffuse"},
        "a": {"type": "dielectric", "ior": 0},
        "b": {"type": "rough_dielectric", "ior": 1.5, "alpha": 0},
        "c": {"type": "rough_conductor", "metal": "gold", "alpha": -0.1},
        "d": {"type": "phong", "diffuse_reflectance": 0.5, "glossy_reflectance": [0.2, 0.6, 0.2], "exponent": 0},
        "e": {"type": "rough_conductor", "metal": "tin", "alpha": 0.1},
        "f": {"type": "rough_conductor", "alpha": 0.1},
        "g": {"type": "rough_conductor", "metal": "gold", "alpha": 0.1, "masking": "smith"})json",
        kRect, kPoint));
    ASSERT_EQ(d.size(), 8u);
    EXPECT_EQ(d[7].where, "/materials/g/masking");
    EXPECT_EQ(d[7].message,
              "unknown masking 'smith' (expected \"height_correlated\" or \"separable\")");
    EXPECT_EQ(d[0].format(),
              "scene.json:4:44: error: at /materials/a/ior: expected a number > 0, got 0");
    EXPECT_EQ(d[1].message, "expected a number in (0, 1], got 0");
    EXPECT_EQ(d[2].where, "/materials/c/alpha");
    EXPECT_EQ(d[3].where, "/materials/d/exponent");
    EXPECT_EQ(d[4].format(),
              "scene.json:7:14: error: at /materials/d: diffuse_reflectance + "
              "glossy_reflectance = 1.1 > 1 in the green channel: the material "
              "would create energy (expected a sum <= 1)");
    EXPECT_EQ(d[5].message, "unknown metal 'tin'; valid metals: gold, copper, silver, aluminium");
    EXPECT_EQ(d[6].message,
              "a rough_conductor needs \"metal\" (one of gold, copper, silver, "
              "aluminium) or both \"eta\" and \"k\" (RGB)");
}

TEST(JsonLoaderErrors, SphereRadiusAndNonUniformScale) {
    auto d = errorsOf(sceneWith(kWhite,
                                R"json({"type": "sphere", "material": "white", "radius": -1},
        {"type": "sphere", "material": "white", "radius": 1, "transform": {"scale": [1, 2, 1]}})json",
                                kPoint));
    ASSERT_EQ(d.size(), 2u);
    EXPECT_EQ(d[0].format(),
              "scene.json:4:62: error: at /shapes/0/radius: expected a number > 0, got -1");
    EXPECT_EQ(d[1].where, "/shapes/1/transform");
    EXPECT_EQ(d[1].message,
              "a sphere's transform must keep it a sphere: rotations, translations "
              "and uniform scales only (this one scales non-uniformly or shears)");
}

TEST(JsonLoaderErrors, MaxPathLengthBelowOne) {
    std::string text = sceneWith(kWhite, kRect, kPoint);
    text.insert(2, "\"settings\": {\"max_path_length\": 0},\n");
    std::string e = onlyError(text);
    EXPECT_EQ(e,
              "scene.json:2:33: error: at /settings/max_path_length: expected an integer in "
              "[1, 1000], got 0");
}

TEST(JsonLoaderErrors, ZeroAreaEmitter) {
    // Scale factors so small in the rectangle's plane that the squared edge lengths underflow
    // in float: the transform is invertible (determinant 1e-20; the third factor keeps it a
    // normal float, which the renderer's flush-to-zero mode would otherwise make 0, singular)
    // but the rectangle's area is 0.
    std::string e = onlyError(sceneWith(
        kWhite,
        R"json({"type": "rectangle", "emission": 1, "transform": {"scale": [1e-20, 1e-20, 1e20]}})json",
        kPoint));
    EXPECT_EQ(e,
              "scene.json:4:12: error: at /shapes/0: zero-area emitter: the surface area of this "
              "rectangle after its transform is 0 (expected > 0)");
}

TEST(JsonLoaderErrors, DegenerateMeshFile) {
    auto d = errorsOf(sceneWith(
        kWhite, R"json({"type": "obj", "file": "meshes/degenerate.obj", "material": "white"})json",
        kPoint));
    ASSERT_GE(d.size(), 2u);
    // The mesh reader's own error, then ours at the shape's "file" in the scene.
    bool meshError = false;
    for (const auto& x : d) meshError = meshError || contains(x.file, "degenerate.obj");
    EXPECT_TRUE(meshError);
    EXPECT_EQ(d.back().format(),
              "scene.json:4:36: error: at /shapes/0/file: mesh file "
              "'meshes/degenerate.obj' could not be loaded (see the errors "
              "reported for it)");
}

TEST(JsonLoaderErrors, MissingMeshAndEnvMapFiles) {
    auto d = errorsOf(sceneWith(
        kWhite, R"json({"type": "ply", "file": "nowhere/bunny.ply", "material": "white"})json",
        R"json({"type": "envmap", "file": "nowhere/sky.exr"})json"));
    ASSERT_EQ(d.size(), 2u);
    EXPECT_TRUE(contains(d[0].format(),
                         "scene.json:4:36: error: at /shapes/0/file: mesh file "
                         "'nowhere/bunny.ply' not found (looked for '"))
        << d[0].format();
    EXPECT_TRUE(contains(d[1].format(),
                         "scene.json:5:39: error: at /lights/0/file: environment "
                         "map 'nowhere/sky.exr' not found"))
        << d[1].format();
}

TEST(JsonLoaderErrors, UnknownEnvMapFilterListsTheFilters) {
    TempDir tmp;
    Image sky(8, 4);
    for (auto& p : sky.pixels) p = Rgb(1.0f);
    writeExr((tmp.path / "sky.exr").string(), sky);
    std::string e = onlyError(
        sceneWith(kWhite, kRect,
                  R"json({"type": "envmap", "file": "sky.exr", "filter": "bilinar"})json"),
        tmp.path.string());
    EXPECT_TRUE(contains(e, "scene.json:5:")) << e;
    EXPECT_TRUE(contains(e,
                         "error: at /lights/0/filter: unknown environment map filter "
                         "'bilinar' (did you mean 'bilinear'?); valid filters: "))
        << e;
    e = onlyError(
        sceneWith(kWhite, kRect, R"json({"type": "envmap", "file": "sky.exr", "filter": ""})json"),
        tmp.path.string());
    EXPECT_TRUE(contains(e, "at /lights/0/filter: expected a non-empty string")) << e;
    e = onlyError(
        sceneWith(kWhite, kRect, R"json({"type": "envmap", "file": "sky.exr", "filter": 1})json"),
        tmp.path.string());
    EXPECT_TRUE(contains(e, "at /lights/0/filter")) << e;
}

TEST(JsonLoaderErrors, UnreadableEnvMapMergesTheImageError) {
    TempDir tmp;
    std::ofstream((tmp.path / "fake.exr").string()) << "this is not an OpenEXR file\n";
    std::string e =
        onlyError(sceneWith(kWhite, kRect, R"json({"type": "envmap", "file": "fake.exr"})json"),
                  tmp.path.string());
    EXPECT_TRUE(contains(e,
                         "scene.json:5:39: error: at /lights/0/file: cannot read environment "
                         "map 'fake.exr': "))
        << e;
}

TEST(JsonLoaderErrors, MeshTypeMustMatchExtension) {
    std::string e = onlyError(sceneWith(
        kWhite, R"json({"type": "ply", "file": "meshes/triangle.obj", "material": "white"})json",
        kPoint));
    EXPECT_TRUE(contains(e,
                         "at /shapes/0/file: a shape of type 'ply' needs a .ply file, got "
                         "'meshes/triangle.obj'"))
        << e;
}

TEST(JsonLoaderErrors, AtMostOneEnvironmentLight) {
    std::string e = onlyError(sceneWith(kWhite, kRect,
                                        R"json({"type": "constant", "radiance": 1},
        {"type": "constant", "radiance": 2})json"));
    EXPECT_EQ(e,
              "scene.json:6:18: error: at /lights/1/type: more than one environment light: "
              "/lights/0 is one already (a scene has at most one)");
}

TEST(JsonLoaderErrors, SceneWithoutLight) {
    std::string e = onlyError(sceneWith(kWhite, kRect, ""));
    EXPECT_EQ(e,
              "scene.json:1:1: error: at /: the scene has no light (expected an entry in "
              "\"lights\" or a shape with an \"emission\")");
}

TEST(JsonLoaderErrors, SceneWithoutCamera) {
    std::string e =
        onlyError(R"json({"materials": {}, "lights": [{"type": "constant", "radiance": 1}]})json");
    EXPECT_EQ(e,
              "scene.json:1:1: error: at /camera: missing required key 'camera' (expected a "
              "camera object with \"position\" and \"target\")");
}

TEST(JsonLoaderErrors, CameraLooksNowhere) {
    std::string text = sceneWith(kWhite, kRect, kPoint);
    text.replace(text.find("\"up\": [0, 1, 0]"), 15, "\"up\": [0, 0, 2]");
    std::string e = onlyError(text);
    EXPECT_TRUE(contains(e, "at /camera/up: the up vector is parallel to the viewing direction"))
        << e;
}

TEST(JsonLoaderErrors, DuplicateKey) {
    std::string text = sceneWith(kWhite, kRect, kPoint);
    text.replace(text.find("\"fov\": 40"), 9, "\"fov\": 40, \"fov\": 50");
    std::string e = onlyError(text);
    EXPECT_EQ(e,
              "scene.json:2:84: error: at /camera/fov: duplicate key (first given at line 2, "
              "column 73; keys must be unique)");
}

TEST(JsonLoaderErrors, ReportsEveryErrorOfAFileWithPositions) {
    try {
        loadScene(kDataDir + "/many-errors.json");
        FAIL() << "expected an InputError";
    } catch (const InputError& e) {
        std::vector<std::string> got;
        for (const auto& d : e.diagnostics()) {
            EXPECT_EQ(d.file, kDataDir + "/many-errors.json");
            got.push_back(std::to_string(d.line) + ":" + std::to_string(d.column) + " " + d.where);
        }
        // Positions found with a text search in the file (see the comment in the data).
        const std::vector<std::string> expected = {"2:65 /camera/fov",
                                                   "3:33 /camera/resolution/1",
                                                   "4:35 /settings/max_path_length",
                                                   "6:49 /materials/white/reflectance",
                                                   "7:44 /materials/glass/ior",
                                                   "10:36 /shapes/0/material",
                                                   "10:54 /shapes/0/radius",
                                                   "11:14 /shapes/1/type",
                                                   "13:72 /lights/0/colour"};
        EXPECT_EQ(got, expected);
    }
}

TEST(SceneLoader, UnsupportedExtensionListsSupportedOnes) {
    try {
        loadScene("scene.yaml");
        FAIL() << "expected an InputError";
    } catch (const InputError& e) {
        EXPECT_STREQ(e.what(),
                     "scene.yaml: error: unsupported scene file extension '.yaml' (supported: "
                     ".json, .xml, .obj)");
    }
}

TEST(SceneLoader, MissingSceneFile) {
    try {
        loadScene(kDataDir + "/does-not-exist.json");
        FAIL() << "expected an InputError";
    } catch (const InputError& e) {
        EXPECT_TRUE(contains(e.what(), "cannot open the scene file")) << e.what();
    }
}

TEST(JsonLoader, ThinLensFocusesOnTheTargetByDefault) {
    std::string text = sceneWith(kWhite, kRect, kPoint);
    text.replace(text.find("\"fov\": 40"), 9, "\"fov\": 40, \"lens_radius\": 0.1");
    text.insert(2,
                "\"settings\": {\"max_path_length\": 3, \"min_path_length\": 2, \"seed\": 99},\n");
    auto scene = loadJsonSceneFromString(text, "scene.json", kDataDir);
    EXPECT_FALSE(scene->camera.isPinhole());
    EXPECT_FLOAT_EQ(scene->camera.lensRadius(), 0.1f);
    EXPECT_FLOAT_EQ(scene->camera.focusDistance(), 5.0f);  // |target - position|
    EXPECT_EQ(scene->settings.maxPathLength, 3);
    EXPECT_EQ(scene->settings.minPathLength, 2);
    EXPECT_EQ(scene->settings.seed, 99u);
}

TEST(JsonLoader, RotationListAppliesInOrder) {
    // x by 90 first turns the normal +z into -y, then z by 90 turns -y into +x: the
    // rectangle ends up in the plane x = 0 (the other order would give y = 0).
    const std::string shapes =
        R"json({"type": "rectangle", "material": "white", "transform": {"rotate": [{"axis": [1, 0, 0], "angle": 90}, {"axis": [0, 0, 1], "angle": 90}]}},
        {"type": "rectangle", "material": "white", "transform": {"matrix": [1, 0, 0, 5, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]}})json";
    auto scene = loadJsonSceneFromString(sceneWith(kWhite, shapes, kPoint), "scene.json", kDataDir);
    const Bounds3& b = scene->shapes[0].bounds;
    EXPECT_NEAR(b.hi.x - b.lo.x, 0.0f, 1e-5f);
    EXPECT_NEAR(b.hi.y - b.lo.y, 2.0f, 1e-5f);
    EXPECT_NEAR(b.hi.z - b.lo.z, 2.0f, 1e-5f);
    EXPECT_NEAR(scene->shapes[1].bounds.center().x, 5.0f, 1e-5f);  // flat 16-number matrix
}

TEST(JsonLoader, BlackEmissionIsAWarningAndNoLight) {
    std::vector<Diagnostic> warnings;
    auto scene = loadJsonSceneFromString(
        sceneWith(kWhite, R"json({"type": "cube", "material": "white", "emission": 0})json",
                  kPoint),
        "scene.json", kDataDir, &warnings);
    EXPECT_EQ(scene->lights.size(), 1u);
    EXPECT_EQ(scene->shapes[0].lightId, -1);
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_EQ(warnings[0].format(),
              "scene.json:4:62: warning: at /shapes/0/emission: emission is "
              "black: the shape does not emit light");
}

TEST(JsonLoaderErrors, TransformMistakes) {
    auto d = errorsOf(sceneWith(
        kWhite,
        R"json({"type": "cube", "material": "white", "transform": {"matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1], "scale": 2}},
        {"type": "cube", "material": "white", "transform": {"matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 1, 1]}},
        {"type": "cube", "material": "white", "transform": {"scale": [1, 0, 1]}},
        {"type": "cube", "material": "white", "transform": {"rotate": {"axis": [0, 0, 0], "angle": 10}}},
        {"type": "cube", "material": "white", "emission_two_sided": true})json",
        kPoint));
    ASSERT_EQ(d.size(), 5u);
    EXPECT_EQ(d[0].message,
              "\"matrix\" cannot be combined with \"scale\", \"rotate\" or "
              "\"translate\"; use one form");
    EXPECT_EQ(d[1].message,
              "the last row of the matrix must be [0, 0, 0, 1] (only affine "
              "transforms are supported)");
    EXPECT_EQ(d[2].message,
              "a scale factor is zero: the shape would be flattened (expected "
              "non-zero factors)");
    EXPECT_EQ(d[3].where, "/shapes/3/transform/rotate/axis");
    EXPECT_EQ(d[3].message, "expected a non-zero direction [x, y, z], got [0,0,0]");
    EXPECT_EQ(d[4].message, "\"emission_two_sided\" needs an \"emission\" on the same shape");
}

namespace {

uint32_t crc32(const std::string& bytes) {
    uint32_t c = 0xFFFFFFFFu;
    for (unsigned char b : bytes) {
        c ^= b;
        for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
    }
    return ~c;
}

std::string bigEndian(uint32_t v) {
    return {char(v >> 24), char(v >> 16), char(v >> 8), char(v)};
}

std::string pngChunk(const std::string& type, const std::string& data) {
    return bigEndian(uint32_t(data.size())) + type + data + bigEndian(crc32(type + data));
}

/// A PNG whose IHDR announces width x height 8-bit RGB pixels, followed by a few bytes of
/// (not even compressed) image data: a reader has to stop at the header.
std::string pngHeaderOnly(uint32_t width, uint32_t height) {
    return std::string("\x89PNG\r\n\x1a\n", 8) +
           pngChunk("IHDR",
                    bigEndian(width) + bigEndian(height) + std::string("\x08\x02\0\0\0", 5)) +
           pngChunk("IDAT", "xxxx") + pngChunk("IEND", "");
}

/// Writes a valid 2 x 2 OpenEXR file to `path` and returns its bytes, for tests that patch it.
std::string writtenTinyExr(const std::string& path) {
    writeExr(path, Image(2, 2));
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// readExr's error message for `path`, or "" when it reads the file.
std::string readExrError(const std::string& path) {
    try {
        readExr(path);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

}  // namespace

// Image headers announcing absurd sizes are errors before anything is allocated: a PNG of
// 200000 x 200000 pixels ended in std::bad_alloc and exit status 1.
TEST(JsonLoaderErrors, ImageHeaderWithAbsurdSizeIsAnError) {
    TempDir tmp;
    const std::string png = (tmp.path / "huge.png").string();
    std::ofstream(png, std::ios::binary) << pngHeaderOnly(200000, 200000);
    try {
        readPng(png);
        ADD_FAILURE() << "readPng accepted a 200000 x 200000 image";
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()),
                  png +
                      ": error: PNG image of 200000 x 200000 pixels is too large (expected at "
                      "most 65536 pixels on a side and 268435456 pixels in all)");
    }
    std::string e =
        onlyError(sceneWith(std::string(kWhite) + R"json(, "t": {"type": "diffuse", "reflectance":
                  {"type": "bitmap", "file": "huge.png"}})json",
                            kRect, kPoint),
                  tmp.path.string());
    EXPECT_TRUE(contains(e,
                         "cannot read bitmap 'huge.png': PNG image of 200000 x 200000 pixels "
                         "is too large"))
        << e;

    // An OpenEXR file whose data window claims 1e6 x 1e6 pixels (readExr computed the window
    // size in int, which overflows for a corrupt window): a valid 2 x 2 file with the window's
    // maximum corner patched (the attribute is "dataWindow\0box2i\0", size, 4 int32).
    const std::string exr = (tmp.path / "huge.exr").string();
    std::string bytes = writtenTinyExr(exr);
    const std::string tag("dataWindow\0box2i\0", 17);
    const size_t at = bytes.find(tag);
    ASSERT_NE(at, std::string::npos);
    const int32_t maxCorner = 999999;
    std::memcpy(&bytes[at + tag.size() + 4 + 8], &maxCorner, 4);
    std::memcpy(&bytes[at + tag.size() + 4 + 12], &maxCorner, 4);
    std::ofstream(exr, std::ios::binary) << bytes;
    try {
        readExr(exr);
        ADD_FAILURE() << "readExr accepted a 1e6 x 1e6 data window";
    } catch (const InputError& err) {
        // OpenEXR itself reads the scanline offset table on opening and finds the file too
        // short; either way the error names the file and no image buffer is allocated.
        const std::string m = err.what();
        EXPECT_EQ(m.rfind(exr + ": error: ", 0), 0u) << m;
        EXPECT_TRUE(contains(m, "OpenEXR image of 1000000 x 1000000 pixels is too large") ||
                    contains(m, "cannot read OpenEXR image: "))
            << m;
    }

    // A window within the size limits whose pixels cannot be in the file: 4000 x 4000 half
    // pixels are 32 MB, more than 1032 (deflate's best ratio) times the file's bytes. 4 KB of
    // zeros after the chunks give OpenEXR the 250 line offsets it reads on opening.
    const int32_t corner4000 = 3999;
    std::memcpy(&bytes[at + tag.size() + 4 + 8], &corner4000, 4);
    std::memcpy(&bytes[at + tag.size() + 4 + 12], &corner4000, 4);
    std::ofstream(exr, std::ios::binary | std::ios::trunc) << bytes << std::string(4096, '\0');
    {
        const std::string e = readExrError(exr);
        EXPECT_TRUE(contains(e,
                             "corrupt OpenEXR image: 4000 x 4000 pixels need at least 31007 bytes "
                             "of compressed pixel data"))
            << e;
    }
}

// OpenEXR sizes its buffers from the channel list when it opens a file: readExr checks the
// list first (docs/fuzzing.md). A valid 2 x 2 file with one channel's pixel type, then its
// sampling, patched is an error naming the channel; the regression input with a name running
// past the attribute is in tests/data/fuzz-regressions.
TEST(JsonLoaderErrors, OpenExrChannelListIsCheckedBeforeOpening) {
    TempDir tmp;
    const std::string exr = (tmp.path / "bad.exr").string();
    const std::string good = writtenTinyExr(exr);
    const std::string tag("channels\0chlist\0", 16);
    const size_t at = good.find(tag);
    ASSERT_NE(at, std::string::npos);
    const size_t entry = at + tag.size() + 4;  // the first channel: "B\0", then int32 type
    ASSERT_EQ(good.substr(entry, 2), std::string("B\0", 2));
    for (int field : {0, 8}) {  // pixel type, xSampling
        std::string bytes = good;
        const int32_t bad = field == 0 ? 7 : 2;
        std::memcpy(&bytes[entry + 2 + size_t(field)], &bad, 4);
        std::ofstream(exr, std::ios::binary | std::ios::trunc) << bytes;
        try {
            readExr(exr);
            ADD_FAILURE() << "readExr accepted a patched channel list";
        } catch (const InputError& err) {
            const std::string m = err.what();
            EXPECT_TRUE(contains(m, field == 0 ? "OpenEXR channel 'B' has pixel type 7"
                                               : "OpenEXR channel 'B' has pixel type 2 and "
                                                 "sampling 2 x 1"))
                << m;
        }
    }
}

// OpenEXR reads an attribute of a known type by its type, not by the size the file
// announces, and goes on from where that read stops (docs/fuzzing.md): a fixed-size attribute
// whose size field says otherwise, and a channel list whose closing empty name is not its last
// byte, are errors naming what is wrong.
TEST(JsonLoaderErrors, OpenExrAttributeSizesMustBeWhatOpenExrReads) {
    TempDir tmp;
    const std::string exr = (tmp.path / "sizes.exr").string();
    const std::string good = writtenTinyExr(exr);
    auto patchedSize = [&](const std::string& nameAndType, int32_t size) {
        std::string bytes = good;
        const size_t at = bytes.find(nameAndType);
        EXPECT_NE(at, std::string::npos) << nameAndType;
        std::memcpy(&bytes[at + nameAndType.size()], &size, 4);
        std::ofstream(exr, std::ios::binary | std::ios::trunc) << bytes;
    };
    patchedSize(std::string("pixelAspectRatio\0float\0", 23), 8);
    {
        const std::string e = readExrError(exr);
        EXPECT_TRUE(contains(e,
                             "corrupt OpenEXR image: header attribute 'pixelAspectRatio' (float) "
                             "has 8 bytes, expected 4"))
            << e;
    }
    // The 2 x 2 file's channel list holds B, G, R (18 bytes each) and the empty name: 55 bytes.
    const std::string chlist("channels\0chlist\0", 16);
    int32_t listBytes = 0;
    std::memcpy(&listBytes, &good[good.find(chlist) + chlist.size()], 4);
    ASSERT_EQ(listBytes, 55);
    patchedSize(chlist, 56);
    {
        const std::string e = readExrError(exr);
        EXPECT_TRUE(contains(e, "the channel list attribute ends 1 bytes before its size says"))
            << e;
    }
    patchedSize(chlist, 54);
    {
        const std::string e = readExrError(exr);
        EXPECT_TRUE(contains(
            e,
            "the channel list attribute does not end with an empty channel name within its size"))
            << e;
    }
    std::ofstream(exr, std::ios::binary | std::ios::trunc) << good;
    EXPECT_NO_THROW(readExr(exr));
}

// Preview and string-vector attributes must hold what they announce (OpenEXR allocates it on
// opening): a valid file with one such attribute added to its header is read, and with the
// announced size too large it is an error naming the attribute.
TEST(JsonLoaderErrors, OpenExrPreviewAndStringVectorMustFitTheirAttribute) {
    TempDir tmp;
    const std::string exr = (tmp.path / "attr.exr").string();
    const std::string good = writtenTinyExr(exr);
    // The end of the header: walk name, type, int32 size, value from byte 8.
    size_t at = 8;
    while (good[at] != '\0') {
        at = good.find('\0', at) + 1;  // name
        at = good.find('\0', at) + 1;  // type
        int32_t size;
        std::memcpy(&size, &good[at], 4);
        at += 4 + size_t(size);
    }
    auto le32 = [](uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
    auto withAttribute = [&](const std::string& name, const std::string& type,
                             const std::string& value) {
        std::string bytes = good;
        bytes.insert(at, name + std::string(1, '\0') + type + std::string(1, '\0') +
                             le32(uint32_t(value.size())) + value);
        // The chunk offsets after the header are absolute: shift them by the insertion. The
        // first chunk starts right after the table, which gives the table's length.
        const size_t added = bytes.size() - good.size();
        uint64_t first;
        std::memcpy(&first, &good[at + 1], 8);
        const size_t chunks = size_t(first - (at + 1)) / 8;
        for (size_t o = at + added + 1; o < at + added + 1 + 8 * chunks; o += 8) {
            uint64_t off;
            std::memcpy(&off, &bytes[o], 8);
            off += added;
            std::memcpy(&bytes[o], &off, 8);
        }
        std::ofstream(exr, std::ios::binary | std::ios::trunc) << bytes;
    };
    // A 1 x 1 preview (4 bytes of RGBA) and two strings: read.
    withAttribute("preview", "preview", le32(1) + le32(1) + std::string(4, 'p'));
    EXPECT_NO_THROW(readExr(exr));
    withAttribute("notes", "stringvector", le32(2) + "ab" + le32(1) + "c");
    EXPECT_NO_THROW(readExr(exr));
    // Announcing more than the attribute holds: errors naming it.
    withAttribute("preview", "preview", le32(60000) + le32(60000) + std::string(4, 'p'));
    {
        const std::string e = readExrError(exr);
        EXPECT_TRUE(contains(e,
                             "header attribute 'preview' (preview) announces a 60000 x 60000 "
                             "preview (14400000008 bytes) in 12 bytes"))
            << e;
    }
    // Announcing less than the attribute holds: OpenEXR would read the rest as attributes.
    withAttribute("preview", "preview", le32(1) + le32(1) + std::string(8, 'p'));
    {
        const std::string e = readExrError(exr);
        EXPECT_TRUE(contains(e,
                             "header attribute 'preview' (preview) announces a 1 x 1 preview (12 "
                             "bytes) in 16 bytes"))
            << e;
    }
    withAttribute("notes", "stringvector", le32(2) + "ab" + le32(1000000) + "c");
    {
        const std::string e = readExrError(exr);
        EXPECT_TRUE(contains(
            e, "header attribute 'notes' (stringvector) announces a string of 1000000 bytes"))
            << e;
    }
}

// Messages quote what the file holds; control characters, bytes that are not UTF-8 and
// megabytes of text are printed escaped and cut, never raw (a NUL cut the message short).
TEST(JsonLoaderErrors, QuotedTextIsPrintedEscapedAndCut) {
    std::string e = onlyError(sceneWith(
        kWhite, R"json({"type": "cube", "material": "wh\u0000ite\u001b[31m"})json", kPoint));
    EXPECT_TRUE(contains(e, "unknown material 'wh\\x00ite\\x1b[31m'")) << e;
    Diagnostic d{"f.obj", 3, 7, "", "bad token '\xff\xfe" + std::string(10000, '1') + "'"};
    const std::string f = d.format();
    EXPECT_EQ(f.substr(0, 40), "f.obj:3:7: error: bad token '\\xff\\xfe111");
    EXPECT_LT(f.size(), 2100u);
    EXPECT_TRUE(contains(f, "... (")) << f;
    EXPECT_EQ(f.substr(f.size() - 11), "more bytes)");
    // Well-formed UTF-8 stays as it is.
    EXPECT_EQ((Diagnostic{"é.json", 1, 2, "", "ü ≥ 𝄞\tok"}.format()),
              "é.json:1:2: error: ü ≥ 𝄞\tok");
}

// Scene::intersectNearest + completeHit (a medium walk's hit, completed where the path reaches
// it) give what intersect() gives, field for field, on meshes with normals and uvs, normal
// and bump maps, anisotropic materials (tangents), spheres and a mesh attribute.
TEST(SceneLoader, CompletedNearestHitEqualsIntersect) {
    const std::string mitsuba = std::string(UNIBEAM_TEST_DATA_DIR) + "/mitsuba";
    for (const std::string& path :
         {mitsuba + "/normalmap.xml", mitsuba + "/anisotropic.xml", mitsuba + "/interop.xml",
          kScenesDir + "/envmap-spheres.json", kScenesDir + "/glass-medium-caustics.json"}) {
        SCOPED_TRACE(path);
        auto scene = loadScene(path);
        Rng rng(7, 0);
        const SceneSphere& s = scene->sceneSphere;
        int hits = 0;
        for (int i = 0; i < 4000; ++i) {
            Ray ray;
            ray.org = s.center +
                      s.radius * 0.9f *
                          Vec3(rng.uniform() * 2 - 1, rng.uniform() * 2 - 1, rng.uniform() * 2 - 1);
            ray.dir = sampleUniformSphere(rng.uniform2());
            Hit a, b;
            const bool hitA = scene->intersect(ray, &a);
            ASSERT_EQ(scene->intersectNearest(ray, &b), hitA);
            if (!hitA) continue;
            ++hits;
            EXPECT_TRUE(b.detailPending);
            EXPECT_EQ(b.dist, a.dist);
            scene->completeHit(ray, &b);
            EXPECT_FALSE(b.detailPending);
            const auto same = [](const Vec3& x, const Vec3& y) {
                return x.x == y.x && x.y == y.y && x.z == y.z;
            };
            EXPECT_TRUE(same(a.pos, b.pos));
            EXPECT_TRUE(same(a.geoNormal, b.geoNormal));
            EXPECT_TRUE(same(a.shadingNormal, b.shadingNormal));
            EXPECT_TRUE(same(a.tangent, b.tangent));
            EXPECT_TRUE(a.uv.x == b.uv.x && a.uv.y == b.uv.y);
            EXPECT_TRUE(a.attribute[0] == b.attribute[0] && a.attribute[1] == b.attribute[1] &&
                        a.attribute[2] == b.attribute[2]);
            EXPECT_EQ(a.shapeId, b.shapeId);
            EXPECT_EQ(a.primId, b.primId);
            EXPECT_EQ(a.materialId, b.materialId);
            EXPECT_EQ(a.lightId, b.lightId);
            // Completing twice changes nothing.
            Hit c = b;
            scene->completeHit(ray, &c);
            EXPECT_TRUE(same(c.pos, b.pos) && same(c.shadingNormal, b.shadingNormal));
        }
        EXPECT_GT(hits, 500);  // open scenes: rays from inside may escape
    }
}
