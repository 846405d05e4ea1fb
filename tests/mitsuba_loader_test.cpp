// Mitsuba 3 XML subset (src/scene/io/mitsuba_*.cpp, docs/mitsuba.md): valid
// scenes load with the expected contents (parameters, includes, refs,
// transform order, camera, materials, emitters) and bad input gives the
// documented message at the right file:line:column. Line/column numbers in the
// expectations were counted by hand in the test texts.
#include "scene/io/mitsuba_loader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "core/image.h"
#include "render/aov.h"
#include "scene/bsdf.h"
#include "scene/camera.h"
#include "scene/io/mitsuba_spectra.h"
#include "scene/io/scene_loader.h"
#include "scene/light.h"
#include "scene/texture.h"
#include "tests/support/temp_file.h"

using namespace ub;
namespace fs = std::filesystem;

namespace {

bool contains(const std::string& s, const std::string& part) {
    return s.find(part) != std::string::npos;
}

/// A scratch directory for files that scenes include or reference.
std::string scratchDir(const std::string& name) {
    return ub::test::scratchFolder("mitsuba_test_" + name).string();
}

void writeFile(const std::string& path, const std::string& text) {
    std::ofstream(path, std::ios::binary) << text;
}

const char* kSensor = R"(<sensor type="perspective">
  <float name="fov" value="40"/>
  <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
  <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="24"/>
    <rfilter type="box"/></film>
</sensor>
)";

std::string scene(const std::string& body) {
    return std::string("<scene version=\"3.0.0\">\n") + kSensor + body + "</scene>\n";
}

const char* kLight = "<emitter type=\"constant\"><rgb name=\"radiance\" value=\"1\"/></emitter>\n";

std::unique_ptr<Scene> load(const std::string& text, const std::string& dir = ".",
                            const std::map<std::string, std::string>& defines = {}) {
    return loadMitsubaSceneFromString(text, "scene.xml", dir, defines);
}

/// All errors of `text`, one formatted diagnostic per line ("" if it loads).
std::string errorsOf(const std::string& text, const std::string& dir = ".",
                     const std::map<std::string, std::string>& defines = {}) {
    try {
        load(text, dir, defines);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

}  // namespace

TEST(MitsubaXml, DefaultsSubstituteAndDefinesOverride) {
    const std::string text = R"(<scene version="3.0.0">
<default name="res" value="20"/>
<sensor type="perspective">
  <film type="hdrfilm"><integer name="width" value="$res"/><integer name="height" value="$res"/>
    <rfilter type="box"/></film>
</sensor>
)" + std::string(kLight) + "</scene>\n";
    auto s = load(text);
    EXPECT_EQ(s->camera.width(), 20);
    auto o = load(text, ".", {{"res", "8"}});
    EXPECT_EQ(o->camera.width(), 8);
    EXPECT_EQ(o->camera.height(), 8);
}

TEST(MitsubaXml, UndefinedParameterIsAnErrorWithPosition) {
    std::string e = errorsOf(R"(<scene version="3.0.0">
  <integrator type="$algo"/>
</scene>
)");
    EXPECT_TRUE(contains(e,
                         "scene.xml:2:3: error: attribute 'type' uses the undefined parameter "
                         "'$algo'"))
        << e;
}

TEST(MitsubaXml, DefineOfUnknownParameterIsAnError) {
    std::string e = errorsOf(scene(kLight), ".", {{"spp", "4"}});
    EXPECT_TRUE(contains(e, "-D spp: the scene has no <default name=\"spp\"> parameter")) << e;
}

TEST(MitsubaXml, InvalidXmlReportsLineAndColumn) {
    std::string e = errorsOf("<scene version=\"3.0.0\">\n  <shape type=\"obj\">\n</scene>\n");
    EXPECT_TRUE(contains(e, "scene.xml:3:")) << e;
    EXPECT_TRUE(contains(e, "invalid XML")) << e;
}

TEST(MitsubaXml, IncludeAndPathResolveFiles) {
    std::string dir = scratchDir("include");
    fs::create_directories(dir + "/inc");
    fs::create_directories(dir + "/common/meshes");
    writeFile(dir + "/inc/light.xml",
              "<scene version=\"3.0.0\">\n<default name=\"val\" value=\"2\"/>\n"
              "<emitter type=\"constant\"><rgb name=\"radiance\" value=\"$val\"/></emitter>\n"
              "</scene>\n");
    writeFile(dir + "/common/meshes/tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    auto s = load(scene("<path value=\"common\"/>\n<include filename=\"inc/light.xml\"/>\n"
                        "<shape type=\"obj\"><string name=\"filename\" value=\"meshes/tri.obj\"/>"
                        "</shape>\n"),
                  dir);
    ASSERT_EQ(s->lights.size(), 1u);
    EXPECT_FLOAT_EQ(s->lights[0].radiance.x, 2.0f);
    ASSERT_EQ(s->shapes.size(), 1u);

    std::string e =
        errorsOf(scene("<include filename=\"nope.xml\"/>\n" + std::string(kLight)), dir);
    EXPECT_TRUE(contains(e, "scene.xml:8:1: error: included file 'nope.xml' not found")) << e;
}

TEST(MitsubaXml, RefsAttachObjectsAndUnknownIdsAreErrors) {
    auto s = load(scene(std::string(kLight) +
                        "<bsdf type=\"diffuse\" id=\"red\"><rgb name=\"reflectance\" "
                        "value=\"0.8, 0.1, 0.1\"/></bsdf>\n"
                        "<shape type=\"rectangle\"><ref id=\"red\"/></shape>\n"
                        "<shape type=\"cube\"><ref id=\"red\"/></shape>\n"));
    ASSERT_EQ(s->shapes.size(), 2u);
    EXPECT_EQ(s->shapes[0].materialId, s->shapes[1].materialId);
    const Material& m = s->materials[size_t(s->shapes[0].materialId)];
    EXPECT_FLOAT_EQ(m.diffuse.x, 0.8f);
    EXPECT_FALSE(m.twoSided);  // Mitsuba's diffuse is one-sided

    std::string e = errorsOf(
        scene(std::string(kLight) + "<shape type=\"cube\">\n  <ref id=\"blue\"/></shape>\n"));
    EXPECT_TRUE(contains(e, "scene.xml:10:3: error: <ref id=\"blue\">: no object with this id"))
        << e;
}

TEST(MitsubaXml, TransformsComposeInMitsubaOrder) {
    // scale then translate: [-1,1]^2 -> [-2,2]^2 -> x in [1, 5].
    auto s = load(scene(std::string(kLight) +
                        "<shape type=\"rectangle\"><transform name=\"to_world\">"
                        "<scale value=\"2\"/><translate x=\"3\"/></transform></shape>\n"));
    EXPECT_NEAR(s->shapes[0].bounds.lo.x, 1.0f, 1e-5f);
    EXPECT_NEAR(s->shapes[0].bounds.hi.x, 5.0f, 1e-5f);
    // translate then scale: x in [2, 6].
    auto t = load(scene(std::string(kLight) +
                        "<shape type=\"rectangle\"><transform name=\"to_world\">"
                        "<translate x=\"3\"/><scale value=\"2\"/></transform></shape>\n"));
    EXPECT_NEAR(t->shapes[0].bounds.lo.x, 4.0f, 1e-5f);
    EXPECT_NEAR(t->shapes[0].bounds.hi.x, 8.0f, 1e-5f);
    // rotate 90 degrees about z maps +x to +y; matrix gives a translation by (0, 0, 7).
    auto r =
        load(scene(std::string(kLight) +
                   "<shape type=\"sphere\"><point name=\"center\" x=\"1\" y=\"0\" z=\"0\"/>"
                   "<float name=\"radius\" value=\"0.5\"/><transform name=\"to_world\">"
                   "<rotate z=\"1\" angle=\"90\"/>"
                   "<matrix value=\"1 0 0 0 0 1 0 0 0 0 1 7 0 0 0 1\"/></transform></shape>\n"));
    EXPECT_NEAR(r->shapes[0].bounds.center().x, 0.0f, 1e-5f);
    EXPECT_NEAR(r->shapes[0].bounds.center().y, 1.0f, 1e-5f);
    EXPECT_NEAR(r->shapes[0].bounds.center().z, 7.0f, 1e-5f);
}

TEST(MitsubaXml, SensorFieldOfViewAxes) {
    auto fovY = [](const std::string& sensorBody) {
        std::string text = "<scene version=\"3.0.0\">\n<sensor type=\"perspective\">" + sensorBody +
                           "<film type=\"hdrfilm\"><integer name=\"width\" value=\"64\"/>"
                           "<integer name=\"height\" value=\"32\"/><rfilter type=\"box\"/></film>"
                           "</sensor>\n" +
                           kLight + "</scene>\n";
        return double(load(text)->camera.fovYDeg());
    };
    const double d2r = M_PI / 180.0;
    // fov along x = 60 on a 2:1 film: tan(fy/2) = tan(30 deg) / 2.
    EXPECT_NEAR(fovY("<float name=\"fov\" value=\"60\"/>"),
                2 * std::atan(std::tan(30 * d2r) / 2) / d2r, 1e-3);
    EXPECT_NEAR(fovY("<float name=\"fov\" value=\"60\"/><string name=\"fov_axis\" value=\"y\"/>"),
                60.0, 1e-3);
    // Default 50 mm lens: diagonal fov 2 atan(sqrt(36^2 + 24^2) / 100).
    double diag = 2 * std::atan(std::sqrt(36.0 * 36 + 24 * 24) / 100.0);
    double width = 2 * std::tan(diag / 2) / std::sqrt(1 + 1 / 4.0);
    EXPECT_NEAR(fovY(""), 2 * std::atan(width / 2 / 2) / d2r, 1e-3);
}

TEST(MitsubaXml, CameraLooksAlongLookat) {
    auto s = load(scene(kLight));
    EXPECT_NEAR(s->camera.position().z, 5.0f, 1e-6f);
    EXPECT_NEAR(s->camera.forward().z, -1.0f, 1e-6f);
    EXPECT_NEAR(s->camera.up().y, 1.0f, 1e-6f);
}

TEST(MitsubaXml, NamedIorsAndDielectrics) {
    auto s = load(scene(std::string(kLight) +
                        "<shape type=\"sphere\"><bsdf type=\"dielectric\">"
                        "<string name=\"int_ior\" value=\"water\"/><string name=\"ext_ior\" "
                        "value=\"air\"/></bsdf></shape>\n"));
    const Material& m = s->materials[size_t(s->shapes[0].materialId)];
    EXPECT_EQ(m.type, MaterialType::Dielectric);
    EXPECT_NEAR(m.ior, 1.3330f / 1.00028f, 1e-5f);

    std::string e = errorsOf(scene(std::string(kLight) +
                                   "<shape type=\"sphere\"><bsdf type=\"dielectric\">\n"
                                   "  <string name=\"int_ior\" value=\"glas\"/></bsdf></shape>\n"));
    EXPECT_TRUE(contains(e,
                         "scene.xml:10:3: error: <bsdf type=\"dielectric\">: unknown IOR name "
                         "'glas' in 'int_ior' (known: vacuum, helium"))
        << e;
}

TEST(MitsubaXml, UnsupportedPluginNamesFileLineAndPlugin) {
    std::string e = errorsOf(
        scene(std::string(kLight) + "<shape type=\"sphere\">\n  <bsdf type=\"hair\"/></shape>\n"));
    EXPECT_TRUE(contains(e,
                         "scene.xml:10:3: error: unsupported bsdf plugin 'hair' (supported: "
                         "diffuse, conductor"))
        << e;
    std::string s = errorsOf(scene(std::string(kLight) + "<shape type=\"linearcurve\"/>\n"));
    EXPECT_TRUE(contains(s, "scene.xml:9:1: error: unsupported shape plugin 'linearcurve'")) << s;
}

TEST(MitsubaXml, UnsupportedParameterIsAnError) {
    std::string e = errorsOf(scene(std::string(kLight) +
                                   "<shape type=\"sphere\"><bsdf type=\"diffuse\">\n"
                                   "  <float name=\"roughness\" value=\"0.3\"/></bsdf></shape>\n"));
    EXPECT_TRUE(contains(e,
                         "scene.xml:10:3: error: <bsdf type=\"diffuse\">: unsupported "
                         "parameter 'roughness' (<float>)"))
        << e;
}

TEST(MitsubaXml, WrongPropertyTypeAndBadNumbers) {
    std::string e =
        errorsOf(scene(std::string(kLight) +
                       "<shape type=\"sphere\">\n  <string name=\"radius\" value=\"2\"/>"
                       "</shape>\n"));
    EXPECT_TRUE(contains(e,
                         "scene.xml:10:3: error: <shape type=\"sphere\">: parameter 'radius' "
                         "must be a <float>, got <string>"))
        << e;
    std::string f =
        errorsOf(scene(std::string(kLight) +
                       "<shape type=\"sphere\">\n  <float name=\"radius\" value=\"2x\"/>"
                       "</shape>\n"));
    EXPECT_TRUE(contains(f,
                         "scene.xml:10:3: error: <float> property 'radius': expected a finite "
                         "number, got '2x'"))
        << f;
}

TEST(MitsubaXml, EmittersAndMaxDepth) {
    auto s = load(scene(R"(<integrator type="moment"><integrator type="volpath">
  <integer name="max_depth" value="6"/></integrator></integrator>
<emitter type="point"><point name="position" x="1" y="2" z="3"/><rgb name="intensity" value="5"/></emitter>
<emitter type="directional"><vector name="direction" x="0" y="-1" z="0"/><rgb name="irradiance" value="2"/></emitter>
<shape type="rectangle"><emitter type="area"><rgb name="radiance" value="3, 2, 1"/></emitter></shape>
)"));
    EXPECT_EQ(s->settings.maxPathLength, 6);
    ASSERT_EQ(s->lights.size(), 3u);
    EXPECT_EQ(s->lights[0].type, LightType::Point);
    EXPECT_FLOAT_EQ(s->lights[0].position.y, 2.0f);
    EXPECT_EQ(s->lights[1].type, LightType::Directional);
    EXPECT_NEAR(s->lights[1].direction.y, -1.0f, 1e-6f);
    EXPECT_EQ(s->lights[2].type, LightType::Area);
    EXPECT_FALSE(s->lights[2].twoSided);
    EXPECT_FLOAT_EQ(s->lights[2].radiance.x, 3.0f);
}

// Mitsuba's default microfacet distribution is Beckmann; "ggx" selects GGX; anything else
// is an error naming the value.
TEST(MitsubaXml, RoughConductorDistributions) {
    auto s =
        load(scene(std::string(kLight) +
                   "<shape type=\"sphere\">\n  <bsdf type=\"roughconductor\">"
                   "<rgb name=\"eta\" value=\"0.2\"/><rgb name=\"k\" value=\"3\"/>"
                   "</bsdf></shape>\n<shape type=\"sphere\"><point name=\"center\" x=\"3\" y=\"0\" "
                   "z=\"0\"/><bsdf type=\"roughdielectric\"><string name=\"distribution\" "
                   "value=\"ggx\"/></bsdf></shape>\n"));
    bool beckmann = false, ggx = false;
    for (const Material& m : s->materials) {
        beckmann |= m.type == MaterialType::RoughConductor &&
                    m.distribution == MicrofacetDistribution::kBeckmann;
        ggx |= m.type == MaterialType::RoughDielectric &&
               m.distribution == MicrofacetDistribution::kGgx;
    }
    EXPECT_TRUE(beckmann);
    EXPECT_TRUE(ggx);
    std::string e = errorsOf(scene(std::string(kLight) +
                                   "<shape type=\"sphere\">\n  <bsdf type=\"roughconductor\">"
                                   "<string name=\"distribution\" value=\"phong\"/>"
                                   "</bsdf></shape>\n"));
    EXPECT_TRUE(contains(e,
                         "scene.xml:10:31: error: <bsdf type=\"roughconductor\">: unknown "
                         "microfacet distribution 'phong' (expected 'beckmann' or 'ggx')"))
        << e;
}

// Anisotropic and textured roughness (docs/mitsuba.md): alpha_u/alpha_v as floats or textures
// on roughconductor and roughdielectric, alpha as a texture; roughplastic stays isotropic and
// untextured, and the malformed combinations are errors naming the parameter.
TEST(MitsubaXml, AnisotropicAndTexturedRoughness) {
    const std::string checker =
        "<texture name=\"%s\" type=\"checkerboard\"><float name=\"color0\" value=\"0.1\"/>"
        "<float name=\"color1\" value=\"0.3\"/></texture>";
    auto tex = [&](const std::string& name) {
        std::string t = checker;
        t.replace(t.find("%s"), 2, name);
        return t;
    };
    auto s = load(scene(std::string(kLight) +
                        "<shape type=\"sphere\"><bsdf type=\"roughconductor\">"
                        "<float name=\"alpha_u\" value=\"0.05\"/>"
                        "<float name=\"alpha_v\" value=\"0.3\"/></bsdf></shape>\n"
                        "<shape type=\"sphere\"><point name=\"center\" x=\"3\" y=\"0\" z=\"0\"/>"
                        "<bsdf type=\"roughdielectric\">" +
                        tex("alpha") +
                        "</bsdf></shape>\n"
                        "<shape type=\"sphere\"><point name=\"center\" x=\"-3\" y=\"0\" z=\"0\"/>"
                        "<bsdf type=\"roughconductor\">" +
                        tex("alpha_u") +
                        "<float name=\"alpha_v\" value=\"0.1\"/></bsdf></shape>\n"
                        "<shape type=\"sphere\"><point name=\"center\" x=\"0\" y=\"3\" z=\"0\"/>"
                        "<bsdf type=\"roughconductor\"><float name=\"alpha_u\" value=\"0.2\"/>"
                        "<float name=\"alpha_v\" value=\"0.2\"/></bsdf></shape>\n"));
    ASSERT_GE(s->materials.size(), 4u);
    const Material& aniso = s->materials[0];
    EXPECT_EQ(aniso.alpha, 0.05f);
    EXPECT_EQ(aniso.alphaV, 0.3f);
    EXPECT_TRUE(aniso.anisotropic());
    const Material& glass = s->materials[1];
    EXPECT_EQ(glass.type, MaterialType::RoughDielectric);
    EXPECT_GE(glass.textures.alpha, 0);
    EXPECT_LT(glass.textures.alphaV, 0);
    EXPECT_FALSE(glass.anisotropic());
    const Material& half = s->materials[2];
    EXPECT_GE(half.textures.alpha, 0);
    EXPECT_EQ(half.alphaV, 0.1f);
    EXPECT_TRUE(half.anisotropic()) << "a textured alpha_u with alpha_v = the default 0.1";
    EXPECT_FALSE(s->materials[3].anisotropic()) << "equal constants are isotropic";
    // The textured roughness reaches the BSDF: at two uvs of the checkerboard's two colours.
    // (Mitsuba's float parity: a checkerboard used as a float swaps its colours.)
    const Vec2 uv0(0.25f, 0.25f), uv1(0.75f, 0.25f);
    const SurfaceColors c0 = s->surfaceColors(glass, uv0, Rgb(0.0f));
    const SurfaceColors c1 = s->surfaceColors(glass, uv1, Rgb(0.0f));
    EXPECT_NEAR(c0.alphaU, 0.3f, 1e-6f);
    EXPECT_NEAR(c1.alphaU, 0.1f, 1e-6f);
    EXPECT_EQ(c0.alphaV, c0.alphaU);
    EXPECT_EQ(c1.alphaV, c1.alphaU);

    const std::string sphere = "<shape type=\"sphere\"><bsdf type=\"";
    auto bsdfErrors = [&](const std::string& type, const std::string& body) {
        return errorsOf(
            scene(std::string(kLight) + sphere + type + "\">" + body + "</bsdf></shape>\n"));
    };
    std::string e = bsdfErrors("roughconductor", "<float name=\"alpha_u\" value=\"0.2\"/>");
    EXPECT_TRUE(contains(e, "give both 'alpha_u' and 'alpha_v'")) << e;
    e = bsdfErrors("roughdielectric",
                   "<float name=\"alpha\" value=\"0.2\"/>" + tex("alpha_u") + tex("alpha_v"));
    EXPECT_TRUE(contains(e, "give either 'alpha' or 'alpha_u'/'alpha_v', not both")) << e;
    e = bsdfErrors(
        "roughplastic",
        "<float name=\"alpha_u\" value=\"0.1\"/><float name=\"alpha_v\" value=\"0.3\"/>");
    EXPECT_TRUE(contains(e, "Mitsuba's roughplastic is isotropic")) << e;
    e = bsdfErrors("roughplastic", tex("alpha"));
    EXPECT_TRUE(contains(e, "a textured 'alpha' is not supported here")) << e;
}

// rawconstant (Mitsuba 2's raw constant texture) and the bitmap's storage `format`.
TEST(MitsubaXml, RawConstantAndBitmapFormat) {
    auto s = load(scene(std::string(kLight) +
                        "<shape type=\"sphere\"><bsdf type=\"normalmap\">"
                        "<texture name=\"normalmap\" type=\"rawconstant\">"
                        "<vector name=\"value\" value=\"0.5, 0.5, 1.0\"/></texture>"
                        "<bsdf type=\"diffuse\"><texture name=\"reflectance\" type=\"rawconstant\">"
                        "<float name=\"value\" value=\"0.25\"/></texture></bsdf>"
                        "</bsdf></shape>\n"));
    int constants = 0;
    for (const Texture& t : s->textures)
        if (t.type == TextureType::Constant) {
            ++constants;
            EXPECT_TRUE((t.color0.x == 0.5f && t.color0.z == 1.0f) || t.color0.x == 0.25f);
        }
    EXPECT_EQ(constants, 2);
    std::string e = errorsOf(scene(std::string(kLight) +
                                   "<shape type=\"sphere\"><bsdf type=\"diffuse\"><texture "
                                   "name=\"reflectance\" type=\"rawconstant\"/></bsdf></shape>\n"));
    EXPECT_TRUE(contains(e, "needs a <float> or <vector> named \"value\"")) << e;
    const std::string dir = scratchDir("bitmap_format");
    Image img(2, 2);
    for (Rgb& p : img.pixels) p = Rgb(0.5f);
    writeExr(dir + "/t.exr", img);
    auto bitmap = [&](const std::string& format) {
        return errorsOf(scene(std::string(kLight) +
                              "<shape type=\"sphere\"><bsdf type=\"diffuse\"><texture "
                              "name=\"reflectance\" type=\"bitmap\"><string name=\"filename\" "
                              "value=\"t.exr\"/><string name=\"format\" value=\"" +
                              format + "\"/></texture></bsdf></shape>\n"),
                        dir);
    };
    EXPECT_EQ(bitmap("variant"), "");
    EXPECT_EQ(bitmap("float16"), "");
    EXPECT_TRUE(contains(bitmap("uint8"), "format 'uint8' on a floating-point image"));
    EXPECT_TRUE(contains(bitmap("int4"), "format 'int4' is not one of auto, variant"));
}

// A textured area emitter keeps its texture and the mesh's uvs per triangle vertex (a sphere
// none: spherical uvs); a mesh_attribute radiance is an error.
TEST(MitsubaXml, TexturedAreaEmitters) {
    const std::string checker =
        "<texture name=\"radiance\" type=\"checkerboard\"><rgb name=\"color0\" value=\"0.9\"/>"
        "<rgb name=\"color1\" value=\"0.1\"/></texture>";
    auto s = load(scene("<shape type=\"rectangle\"><emitter type=\"area\">" + checker +
                        "</emitter></shape>\n<shape type=\"sphere\"><point name=\"center\" "
                        "x=\"3\" y=\"0\" z=\"0\"/><emitter type=\"area\">" +
                        checker + "</emitter></shape>\n"));
    ASSERT_EQ(s->lights.size(), 2u);
    for (const Light& l : s->lights) {
        ASSERT_TRUE(l.radianceTexture != nullptr) << l.name;
        EXPECT_EQ(l.radianceTexture->type, TextureType::Checkerboard);
        EXPECT_EQ(l.triangleUvs.size(), l.isSphere ? 0u : l.triangles.size()) << l.name;
    }
    // As radiance, a checkerboard's colours are not bounded by 1 (Mitsuba's rgb variants read
    // them as plain textures); in a BSDF they are reflectances.
    const std::string bright =
        "<texture name=\"radiance\" type=\"checkerboard\"><rgb name=\"color0\" value=\"5, 4, 3\"/>"
        "<spectrum name=\"color1\" value=\"2\"/></texture>";
    auto lit = load(scene("<shape type=\"rectangle\"><emitter type=\"area\">" + bright +
                          "</emitter></shape>\n"));
    ASSERT_EQ(lit->lights.size(), 1u);
    ASSERT_TRUE(lit->lights[0].radianceTexture != nullptr);
    const Texture& t = *lit->lights[0].radianceTexture;
    EXPECT_EQ(t.color0.x, 5.0f);
    EXPECT_EQ(t.color0.y, 4.0f);
    EXPECT_EQ(t.color0.z, 3.0f);
    EXPECT_EQ(t.color1.x, 2.0f);
    EXPECT_EQ(t.color1.z, 2.0f);
    std::string reflect = errorsOf(
        scene("<shape type=\"sphere\"><bsdf type=\"diffuse\"><texture name=\"reflectance\" "
              "type=\"checkerboard\"><rgb name=\"color0\" value=\"5, 4, 3\"/></texture></bsdf>"
              "</shape>\n"));
    EXPECT_TRUE(contains(reflect, "reflectance 'color0' = 5, 4, 3 exceeds 1")) << reflect;
    std::string e = errorsOf(
        scene("<shape type=\"rectangle\"><emitter type=\"area\"><texture name=\"radiance\" "
              "type=\"mesh_attribute\"><string name=\"name\" value=\"vertex_color\"/></texture>"
              "</emitter></shape>\n"));
    EXPECT_TRUE(contains(e, "a mesh_attribute radiance is not supported")) << e;
}

// The orthographic sensor: the region's size from to_world's scale, rays from the near plane;
// a sheared to_world is an error.
TEST(MitsubaXml, OrthographicSensor) {
    auto ortho = [](const std::string& transform) {
        return std::string(
                   "<scene version=\"3.0.0\">\n<sensor type=\"orthographic\">"
                   "<float name=\"near_clip\" value=\"2\"/><transform name=\"to_world\">") +
               transform +
               "</transform><film type=\"hdrfilm\"><integer name=\"width\" value=\"40\"/>"
               "<integer name=\"height\" value=\"20\"/><rfilter type=\"box\"/></film></sensor>\n" +
               kLight + "</scene>\n";
    };
    auto s =
        load(ortho("<scale x=\"3\" y=\"2\"/><lookat origin=\"0, 0, 5\" target=\"0, 0, 0\" "
                   "up=\"0, 1, 0\"/>"));
    const Camera& c = s->camera;
    ASSERT_TRUE(c.isOrthographic());
    EXPECT_FALSE(c.isPinhole());
    EXPECT_NEAR(c.orthoHalfWidth(), 3.0f, 1e-5f);
    EXPECT_NEAR(c.orthoHalfHeight(), 2.0f / 2.0f, 1e-5f);  // y in [-1/aspect, 1/aspect] x 2
    // The top-left corner's ray: camera x = +1 (the image's left) is world -x here.
    const Ray r = c.generateRay(Vec2(0.0f, 0.0f));
    EXPECT_NEAR(r.org.x, -3.0f, 1e-5f);
    EXPECT_NEAR(r.org.y, 1.0f, 1e-5f);
    EXPECT_NEAR(r.org.z, 3.0f, 1e-5f);  // the near plane, 2 in front of the origin
    EXPECT_NEAR(r.dir.z, -1.0f, 1e-6f);
    const std::string e = errorsOf(ortho("<matrix value=\"1 0.5 0 0 0 1 0 0 0 0 1 0 0 0 0 1\"/>"));
    EXPECT_TRUE(contains(e, "to_world must map the camera axes to orthogonal")) << e;
}

TEST(MitsubaXml, SceneLoaderDispatchesXmlAndRejectsDefinesForJson) {
    std::string dir = scratchDir("dispatch");
    writeFile(dir + "/s.xml", scene(kLight));
    EXPECT_NO_THROW(loadScene(dir + "/s.xml"));
    writeFile(dir + "/s.json", "{}");
    try {
        loadScene(dir + "/s.json", {{"x", "1"}});
        FAIL() << "expected an error";
    } catch (const InputError& e) {
        EXPECT_TRUE(contains(e.what(), "apply only to Mitsuba .xml scenes")) << e.what();
    }
}

TEST(MitsubaSpectra, ConstantReflectanceIsWhiteAndEmissionIsLinear) {
    // A constant reflectance of 1 under D65 is (close to) sRGB white; the approximate CIE fit
    // and black-body D65 keep each channel within 3% (the error budget stated in mitsuba.md).
    Rgb w = spectrumToLinearSrgb({360, 830}, {1, 1}, false);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(w[c], 1.0f, 0.03f) << c;
    Rgb a = spectrumToLinearSrgb({360, 830}, {0.5, 0.5}, true);
    Rgb b = spectrumToLinearSrgb({360, 830}, {1.0, 1.0}, true);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(2 * a[c], b[c], 1e-5f);
}

TEST(MitsubaXml, CheckerboardTextureAndPlastics) {
    auto s = load(scene(std::string(kLight) + R"(<shape type="rectangle"><bsdf type="diffuse">
  <texture type="checkerboard" name="reflectance"><rgb name="color0" value="0.2"/>
    <rgb name="color1" value="0.4"/><transform name="to_uv"><scale x="16" y="16"/></transform>
  </texture></bsdf></shape>
<shape type="cube"><bsdf type="roughplastic"><string name="distribution" value="ggx"/>
  <float name="alpha" value="0.2"/><rgb name="diffuse_reflectance" value="0.3, 0.4, 0.5"/></bsdf></shape>
<shape type="sphere"><bsdf type="thindielectric"><string name="int_ior" value="water"/></bsdf></shape>
)"));
    const Material& d = s->materials[size_t(s->shapes[0].materialId)];
    ASSERT_GE(d.textures.diffuse, 0);
    const Texture& t = s->textures[size_t(d.textures.diffuse)];
    EXPECT_EQ(t.type, TextureType::Checkerboard);
    EXPECT_FLOAT_EQ(t.color0.x, 0.2f);
    EXPECT_FLOAT_EQ(t.toUv.m[0][0], 16.0f);
    const Material& p = s->materials[size_t(s->shapes[1].materialId)];
    EXPECT_EQ(p.type, MaterialType::RoughPlastic);
    EXPECT_NEAR(p.ior, 1.49f / 1.000277f, 1e-5f);
    EXPECT_FLOAT_EQ(p.alpha, 0.2f);
    const Material& th = s->materials[size_t(s->shapes[2].materialId)];
    EXPECT_EQ(th.type, MaterialType::ThinDielectric);
    EXPECT_NEAR(th.ior, 1.333f / 1.000277f, 1e-4f);
}

TEST(MitsubaXml, SpotLightFollowsToWorld) {
    auto s = load(scene(R"(<emitter type="spot"><rgb name="intensity" value="4"/>
  <float name="cutoff_angle" value="30"/>
  <transform name="to_world"><lookat origin="0, 3, 0" target="0, 0, 0" up="0, 0, 1"/></transform>
</emitter>
)"));
    ASSERT_EQ(s->lights.size(), 1u);
    const Light& l = s->lights[0];
    EXPECT_EQ(l.type, LightType::Spot);
    EXPECT_NEAR(l.position.y, 3.0f, 1e-6f);
    EXPECT_NEAR(l.direction.y, -1.0f, 1e-6f);
    EXPECT_FLOAT_EQ(l.cutoffAngleDeg, 30.0f);
    EXPECT_FLOAT_EQ(l.beamWidthDeg, 22.5f);  // Mitsuba's default: 3/4 of the cutoff
}

// Projected textures: a projector's irradiance bitmap, scale, fov and frame (to_world's x, y,
// z), its aspect from the bitmap; a constant irradiance; a spot's texture; and the errors
// (a non-bitmap texture, a scaled to_world, a textured spot's cutoff >= 90).
TEST(MitsubaXml, ProjectorsAndSpotTexturesLoad) {
    const std::string tex = std::string(UNIBEAM_TEST_DATA_DIR) + "/mitsuba/textures/slide.png";
    auto s = load(scene(R"(<emitter type="projector"><float name="fov" value="30"/>
  <float name="scale" value="7"/>
  <transform name="to_world"><lookat origin="0, 3, 0" target="0, 0, 0" up="0, 0, 1"/></transform>
  <texture type="bitmap" name="irradiance"><string name="filename" value=")" +
                        tex + R"("/></texture>
</emitter>
<emitter type="projector"><rgb name="irradiance" value="0.5, 1, 2"/></emitter>
<emitter type="spot"><float name="cutoff_angle" value="40"/>
  <texture type="bitmap" name="texture"><string name="filename" value=")" +
                        tex + R"("/></texture>
</emitter>
)"));
    ASSERT_EQ(s->lights.size(), 3u);
    const Light& p = s->lights[0];
    EXPECT_EQ(p.type, LightType::Projector);
    EXPECT_FLOAT_EQ(p.intensity.x, 7.0f);
    EXPECT_FLOAT_EQ(p.projFovXDeg, 30.0f);
    EXPECT_FLOAT_EQ(p.projAspect, 2.0f);  // 24 x 12
    EXPECT_NEAR(p.direction.y, -1.0f, 1e-6f);
    EXPECT_NEAR(p.frameY.z, 1.0f, 1e-6f);  // up
    EXPECT_NEAR(p.frameX.x, 1.0f, 1e-6f);  // Mitsuba's lookat: x = up x direction
    ASSERT_TRUE(p.projTexture && p.projTexture->type == TextureType::Bitmap);
    const Light& c = s->lights[1];
    EXPECT_EQ(c.projTexture->type, TextureType::Constant);
    EXPECT_FLOAT_EQ(c.projTexture->color0.z, 2.0f);
    EXPECT_FLOAT_EQ(c.projAspect, 1.0f);
    // The default focal length, 50 mm on 36 x 24 mm film along the diagonal, at aspect 1.
    const double diag = 2 * std::atan(std::sqrt(36.0 * 36 + 24 * 24) / 100.0);
    EXPECT_NEAR(c.projFovXDeg, 2 * std::atan(std::tan(diag / 2) / std::sqrt(2.0)) * 180 / kPi,
                1e-3);
    EXPECT_EQ(s->lights[2].type, LightType::Spot);
    ASSERT_TRUE(s->lights[2].projTexture);

    std::string e = errorsOf(scene(R"(<emitter type="projector">
  <texture type="checkerboard" name="irradiance"/></emitter>
)"));
    EXPECT_NE(e.find("scene.xml:9:3: error: <emitter type=\"projector\">: the projected texture "
                     "must be a bitmap"),
              std::string::npos)
        << e;
    e = errorsOf(scene(R"(<emitter type="projector"><transform name="to_world"><scale value="2"/>
  </transform></emitter>
)"));
    EXPECT_NE(e.find("scene.xml:8:27: error: <emitter type=\"projector\">: to_world must be a "
                     "rotation and translation"),
              std::string::npos)
        << e;
    e = errorsOf(scene(R"(<emitter type="spot"><float name="cutoff_angle" value="95"/>
  <texture type="bitmap" name="texture"><string name="filename" value=")" +
                       tex + R"("/></texture>
</emitter>
)"));
    EXPECT_NE(e.find("cutoff_angle < 90"), std::string::npos) << e;
    e = errorsOf(scene("<emitter type=\"spot\"><rgb name=\"texture\" value=\"1\"/></emitter>\n"));
    EXPECT_NE(e.find("'texture' must be a spatially varying texture"), std::string::npos) << e;
}

TEST(MitsubaXml, MediaOnShapesBecomeBoundaries) {
    auto s = load(scene(std::string(kLight) + R"(<medium id="fog" type="homogeneous">
  <rgb name="sigma_t" value="1, 2, 3"/><rgb name="albedo" value="0.5"/><float name="scale" value="2"/>
  <phase type="hg"><float name="g" value="0.3"/></phase></medium>
<shape type="sphere"><bsdf type="null"/><ref id="fog" name="interior"/></shape>
<shape type="cube"><bsdf type="dielectric"/><ref id="fog" name="interior"/></shape>
)"));
    ASSERT_EQ(s->media.size(), 1u);  // one medium, shared by reference
    const Medium& m = s->media[0];
    EXPECT_NEAR(m.sigmaS.z, 0.5f * 3 * 2, 1e-5f);
    EXPECT_NEAR(m.sigmaA.y, 0.5f * 2 * 2, 1e-5f);
    EXPECT_FLOAT_EQ(m.g, 0.3f);
    EXPECT_TRUE(s->shapes[0].isMediumBoundary);
    EXPECT_TRUE(s->shapes[0].imaginary);  // null BSDF: an index-matched boundary
    EXPECT_FALSE(s->shapes[1].imaginary);
    EXPECT_EQ(s->shapes[1].interiorMediumId, 0);

    // Mitsuba's volpath semantics (docs/mitsuba.md, scene.h).
    EXPECT_EQ(s->settings.mediumTransitions, MediumTransitions::kShapeSides);
    EXPECT_EQ(s->settings.depthCounting, DepthCounting::kNonNullVertices);
    EXPECT_EQ(s->settings.shadingNormals, ShadingNormals::kShadingOnly);

    // An exterior medium alone also makes a boundary (entering: vacuum, leaving: fog).
    auto ext = load(scene(std::string(kLight) + "<medium id=\"f\" type=\"homogeneous\"/>\n"
                                                "<shape type=\"sphere\"><bsdf type=\"null\"/>\n"
                                                "  <ref id=\"f\" name=\"exterior\"/></shape>\n"));
    ASSERT_EQ(ext->shapes.size(), 1u);
    EXPECT_TRUE(ext->shapes[0].isMediumBoundary);
    EXPECT_TRUE(ext->shapes[0].imaginary);
    EXPECT_EQ(ext->shapes[0].interiorMediumId, -1);
    EXPECT_EQ(ext->shapes[0].exteriorMediumId, 0);
}

TEST(MitsubaXml, SharedTestScenesLoad) {
    // Every Mitsuba scene of tests/data/mitsuba-data loads without errors (the reference test
    // renders them).
    const std::string dir = std::string(UNIBEAM_MITSUBA_MEDIA_DIR);
    ASSERT_TRUE(fs::is_directory(dir)) << "test data not found: " << dir;
    int n = 0;
    for (const auto& e : fs::directory_iterator(dir)) {
        if (e.path().extension() != ".xml") continue;
        ++n;
        std::vector<Diagnostic> warnings;
        std::unique_ptr<Scene> s;
        EXPECT_NO_THROW(s = loadMitsubaScene(e.path().string(), {}, &warnings)) << e.path();
        if (!s) continue;
        EXPECT_EQ(s->camera.width(), 48);
        EXPECT_EQ(s->media.size(), 1u) << e.path();
    }
    EXPECT_EQ(n, 5);
}

// A file that includes itself twice would be read 2^32 times under the depth bound alone (a
// hang); the cycle is an error at the first repeated file, and mutual includes are found too.
TEST(MitsubaXml, IncludeCyclesAreErrorsNotHangs) {
    std::string dir = scratchDir("cycle");
    writeFile(dir + "/self.xml",
              "<scene version=\"3.0.0\">\n<include filename=\"self.xml\"/>\n"
              "<include filename=\"self.xml\"/>\n</scene>\n");
    writeFile(dir + "/a.xml",
              "<scene version=\"3.0.0\">\n<include filename=\"b.xml\"/>\n</scene>\n");
    writeFile(dir + "/b.xml",
              "<scene version=\"3.0.0\">\n\n<include filename=\"a.xml\"/>\n</scene>\n");
    std::string e =
        errorsOf(scene("<include filename=\"self.xml\"/>\n" + std::string(kLight)), dir);
    EXPECT_TRUE(contains(e, "self.xml:2:1: error: include cycle: '")) << e;
    EXPECT_TRUE(contains(e, "self.xml:3:1: error: include cycle: '")) << e;
    EXPECT_TRUE(contains(e,
                         "is already being read (it includes itself, directly or through "
                         "other files)"))
        << e;
    e = errorsOf(scene("<include filename=\"a.xml\"/>\n" + std::string(kLight)), dir);
    EXPECT_TRUE(contains(e, "b.xml:3:1: error: include cycle: '")) << e;
}

// Plugin objects nested 20000 deep overflowed the stack (segmentation fault) while reading;
// nesting is bounded at 64 with an error at the first object too deep.
TEST(MitsubaXml, DeepObjectNestingIsAnErrorNotACrash) {
    std::string body = "<shape type=\"cube\">";
    for (int i = 0; i < 20000; ++i) body += "<bsdf type=\"twosided\">";
    for (int i = 0; i < 20000; ++i) body += "</bsdf>";
    body += "</shape>\n";
    std::string e = errorsOf(scene(std::string(kLight) + body));
    EXPECT_TRUE(contains(e, "error: <bsdf> is nested more than 64 objects deep"))
        << e.substr(0, 500);
}

// Bytes that are not UTF-8 and control characters in a quoted token are printed escaped, never
// raw onto the terminal.
TEST(MitsubaXml, NonUtf8PluginNameIsEscapedInTheMessage) {
    std::string e = errorsOf(scene(std::string(kLight) + "<shape type=\"cu\xff\xfe"
                                                         "be\"/>\n"));
    EXPECT_TRUE(contains(e, "scene.xml:9:1: error: unsupported shape plugin 'cu\\xff\\xfebe'"))
        << e;
}

TEST(MitsubaXml, ShapesWithoutBsdfGetMitsubasDefaults) {
    // Mitsuba 3 (Shape's constructor): no BSDF gives a diffuse BSDF of reflectance 0.5, or 0
    // when the shape carries an area emitter (an emitter does not reflect by default). A
    // grey emitter showed up as +1% of the whole image against Mitsuba 3 in the
    // surfaces reference scene (tests/data/mitsuba/surfaces.xml).
    auto s = load(scene(R"(<shape type="rectangle"/>
<shape type="rectangle"><transform name="to_world"><translate z="1"/></transform>
  <emitter type="area"><rgb name="radiance" value="2"/></emitter></shape>
)"));
    ASSERT_EQ(s->shapes.size(), 2u);
    const Material& plain = s->materials[size_t(s->shapes[0].materialId)];
    const Material& emitter = s->materials[size_t(s->shapes[1].materialId)];
    EXPECT_EQ(plain.type, MaterialType::Diffuse);
    EXPECT_EQ(plain.diffuse.x, 0.5f);
    EXPECT_FALSE(plain.twoSided);
    EXPECT_EQ(emitter.type, MaterialType::Diffuse);
    EXPECT_EQ(maxComponent(emitter.diffuse), 0.0f);
    EXPECT_GE(s->shapes[1].lightId, 0);
}

// Only regular files are included: /dev/zero never ends (reading it hung and filled memory).
TEST(MitsubaXml, IncludeOfADeviceIsAnError) {
    ASSERT_TRUE(fs::exists("/dev/zero")) << "/dev/zero not found";
    std::string e = errorsOf(scene("<include filename=\"/dev/zero\"/>\n" + std::string(kLight)));
    EXPECT_TRUE(contains(e,
                         "scene.xml:8:1: error: cannot open the included file '/dev/zero' (not "
                         "a readable regular file)"))
        << e;
}

// Range messages print their bounds as numbers ("(0, 1e+30]"), not "(0.000000, inf]", which
// read as if 3e38 were allowed.
TEST(MitsubaXml, OutOfRangeMessageShowsTheBounds) {
    std::string e = errorsOf(scene(std::string(kLight) +
                                   "<shape type=\"sphere\"><float name=\"radius\" value=\"3e38\"/>"
                                   "</shape>\n"));
    EXPECT_TRUE(contains(e,
                         "<shape type=\"sphere\">: parameter 'radius' = 3e38 is out of range "
                         "(expected a value in (0, 1e+30])"))
        << e;
}

// blendbsdf and mask (scene/bsdf.cpp, "Blend"): the parts in document order, a mask's null
// part first; weight / opacity as a float or a texture; twosided reaches the parts.
TEST(MitsubaBsdfs, BlendAndMaskBuildBlendMaterials) {
    std::unique_ptr<Scene> s = load(scene(std::string(kLight) + R"(
<shape type="sphere"><bsdf type="blendbsdf"><float name="weight" value="0.25"/>
  <bsdf type="diffuse"/><bsdf type="conductor"/></bsdf></shape>
<shape type="rectangle"><bsdf type="twosided"><bsdf type="mask" id="leaf">
  <texture type="checkerboard" name="opacity"><float name="color0" value="1"/>
    <float name="color1" value="0"/></texture>
  <bsdf type="diffuse"/></bsdf></bsdf></shape>
)"));
    const Material& blend = s->materials[size_t(s->shapes[0].materialId)];
    ASSERT_EQ(blend.type, MaterialType::Blend);
    EXPECT_FLOAT_EQ(blend.blendWeight, 0.25f);
    EXPECT_EQ(s->materials[size_t(blend.blendParts[0])].type, MaterialType::Diffuse);
    EXPECT_EQ(s->materials[size_t(blend.blendParts[1])].type, MaterialType::Mirror);
    const Material& mask = s->materials[size_t(s->shapes[1].materialId)];
    ASSERT_EQ(mask.type, MaterialType::Blend);
    EXPECT_GE(mask.textures.weight, 0);
    const Material& pass = s->materials[size_t(mask.blendParts[0])];
    EXPECT_EQ(pass.type, MaterialType::ThinDielectric);
    EXPECT_EQ(pass.ior, 1.0f);
    const Material& leaf = s->materials[size_t(mask.blendParts[1])];
    EXPECT_EQ(leaf.type, MaterialType::Diffuse);
    EXPECT_TRUE(leaf.twoSided);  // twosided around the mask reaches the masked BSDF
}

// A null BSDF on an emitter: the shape emits and lets rays pass (the pass-through material);
// with a medium it is refused.
TEST(MitsubaBsdfs, NullBsdfEmitterPassesRays) {
    std::unique_ptr<Scene> s = load(scene(R"(
<shape type="rectangle"><bsdf type="null"/>
  <emitter type="area"><rgb name="radiance" value="2"/></emitter></shape>
)"));
    ASSERT_EQ(s->shapes.size(), 1u);
    EXPECT_GE(s->shapes[0].lightId, 0);
    const Material& m = s->materials[size_t(s->shapes[0].materialId)];
    EXPECT_EQ(m.type, MaterialType::ThinDielectric);
    EXPECT_EQ(m.ior, 1.0f);
    EXPECT_FALSE(s->shapes[0].isMediumBoundary);
    const std::string e = errorsOf(scene(R"(<medium type="homogeneous" id="fog"/>
<shape type="sphere"><bsdf type="null"/><ref id="fog" name="interior"/>
  <emitter type="area"/></shape>
)"));
    EXPECT_NE(e.find("null BSDF and a medium cannot emit"), std::string::npos) << e;
    EXPECT_NE(e.find("scene.xml:"), std::string::npos) << e;
}

TEST(MitsubaBsdfs, BadBlendsAreErrorsWithPosition) {
    auto errorOf = [](const std::string& bsdf) {
        return errorsOf(
            scene(std::string(kLight) + "<shape type=\"sphere\">\n" + bsdf + "</shape>\n"));
    };
    std::string e = errorOf("<bsdf type=\"blendbsdf\"><bsdf type=\"diffuse\"/></bsdf>\n");
    EXPECT_NE(e.find("expected exactly 2 nested <bsdf>s, got 1"), std::string::npos) << e;
    EXPECT_NE(e.find("scene.xml:"), std::string::npos) << e;
    e = errorOf("<bsdf type=\"mask\"><bsdf type=\"diffuse\"/><bsdf type=\"diffuse\"/></bsdf>\n");
    EXPECT_NE(e.find("expected exactly 1 nested <bsdf>, got 2"), std::string::npos) << e;
    e = errorOf(
        "<bsdf type=\"blendbsdf\"><float name=\"weight\" value=\"1.5\"/>\n"
        "<bsdf type=\"diffuse\"/><bsdf type=\"diffuse\"/></bsdf>\n");
    EXPECT_NE(e.find("weight"), std::string::npos) << e;
    e = errorOf(
        "<bsdf type=\"mask\"><float name=\"opacity\" value=\"-0.1\"/>"
        "<bsdf type=\"diffuse\"/></bsdf>\n");
    EXPECT_NE(e.find("opacity"), std::string::npos) << e;
    e = errorOf(
        "<bsdf type=\"blendbsdf\"><bsdf type=\"dielectric\"/><bsdf type=\"diffuse\"/>"
        "</bsdf>\n");
    EXPECT_NE(e.find("cannot hold a 'dielectric'"), std::string::npos) << e;
    e = errorOf(
        "<bsdf type=\"mask\"><rgb name=\"tint\" value=\"1\"/><bsdf type=\"diffuse\"/>"
        "</bsdf>\n");
    EXPECT_NE(e.find("tint"), std::string::npos) << e;
}

TEST(MitsubaLoader, MeshAttributeTexturesBindToTheirShape) {
    const std::string dir = std::string(UNIBEAM_SOURCE_DIR) + "/tests/data/mitsuba";
    auto shape = [](const std::string& bsdf, const std::string& type = "ply") {
        return "<shape type=\"" + type + "\">" +
               (type == "ply" ? "<string name=\"filename\" value=\"meshes/attributes.ply\"/>"
                              : "") +
               bsdf + "</shape>\n";
    };
    auto attr = [](const std::string& param, const std::string& name) {
        return "<texture type=\"mesh_attribute\" name=\"" + param +
               "\"><string name=\"name\" value=\"" + name + "\"/></texture>";
    };
    const std::string diffuse =
        "<bsdf type=\"diffuse\">" + attr("reflectance", "vertex_color") + "</bsdf>";
    auto s = load(scene(shape(diffuse) + kLight), dir);
    ASSERT_EQ(s->textures.size(), 1u);
    EXPECT_EQ(s->textures[0].type, TextureType::MeshAttribute);
    EXPECT_EQ(s->textures[0].attributeName, "vertex_color");
    // A ray into the cube's +z face sees the interpolated vertex colour, not 0.
    Ray ray;
    ray.org = Vec3(0.2f, 0.1f, 5.0f);
    ray.dir = Vec3(0, 0, -1);
    Hit hit;
    ASSERT_TRUE(s->intersect(ray, &hit));
    EXPECT_GT(hit.attribute.x + hit.attribute.y + hit.attribute.z, 0.1f);

    std::string e = errorsOf(
        scene(shape("<bsdf type=\"diffuse\">" + attr("reflectance", "vertex_foo") + "</bsdf>") +
              kLight),
        dir);
    EXPECT_TRUE(contains(e,
                         "its BSDF looks up the mesh attribute 'vertex_foo', which the mesh "
                         "does not have (it has vertex_color, face_color, face_weight"))
        << e;
    e = errorsOf(scene(shape(diffuse, "sphere") + kLight), dir);
    EXPECT_TRUE(contains(e, "'vertex_color', which a sphere does not have")) << e;
    e = errorsOf(scene(shape("<bsdf type=\"blendbsdf\">" + attr("weight", "face_weight") +
                             "<bsdf type=\"diffuse\">" + attr("reflectance", "face_color") +
                             "</bsdf><bsdf type=\"diffuse\"/></bsdf>") +
                       kLight),
                 dir);
    EXPECT_TRUE(contains(e,
                         "looks up the mesh attributes 'face_color' and 'face_weight' "
                         "(unibeam supports one mesh attribute per shape)"))
        << e;
    e = errorsOf(scene(shape("<bsdf type=\"normalmap\">" + attr("normalmap", "vertex_color") +
                             "<bsdf type=\"diffuse\"/></bsdf>") +
                       kLight),
                 dir);
    EXPECT_TRUE(contains(e, "a mesh_attribute cannot be its normal map")) << e;
    e = errorsOf(
        scene(shape("<bsdf type=\"diffuse\">" + attr("reflectance", "color") + "</bsdf>") + kLight),
        dir);
    EXPECT_TRUE(contains(e, "attribute name 'color' does not start with vertex_ or face_")) << e;
}

// Mitsuba's principled: parameters, textured weights, defaults (eta from specular 0.5 is 1.5),
// one-sided unless in twosided, and the errors: eta with specular, a weight outside [0, 1],
// twosided around a transmitting one.
TEST(MitsubaXml, PrincipledParametersDefaultsAndErrors) {
    auto s =
        load(scene(std::string(kLight) +
                   "<shape type=\"sphere\"><bsdf type=\"principled\">"
                   "<rgb name=\"base_color\" value=\"0.2, 0.4, 0.6\"/>"
                   "<float name=\"metallic\" value=\"0.3\"/><float name=\"sheen\" value=\"0.5\"/>"
                   "<float name=\"clearcoat_sampling_rate\" value=\"0.25\"/>"
                   "</bsdf></shape>\n"
                   "<shape type=\"sphere\"><bsdf type=\"twosided\"><bsdf type=\"principled\">"
                   "<float name=\"eta\" value=\"1.33\"/><float name=\"spec_trans\" value=\"0\"/>"
                   "</bsdf></bsdf></shape>\n"));
    const Material& a = s->materials[size_t(s->shapes[0].materialId)];
    EXPECT_EQ(a.type, MaterialType::Principled);
    EXPECT_FALSE(a.twoSided);
    EXPECT_NEAR(a.diffuse.y, 0.4f, 1e-6f);
    EXPECT_NEAR(a.alpha, 0.5f, 1e-6f);  // roughness default
    EXPECT_NEAR(a.ior, 1.5f, 1e-5f);    // specular 0.5
    EXPECT_NEAR(a.principled.metallic, 0.3f, 1e-6f);
    EXPECT_NEAR(a.principled.sheen, 0.5f, 1e-6f);
    EXPECT_NEAR(a.principled.rateClearcoat, 0.25f, 1e-6f);
    const Material& b = s->materials[size_t(s->shapes[1].materialId)];
    EXPECT_TRUE(b.twoSided);
    EXPECT_NEAR(b.ior, 1.33f, 1e-6f);

    std::string e = errorsOf(scene(std::string(kLight) +
                                   "<shape type=\"sphere\"><bsdf type=\"principled\">\n"
                                   "  <float name=\"eta\" value=\"1.4\"/>\n"
                                   "  <float name=\"specular\" value=\"0.4\"/></bsdf></shape>\n"));
    EXPECT_TRUE(contains(e,
                         "scene.xml:11:3: error: <bsdf type=\"principled\">: give either "
                         "'eta' or 'specular', not both"))
        << e;
    // textured weights (Mitsuba's float textures)
    auto t = load(scene(std::string(kLight) +
                        "<shape type=\"sphere\"><bsdf type=\"principled\">"
                        "<texture name=\"metallic\" type=\"checkerboard\"/>"
                        "<texture name=\"anisotropic\" type=\"checkerboard\"/></bsdf></shape>\n"));
    const Material& c = t->materials[size_t(t->shapes[0].materialId)];
    EXPECT_GE(c.textures.principled[1], 0);  // metallic
    EXPECT_GE(c.textures.principled[0], 0);  // anisotropic
    EXPECT_EQ(c.textures.principled[2], -1);
    EXPECT_TRUE(c.anisotropic());
    e = errorsOf(scene(std::string(kLight) +
                       "<shape type=\"sphere\"><bsdf type=\"twosided\">\n"
                       "  <bsdf type=\"principled\"><float name=\"spec_trans\" value=\"0.5\"/>"
                       "</bsdf></bsdf></shape>\n"));
    EXPECT_TRUE(contains(e, "cannot wrap a 'principled' BSDF with spec_trans")) << e;
    // principledthin: a sheet (two-sided), diff_trans in [0, 2], its own sampling rates; not
    // inside twosided (it transmits)
    auto thin = load(scene(std::string(kLight) +
                           "<shape type=\"rectangle\"><bsdf type=\"principledthin\">"
                           "<float name=\"diff_trans\" value=\"1.6\"/>"
                           "<float name=\"eta\" value=\"1.33\"/>"
                           "<float name=\"specular_transmittance_sampling_rate\" value=\"2\"/>"
                           "</bsdf></shape>\n"));
    const Material& d = thin->materials[size_t(thin->shapes[0].materialId)];
    EXPECT_EQ(d.type, MaterialType::PrincipledThin);
    EXPECT_TRUE(d.twoSided);
    EXPECT_NEAR(d.principled.diffTrans, 1.6f, 1e-6f);
    EXPECT_NEAR(d.principled.rateSpecTrans, 2.0f, 1e-6f);
    EXPECT_NEAR(d.ior, 1.33f, 1e-6f);
    e = errorsOf(scene(std::string(kLight) +
                       "<shape type=\"rectangle\"><bsdf type=\"principledthin\">\n"
                       "  <float name=\"metallic\" value=\"0.5\"/></bsdf></shape>\n"));
    EXPECT_TRUE(contains(e, "unsupported parameter 'metallic'")) << e;
    e = errorsOf(scene(std::string(kLight) + "<shape type=\"rectangle\"><bsdf type=\"twosided\">\n"
                                             "  <bsdf type=\"principledthin\"/></bsdf></shape>\n"));
    EXPECT_TRUE(contains(e, "cannot wrap a 'principledthin' BSDF")) << e;
    e = errorsOf(scene(std::string(kLight) +
                       "<shape type=\"sphere\"><bsdf type=\"principled\">\n"
                       "  <float name=\"sheen\" value=\"1.5\"/></bsdf></shape>\n"));
    EXPECT_TRUE(contains(e, "scene.xml:10:3: error")) << e;
    EXPECT_TRUE(contains(e, "'sheen'")) << e;
}

// Mitsuba's aov integrator: its "name:type" list and nested integrator are read, the
// variables are rendered as layers (render/aov.h): on a plane z = -1 seen head-on, position.z
// is -1 and sh_normal (0, 0, 1) everywhere the plane covers, depth between the plane's
// nearest and farthest distance; unsupported types and a missing nested integrator are errors.
TEST(MitsubaXml, AovIntegratorListsVariablesAndRendersThem) {
    const std::string body = std::string(kLight) +
                             "<shape type=\"rectangle\"><transform name=\"to_world\">"
                             "<scale value=\"10\"/><translate z=\"-1\"/></transform></shape>\n";
    auto s = load(std::string("<scene version=\"3.0.0\">\n") +
                  "<integrator type=\"aov\"><string name=\"aovs\" value=\"dd:depth, nn:sh_normal,"
                  " pp:position\"/><integrator type=\"path\"/></integrator>\n" +
                  kSensor + body + "</scene>\n");
    ASSERT_EQ(s->settings.aovs.size(), 3u);
    EXPECT_EQ(s->settings.aovs[0].name, "dd");
    EXPECT_EQ(s->settings.aovs[1].type, "sh_normal");
    const auto layers = renderAovs(*s, 4, 1);
    ASSERT_EQ(layers.size(), 3u);
    EXPECT_EQ(layers[2].first, "pp");
    const float maxDist = 5.0f / std::cos(20.0f * 3.14159265f / 180.0f) * 1.5f;
    for (int y = 0; y < 24; ++y)
        for (int x = 0; x < 32; ++x) {
            ASSERT_NEAR(layers[2].second.at(x, y).z, -1.0f, 1e-5f);
            ASSERT_NEAR(layers[1].second.at(x, y).z, 1.0f, 1e-5f);
            const float d = layers[0].second.at(x, y).x;
            ASSERT_GE(d, 6.0f - 1e-4f);  // the camera is at z = 5
            ASSERT_LE(d, maxDist);
        }
    std::string e = errorsOf(std::string("<scene version=\"3.0.0\">\n") +
                             "<integrator type=\"aov\"><string name=\"aovs\" value=\"a:albedo\"/>"
                             "<integrator type=\"path\"/></integrator>\n" +
                             kSensor + body + "</scene>\n");
    EXPECT_TRUE(contains(e, "aov 'a:albedo': expected NAME:TYPE with TYPE one of depth")) << e;
    e = errorsOf(std::string("<scene version=\"3.0.0\">\n") +
                 "<integrator type=\"aov\"><string name=\"aovs\" value=\"d:depth\"/>"
                 "</integrator>\n" +
                 kSensor + body + "</scene>\n");
    EXPECT_TRUE(contains(e, "expected exactly one nested <integrator>")) << e;
}
