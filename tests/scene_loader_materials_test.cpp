// Native JSON format: plastic, rough_plastic and thin_dielectric materials, textured
// colours (checkerboard, bitmap) and spot lights (docs/scene-format.md), and their errors
// with file:line:column and JSON pointer.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/image.h"
#include "scene/bsdf.h"
#include "scene/io/json_loader.h"
#include "scene/scene.h"

using namespace ub;
namespace fs = std::filesystem;

namespace {

struct TempDir {
    fs::path path;
    TempDir() {
        path = fs::temp_directory_path() /
               ("unibeam_materials_test_" +
                std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
        fs::create_directories(path);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path, ec);
    }
};

const char* kCamera =
    R"json("camera": {"position": [0, 0, 5], "target": [0, 0, 0], "fov": 40, "resolution": [32, 24]})json";

/// Materials on line 3 (after `"materials": {`, column 15), shapes on line 4, lights on
/// line 5.
std::string sceneWith(const std::string& materials, const std::string& shapes,
                      const std::string& lights) {
    return std::string("{\n") + kCamera + ",\n\"materials\": {" + materials + "},\n\"shapes\": [" +
           shapes + "],\n\"lights\": [" + lights + "]\n}\n";
}

const char* kPoint = R"json({"type": "point", "position": [0, 0, 3], "intensity": 10})json";

std::vector<Diagnostic> errorsOf(const std::string& text, const std::string& baseDir) {
    try {
        loadJsonSceneFromString(text, "scene.json", baseDir);
    } catch (const InputError& e) {
        return e.diagnostics();
    }
    return {};
}

std::string allErrors(const std::vector<Diagnostic>& d) {
    std::string s;
    for (const auto& x : d) s += x.format() + "\n";
    return s;
}

bool contains(const std::string& s, const std::string& part) {
    return s.find(part) != std::string::npos;
}

void writeTestPng(const fs::path& path) {
    Image img(4, 2);
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 4; ++x) img.at(x, y) = Rgb(0.1f * x, 0.5f * y, 0.25f);
    writePng(path.string(), img);
}

}  // namespace

TEST(JsonLoader, PlasticsThinDielectricTexturesAndSpotLoad) {
    TempDir dir;
    writeTestPng(dir.path / "tiles.png");
    const std::string materials = R"json(
  "shiny": {"type": "plastic", "diffuse_reflectance": [0.1, 0.27, 0.36], "int_ior": 1.9},
  "matte": {"type": "rough_plastic", "diffuse_reflectance": {"type": "bitmap", "file": "tiles.png",
            "to_uv": {"scale": [4, 2]}}, "nonlinear": true, "two_sided": false},
  "sheet": {"type": "thin_dielectric", "specular_transmittance": [0.9, 0.95, 1]},
  "floor": {"type": "diffuse", "reflectance": {"type": "checkerboard", "color0": 0.8,
            "color1": [0.1, 0.2, 0.3], "to_uv": {"matrix": [[2, 0, 0.5], [0, 2, 0], [0, 0, 1]]}}},
  "raw":   {"type": "diffuse", "reflectance": {"type": "bitmap", "file": "tiles.png", "raw": true}})json";
    const std::string shapes =
        R"json({"type": "rectangle", "material": "shiny"}, {"type": "cube", "material": "matte"},
               {"type": "sphere", "radius": 1, "material": "sheet"}, {"type": "rectangle", "material": "floor"},
               {"type": "rectangle", "material": "raw"})json";
    const std::string lights =
        R"json({"type": "spot", "position": [0, 0, 3], "target": [0, 0, 0], "intensity": 10,
                "cutoff_angle": 40},
               {"type": "spot", "position": [1, 0, 3], "direction": [0, 0, -2], "intensity": 5,
                "cutoff_angle": 30, "beam_width": 10})json";
    auto scene = loadJsonSceneFromString(sceneWith(materials, shapes, lights), "scene.json",
                                         dir.path.string());
    ASSERT_EQ(scene->materials.size(), 5u);
    const Material& shiny = scene->materials[0];
    EXPECT_EQ(shiny.type, MaterialType::Plastic);
    EXPECT_NEAR(shiny.ior, 1.9f / 1.000277f, 1e-6f);  // int_ior / ext_ior (air)
    EXPECT_FALSE(shiny.nonlinear);
    EXPECT_EQ(shiny.specular.x, 1.0f);
    EXPECT_EQ(shiny.textures.diffuse, -1);
    EXPECT_EQ(shiny.preparedIor, shiny.ior);  // Scene::addMaterial prepared it
    const Material& matte = scene->materials[1];
    EXPECT_EQ(matte.type, MaterialType::RoughPlastic);
    EXPECT_NEAR(matte.ior, 1.49f / 1.000277f, 1e-6f);  // Mitsuba's polypropylene default
    EXPECT_EQ(matte.alpha, 0.1f);                      // Mitsuba's default roughness
    EXPECT_TRUE(matte.nonlinear);
    EXPECT_FALSE(matte.twoSided);
    EXPECT_GT(matte.internalReflectance, 0.0f);
    ASSERT_GE(matte.textures.diffuse, 0);
    const Material& sheet = scene->materials[2];
    EXPECT_EQ(sheet.type, MaterialType::ThinDielectric);
    EXPECT_NEAR(sheet.ior, 1.5046f / 1.000277f, 1e-6f);  // BK7
    EXPECT_EQ(sheet.transmittance.y, 0.95f);

    ASSERT_EQ(scene->textures.size(), 3u);
    const Texture& tiles = scene->textures[size_t(matte.textures.diffuse)];
    EXPECT_EQ(tiles.type, TextureType::Bitmap);
    ASSERT_TRUE(tiles.image);
    EXPECT_EQ(tiles.image->width, 4);
    EXPECT_EQ(tiles.toUv.m[0][0], 4.0f);
    EXPECT_EQ(tiles.toUv.m[1][1], 2.0f);
    // PNG values are sRGB: 0.5 linear was written as byte 188, decoded back to ~0.5.
    EXPECT_NEAR(tiles.image->at(0, 1).y, 0.5f, 0.01f);
    const Texture& checks = scene->textures[size_t(scene->materials[3].textures.diffuse)];
    EXPECT_EQ(checks.type, TextureType::Checkerboard);
    EXPECT_EQ(checks.color0.x, 0.8f);
    EXPECT_EQ(checks.color1.z, 0.3f);
    EXPECT_EQ(checks.toUv.m[0][2], 0.5f);
    const Texture& raw = scene->textures[size_t(scene->materials[4].textures.diffuse)];
    EXPECT_NEAR(raw.image->at(0, 1).y, 188.0f / 255.0f, 1e-6f);  // raw: the sRGB bytes / 255

    ASSERT_EQ(scene->lights.size(), 2u);
    const Light& spot = scene->lights[0];
    EXPECT_EQ(spot.type, LightType::Spot);
    EXPECT_NEAR(spot.direction.z, -1.0f, 1e-6f);
    EXPECT_EQ(spot.cutoffAngleDeg, 40.0f);
    EXPECT_EQ(spot.beamWidthDeg, 30.0f);  // 3/4 of the cutoff (Mitsuba's default)
    EXPECT_EQ(scene->lights[1].beamWidthDeg, 10.0f);
    EXPECT_NEAR(scene->lights[1].direction.z, -1.0f, 1e-6f);
}

// Bitmaps: missing file, unsupported extension, unreadable file, pixels outside the
// parameter's range; unknown texture type with a suggestion; a string where a colour is
// expected; a malformed to_uv. Every error is reported in one go, at its JSON pointer.
TEST(JsonLoaderErrors, TextureErrors) {
    TempDir dir;
    Image bright(2, 2);
    bright.at(1, 0) = Rgb(0.5f, 2.0f, 0.5f);
    writeExr((dir.path / "bright.exr").string(), bright);
    std::ofstream(dir.path / "broken.png") << "not a png";
    const std::string materials = R"json(
"a": {"type": "diffuse", "reflectance": {"type": "bitmap", "file": "missing.png"}},
"b": {"type": "diffuse", "reflectance": {"type": "bitmap", "file": "tiles.gif"}},
"c": {"type": "diffuse", "reflectance": {"type": "bitmap", "file": "broken.png"}},
"d": {"type": "diffuse", "reflectance": {"type": "bitmap", "file": "bright.exr"}},
"e": {"type": "diffuse", "reflectance": {"type": "checkerbord"}},
"f": {"type": "plastic", "diffuse_reflectance": "red"},
"g": {"type": "diffuse", "reflectance": {"type": "checkerboard", "to_uv": {"matrix": [[1, 0], [0, 1]]}}},
"h": {"type": "diffuse", "reflectance": {"type": "checkerboard", "color1": 1.5, "size": 2}})json";
    const std::string shapes = R"json({"type": "rectangle", "material": "a"})json";
    auto d = errorsOf(sceneWith(materials, shapes, kPoint), dir.path.string());
    const std::string all = allErrors(d);
    ASSERT_EQ(d.size(), 9u) << all;
    EXPECT_TRUE(contains(all,
                         "scene.json:4:68: error: at /materials/a/reflectance/file: bitmap "
                         "'missing.png' not found (looked for '" +
                             (dir.path / "missing.png").string() +
                             "'; paths are relative to the scene file)"))
        << all;
    EXPECT_TRUE(contains(all,
                         "scene.json:5:68: error: at /materials/b/reflectance/file: "
                         "unsupported bitmap file 'tiles.gif' (expected .png, .jpg/.jpeg, .exr, "
                         ".bmp, .tga, .hdr/.rgbe or .ppm/.pgm/.pnm; EXR and RGBE are linear, "
                         "the others sRGB unless raw)"))
        << all;
    EXPECT_TRUE(contains(all,
                         "error: at /materials/c/reflectance/file: cannot read bitmap "
                         "'broken.png': not a PNG file (bad signature)"))
        << all;
    EXPECT_TRUE(contains(all,
                         "error: at /materials/d/reflectance/file: bitmap 'bright.exr' "
                         "pixel (1, 0) = [0.5, 2, 0.5] is not a number in [0, 1]"))
        << all;
    EXPECT_TRUE(contains(all,
                         "scene.json:8:50: error: at /materials/e/reflectance/type: unknown "
                         "texture type 'checkerbord' (did you mean 'checkerboard'?); valid "
                         "types: checkerboard, bitmap (or give an RGB colour)"))
        << all;
    EXPECT_TRUE(contains(all,
                         "scene.json:9:49: error: at /materials/f/diffuse_reflectance: "
                         "expected an RGB colour (one number or [r, g, b], each a number in "
                         "[0, 1]) or a texture object {\"type\": \"checkerboard\" or "
                         "\"bitmap\", ...}, got a string (\"red\")"))
        << all;
    EXPECT_TRUE(contains(all,
                         "error: at /materials/g/reflectance/to_uv/matrix: expected a "
                         "row-major 3x3 matrix (3 rows of 3 numbers) or 4x4 matrix (4 rows "
                         "of 4 numbers)"))
        << all;
    EXPECT_TRUE(contains(all,
                         "error: at /materials/h/reflectance/color1: "
                         "expected a number in [0, 1], got 1.5"))
        << all;
    EXPECT_TRUE(contains(all,
                         "error: at /materials/h/reflectance/size: unknown key 'size' in "
                         "checkerboard texture"))
        << all;
}

// A textured Phong must conserve energy with the textures' maxima.
TEST(JsonLoaderErrors, TexturedPhongEnergyUsesMaxima) {
    const std::string materials = R"json(
"p": {"type": "phong", "exponent": 10, "glossy_reflectance": 0.5,
      "diffuse_reflectance": {"type": "checkerboard", "color0": 0.2, "color1": [0.2, 0.6, 0.2]}})json";
    const std::string shapes = R"json({"type": "rectangle", "material": "p"})json";
    auto d = errorsOf(sceneWith(materials, shapes, kPoint), ".");
    ASSERT_EQ(d.size(), 1u) << allErrors(d);
    EXPECT_TRUE(contains(d[0].format(),
                         "at /materials/p: diffuse_reflectance + "
                         "glossy_reflectance = 1.1 > 1 in the green channel"))
        << d[0].format();
}

// multi_lobe (SmallUPBP's sum of lobes): the lobes are read; a material whose lobes add up
// to more than 1 is an error unless allow_energy_gain says it is meant.
TEST(JsonLoader, MultiLobeMaterialAndItsEnergyCheck) {
    const std::string ok = R"json(
"wax": {"type": "multi_lobe", "diffuse_reflectance": 0.588, "ior": 1.0, "allow_energy_gain": true},
"lacquer": {"type": "multi_lobe", "diffuse_reflectance": 0.3, "glossy_reflectance": 0.2, "exponent": 40, "mirror_reflectance": 0.4})json";
    const std::string shapes = R"json({"type": "rectangle", "material": "wax"},
{"type": "sphere", "radius": 0.5, "material": "lacquer"})json";
    auto s = loadJsonSceneFromString(sceneWith(ok, shapes, kPoint), "scene.json", ".");
    ASSERT_EQ(s->materials.size(), 2u);
    for (const Material& m : s->materials) {
        EXPECT_EQ(m.type, MaterialType::MultiLobe);
        if (m.name == "wax") {
            EXPECT_TRUE(m.refract);
            EXPECT_FLOAT_EQ(m.ior, 1.0f);
            EXPECT_FLOAT_EQ(m.diffuse.x, 0.588f);
        } else {
            EXPECT_FALSE(m.refract);
            EXPECT_FLOAT_EQ(m.specular.y, 0.4f);
            EXPECT_FLOAT_EQ(m.exponent, 40.0f);
        }
    }
    const std::string gain = R"json(
"w": {"type": "multi_lobe", "diffuse_reflectance": 0.5, "ior": 1.3})json";
    auto d =
        errorsOf(sceneWith(gain, R"json({"type": "rectangle", "material": "w"})json", kPoint), ".");
    ASSERT_EQ(d.size(), 1u) << allErrors(d);
    EXPECT_TRUE(contains(d[0].format(),
                         "at /materials/w: the lobes add up to an albedo of 1.5 in the red "
                         "channel (diffuse + glossy + refraction 1)"))
        << d[0].format();
}

// Textured roughness (rough_conductor, rough_dielectric): "alpha" and "alpha_v" take a
// texture; its value at the hit's uv (the luminance of an RGB one) is the roughness there.
// A texture on a material without a microfacet lobe, and a value outside [0, 1], are errors.
TEST(JsonLoader, TexturedRoughness) {
    const std::string mats = R"json(
"brushed": {"type": "rough_conductor", "metal": "gold", "alpha": {"type": "checkerboard", "color0": 0.05, "color1": 0.5}},
"aniso": {"type": "rough_dielectric", "ior": 1.5, "alpha": 0.2, "alpha_v": {"type": "checkerboard", "color0": 0.3, "color1": 0.6}})json";
    const std::string shapes = R"json({"type": "rectangle", "material": "brushed"},
{"type": "sphere", "radius": 0.5, "material": "aniso"})json";
    auto s = loadJsonSceneFromString(sceneWith(mats, shapes, kPoint), "scene.json", ".");
    ASSERT_EQ(s->materials.size(), 2u);
    const Material& brushed = s->materials[0];
    ASSERT_GE(brushed.textures.alpha, 0);
    EXPECT_LT(brushed.alphaV, 0.0f);  // isotropic: alpha_v follows the texture
    // The checkerboard's cells (texture.cpp): color0 where both uv halves agree.
    SurfaceColors c = s->surfaceColors(brushed, Vec2(0.25f, 0.25f), Rgb(0.0f));
    EXPECT_FLOAT_EQ(c.alphaU, 0.05f);
    EXPECT_FLOAT_EQ(c.alphaV, 0.05f);
    c = s->surfaceColors(brushed, Vec2(0.75f, 0.25f), Rgb(0.0f));
    EXPECT_FLOAT_EQ(c.alphaU, 0.5f);
    const Material& aniso = s->materials[1];
    EXPECT_EQ(aniso.textures.alpha, -1);
    ASSERT_GE(aniso.textures.alphaV, 0);
    EXPECT_TRUE(aniso.anisotropic());
    c = s->surfaceColors(aniso, Vec2(0.75f, 0.25f), Rgb(0.0f));
    EXPECT_FLOAT_EQ(c.alphaU, 0.2f);
    EXPECT_FLOAT_EQ(c.alphaV, 0.6f);

    auto d = errorsOf(
        sceneWith(R"json("p": {"type": "rough_plastic", "alpha": {"type": "checkerboard"}})json",
                  R"json({"type": "rectangle", "material": "p"})json", kPoint),
        ".");
    ASSERT_FALSE(d.empty());
    EXPECT_TRUE(contains(allErrors(d), "at /materials/p/alpha: expected a number in (0, 1]"))
        << allErrors(d);
    d = errorsOf(
        sceneWith(
            R"json("c": {"type": "rough_conductor", "alpha": {"type": "checkerboard", "color0": 1.5}})json",
            R"json({"type": "rectangle", "material": "c"})json", kPoint),
        ".");
    ASSERT_FALSE(d.empty());
    EXPECT_TRUE(contains(allErrors(d), "/materials/c/alpha")) << allErrors(d);
}

TEST(JsonLoaderErrors, PlasticAndThinDielectricErrors) {
    const std::string materials = R"json(
"r": {"type": "rough_plastic", "int_ior": 1.3, "ext_ior": 1.3, "alpha": 0},
"p": {"type": "plastic", "ior": 1.5},
"t": {"type": "thin_dielectric", "int_ior": -1, "two_sided": true})json";
    const std::string shapes = R"json({"type": "rectangle", "material": "r"})json";
    auto d = errorsOf(sceneWith(materials, shapes, kPoint), ".");
    const std::string all = allErrors(d);
    ASSERT_EQ(d.size(), 5u) << all;
    EXPECT_TRUE(contains(all,
                         "scene.json:4:43: error: at /materials/r/int_ior: int_ior and "
                         "ext_ior are equal (1.3): a rough_plastic needs a coating that "
                         "differs from the outside"))
        << all;
    EXPECT_TRUE(contains(all, "at /materials/r/alpha: expected a number in (0, 1], got 0")) << all;
    EXPECT_TRUE(contains(all, "at /materials/p/ior: unknown key 'ior' in plastic material")) << all;
    EXPECT_TRUE(contains(all, "at /materials/t/int_ior: expected a number > 0, got -1")) << all;
    EXPECT_TRUE(contains(all,
                         "at /materials/t/two_sided: unknown key 'two_sided' in "
                         "thin_dielectric material"))
        << all;
}

TEST(JsonLoaderErrors, SpotLightErrors) {
    const std::string materials = R"json("w": {"type": "diffuse"})json";
    const std::string shapes = R"json({"type": "rectangle", "material": "w"})json";
    const std::string lights = R"json(
{"type": "spot", "position": [0, 0, 3], "direction": [0, 0, -1], "target": [0, 0, 0], "intensity": 1},
{"type": "spot", "position": [0, 0, 3], "intensity": 1},
{"type": "spot", "position": [0, 0, 3], "target": [0, 0, 3], "intensity": 1},
{"type": "spot", "position": [0, 0, 3], "direction": [0, 0, -1], "intensity": 1, "cutoff_angle": 30, "beam_width": 40},
{"type": "spot", "position": [0, 0, 3], "direction": [0, 0, -1], "intensity": 1, "cutoff_angle": 0},
{"type": "spott", "position": [0, 0, 3]})json";
    auto d = errorsOf(sceneWith(materials, shapes, lights), ".");
    const std::string all = allErrors(d);
    ASSERT_EQ(d.size(), 6u) << all;
    EXPECT_TRUE(contains(all,
                         "scene.json:6:76: error: at /lights/0/target: a spot light needs "
                         "exactly one of \"direction\" (the axis of its cone) or \"target\" "
                         "(a point on the axis)"))
        << all;
    EXPECT_TRUE(contains(all, "at /lights/1: a spot light needs exactly one of")) << all;
    EXPECT_TRUE(contains(all,
                         "at /lights/2/target: the target equals the position: the spot "
                         "light has no direction"))
        << all;
    EXPECT_TRUE(contains(all,
                         "at /lights/3/beam_width: beam_width 40 exceeds cutoff_angle 30 "
                         "(expected a number in [0, cutoff_angle] degrees)"))
        << all;
    EXPECT_TRUE(contains(all, "at /lights/4/cutoff_angle: expected a number in (0, 180], got 0"))
        << all;
    EXPECT_TRUE(contains(all,
                         "at /lights/5/type: unknown light type 'spott' (did you mean "
                         "'spot'?)"))
        << all;
}

// The material, texture and light examples of docs/scene-format.md load (the texture
// example's bitmap is created in a temporary folder; the light example's sky map is the
// bundled one).
TEST(SceneFormatDoc, MaterialTextureAndLightExamplesLoad) {
    std::ifstream in(std::string(UNIBEAM_SOURCE_DIR) + "/docs/scene-format.md");
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string doc = ss.str();
    auto block = [&](const std::string& start) {
        size_t b = doc.find("```json\n" + start);
        EXPECT_NE(b, std::string::npos) << start;
        if (b == std::string::npos) return std::string();
        b += 8;
        return doc.substr(b, doc.find("```", b) - b);
    };
    const std::string materials = block("\"materials\": {\n  \"white\"");
    const std::string textures = block("\"materials\": {\n  \"tiles\"");
    const std::string lights = block("\"lights\": [");
    const std::string scenes = std::string(UNIBEAM_SOURCE_DIR) + "/scenes";
    auto scene = loadJsonSceneFromString(
        std::string("{") + kCamera + ",\n" + materials + ",\n" + lights +
            ",\n\"shapes\": [{\"type\": \"rectangle\", \"material\": \"shiny\"}]}",
        "doc.json", scenes);
    EXPECT_EQ(scene->materials.size(), 11u);
    EXPECT_EQ(scene->lights.size(), 4u);
    TempDir dir;
    fs::create_directories(dir.path / "textures");
    writeTestPng(dir.path / "textures" / "wood.png");
    scene = loadJsonSceneFromString(
        std::string("{") + kCamera + ",\n" + textures + ",\n\"lights\": [" + kPoint +
            "],\n\"shapes\": [{\"type\": \"rectangle\", \"material\": \"wood\"}]}",
        "doc.json", dir.path.string());
    EXPECT_EQ(scene->textures.size(), 2u);
}

// OBJ texture coordinates are flipped (v = 1 - t) as Mitsuba 3 does by default, PLY ones are
// kept: a ray down onto the OBJ triangle's vertex with vt (0, 1) sees uv (0, 0).
TEST(JsonLoader, ObjTextureCoordinatesAreFlippedPlyAreNot) {
    const std::string dataDir = std::string(UNIBEAM_TEST_DATA_DIR);
    auto scene = loadJsonSceneFromString(
        sceneWith(R"json("w": {"type": "diffuse"})json",
                  R"json({"type": "obj", "file": "meshes/triangle.obj", "material": "w"},
                         {"type": "ply", "file": "meshes/square.ply", "material": "w",
                          "transform": {"translate": [5, 0, 0]}})json",
                  kPoint),
        "scene.json", dataDir);
    auto uvAt = [&](const Vec3& p) {
        Ray ray;
        ray.org = p + Vec3(0, 0, 1);
        ray.dir = Vec3(0, 0, -1);
        Hit hit;
        EXPECT_TRUE(scene->intersect(ray, &hit));
        return hit.uv;
    };
    // triangle.obj: (0,0,0) vt (0,0), (2,0,0) vt (1,0), (0,2,0) vt (0,1).
    Vec2 uv = uvAt(Vec3(0.02f, 1.9f, 0.0f));  // near the vertex with vt (0, 1)
    EXPECT_NEAR(uv.x, 0.01f, 1e-4f);
    EXPECT_NEAR(uv.y, 1.0f - 0.95f, 1e-4f);
    // square.ply: the file's (s, t) equals (x, y).
    uv = uvAt(Vec3(5.25f, 0.75f, 0.0f));
    EXPECT_NEAR(uv.x, 0.25f, 1e-4f);
    EXPECT_NEAR(uv.y, 0.75f, 1e-4f);
}

// principled: Mitsuba's keys and defaults; one-sided by default; eta from specular; errors
// for eta with specular, a weight outside [0, 1], and two_sided with spec_trans.
TEST(JsonLoader, PrincipledMaterialAndItsErrors) {
    const std::string ok = R"json(
"paint": {"type": "principled", "base_color": [0.8, 0.3, 0.2], "roughness": 0.3, "clearcoat": 0.5, "sheen": 0.4},
"glass": {"type": "principled", "spec_trans": 1, "eta": 1.33, "roughness": {"type": "checkerboard", "color0": 0.1, "color1": 0.5}},
"leaf": {"type": "principled_thin", "diff_trans": 1.5, "spec_trans": 0.2, "eta": 1.4})json";
    const std::string shapes = R"json({"type": "rectangle", "material": "paint"},
{"type": "sphere", "radius": 0.5, "material": "glass"}, {"type": "rectangle", "material": "leaf"})json";
    auto s = loadJsonSceneFromString(sceneWith(ok, shapes, kPoint), "scene.json", ".");
    ASSERT_EQ(s->materials.size(), 3u);
    for (const Material& m : s->materials) {
        if (m.name == "leaf") {
            EXPECT_EQ(m.type, MaterialType::PrincipledThin);
            EXPECT_TRUE(m.twoSided);
            EXPECT_FLOAT_EQ(m.principled.diffTrans, 1.5f);
            EXPECT_FLOAT_EQ(m.ior, 1.4f);
            continue;
        }
        EXPECT_EQ(m.type, MaterialType::Principled);
        EXPECT_FALSE(m.twoSided);
        if (m.name == "paint") {
            EXPECT_FLOAT_EQ(m.alpha, 0.3f);
            EXPECT_FLOAT_EQ(m.principled.clearcoat, 0.5f);
            EXPECT_FLOAT_EQ(m.principled.sheen, 0.4f);
            EXPECT_NEAR(m.ior, 1.5f, 1e-5f);  // specular 0.5
        } else {
            EXPECT_FLOAT_EQ(m.principled.specTrans, 1.0f);
            EXPECT_FLOAT_EQ(m.ior, 1.33f);
            EXPECT_GE(m.textures.alpha, 0);
        }
    }
    const std::string bad = R"json(
"a": {"type": "principled", "eta": 1.4, "specular": 0.3},
"b": {"type": "principled", "sheen": 1.5},
"c": {"type": "principled", "spec_trans": 0.5, "two_sided": true},
"d": {"type": "principled_thin", "metallic": 0.5})json";
    const std::string three = R"json({"type": "rectangle", "material": "a"},
{"type": "rectangle", "material": "b"}, {"type": "rectangle", "material": "c"},
{"type": "rectangle", "material": "d"})json";
    const std::string e = allErrors(errorsOf(sceneWith(bad, three, kPoint), "."));
    EXPECT_TRUE(contains(e, "at /materials/a/specular: give either \"eta\" or \"specular\"")) << e;
    EXPECT_TRUE(contains(e, "/materials/b/sheen")) << e;
    EXPECT_TRUE(contains(e,
                         "at /materials/c/two_sided: a two-sided principled material cannot "
                         "transmit"))
        << e;
}
