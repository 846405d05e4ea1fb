// Mitsuba 3 XML plugins read for the corpus of Mitsuba's own scenes (docs/mitsuba.md):
// reconstruction filters, the direct and ptracer integrators, samplers, the thinlens
// sensor and focus_distance, to_world on constvolume, named conductor presets. Valid input
// loads with the mapped settings; bad input is an error naming file:line:column, the
// plugin and the parameter.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "scene/io/mitsuba_loader.h"
#include "scene/io/mitsuba_spectra.h"
#include "scene/texture.h"
#include "tests/support/mitsuba_text.h"
#include "tests/support/temp_file.h"
#include "tests/support/vol_file.h"

using namespace ub;

namespace {

bool contains(const std::string& s, const std::string& part) {
    return s.find(part) != std::string::npos;
}

const char* kLight = "<emitter type=\"constant\"><rgb name=\"radiance\" value=\"1\"/></emitter>\n";

/// A scene with a sensor whose film holds `film` (inside <film>), sensor type and extra
/// sensor parameters `sensorExtra`, then `body`.
std::string scene(const std::string& film, const std::string& body = kLight,
                  const std::string& sensorType = "perspective",
                  const std::string& sensorExtra = "") {
    return "<scene version=\"3.0.0\">\n<sensor type=\"" + sensorType + "\">\n" + sensorExtra +
           "<float name=\"fov\" value=\"40\"/>\n<film type=\"hdrfilm\"><integer name=\"width\" "
           "value=\"32\"/><integer name=\"height\" value=\"24\"/>" +
           film + "</film>\n</sensor>\n" + body + "</scene>\n";
}

std::unique_ptr<Scene> load(const std::string& text, std::vector<Diagnostic>* warnings = nullptr) {
    return test::loadMitsubaText(text, warnings);
}

std::string errorsOf(const std::string& text) {
    return test::mitsubaErrorsOf(text);
}

}  // namespace

TEST(MitsubaInterop, ReconstructionFilters) {
    // No <rfilter>: Mitsuba's default Gaussian, stddev 0.5 (radius 2).
    auto s = load(scene(""));
    EXPECT_EQ(s->settings.pixelFilter.type(), PixelFilterType::kGaussian);
    EXPECT_FLOAT_EQ(s->settings.pixelFilter.stddev(), 0.5f);
    EXPECT_FLOAT_EQ(s->settings.pixelFilter.radius(), 2.0f);
    s = load(scene("<rfilter type=\"gaussian\"><float name=\"stddev\" value=\"0.25\"/></rfilter>"));
    EXPECT_FLOAT_EQ(s->settings.pixelFilter.radius(), 1.0f);
    s = load(scene("<rfilter type=\"tent\"/>"));
    EXPECT_EQ(s->settings.pixelFilter.type(), PixelFilterType::kTent);
    EXPECT_FLOAT_EQ(s->settings.pixelFilter.radius(), 1.0f);
    s = load(scene("<rfilter type=\"tent\"><float name=\"radius\" value=\"1.5\"/></rfilter>"));
    EXPECT_FLOAT_EQ(s->settings.pixelFilter.radius(), 1.5f);
    s = load(scene("<rfilter type=\"box\"/>"));
    EXPECT_TRUE(s->settings.pixelFilter.isBox());

    std::string e = errorsOf(scene("<rfilter type=\"mitchell\"/>"));
    EXPECT_TRUE(contains(e, "scene.xml:4:") && contains(e,
                                                        "unsupported rfilter plugin 'mitchell' "
                                                        "(supported: box, tent, gaussian)"))
        << e;
    e = errorsOf(
        scene("<rfilter type=\"gaussian\"><float name=\"stddev\" value=\"0\"/></rfilter>"));
    EXPECT_TRUE(contains(e, "<rfilter type=\"gaussian\">: parameter 'stddev' = 0 is out of range"))
        << e;
    e = errorsOf(scene("<rfilter type=\"tent\"><float name=\"radius\" value=\"-1\"/></rfilter>"));
    EXPECT_TRUE(contains(e, "<rfilter type=\"tent\">: parameter 'radius' = -1 is out of range"))
        << e;
    e = errorsOf(scene("<rfilter type=\"box\"><float name=\"radius\" value=\"1\"/></rfilter>"));
    EXPECT_TRUE(contains(e, "<rfilter type=\"box\">: unsupported parameter 'radius'")) << e;
}

TEST(MitsubaInterop, DirectAndPtracerIntegrators) {
    auto s =
        load(scene("", std::string("<integrator type=\"direct\"><integer name=\"emitter_samples\" "
                                   "value=\"4\"/></integrator>\n") +
                           kLight));
    EXPECT_EQ(s->settings.maxPathLength, 2);
    EXPECT_EQ(s->settings.defaultAlgorithm, "");
    s = load(scene("", std::string("<integrator type=\"ptracer\"><integer name=\"max_depth\" "
                                   "value=\"5\"/><integer name=\"samples_per_pass\" "
                                   "value=\"64\"/></integrator>\n") +
                           kLight));
    EXPECT_EQ(s->settings.maxPathLength, 5);
    EXPECT_EQ(s->settings.defaultAlgorithm, "lt");
    s = load(scene("", std::string("<integrator type=\"path\"/>\n") + kLight));
    EXPECT_EQ(s->settings.defaultAlgorithm, "");

    // A strategy dropped by a zero sample count: the image keeps its expectation unless the
    // scene has what only that strategy reaches (delta emitters, delta BSDF lobes).
    auto direct = [](const char* counts, const std::string& rest) {
        return scene(
            "", std::string("<integrator type=\"direct\">") + counts + "</integrator>\n" + rest);
    };
    const std::string sphere = "<shape type=\"sphere\"><bsdf type=\"dielectric\"/></shape>\n";
    const std::string point =
        "<emitter type=\"point\"><rgb name=\"intensity\" value=\"1\"/></emitter>\n";
    s = load(direct("<integer name=\"bsdf_samples\" value=\"0\"/>", kLight));
    EXPECT_EQ(s->settings.maxPathLength, 2);
    s = load(direct("<integer name=\"emitter_samples\" value=\"0\"/>", sphere + kLight));
    EXPECT_EQ(s->settings.maxPathLength, 2);
    s =
        load(direct("<integer name=\"emitter_samples\" value=\"0\"/><integer "
                    "name=\"bsdf_samples\" value=\"0\"/>",
                    sphere + point));
    EXPECT_EQ(s->settings.maxPathLength, 1);  // directly visible emitters only
    std::string e =
        errorsOf(direct("<integer name=\"bsdf_samples\" value=\"0\"/>", sphere + kLight));
    EXPECT_TRUE(contains(e, "scene.xml:6:27:") &&
                contains(e,
                         "<integrator type=\"direct\">: bsdf_samples = 0 leaves light "
                         "reflected or refracted by the smooth BSDF"))
        << e;
    e = errorsOf(direct("<integer name=\"emitter_samples\" value=\"0\"/>", point + kLight));
    EXPECT_TRUE(contains(e, "scene.xml:6:27:") &&
                contains(e,
                         "<integrator type=\"direct\">: emitter_samples = 0 leaves the "
                         "delta emitter"))
        << e;
    e = errorsOf(direct("<integer name=\"emitter_samples\" value=\"-1\"/>", kLight));
    EXPECT_TRUE(contains(e, "parameter 'emitter_samples' = -1 is out of range")) << e;
    e = errorsOf(scene("", std::string("<integrator type=\"direct\"><integer name=\"max_depth\" "
                                       "value=\"3\"/></integrator>\n") +
                               kLight));
    EXPECT_TRUE(contains(e, "<integrator type=\"direct\">: unsupported parameter 'max_depth'"))
        << e;
    e = errorsOf(scene("", std::string("<integrator type=\"stokes\"/>\n") + kLight));
    EXPECT_TRUE(contains(e,
                         "unsupported integrator plugin 'stokes' (supported: path, volpath, "
                         "volpathmis, direct, ptracer, moment, aov)"))
        << e;
}

TEST(MitsubaInterop, SamplersAreAcceptedWithANote) {
    for (const char* type :
         {"independent", "stratified", "multijitter", "orthogonal", "ldsampler"}) {
        std::string extra = std::string("<sampler type=\"") + type +
                            "\"><integer name=\"sample_count\" value=\"16\"/></sampler>\n";
        std::vector<Diagnostic> warnings;
        auto s = load(scene("<rfilter type=\"box\"/>", kLight, "perspective", extra), &warnings);
        bool noted = false;
        for (const Diagnostic& w : warnings)
            noted = noted || contains(w.format(),
                                      "unibeam uses its own independent sampler; "
                                      "sample_count 16 is not used");
        EXPECT_TRUE(noted) << type;
    }
    std::string e =
        errorsOf(scene("", kLight, "perspective", "<sampler type=\"sobol\"></sampler>\n"));
    EXPECT_TRUE(contains(e, "unsupported sampler plugin 'sobol'")) << e;
    e = errorsOf(scene("", kLight, "perspective",
                       "<sampler type=\"independent\"><boolean name=\"jitter\" value=\"true\"/>"
                       "</sampler>\n"));
    EXPECT_TRUE(contains(e, "<sampler type=\"independent\">: unsupported parameter 'jitter'")) << e;
}

TEST(MitsubaInterop, ThinLensAndFocusDistance) {
    auto s =
        load(scene("", kLight, "perspective", "<float name=\"focus_distance\" value=\"3\"/>\n"));
    EXPECT_TRUE(s->camera.isPinhole());  // Mitsuba's perspective sensor ignores it
    s = load(scene("", kLight, "thinlens",
                   "<float name=\"aperture_radius\" value=\"0.1\"/><float "
                   "name=\"focus_distance\" value=\"4\"/>\n"));
    EXPECT_FALSE(s->camera.isPinhole());
    EXPECT_FLOAT_EQ(s->camera.lensRadius(), 0.1f);
    EXPECT_FLOAT_EQ(s->camera.focusDistance(), 4.0f);
    std::string e = errorsOf(scene("", kLight, "thinlens"));
    EXPECT_TRUE(contains(e,
                         "scene.xml:2:1: error: <sensor type=\"thinlens\">: needs <float "
                         "name=\"aperture_radius\">"))
        << e;
    e = errorsOf(scene("", kLight, "thinlens",
                       "<float name=\"aperture_radius\" value=\"0.1\"/><float "
                       "name=\"focus_distance\" value=\"0\"/>\n"));
    EXPECT_TRUE(contains(e, "parameter 'focus_distance' = 0 is out of range")) << e;
}

TEST(MitsubaInterop, ConstVolumeToWorldIsAccepted) {
    const std::string medium =
        "<shape type=\"cube\"><bsdf type=\"null\"/><medium type=\"heterogeneous\" "
        "name=\"interior\"><volume type=\"constvolume\" name=\"sigma_t\"><rgb name=\"value\" "
        "value=\"2\"/><transform name=\"to_world\">TRANSFORM</transform></volume></medium>"
        "</shape>\n";
    std::string ok = medium;
    ok.replace(ok.find("TRANSFORM"), 9, "<scale value=\"3\"/><rotate y=\"1\" angle=\"30\"/>");
    auto s = load(scene("", ok + kLight));
    ASSERT_EQ(s->media.size(), 1u);
    EXPECT_FLOAT_EQ(s->media[0].sigmaA.x + s->media[0].sigmaS.x, 2.0f);
    std::string singular = medium;
    singular.replace(singular.find("TRANSFORM"), 9, "<scale x=\"0\"/>");
    std::string e = errorsOf(scene("", singular + kLight));
    EXPECT_TRUE(contains(e, "<volume type=\"constvolume\">: transform 'to_world' is singular"))
        << e;
}

TEST(MitsubaInterop, NamedConductorPresets) {
    auto conductor = [](const std::string& params) {
        return "<shape type=\"sphere\"><bsdf type=\"roughconductor\"><string "
               "name=\"distribution\" value=\"ggx\"/>" +
               params + "</bsdf></shape>\n" + kLight;
    };
    auto s = load(scene("", conductor("<string name=\"material\" value=\"Au\"/>")));
    ASSERT_EQ(s->materials.size(), 1u);
    // Mitsuba 3.9.1 scalar_rgb: eta = (0.143036, 0.375307, 1.44205), k = (3.983, 2.38556,
    // 1.60336).
    EXPECT_FLOAT_EQ(s->materials[0].eta.x, 0.143036f);
    EXPECT_FLOAT_EQ(s->materials[0].k.z, 1.60336f);
    // No material and no eta/k: Mitsuba's "none", eta 0 and k 1 (reflectance 1).
    s = load(scene("", conductor("")));
    EXPECT_EQ(s->materials[0].eta.x, 0.0f);
    EXPECT_EQ(s->materials[0].k.y, 1.0f);
    Rgb eta, k;
    for (const char* name : {"Ag", "Al", "Cu", "Cr", "W", "a-C", "d-C", "Cu_palik", "TiO2-e"})
        EXPECT_TRUE(namedConductor(name, &eta, &k)) << name;
    EXPECT_FALSE(namedConductor("none", &eta, &k));
    EXPECT_EQ(namedConductorNames().size(), 71u);

    std::string e = errorsOf(scene("", conductor("<string name=\"material\" value=\"Gold\"/>")));
    EXPECT_TRUE(contains(e,
                         "<bsdf type=\"roughconductor\">: unknown conductor material 'Gold' "
                         "(expected none or one of Ag, Al,"))
        << e;
    e = errorsOf(scene("", conductor("<string name=\"material\" value=\"Au\"/><rgb name=\"eta\" "
                                     "value=\"1\"/>")));
    EXPECT_TRUE(contains(e, "give either 'material' or eta/k")) << e;
    // A smooth conductor: "none" is a perfect mirror, a preset a mirror with its Fresnel
    // term (tests/mitsuba_shapes_test.cpp checks the parameters).
    s = load(scene(
        "", "<shape type=\"sphere\"><bsdf type=\"conductor\"/></shape>\n" + std::string(kLight)));
    EXPECT_EQ(s->materials[0].type, MaterialType::Mirror);
    EXPECT_FALSE(s->materials[0].conductorFresnel);
    s = load(scene("",
                   "<shape type=\"sphere\"><bsdf type=\"conductor\"><string "
                   "name=\"material\" value=\"Au\"/></bsdf></shape>\n" +
                       std::string(kLight)));
    EXPECT_EQ(s->materials[0].type, MaterialType::Mirror);
    EXPECT_TRUE(s->materials[0].conductorFresnel);
}

TEST(MitsubaInterop, TopLevelSamplerAndNamedAreaEmitterAreAttachedByRef) {
    const std::string text = R"(<scene version="3.0.0">
<sampler type="independent" id="spp16"><integer name="sample_count" value="16"/></sampler>
<sensor type="perspective"><ref id="spp16"/><film type="hdrfilm"><integer name="width" value="8"/>
<integer name="height" value="8"/></film></sensor>
<shape type="rectangle"><ref id="light"/></shape>
<shape type="rectangle"><transform name="to_world"><translate z="1"/></transform><ref id="light"/></shape>
<emitter type="area" id="light"><rgb name="radiance" value="2"/></emitter>
</scene>
)";
    auto s = load(text);
    ASSERT_EQ(s->lights.size(), 2u);  // one area light per shape
    EXPECT_FLOAT_EQ(s->lights[1].radiance.x, 2.0f);
    std::string e = errorsOf(R"(<scene version="3.0.0">
<sensor type="perspective"/>
<emitter type="area"><rgb name="radiance" value="2"/></emitter>
</scene>
)");
    EXPECT_TRUE(contains(e,
                         "scene.xml:3:1: error: an 'area' emitter must be nested inside a "
                         "<shape> (or given an id and attached to shapes with <ref"))
        << e;
}

TEST(MitsubaInterop, HasSpectralExtinctionIsAHintForGreyMedia) {
    auto medium = [](const std::string& sigma, const std::string& flag) {
        return "<shape type=\"cube\"><bsdf type=\"null\"/><medium type=\"homogeneous\" "
               "name=\"interior\">" +
               sigma + "<boolean name=\"has_spectral_extinction\" value=\"" + flag +
               "\"/></medium></shape>\n" + kLight;
    };
    auto s = load(scene("", medium("<float name=\"sigma_t\" value=\"3\"/>", "false")));
    EXPECT_EQ(s->media.size(), 1u);
    s = load(scene("", medium("<rgb name=\"sigma_t\" value=\"1, 2, 3\"/>", "true")));
    EXPECT_EQ(s->media.size(), 1u);
    std::string e =
        errorsOf(scene("", medium("<rgb name=\"sigma_t\" value=\"1, 2, 3\"/>", "false")));
    EXPECT_TRUE(contains(e,
                         "has_spectral_extinction = false with a sigma_t that differs between "
                         "channels"))
        << e;
}

// Bitmap filter_type and wrap_mode against values printed by Mitsuba 3.9.1 (scalar_rgb, a raw
// 4 x 1 bitmap of 0.1, 0.3, 0.6, 0.9, evaluated at v = 0.5 and the u below).
TEST(MitsubaInterop, BitmapFilterAndWrapModesMatchMitsuba) {
    Texture t;
    t.type = TextureType::Bitmap;
    auto img = std::make_shared<Image>(4, 1);
    const float texels[4] = {0.1f, 0.3f, 0.6f, 0.9f};
    for (int x = 0; x < 4; ++x) img->at(x, 0) = Rgb(texels[x]);
    t.image = img;
    const float us[9] = {-0.6f, -0.1f, 0.05f, 0.3f, 0.95f, 1.05f, 1.3f, 1.6f, 2.2f};
    struct Expected {
        TextureFilter filter;
        TextureWrap wrap;
        float values[9];
    };
    const Expected cases[] = {
        {TextureFilter::Nearest,
         TextureWrap::Repeat,
         {0.3f, 0.9f, 0.1f, 0.3f, 0.9f, 0.1f, 0.3f, 0.6f, 0.1f}},
        {TextureFilter::Nearest,
         TextureWrap::Mirror,
         {0.6f, 0.1f, 0.1f, 0.3f, 0.9f, 0.9f, 0.6f, 0.3f, 0.1f}},
        {TextureFilter::Nearest,
         TextureWrap::Clamp,
         {0.1f, 0.1f, 0.1f, 0.3f, 0.9f, 0.9f, 0.9f, 0.9f, 0.9f}},
        {TextureFilter::Bilinear,
         TextureWrap::Repeat,
         {0.33f, 0.82f, 0.34f, 0.24f, 0.66f, 0.34f, 0.24f, 0.57f, 0.16f}},
        {TextureFilter::Bilinear,
         TextureWrap::Mirror,
         {0.57f, 0.1f, 0.1f, 0.24f, 0.9f, 0.9f, 0.69f, 0.33f, 0.16f}},
        {TextureFilter::Bilinear,
         TextureWrap::Clamp,
         {0.1f, 0.1f, 0.1f, 0.24f, 0.9f, 0.9f, 0.9f, 0.9f, 0.9f}},
    };
    for (const Expected& c : cases) {
        t.filter = c.filter;
        t.wrap = c.wrap;
        for (int i = 0; i < 9; ++i)
            EXPECT_NEAR(t.eval(Vec2(us[i], 0.5f)).x, c.values[i], 1e-4f)
                << "filter " << int(c.filter) << " wrap " << int(c.wrap) << " u " << us[i];
    }
    std::string e = errorsOf(scene("",
                                   "<shape type=\"rectangle\"><bsdf type=\"diffuse\"><texture "
                                   "type=\"bitmap\" name=\"reflectance\"><string "
                                   "name=\"filename\" value=\"x.png\"/><string "
                                   "name=\"wrap_mode\" value=\"border\"/></texture></bsdf>"
                                   "</shape>\n" +
                                       std::string(kLight)));
    EXPECT_TRUE(contains(e, "wrap_mode 'border' is not one of repeat, mirror, clamp")) << e;
}

// <path> in an included file: relative to that file's folder, else found through the search
// path (the main scene's folder), as Mitsuba resolves it.
TEST(MitsubaInterop, PathInAnIncludedFileFallsBackToTheSearchPath) {
    namespace fs = std::filesystem;
    const fs::path dir = ub::test::scratchFolder("interop_path");
    fs::create_directories(dir / "inc");
    fs::create_directories(dir / "common" / "meshes");
    std::ofstream(dir / "common" / "meshes" / "tri.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    std::ofstream(dir / "inc" / "shapes.xml")
        << "<scene version=\"3.0.0\">\n<path value=\"common\"/>\n<shape type=\"obj\"><string "
           "name=\"filename\" value=\"meshes/tri.obj\"/></shape>\n</scene>\n";
    std::ofstream(dir / "main.xml")
        << scene("", std::string("<include filename=\"inc/shapes.xml\"/>\n") + kLight);
    auto s = loadMitsubaScene((dir / "main.xml").string());
    EXPECT_EQ(s->shapes.size(), 1u);
    std::ofstream(dir / "inc" / "shapes.xml")
        << "<scene version=\"3.0.0\">\n<path value=\"nowhere\"/>\n</scene>\n";
    try {
        loadMitsubaScene((dir / "main.xml").string());
        ADD_FAILURE() << "expected an error";
    } catch (const InputError& e) {
        EXPECT_TRUE(
            contains(e.what(), "shapes.xml:2:1: error: <path> 'nowhere' is not a directory"))
            << e.what();
    }
}

// A gridvolume's unit cube is mapped by its to_world, any affine matrix (here with shear):
// the voxel containing local point q is found at world point to_world(q).
TEST(MitsubaInterop, GridVolumeToWorldMapsTheUnitCube) {
    namespace fs = std::filesystem;
    const fs::path dir = ub::test::scratchFolder("interop_grid");
    std::vector<float> values;
    for (int i = 0; i < 8; ++i) values.push_back(1.0f + float(i));  // x fastest
    ub::test::writeBinaryFile((dir / "g.vol").string(), ub::test::volBytes(2, 2, 2, 1, values));
    const char* matrix = "2 0.5 0 1   0 1 0.3 -1   0.2 0 1.5 0.5   0 0 0 1";
    const std::string body =
        std::string(
            "<shape type=\"cube\"><transform name=\"to_world\"><scale value=\"10\"/>"
            "</transform><bsdf type=\"null\"/><medium type=\"heterogeneous\" "
            "name=\"interior\"><volume type=\"gridvolume\" name=\"sigma_t\"><string "
            "name=\"filename\" value=\"g.vol\"/><string name=\"filter_type\" "
            "value=\"nearest\"/><transform name=\"to_world\"><matrix value=\"") +
        matrix + "\"/></transform></volume><float name=\"scale\" value=\"3\"/></medium></shape>\n" +
        kLight;
    auto s = loadMitsubaSceneFromString(scene("", body), "scene.xml", dir.string());
    ASSERT_EQ(s->media.size(), 1u);
    auto world = [&](const Vec3& q) {
        return Vec3(2 * q.x + 0.5f * q.y + 1, q.y + 0.3f * q.z - 1, 0.2f * q.x + 1.5f * q.z + 0.5f);
    };
    for (int i = 0; i < 8; ++i) {
        const Vec3 q(0.25f + 0.5f * float(i & 1), 0.25f + 0.5f * float((i >> 1) & 1),
                     0.25f + 0.5f * float((i >> 2) & 1));
        const MediumCoefficients c = mediumCoefficientsAt(s->media[0], world(q));
        EXPECT_NEAR(c.sigmaT.x, 3.0f * values[size_t(i)], 1e-4f) << "voxel " << i;
    }
    // Outside the mapped cube: no medium.
    EXPECT_EQ(mediumCoefficientsAt(s->media[0], world(Vec3(1.2f, 0.5f, 0.5f))).sigmaT.x, 0.0f);
    EXPECT_EQ(mediumCoefficientsAt(s->media[0], world(Vec3(0.5f, -0.1f, 0.5f))).sigmaT.x, 0.0f);
}
