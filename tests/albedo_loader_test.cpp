// Albedo grids in the scene formats (docs/mitsuba.md, docs/scene-format.md):
//  * Mitsuba: <volume name="albedo" type="gridvolume"> in a heterogeneous medium (.vol with
//    1 or 3 channels, .vdb float or vec3 grids chosen by grid_name), with its own to_world
//    and filter_type; the sigma_t gridvolume reads a named .vdb grid; errors name
//    file:line:col;
//  * JSON: "albedo_grid", "albedo_file", "albedo_filter" of heterogeneous media and their
//    errors at the JSON pointer of the key;
//  * chromatic extinction: a 3-channel sigma_t (.vol, vec3 .vdb grid, a spectrally varying
//    constant with an albedo grid) in both formats.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.h"
#include "scene/albedo_grid.h"
#include "scene/io/json_loader.h"
#include "scene/io/mitsuba_loader.h"
#include "scene/scene.h"
#include "scene/vdb_grid.h"
#include "scene/vol_grid.h"
#include "tests/support/temp_file.h"
#include "tests/support/vol_file.h"

using namespace ub;
using namespace ub::test;
namespace fs = std::filesystem;

namespace {

bool contains(const std::string& s, const std::string& part) {
    return s.find(part) != std::string::npos;
}

/// Scratch folder (removed at the end of the test).
struct ScratchDir {
    fs::path path;
    ScratchDir() {
        path = ub::test::processScratchDir() /
               ("albedo_loader_" +
                std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
        fs::create_directories(path);
    }
    ~ScratchDir() {
        std::error_code ec;
        fs::remove_all(path, ec);
    }
    std::string operator/(const std::string& name) const { return (path / name).string(); }
};

const char* kSensor = R"(<sensor type="perspective">
  <float name="fov" value="40"/>
  <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
  <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/></film>
</sensor>
<emitter type="constant"><rgb name="radiance" value="1"/></emitter>
)";

/// A Mitsuba scene whose medium "m" (given in full) fills a null-BSDF cube.
std::string xmlScene(const std::string& medium) {
    return std::string("<scene version=\"3.0.0\">\n") + kSensor + medium +
           "\n<shape type=\"cube\"><bsdf type=\"null\"/><ref id=\"m\" name=\"interior\"/></shape>\n"
           "</scene>\n";
}

std::unique_ptr<Scene> loadXml(const std::string& text, const std::string& dir) {
    return loadMitsubaSceneFromString(text, "scene.xml", dir, {});
}

std::string xmlErrors(const std::string& text, const std::string& dir) {
    try {
        loadXml(text, dir);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

/// "scene.xml:LINE:COL" of the first occurrence of `what` in text (1-based, as the loader).
std::string where(const std::string& text, const std::string& what) {
    size_t at = text.find(what);
    if (at == std::string::npos) return "<not in the text>";
    int line = 1;
    size_t lineStart = 0;
    for (size_t i = 0; i < at; ++i)
        if (text[i] == '\n') ++line, lineStart = i + 1;
    return "scene.xml:" + std::to_string(line) + ":" + std::to_string(at - lineStart + 1);
}

std::string gridVolume(const std::string& name, const std::string& file,
                       const std::string& extra = "") {
    return "<volume name=\"" + name + "\" type=\"gridvolume\"><string name=\"filename\" value=\"" +
           file + "\"/>" + extra + "</volume>";
}

std::string heterogeneous(const std::string& sigmaT, const std::string& albedo) {
    return "<medium id=\"m\" type=\"heterogeneous\">" + sigmaT + albedo + "</medium>";
}

/// 2x2x2 density 1 and a 2x1x1 RGB albedo: voxel 0 (0.1, 0.2, 0.3), voxel 1 (0.7, 0.8, 0.9).
void writeVolFiles(const ScratchDir& dir) {
    writeBinaryFile(dir / "sigma.vol", volBytes(2, 2, 2, 1, std::vector<float>(8, 1.0f)));
    writeBinaryFile(dir / "albedo.vol", volBytes(2, 1, 1, 3, {0.1f, 0.2f, 0.3f, 0.7f, 0.8f, 0.9f}));
    writeBinaryFile(dir / "grey.vol", volBytes(2, 1, 1, 1, {0.25f, 0.75f}));
    writeBinaryFile(dir / "hot.vol", volBytes(2, 1, 1, 1, {0.25f, 1.5f}));
    writeBinaryFile(dir / "rgb_sigma.vol", volBytes(1, 1, 1, 3, {1.0f, 1.0f, 1.0f}));
}

void expectRgbNear(const Rgb& a, const Rgb& b, const char* what) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], 1e-5f) << what << " channel " << c;
}

}  // namespace

TEST(MitsubaAlbedo, VolAlbedoGridHasItsOwnTransformAndFilter) {
    ScratchDir dir;
    writeVolFiles(dir);
    const std::string toWorld =
        "<transform name=\"to_world\"><translate x=\"-0.5\" y=\"-0.5\" z=\"-0.5\"/></transform>";
    // Default filter (trilinear): the unit cube moved to [-0.5, 0.5]^3; voxel centres at
    // x = -0.25 and 0.25, linear in between, clamped beyond.
    auto s = loadXml(xmlScene(heterogeneous(gridVolume("sigma_t", "sigma.vol"),
                                            gridVolume("albedo", "albedo.vol", toWorld))),
                     dir.path.string());
    ASSERT_EQ(s->media.size(), 1u);
    const Medium& m = s->media[0];
    ASSERT_TRUE(m.albedoGrid);
    EXPECT_EQ(m.albedoGrid->channelCount, 3);
    EXPECT_EQ(m.albedoGrid->filter, GridFilter::kTrilinear);
    expectRgbNear(albedoGridAt(*m.albedoGrid, Vec3(-0.25f, 0.1f, 0.0f)), Rgb(0.1f, 0.2f, 0.3f),
                  "voxel 0 centre");
    expectRgbNear(albedoGridAt(*m.albedoGrid, Vec3(0.0f, 0.0f, 0.3f)), Rgb(0.4f, 0.5f, 0.6f),
                  "half-way");
    expectRgbNear(albedoGridAt(*m.albedoGrid, Vec3(0.45f, -0.4f, 0.0f)), Rgb(0.7f, 0.8f, 0.9f),
                  "beyond voxel 1 centre (clamped)");
    // sigma_s = albedo * sigma_t at a point.
    const MediumCoefficients c = mediumCoefficientsAt(m, Vec3(0.25f, 0.5f, 0.5f));
    EXPECT_NEAR(c.sigmaS.y, 0.8f * c.sigmaT.y, 1e-5f);

    // filter_type="nearest", a grey grid, no to_world (the unit cube).
    s = loadXml(
        xmlScene(heterogeneous(
            gridVolume("sigma_t", "sigma.vol"),
            gridVolume("albedo", "grey.vol", "<string name=\"filter_type\" value=\"nearest\"/>"))),
        dir.path.string());
    const AlbedoGrid& a = *s->media[0].albedoGrid;
    EXPECT_EQ(a.channelCount, 1);
    EXPECT_EQ(a.filter, GridFilter::kNearest);
    expectRgbNear(albedoGridAt(a, Vec3(0.49f, 0.5f, 0.5f)), Rgb(0.25f), "nearest voxel 0");
    expectRgbNear(albedoGridAt(a, Vec3(0.51f, 0.5f, 0.5f)), Rgb(0.75f), "nearest voxel 1");
}

TEST(MitsubaAlbedo, SharedTestAlbedoVolMatchesTheFile) {
    // The RGB albedo.vol of Mitsuba's participating-media tests (16^3 x 3): at voxel centres
    // the trilinear lookup returns the stored values.
    const std::string dir = std::string(UNIBEAM_MITSUBA_MEDIA_DIR);
    ASSERT_TRUE(fs::is_directory(dir)) << "test data not found: " << dir;
    auto s = loadXml(xmlScene(heterogeneous(gridVolume("sigma_t", "textures/sigmat.vol"),
                                            gridVolume("albedo", "textures/albedo.vol"))),
                     dir);
    const AlbedoGrid& a = *s->media[0].albedoGrid;
    VolGrid vol = readVolFile(dir + "/textures/albedo.vol");
    ASSERT_EQ(vol.channels, 3);
    for (int k : {0, 5, 15})
        for (int j : {0, 7, 15})
            for (int i : {0, 3, 15}) {
                const Vec3 p((i + 0.5f) / 16.0f, (j + 0.5f) / 16.0f, (k + 0.5f) / 16.0f);
                expectRgbNear(albedoGridAt(a, p),
                              Rgb(vol.at(i, j, k, 0), vol.at(i, j, k, 1), vol.at(i, j, k, 2)),
                              "voxel centre");
            }
}

TEST(MitsubaAlbedo, ConstantSigmaTWithAnAlbedoGrid) {
    // A grey constant sigma_t with an albedo gridvolume: a grid medium of constant density
    // (inside and outside the grid's one voxel), sigma_s = albedo(x) sigma_t.
    ScratchDir dir;
    writeVolFiles(dir);
    auto s = loadXml(
        xmlScene(heterogeneous("<float name=\"sigma_t\" value=\"2\"/><float name=\"scale\" "
                               "value=\"1.5\"/>",
                               gridVolume("albedo", "albedo.vol",
                                          "<string name=\"filter_type\" value=\"nearest\"/>"))),
        dir.path.string());
    const Medium& m = s->media[0];
    ASSERT_EQ(m.type, MediumType::kGrid);
    ASSERT_TRUE(m.albedoGrid);
    for (const Vec3& p : {Vec3(0.25f, 0.5f, 0.5f), Vec3(0.75f, 0.2f, 0.9f), Vec3(-3, 7, 2)}) {
        const MediumCoefficients c = mediumCoefficientsAt(m, p);
        expectRgbNear(c.sigmaT, Rgb(3.0f), "sigma_t");
        expectRgbNear(c.sigmaS, albedoGridAt(*m.albedoGrid, p) * 3.0f, "sigma_s");
    }
    expectRgbNear(mediumCoefficientsAt(m, Vec3(0.75f, 0.5f, 0.5f)).sigmaS,
                  Rgb(0.7f, 0.8f, 0.9f) * 3.0f, "voxel 1");
    // Transmittance through and beside the grid's voxel: exp(-3 L).
    for (const Vec3& o : {Vec3(-1.0f, 0.5f, 0.5f), Vec3(-1.0f, 4.0f, -2.0f)}) {
        const Rgb T = transmittance(m, o, Vec3(1, 0, 0), 2.5f);
        expectRgbNear(T, Rgb(std::exp(-3.0f * 2.5f)), "transmittance");
    }
}

TEST(MitsubaAlbedo, VdbGridNamesForSigmaTAndAlbedo) {
    ScratchDir dir;
    DenseFloatGrid one(2, 2, 2, 1.0f), half(2, 2, 2, 0.5f), quarter(2, 2, 2, 0.25f);
    writeDenseVdb(dir / "media.vdb", {{"density", {half}},
                                      {"sigma", {one}},
                                      {"albedo", {half, quarter, one}},
                                      {"tint", {quarter}}});
    // Defaults: grid_name "density" for sigma_t, "albedo" for the albedo.
    auto s = loadXml(xmlScene(heterogeneous(gridVolume("sigma_t", "media.vdb"),
                                            gridVolume("albedo", "media.vdb"))),
                     dir.path.string());
    const Medium& m = s->media[0];
    EXPECT_EQ(m.grid->name(), "density");
    ASSERT_TRUE(m.albedoGrid);
    EXPECT_EQ(m.albedoGrid->channelCount, 3);
    expectRgbNear(albedoGridAt(*m.albedoGrid, Vec3(0.5f)), Rgb(0.5f, 0.25f, 1.0f), "vec3 grid");
    // Named grids.
    const std::string named = "<string name=\"grid_name\" value=\"";
    s = loadXml(xmlScene(heterogeneous(gridVolume("sigma_t", "media.vdb", named + "sigma\"/>"),
                                       gridVolume("albedo", "media.vdb", named + "tint\"/>"))),
                dir.path.string());
    EXPECT_EQ(s->media[0].grid->name(), "sigma");
    EXPECT_EQ(s->media[0].albedoGrid->channelCount, 1);
    expectRgbNear(albedoGridAt(*s->media[0].albedoGrid, Vec3(0.5f)), Rgb(0.25f), "float grid");

    // A missing grid names the grids present, at the filename of the volume.
    std::string text =
        xmlScene(heterogeneous(gridVolume("sigma_t", "media.vdb", named + "smoke\"/>"), ""));
    std::string e = xmlErrors(text, dir.path.string());
    EXPECT_TRUE(contains(
        e, where(text, "<string name=\"filename\"") + ": error: <volume type=\"gridvolume\">"))
        << e;
    EXPECT_TRUE(contains(e,
                         "cannot load grid 'smoke': no grid of that name in the file; grids "
                         "present: 'albedo' (vec3s), 'density' (float), 'sigma' (float), "
                         "'tint' (float)"))
        << e;
    // A vec3 grid as sigma_t: a chromatic extinction, one density per channel.
    s = loadXml(
        xmlScene(heterogeneous(gridVolume("sigma_t", "media.vdb", named + "albedo\"/>"), "")),
        dir.path.string());
    ASSERT_TRUE(s->media[0].chromatic());
    expectRgbNear(mediumCoefficientsAt(s->media[0], Vec3(0.5f)).sigmaT, Rgb(0.5f, 0.25f, 1.0f),
                  "vec3 sigma_t");
}

TEST(MitsubaAlbedo, UnsupportedAlbedoVolumesAreErrorsWithPositions) {
    ScratchDir dir;
    writeVolFiles(dir);
    const std::string sigma = gridVolume("sigma_t", "sigma.vol");
    // Bad filter value.
    std::string text = xmlScene(heterogeneous(
        sigma,
        gridVolume("albedo", "albedo.vol", "<string name=\"filter_type\" value=\"cubic\"/>")));
    std::string e = xmlErrors(text, dir.path.string());
    EXPECT_TRUE(contains(e, where(text, "<string name=\"filter_type\"") +
                                ": error: <volume type=\"gridvolume\">: filter_type 'cubic' is "
                                "not one of trilinear, nearest"))
        << e;
    // An extinction grid with 3 channels and the hint that sigma_t is grey.
    text = "<medium id=\"m\" type=\"heterogeneous\">" + gridVolume("sigma_t", "rgb_sigma.vol") +
           "<boolean name=\"has_spectral_extinction\" value=\"false\"/></medium>";
    text = xmlScene(text);
    e = xmlErrors(text, dir.path.string());
    EXPECT_TRUE(contains(e, where(text, "<boolean name=\"has_spectral_extinction\"") +
                                ": error: <medium type=\"heterogeneous\">: "
                                "has_spectral_extinction = false with a 3-channel sigma_t grid"))
        << e;
    // Albedo values above 1.
    text = xmlScene(heterogeneous(sigma, gridVolume("albedo", "hot.vol")));
    e = xmlErrors(text, dir.path.string());
    EXPECT_TRUE(contains(e, "grid 'albedo' has an albedo 1.5 at voxel (1, 0, 0)")) << e;
    EXPECT_TRUE(contains(e, "hot.vol")) << e;
    // grid_name on a .vol file.
    text = xmlScene(heterogeneous(
        sigma, gridVolume("albedo", "albedo.vol", "<string name=\"grid_name\" value=\"x\"/>")));
    e = xmlErrors(text, dir.path.string());
    EXPECT_TRUE(contains(e, where(text, "<string name=\"grid_name\"") +
                                ": error: <volume type=\"gridvolume\">: grid_name applies to .vdb "
                                "files only"))
        << e;
    // An albedo volume in a homogeneous medium (Mitsuba's homogeneous takes a volume albedo):
    // a grid medium of constant density (sigma_t 2 x scale 1.5) with that albedo grid.
    {
        auto sc = loadXml(xmlScene("<medium id=\"m\" type=\"homogeneous\"><float name=\"sigma_t\" "
                                   "value=\"2\"/><float name=\"scale\" value=\"1.5\"/>" +
                                   gridVolume("albedo", "albedo.vol",
                                              "<string name=\"filter_type\" value=\"nearest\"/>") +
                                   "</medium>"),
                          dir.path.string());
        const Medium& m = sc->media[0];
        ASSERT_EQ(m.type, MediumType::kGrid);
        ASSERT_TRUE(m.albedoGrid);
        const MediumCoefficients c = mediumCoefficientsAt(m, Vec3(0.75f, 0.5f, 0.5f));
        expectRgbNear(c.sigmaT, Rgb(3.0f), "homogeneous sigma_t");
        expectRgbNear(c.sigmaS, Rgb(0.7f, 0.8f, 0.9f) * 3.0f, "homogeneous sigma_s");
    }
    // With a spectrally varying constant sigma_t: one constant grid per channel.
    {
        auto sc = loadXml(xmlScene(heterogeneous("<rgb name=\"sigma_t\" value=\"1, 2, 3\"/>",
                                                 gridVolume("albedo", "albedo.vol"))),
                          dir.path.string());
        const Medium& m = sc->media[0];
        ASSERT_TRUE(m.chromatic());
        ASSERT_TRUE(m.albedoGrid);
        for (const Vec3& p : {Vec3(0.25f, 0.5f, 0.5f), Vec3(-3, 7, 2)})
            expectRgbNear(mediumCoefficientsAt(m, p).sigmaT, Rgb(1, 2, 3), "constant sigma_t");
        const Rgb T = transmittance(m, Vec3(-1.0f, 0.5f, 0.5f), Vec3(1, 0, 0), 0.5f);
        expectRgbNear(T, Rgb(std::exp(-0.5f), std::exp(-1.0f), std::exp(-1.5f)), "T");
    }
    // An unknown volume plugin lists the supported ones.
    text = xmlScene(heterogeneous(sigma, "<volume name=\"albedo\" type=\"noise\"/>"));
    e = xmlErrors(text, dir.path.string());
    EXPECT_TRUE(contains(e, where(text, "<volume name=\"albedo\"") +
                                ": error: unsupported volume plugin 'noise' (supported: "
                                "gridvolume, constvolume)"))
        << e;
    // A constvolume albedo stays a constant.
    auto s = loadXml(
        xmlScene(heterogeneous(sigma,
                               "<volume name=\"albedo\" type=\"constvolume\"><rgb name=\"value\" "
                               "value=\"0.2, 0.4, 0.6\"/></volume>")),
        dir.path.string());
    EXPECT_FALSE(s->media[0].albedoGrid);
    expectRgbNear(s->media[0].albedo, Rgb(0.2f, 0.4f, 0.6f), "constvolume");
}

// ---- JSON -------------------------------------------------------------------------------

namespace {

std::string jsonScene(const std::string& medium) {
    return R"({"camera": {"position": [0, 0, 5], "target": [0, 0, 0], "resolution": [16, 16]},
"media": {"smoke": )" +
           medium + R"(},
"shapes": [{"type": "cube", "interior_medium": "smoke", "imaginary": true}],
"lights": [{"type": "point", "position": [0, 2.5, 0], "intensity": 1}]})";
}

std::string jsonErrors(const std::string& text, const std::string& dir) {
    std::string all;
    try {
        loadJsonSceneFromString(text, "scene.json", dir);
    } catch (const InputError& e) {
        for (const auto& d : e.diagnostics()) all += d.format() + "\n";
    }
    return all;
}

void writeJsonVdbs(const ScratchDir& dir) {
    DenseFloatGrid one(2, 2, 2, 1.0f), half(2, 2, 2, 0.5f), quarter(2, 2, 2, 0.25f),
        hot(2, 2, 2, 0.5f);
    hot.at(0, 1, 1) = 3.0f;
    writeDenseVdb(dir / "smoke.vdb", {{"density", {one}},
                                      {"albedo", {half, quarter, one}},
                                      {"grey", {quarter}},
                                      {"hot", {hot}}});
    writeDenseVdb(dir / "other.vdb", {{"albedo", {quarter}}});
}

}  // namespace

TEST(JsonAlbedo, AlbedoGridKeysLoad) {
    ScratchDir dir;
    writeJsonVdbs(dir);
    const std::string base = dir.path.string();
    // In the density's file, nearest by default.
    auto s = loadJsonSceneFromString(
        jsonScene(R"({"type": "heterogeneous", "file": "smoke.vdb", "albedo_grid": "albedo"})"),
        "scene.json", base);
    const Medium& m = s->media[0];
    ASSERT_TRUE(m.albedoGrid);
    EXPECT_EQ(m.albedoGrid->channelCount, 3);
    EXPECT_EQ(m.albedoGrid->filter, GridFilter::kNearest);
    expectRgbNear(albedoGridAt(*m.albedoGrid, Vec3(1.0f, 0.0f, 1.0f)), Rgb(0.5f, 0.25f, 1.0f),
                  "vec3");
    // A grey grid, trilinear; the medium's transform moves both grids.
    s = loadJsonSceneFromString(
        jsonScene(R"({"type": "heterogeneous", "file": "smoke.vdb", "albedo_grid": "grey",
                      "albedo_filter": "trilinear", "transform": {"translate": [5, 0, 0]}})"),
        "scene.json", base);
    EXPECT_EQ(s->media[0].albedoGrid->channelCount, 1);
    EXPECT_EQ(s->media[0].albedoGrid->filter, GridFilter::kTrilinear);
    expectRgbNear(albedoGridAt(*s->media[0].albedoGrid, Vec3(5.5f, 0.5f, 0.5f)), Rgb(0.25f),
                  "grey");
    // Another file, default grid name "albedo".
    s = loadJsonSceneFromString(
        jsonScene(R"({"type": "heterogeneous", "file": "smoke.vdb", "albedo_file": "other.vdb"})"),
        "scene.json", base);
    EXPECT_EQ(s->media[0].albedoGrid->channelCount, 1);
    expectRgbNear(albedoGridAt(*s->media[0].albedoGrid, Vec3(0.0f)), Rgb(0.25f), "other file");
}

TEST(JsonAlbedo, AlbedoGridErrorsNameTheKey) {
    ScratchDir dir;
    writeJsonVdbs(dir);
    const std::string base = dir.path.string();
    auto err = [&](const std::string& medium) { return jsonErrors(jsonScene(medium), base); };
    std::string e = err(R"({"type": "heterogeneous", "file": "smoke.vdb", "albedo": 0.5,
                            "albedo_grid": "albedo"})");
    EXPECT_TRUE(contains(e, "at /media/smoke: give either a constant \"albedo\" or an albedo grid"))
        << e;
    e = err(R"({"type": "heterogeneous", "file": "smoke.vdb", "albedo_filter": "nearest"})");
    EXPECT_TRUE(contains(e,
                         "at /media/smoke/albedo_filter: \"albedo_filter\" needs an albedo "
                         "grid"))
        << e;
    e = err(R"({"type": "heterogeneous", "file": "smoke.vdb", "albedo_grid": "albedo",
                "albedo_filter": "trilinar"})");
    EXPECT_TRUE(contains(e, "at /media/smoke/albedo_filter: unknown albedo filter 'trilinar'"))
        << e;
    EXPECT_TRUE(contains(e, "valid filters: nearest, trilinear")) << e;
    e = err(R"({"type": "heterogeneous", "file": "smoke.vdb", "albedo_grid": "colour"})");
    EXPECT_TRUE(contains(e,
                         "at /media/smoke/albedo_grid: cannot use VDB file 'smoke.vdb': "
                         "cannot load grid 'colour': no grid of that name in the file; grids "
                         "present: 'albedo' (vec3s), 'density' (float), 'grey' (float), "
                         "'hot' (float)"))
        << e;
    e = err(R"({"type": "heterogeneous", "file": "smoke.vdb", "albedo_grid": "hot"})");
    EXPECT_TRUE(contains(e, "grid 'hot' has an albedo 3 at voxel (0, 1, 1)")) << e;
    e = err(R"({"type": "heterogeneous", "file": "smoke.vdb", "albedo_file": "missing.vdb"})");
    EXPECT_TRUE(contains(e, "at /media/smoke/albedo_file: VDB file 'missing.vdb' not found")) << e;
    e = err(R"({"type": "heterogeneous", "file": "smoke.vdb", "albedo_grid": 3})");
    EXPECT_TRUE(contains(e, "/media/smoke/albedo_grid")) << e;
}

// ---- Chromatic extinction (3-channel sigma_t grids) -------------------------------------

// A 3-channel .vol as sigma_t is one density grid per channel; a channel that is zero
// everywhere is an empty channel (transmittance 1), not an error.
TEST(MitsubaChromatic, ThreeChannelVolIsAChromaticExtinction) {
    ScratchDir dir;
    writeBinaryFile(dir / "rgb.vol", volBytes(2, 1, 1, 3, {0.5f, 1.0f, 2.0f, 0.0f, 3.0f, 0.25f}));
    writeBinaryFile(dir / "no_blue.vol",
                    volBytes(2, 1, 1, 3, {1.0f, 2.0f, 0.0f, 3.0f, 4.0f, 0.0f}));
    const std::string nearest = "<string name=\"filter_type\" value=\"nearest\"/>";
    auto s = loadXml(
        xmlScene(heterogeneous(
            gridVolume("sigma_t", "rgb.vol", nearest) + "<float name=\"scale\" value=\"2\"/>", "")),
        dir.path.string());
    const Medium& m = s->media[0];
    ASSERT_TRUE(m.chromatic());
    // The .vol spans the unit cube: voxel 0 is x in [0, 0.5), voxel 1 [0.5, 1).
    expectRgbNear(mediumCoefficientsAt(m, Vec3(0.25f, 0.5f, 0.5f)).sigmaT, Rgb(1, 2, 4), "voxel 0");
    expectRgbNear(mediumCoefficientsAt(m, Vec3(0.75f, 0.5f, 0.5f)).sigmaT, Rgb(0, 6, 0.5f),
                  "voxel 1");
    // Across both voxels (0.5 each): tau = 2 * 0.5 * (v0 + v1) per channel.
    const Rgb T = transmittance(m, Vec3(-1.0f, 0.5f, 0.5f), Vec3(1, 0, 0), 3.0f);
    expectRgbNear(T, Rgb(std::exp(-0.5f), std::exp(-4.0f), std::exp(-2.25f)), "T");

    s = loadXml(xmlScene(heterogeneous(gridVolume("sigma_t", "no_blue.vol", nearest), "")),
                dir.path.string());
    ASSERT_TRUE(s->media[0].chromatic());
    const Rgb T2 = transmittance(s->media[0], Vec3(-1.0f, 0.5f, 0.5f), Vec3(1, 0, 0), 3.0f);
    expectRgbNear(T2, Rgb(std::exp(-2.0f), std::exp(-3.0f), 1.0f), "no blue");
    // Trilinear (Mitsuba's default) reads the same grid as chromatic too.
    s = loadXml(xmlScene(heterogeneous(gridVolume("sigma_t", "rgb.vol"), "")), dir.path.string());
    EXPECT_TRUE(s->media[0].chromatic());
    EXPECT_EQ(s->media[0].filter, GridFilter::kTrilinear);
}

// JSON: a vec3 grid named by "grid" is a chromatic extinction.
TEST(JsonChromatic, Vec3DensityGridIsAChromaticExtinction) {
    ScratchDir dir;
    writeJsonVdbs(dir);
    auto s = loadJsonSceneFromString(
        jsonScene(R"({"type": "heterogeneous", "file": "smoke.vdb", "grid": "albedo",
                      "density_scale": 2})"),
        "scene.json", dir.path.string());
    const Medium& m = s->media[0];
    ASSERT_TRUE(m.chromatic());
    expectRgbNear(mediumCoefficientsAt(m, Vec3(1.0f, 0.0f, 1.0f)).sigmaT, Rgb(1.0f, 0.5f, 2.0f),
                  "vec3 density");
    // A float grid stays grey.
    s = loadJsonSceneFromString(jsonScene(R"({"type": "heterogeneous", "file": "smoke.vdb"})"),
                                "scene.json", dir.path.string());
    EXPECT_FALSE(s->media[0].chromatic());
}

// wrap_mode on gridvolumes: repeat and mirror wrap an albedo volume (Mitsuba's address modes;
// scene/albedo_grid.h), an extinction volume takes clamp only (an error naming the mode).
TEST(MitsubaAlbedo, WrapModesOnAlbedoVolumesAndErrorOnExtinction) {
    ScratchDir dir;
    writeVolFiles(dir);
    const std::string nearest = "<string name=\"filter_type\" value=\"nearest\"/>";
    for (const char* mode : {"repeat", "mirror"}) {
        auto s = loadXml(
            xmlScene(heterogeneous(
                gridVolume("sigma_t", "sigma.vol"),
                gridVolume("albedo", "albedo.vol",
                           nearest + "<string name=\"wrap_mode\" value=\"" + mode + "\"/>"))),
            dir.path.string());
        const Medium& m = s->media[0];
        ASSERT_TRUE(m.albedoGrid);
        EXPECT_EQ(m.albedoGrid->wrap,
                  std::string(mode) == "repeat" ? GridWrap::kRepeat : GridWrap::kMirror);
        // the unit cube holds voxels [0, 0.5) and [0.5, 1) along x; x = 1.25 is voxel 2:
        // repeat -> voxel 0, mirror -> voxel 1
        expectRgbNear(albedoGridAt(*m.albedoGrid, Vec3(1.25f, 0.5f, 0.5f)),
                      std::string(mode) == "repeat" ? Rgb(0.1f, 0.2f, 0.3f) : Rgb(0.7f, 0.8f, 0.9f),
                      mode);
    }
    const std::string text = xmlScene(heterogeneous(
        gridVolume("sigma_t", "sigma.vol", "<string name=\"wrap_mode\" value=\"repeat\"/>"), ""));
    const std::string e = xmlErrors(text, dir.path.string());
    EXPECT_NE(e.find("wrap_mode 'repeat' is supported on albedo volumes only"), std::string::npos)
        << e;
    const std::string bad = xmlErrors(
        xmlScene(heterogeneous(
            gridVolume("sigma_t", "sigma.vol"),
            gridVolume("albedo", "albedo.vol", "<string name=\"wrap_mode\" value=\"wrap\"/>"))),
        dir.path.string());
    EXPECT_NE(bad.find("wrap_mode 'wrap' is not one of clamp, repeat, mirror"), std::string::npos)
        << bad;
}
