// SmallUPBP scenes (.obj + .mtl + .obj.aux): the three paper/gpuupbp scenes in
// scenes/smallupbp load with the counts and camera of their files and render
// finite images with vpt; every class of bad input gives its message with
// file:line:column; the environment-map frame reproduces SmallUPBP's lookup.
#include "scene/io/smallupbp_loader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/image.h"
#include "render/integrator.h"
#include "scene/io/scene_loader.h"
#include "scene/io/smallupbp_boundary.h"
#include "tests/support/temp_file.h"

namespace fs = std::filesystem;
using namespace ub;

namespace {

const std::string kScenes = std::string(UNIBEAM_SCENES_DIR) + "/smallupbp";

bool contains(const std::string& s, const std::string& part) {
    return s.find(part) != std::string::npos;
}

std::string allMessages(const std::vector<Diagnostic>& d) {
    std::string s;
    for (const auto& x : d) s += x.format() + "\n";
    return s;
}

/// The .aux camera of the scratch scenes: at z = 3, looking down the -z axis.
const char* const kCameraAbove =
    "TM_ROW0 1 0 0\nTM_ROW1 0 1 0\nTM_ROW2 0 0 1\nTM_ROW3 0 0 3\nCAMERA_FOV 0.9\n";

/// A scratch folder with a small valid scene t.obj / t.mtl / t.obj.aux that tests edit.
class TinyScene {
  public:
    explicit TinyScene(const std::string& name)
        : dir_(ub::test::processScratchDir() / ("upbp_" + name)) {
        fs::remove_all(dir_);
        fs::create_directories(dir_);
        mtl =
            "newmtl white\nKd 0.5 0.5 0.5\nnewmtl glass\nKd 0 0 0\nnewmtl lamp\nKd 0 0 0\n"
            "Ke 2 2 2\n";
        // A floor quad, a closed tetrahedron of glass, and a lamp quad facing down.
        obj =
            "mtllib t.mtl\n"
            "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n"
            "v -0.2 -0.2 0.1\nv 0.2 -0.2 0.1\nv 0 0.2 0.1\nv 0 0 0.5\n"
            "v -0.3 -0.3 1\nv 0.3 -0.3 1\nv 0.3 0.3 1\nv -0.3 0.3 1\n"
            "usemtl white\nf 1 2 3 4\n"
            "usemtl glass\nf 5 7 6\nf 5 6 8\nf 6 7 8\nf 7 5 8\n"
            "usemtl lamp\nf 9 12 11 10\n";
        aux = std::string(kCameraAbove) +
              "medium inside\nabsorption 0.1 0.1 0.1\nscattering 0.5 0.5 0.5\ng 0.3\n"
              "material glass\nior 1.5\nmirror 1 1 1\nmediumId inside\npriority 2\n";
    }
    ~TinyScene() { fs::remove_all(dir_); }

    std::string objPath() const { return (dir_ / "t.obj").string(); }
    std::string auxPath() const { return objPath() + ".aux"; }
    std::string mtlPath() const { return (dir_ / "t.mtl").string(); }

    void write() const {
        std::ofstream(objPath()) << obj;
        std::ofstream(mtlPath()) << mtl;
        std::ofstream(auxPath()) << aux;
    }
    /// Loads and returns the error text ("" if it loaded); warnings into *w.
    std::string errors(std::vector<Diagnostic>* w = nullptr) const {
        write();
        try {
            loadScene(objPath(), w);
        } catch (const InputError& e) {
            return e.what();
        }
        return "";
    }

    std::string obj, mtl, aux;

  private:
    fs::path dir_;
};

void expectCameraFromAux(const Scene& s, const Vec3& row1, const Vec3& row2, const Vec3& row3,
                         float fovXRad) {
    const Camera& c = s.camera;
    EXPECT_NEAR(c.position().x, row3.x, 1e-3f);
    EXPECT_NEAR(c.position().y, row3.y, 1e-3f);
    EXPECT_NEAR(c.position().z, row3.z, 1e-3f);
    const Vec3 fwd = normalize(-row2);
    EXPECT_NEAR(dot(c.forward(), fwd), 1.0f, 1e-5f);
    // The image's up vector is TM_ROW1 made orthogonal to the viewing direction.
    const Vec3 up = normalize(row1 - fwd * dot(row1, fwd));
    EXPECT_NEAR(dot(c.up(), up), 1.0f, 1e-4f);
    EXPECT_EQ(c.width(), 256);
    EXPECT_EQ(c.height(), 256);
    // Square image: the vertical field of view equals the horizontal CAMERA_FOV.
    EXPECT_NEAR(c.fovYDeg(), fovXRad * 180.0f / float(M_PI), 1e-3f);
}

/// Renders `iterations` of vpt at 32x32 and checks every pixel is finite and >= 0;
/// returns the mean luminance.
float renderFinite(Scene& scene, int iterations) {
    Camera small;
    const Camera& c = scene.camera;
    small.setup(c.position(), c.position() + c.forward(), c.up(), c.fovYDeg(), 32, 32);
    scene.camera = small;
    RenderOptions opt;
    opt.algorithm = "vpt";
    opt.maxPathLength = 10;
    opt.seed = 7;
    auto integrator = makeIntegrator(scene, opt);
    Image img(32, 32);
    double sum = 0.0;
    int bad = 0;
    for (int it = 0; it < iterations; ++it) {
        integrator->renderIteration(it, img);
        for (const Rgb& p : img.pixels) {
            if (!isFinite(p) || minComponent(p) < 0.0f) ++bad;
            sum += luminance(p);
        }
    }
    EXPECT_EQ(bad, 0) << "non-finite or negative pixels";
    return float(sum / (double(iterations) * 32 * 32));
}

int countBoundaries(const Scene& s, bool imaginary) {
    int n = 0;
    for (const ShapeInfo& sh : s.shapes) n += sh.isMediumBoundary && sh.imaginary == imaginary;
    return n;
}

const ShapeInfo* shapeNamed(const Scene& s, const std::string& name) {
    for (const ShapeInfo& sh : s.shapes)
        if (sh.name == name) return &sh;
    return nullptr;
}

}  // namespace

// ---- the three scenes -----------------------------------------------------------

TEST(SmallUpbpScenes, CandleLoadsAsWritten) {
    const std::string path = kScenes + "/candle/candle.obj";
    ASSERT_TRUE(fs::is_regular_file(path)) << path;
    std::vector<Diagnostic> w;
    auto scene = loadScene(path, &w);
    // candle.mtl: 6 materials, all used by one usemtl group each.
    EXPECT_EQ(scene->materials.size(), 6u);
    EXPECT_EQ(scene->shapes.size(), 6u);
    EXPECT_EQ(scene->media.size(), 1u);   // M_svicka
    EXPECT_EQ(scene->lights.size(), 1u);  // Svetlo (Ke 100 in the .aux)
    EXPECT_EQ(scene->globalMediumId, -1);
    EXPECT_EQ(countBoundaries(*scene, false), 1);  // svicka, priority 1
    const ShapeInfo* candle = shapeNamed(*scene, "svicka");
    ASSERT_NE(candle, nullptr);
    EXPECT_EQ(candle->mediumPriority, 1);
    EXPECT_EQ(scene->media[size_t(candle->interiorMediumId)].sigmaS.x, 2.0f);
    // wire_088144225: Kd + Ks 0.35 with Ns 32 -> Phong.
    bool phong = false;
    for (const Material& m : scene->materials)
        if (m.name == "wire_088144225") {
            phong = m.type == MaterialType::Phong && m.exponent == 32.0f && m.glossy.x == 0.35f;
        }
    EXPECT_TRUE(phong);
    expectCameraFromAux(*scene, Vec3(0.5f, 0.0f, 0.8660f), Vec3(-0.8660f, 0.0f, 0.5f),
                        Vec3(-84.8188f, 22.9605f, 31.0322f), 0.7854f);
    // The .aux block of Pozadi uses Ka/Kd/Ks, which SmallUPBP reads as Ke: warned.
    const std::string msgs = allMessages(w);
    EXPECT_TRUE(contains(msgs,
                         "candle.obj.aux:35:1: warning: 'Kd' in an .aux file is read as "
                         "'Ke' (emission)"))
        << msgs;
    EXPECT_GT(renderFinite(*scene, 2), 0.0f);
}

TEST(SmallUpbpScenes, MirrorballsLoadsAsWritten) {
    const std::string path = kScenes + "/mirrorballs/mirrorballs.obj";
    ASSERT_TRUE(fs::is_regular_file(path)) << path;
    std::vector<Diagnostic> w;
    auto scene = loadScene(path, &w);
    EXPECT_EQ(scene->materials.size(), 9u);
    // 17 'g' groups use 9 materials; SmallUPBP groups faces by material, and the medium
    // boundary matGlass is split into its 3 closed pieces (a ball and two lamp glasses).
    EXPECT_EQ(scene->shapes.size(), 11u);
    EXPECT_EQ(scene->media.size(), 4u);
    EXPECT_EQ(scene->lights.size(), 1u);           // matLight, Ke 80000
    EXPECT_EQ(countBoundaries(*scene, false), 5);  // matGlass (3 pieces), matBall, matBall2
    EXPECT_EQ(countBoundaries(*scene, true), 1);   // matGlobal
    EXPECT_NE(shapeNamed(*scene, "matGlass (piece 3 of 3)"), nullptr);
    const ShapeInfo* global = shapeNamed(*scene, "matGlobal");
    ASSERT_NE(global, nullptr);
    EXPECT_EQ(global->mediumPriority, 1);
    // medBall's 'scaterring' is its scattering coefficient.
    EXPECT_EQ(scene->mediumNames[0], "medBall");
    EXPECT_EQ(scene->media[0].sigmaS.y, 0.1f);
    EXPECT_TRUE(contains(allMessages(w),
                         "mirrorballs.obj.aux:16:1: warning: 'scaterring' read "
                         "as 'scattering'"))
        << allMessages(w);
    expectCameraFromAux(*scene, Vec3(0.0f, 0.0f, 1.0f), Vec3(-0.0117f, 0.9999f, 0.0f),
                        Vec3(22.4941f, 1496.1625f, 279.8196f), 0.6911f);
    EXPECT_GT(renderFinite(*scene, 2), 0.0f);
}

TEST(SmallUpbpScenes, BunnyLoadsAsWritten) {
    const std::string path = kScenes + "/bunny/bunny.obj";
    ASSERT_TRUE(fs::is_regular_file(path)) << path;
    std::vector<Diagnostic> w;
    auto scene = loadScene(path, &w);
    EXPECT_EQ(scene->materials.size(), 9u);
    EXPECT_EQ(scene->shapes.size(), 5u);  // matBall2, matChrome, matGlass, matLight, matGlobal
    EXPECT_EQ(scene->media.size(), 4u);
    EXPECT_EQ(scene->lights.size(), 1u);
    EXPECT_EQ(countBoundaries(*scene, false), 2);  // the bunny (matBall2), matGlass
    EXPECT_EQ(countBoundaries(*scene, true), 1);
    // The Stanford bunny's base has holes: closed with a warning at its material block.
    EXPECT_TRUE(contains(allMessages(w),
                         "bunny.obj.aux:61:1: warning: material 'matBall2': "
                         "its mesh has"))
        << allMessages(w);
    expectCameraFromAux(*scene, Vec3(0.0f, 0.0f, 1.0f), Vec3(0.0f, 1.0f, 0.0f),
                        Vec3(209.99f, 1496.1625f, 300.0f), 0.2f);
    // Its only light sits in a chrome shade behind a glass: all light arrives through
    // specular refraction (the scene shows what UPBP's photon estimators add), so a few
    // vpt samples are black; only finiteness is checked.
    renderFinite(*scene, 2);
}

// ---- the tiny scene and its mapping ----------------------------------------------

TEST(SmallUpbpLoader, TinySceneMapsMaterialsMediaAndLights) {
    TinyScene t("tiny");
    t.write();
    std::vector<Diagnostic> w;
    auto s = loadScene(t.objPath(), &w);
    EXPECT_TRUE(w.empty()) << allMessages(w);
    ASSERT_EQ(s->materials.size(), 3u);
    EXPECT_EQ(s->materials[0].type, MaterialType::Diffuse);
    // ior >= 0: SmallUPBP's lobes with refraction (MultiLobe, every lobe kept).
    EXPECT_EQ(s->materials[1].type, MaterialType::MultiLobe);
    EXPECT_TRUE(s->materials[1].refract);
    EXPECT_EQ(s->materials[1].ior, 1.5f);
    ASSERT_EQ(s->shapes.size(), 3u);
    EXPECT_EQ(s->shapes[0].triangleCount, 2u);  // the quad, fanned
    EXPECT_TRUE(s->shapes[1].isMediumBoundary);
    EXPECT_EQ(s->shapes[1].mediumPriority, 2);
    ASSERT_EQ(s->lights.size(), 1u);
    EXPECT_EQ(s->lights[0].type, LightType::Area);
    EXPECT_EQ(s->lights[0].radiance.x, 2.0f);
    ASSERT_EQ(s->media.size(), 1u);
    EXPECT_EQ(s->media[0].g, 0.3f);
    EXPECT_GT(renderFinite(*s, 2), 0.0f);
}

TEST(SmallUpbpLoader, MediumEmissionIsSourceTermPerLength) {
    // SmallUPBP adds emission * distance; unibeam's source is sigma_a * Le.
    TinyScene t("emission");
    t.aux +=
        "medium glow\nabsorption 0.5 0.25 1\nemission 1 1 1\nscattering 0 0 0\n"
        "globalMediumId glow\n";
    t.write();
    auto s = loadScene(t.objPath());
    ASSERT_EQ(s->media.size(), 2u);
    EXPECT_EQ(s->globalMediumId, 1);
    EXPECT_FLOAT_EQ(s->media[1].Le.x * s->media[1].sigmaA.x, 1.0f);
    EXPECT_FLOAT_EQ(s->media[1].Le.y * s->media[1].sigmaA.y, 1.0f);
    EXPECT_FLOAT_EQ(s->media[1].Le.z * s->media[1].sigmaA.z, 1.0f);
}

TEST(SmallUpbpLoader, AuxLightsMapToPointDirectionalConstant) {
    TinyScene t("lights");
    t.aux +=
        "light_point 0 0 2 5 6 7\nlight_directional 0 0 -2 1 1 1\n"
        "light_background_constant 0.1 0.2 0.3\n";
    t.write();
    auto s = loadScene(t.objPath());
    ASSERT_EQ(s->lights.size(), 4u);
    EXPECT_EQ(s->lights[1].type, LightType::Point);
    EXPECT_EQ(s->lights[1].intensity.z, 7.0f);
    EXPECT_EQ(s->lights[2].type, LightType::Directional);
    EXPECT_NEAR(s->lights[2].direction.z, -1.0f, 1e-6f);  // direction light travels
    EXPECT_EQ(s->lights[3].type, LightType::ConstantEnv);
    EXPECT_EQ(s->backgroundLightId, 3);
}

// SmallUPBP's -r WxH keeps the horizontal CAMERA_FOV; so does unibeam's --resolution
// for these scenes (Camera::resized with RenderSettings::keepHorizontalFov).
TEST(SmallUpbpLoader, ResolutionKeepsHorizontalFov) {
    TinyScene t("resize");
    t.write();
    auto s = loadScene(t.objPath());
    ASSERT_TRUE(s->settings.keepHorizontalFov);
    const Camera c = s->camera.resized(400, 800, s->settings.keepHorizontalFov);
    // Horizontal half angle from the image plane: tan = (width / 2) / imagePlaneDist.
    const float tanHalfX = 0.5f * float(c.width()) / c.imagePlaneDist();
    EXPECT_NEAR(tanHalfX, std::tan(0.5f * 0.9f), 1e-5f);  // CAMERA_FOV 0.9
    // The default keeps the vertical angle instead.
    const Camera v = s->camera.resized(400, 800);
    EXPECT_NEAR(v.fovYDeg(), s->camera.fovYDeg(), 1e-5f);
}

// SmallUPBP's EnvMap::Dir2LatLong (z up): u = 1/2 - atan2(y, x) / 2pi, v = acos(z) / pi,
// column u of the rotated map = file column u - rotate. Our envmap light, built from the
// .aux line, must return the same pixel for directions inside that pixel (away from its
// edges: SmallUPBP filters bilinearly, unibeam does not).
TEST(SmallUpbpLoader, EnvironmentMapLookupMatchesSmallUpbp) {
    TinyScene t("envmap");
    const int W = 16, H = 8;
    Image map(W, H);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) map.at(x, y) = Rgb(float(x + 1), float(y + 1), 1.0f);
    writeExr((fs::path(t.objPath()).parent_path() / "room.exr").string(), map);
    t.aux += "light_background_em 2 0.25 room.exr\n";
    t.write();
    auto s = loadScene(t.objPath());
    ASSERT_GE(s->backgroundLightId, 0);
    const Light& env = s->lights[size_t(s->backgroundLightId)];
    const int rot = int(0.25f * W);
    int checked = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            // SmallUPBP looks up the direction d (towards the environment) at
            // (u, v) = ((x + 0.1) / W, (y + 0.5) / H) of the rotated map, which shows file
            // column (x - rot) mod W there.
            const float u = (float(x) + 0.1f) / W, v = (float(y) + 0.5f) / H;
            // Inverting Dir2LatLong: atan2(dy, dx) = pi (1 - 2u), acos(dz) = pi v.
            const float theta = float(M_PI) * v;
            const float alpha = float(M_PI) * (1.0f - 2.0f * u);
            const Vec3 d(std::sin(theta) * std::cos(alpha), std::sin(theta) * std::sin(alpha),
                         std::cos(theta));
            float pdfA = 0, pdfE = 0;
            const Rgb got = env.radianceAlong(s->sceneSphere, d, Vec3(0.0f), Vec3(0.0f),
                                              Vec2(0.0f, 0.0f), &pdfA, &pdfE);
            const int fileX = ((x - rot) % W + W) % W;
            EXPECT_FLOAT_EQ(got.x, 2.0f * float(fileX + 1)) << "x " << x << " y " << y;
            EXPECT_FLOAT_EQ(got.y, 2.0f * float(y + 1)) << "x " << x << " y " << y;
            ++checked;
        }
    EXPECT_EQ(checked, W * H);
}

// ---- bad input: every message names file:line:column ------------------------------

TEST(SmallUpbpLoader, PlainObjWithoutAuxSaysWhatIsExpected) {
    TinyScene t("noaux");
    t.write();
    fs::remove(t.auxPath());
    try {
        loadScene(t.objPath());
        FAIL() << "expected an InputError";
    } catch (const InputError& e) {
        EXPECT_TRUE(contains(e.what(),
                             "t.obj: error: an .obj scene is read in SmallUPBP's "
                             "format, which needs the file 't.obj.aux' beside it"))
            << e.what();
    }
}

TEST(SmallUpbpLoader, MissingKeywordValueNamesLine) {
    TinyScene t("missingvalue");
    t.aux += "material white\nior\npriority 3\n";
    const std::string e = t.errors();
    EXPECT_TRUE(contains(e,
                         "t.obj.aux:16:1: error: missing value: 'ior' expects 1 number "
                         "(index of refraction), found 0 before 'priority' on line 17"))
        << e;
}

TEST(SmallUpbpLoader, NonNumericValueNamesColumn) {
    TinyScene t("nonnumeric");
    t.aux += "medium fog\nabsorption 0.1 abc 0.3\n";
    const std::string e = t.errors();
    EXPECT_TRUE(contains(e,
                         "t.obj.aux:16:16: error: 'abc' is not a number: 'absorption' "
                         "expects 3 numbers (r g b)"))
        << e;
}

TEST(SmallUpbpLoader, UnknownMediumReferenceListsDefinedOnes) {
    TinyScene t("unknownmedium");
    t.aux += "material white\nmediumId insid\npriority 1\n";
    const std::string e = t.errors();
    EXPECT_TRUE(contains(e,
                         "t.obj.aux:16:10: error: unknown medium 'insid' (did you mean "
                         "'inside'?) (defined: inside)"))
        << e;
}

TEST(SmallUpbpLoader, UnknownKeywordIsAnError) {
    TinyScene t("unknownkeyword");
    t.aux += "material white\nroughness 0.3\n";
    const std::string e = t.errors();
    EXPECT_TRUE(contains(e,
                         "t.obj.aux:16:1: error: unknown keyword 'roughness' (SmallUPBP's "
                         ".aux keywords:"))
        << e;
}

TEST(SmallUpbpLoader, UnknownCameraOptionIsAnError) {
    TinyScene t("cameraoption");
    t.aux += "CAMERA_ZOOM 2\n";
    const std::string e = t.errors();
    EXPECT_TRUE(contains(e, "t.obj.aux:15:1: error: unknown keyword 'CAMERA_ZOOM'")) << e;
}

TEST(SmallUpbpLoader, MissingMtlNamesMtllibLine) {
    TinyScene t("missingmtl");
    t.obj.replace(0, 12, "mtllib nothere.mtl");
    const std::string e = t.errors();
    EXPECT_TRUE(contains(e, "t.obj:1:8: error: material library 'nothere.mtl' not found")) << e;
}

TEST(SmallUpbpLoader, MisspellingIsAcceptedWithWarning) {
    TinyScene t("misspelling");
    t.aux += "medium fog\nscaterring 0.2 0.2 0.2\n";
    std::vector<Diagnostic> w;
    EXPECT_EQ(t.errors(&w), "");
    EXPECT_TRUE(contains(allMessages(w),
                         "t.obj.aux:16:1: warning: 'scaterring' read as "
                         "'scattering' (SmallUPBP recognises .aux keywords by "
                         "their first letters)"))
        << allMessages(w);
}

TEST(SmallUpbpLoader, MissingCameraRowAndFovAreErrors) {
    TinyScene t("camera");
    t.aux.replace(t.aux.find("TM_ROW2"), 14, "");
    t.aux.replace(t.aux.find("CAMERA_FOV 0.9"), 14, "");
    const std::string e = t.errors();
    EXPECT_TRUE(contains(e, "t.obj.aux: error: missing 'TM_ROW2'")) << e;
    EXPECT_TRUE(contains(e, "t.obj.aux: error: missing 'CAMERA_FOV'")) << e;
}

TEST(SmallUpbpLoader, UnknownMaterialInAuxListsMtlMaterials) {
    TinyScene t("unknownmaterial");
    t.aux += "material glas\nior 1.2\n";
    const std::string e = t.errors();
    EXPECT_TRUE(contains(e,
                         "t.obj.aux:15:10: error: unknown material 'glas' (did you mean "
                         "'glass'?) (materials come from the .mtl file; it defines: white, "
                         "glass, lamp)"))
        << e;
}

TEST(SmallUpbpLoader, BadObjAndMtlStatementsNameTheirLines) {
    TinyScene t("badobj");
    t.obj += "usemtl white\nf 1 2 99\nvx 1 2 3\nv 1 two 3\n";
    t.mtl += "Kd 0.1 0.2\nnewmtl x\nbumpiness 3\n";
    const std::string e = t.errors();
    EXPECT_TRUE(contains(e,
                         "t.obj:24:7: error: vertex index 99 out of range (the file has 13 "
                         "vertices)"))
        << e;
    EXPECT_TRUE(contains(e, "t.obj:26:5: error: 'two' is not a finite number")) << e;
    EXPECT_TRUE(contains(e,
                         "t.mtl:8:1: error: missing value: 'Kd' expects 3 numbers (r g b), "
                         "found 2 before 'newmtl' on line 9"))
        << e;
    EXPECT_TRUE(contains(e, "t.mtl:10:1: error: unknown .mtl statement 'bumpiness'")) << e;
}

TEST(SmallUpbpLoader, MediumWithoutPriorityIsAnError) {
    TinyScene t("nopriority");
    t.aux += "material white\nmediumId inside\n";
    const std::string e = t.errors();
    EXPECT_TRUE(contains(e,
                         "t.obj.aux:15:1: error: material 'white' has a mediumId but no "
                         "priority"))
        << e;
}

// ---- medium boundaries: pieces, holes, cavities (scene/io/smallupbp_boundary.h) ----

namespace {

/// Axis-aligned cube [lo, hi]^3 as 12 triangles, faces outwards (or inwards).
void addCube(TriangleMesh* m, float lo, float hi, bool inwards, bool skipTop = false) {
    const uint32_t base = uint32_t(m->positions.size());
    for (int i = 0; i < 8; ++i)
        m->positions.push_back(Vec3(i & 1 ? hi : lo, i & 2 ? hi : lo, i & 4 ? hi : lo));
    // Quads as (a, b, c, d) counter-clockwise seen from outside.
    const uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                  {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (int q = 0; q < 6; ++q) {
        if (skipTop && q == 1) continue;  // the z = hi face
        const uint32_t* f = quads[q];
        uint32_t t[2][3] = {{f[0], f[1], f[2]}, {f[0], f[2], f[3]}};
        for (auto& tri : t) {
            if (inwards) std::swap(tri[1], tri[2]);
            for (uint32_t v : tri) m->indices.push_back(base + v);
        }
    }
}

double signedVolume(const TriangleMesh& m) {
    double v = 0.0;
    for (size_t t = 0; t < m.triangleCount(); ++t)
        v += double(dot(m.positions[m.indices[3 * t]], cross(m.positions[m.indices[3 * t + 1]],
                                                             m.positions[m.indices[3 * t + 2]]))) /
             6.0;
    return v;
}

}  // namespace

TEST(SmallUpbpBoundary, SeparateObjectsBecomeSeparatePieces) {
    TriangleMesh m;
    addCube(&m, 0.0f, 1.0f, false);
    addCube(&m, 5.0f, 6.0f, false);
    BoundarySplit s = splitMediumBoundary(m);
    ASSERT_EQ(s.pieces.size(), 2u);
    EXPECT_EQ(s.holes, 0u);
    EXPECT_EQ(s.pieces[0].triangleCount(), 12u);
    EXPECT_NEAR(signedVolume(s.pieces[1]), 1.0, 1e-5);
}

TEST(SmallUpbpBoundary, HoleIsClosedWithOutwardFan) {
    TriangleMesh m;
    addCube(&m, 0.0f, 1.0f, false, /*skipTop=*/true);
    BoundarySplit s = splitMediumBoundary(m);
    ASSERT_EQ(s.pieces.size(), 1u);
    EXPECT_EQ(s.holes, 1u);
    EXPECT_EQ(s.holeEdges, 4u);
    // 10 cube triangles + a fan of 4 around the centre of the missing face; the volume
    // is the cube's again (the fan is flat and faces outwards).
    EXPECT_EQ(s.pieces[0].triangleCount(), 14u);
    EXPECT_NEAR(signedVolume(s.pieces[0]), 1.0, 1e-5);
}

TEST(SmallUpbpBoundary, CavityStaysWithItsShell) {
    // A hollow box: outer wall outwards, inner wall inwards (negative volume).
    TriangleMesh m;
    addCube(&m, 0.0f, 3.0f, false);
    addCube(&m, 1.0f, 2.0f, true);
    BoundarySplit s = splitMediumBoundary(m);
    ASSERT_EQ(s.pieces.size(), 1u);
    EXPECT_EQ(s.cavities, 1u);
    EXPECT_NEAR(signedVolume(s.pieces[0]), 27.0 - 1.0, 1e-4);
}

// SmallUPBP evaluates its Lambert and Phong lobes to zero behind the shading normal: a
// diffuse or Phong floor seen and lit from its back renders black, and the same floor turned
// over is lit. (Before, unibeam's SmallUPBP surfaces were two-sided: the inside of the candle's
// room, the back of its `wire` box, reflected light that SmallUPBP's BSDF gives zero there.)
TEST(SmallUpbpLoader, DiffuseAndPhongAreBlackFromTheBack) {
    const char* materials[] = {"newmtl floor\nKd 0.5 0.5 0.5\n",
                               "newmtl floor\nKd 0.2 0.2 0.2\nKs 0.5 0.5 0.5\nNs 10\n"};
    for (const char* mtl : materials) {
        for (bool front : {true, false}) {
            SCOPED_TRACE(std::string(mtl) + (front ? " front" : " back"));
            TinyScene t(front ? "front" : "back");
            t.mtl = mtl;
            // One quad at z = 0, its winding's normal +z (front) or -z (back), seen from z = 3
            // and lit by a point light at z = 2.
            t.obj = std::string("mtllib t.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n") +
                    "usemtl floor\n" + (front ? "f 1 2 3 4\n" : "f 1 4 3 2\n");
            t.aux = std::string(kCameraAbove) + "light_point 0 0 2 5 5 5\n";
            t.write();
            auto s = loadScene(t.objPath());
            ASSERT_EQ(s->materials.size(), 1u);
            EXPECT_FALSE(s->materials[0].twoSided);
            const float mean = renderFinite(*s, 2);
            if (front)
                EXPECT_GT(mean, 0.01f);
            else
                EXPECT_EQ(mean, 0.0f);
        }
    }
}

// A SmallUPBP material with a mirror and a Lambert lobe but no refraction (MultiLobe): from the
// back of its shading normal the Lambert lobe is black and the mirror reflects, as in
// SmallUPBP. Seen from behind, it then renders the same image in expectation as the mirror
// alone (whose weight the lobe choice divides by its probability). Turned to the viewer's side
// as a two-sided material, its Lambert lobe would add the sky's light.
TEST(SmallUpbpLoader, MirrorLobeReflectsFromTheBackWhereLambertIsBlack) {
    float means[2];
    for (int withLambert = 0; withLambert < 2; ++withLambert) {
        TinyScene t(withLambert ? "mirror_lambert" : "mirror_only");
        t.mtl = withLambert ? "newmtl floor\nKd 0.5 0.5 0.5\n" : "newmtl floor\n";
        // The floor's winding normal points down, away from the camera at z = 3, under a
        // constant sky of radiance 1 (about half of the image is the floor).
        t.obj = "mtllib t.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nusemtl floor\nf 1 4 3 2\n";
        t.aux = std::string(kCameraAbove) +
                "material floor\nmirror 1 1 1\nlight_background_constant 1 1 1\n";
        t.write();
        auto s = loadScene(t.objPath());
        EXPECT_EQ(s->materials[0].type,
                  withLambert ? MaterialType::MultiLobe : MaterialType::Mirror);
        means[withLambert] = renderFinite(*s, 16);
    }
    EXPECT_NEAR(means[0], 1.0f, 1e-3f);  // the sky, seen directly or in the mirror
    // The lobe choice makes the MultiLobe image noisy: the mirror is taken with probability
    // 2/3 (albedos 1 and 0.5), so a floor sample is 0 or 1.5. About half of the 16,384 samples
    // (32 x 32, 16 iterations) are on the floor: the mean's relative standard error is about
    // sqrt(0.5 * 0.5 / 16384) = 0.4%; the bound is 3% (7 standard errors). Two-sided, the
    // Lambert lobe lit by the sky made the ratio 1.24; the whole material black from the
    // back, 0.52.
    EXPECT_NEAR(means[1] / means[0], 1.0f, 0.03f) << means[0] << " " << means[1];
}

// A diffuse or Phong colour above 1 creates energy: SmallUPBP renders it as written, so it
// loads, with a warning at its line.
TEST(SmallUpbpLoader, ReflectanceAboveOneIsAWarning) {
    TinyScene t("kdabove1");
    t.mtl = "newmtl white\nKd 5 0.5 0.5\nnewmtl glass\nKd 0 0 0\nnewmtl lamp\nKd 0 0 0\nKe 2 2 2\n";
    std::vector<Diagnostic> w;
    EXPECT_EQ(t.errors(&w), "");
    EXPECT_TRUE(contains(allMessages(w),
                         "t.mtl:2:1: warning: 'Kd' above 1 reflects more light than arrives"))
        << allMessages(w);
}

// Binary garbage, bytes that are not UTF-8 and a 10 MB token give errors with positions whose
// text is escaped and cut, never a crash or megabytes of output.
TEST(SmallUpbpLoader, GarbageFilesGiveShortPrintableErrors) {
    TinyScene t("garbage");
    std::string binary;
    for (int i = 0; i < 4096; ++i) binary += char(i * 37 % 256);
    t.aux = binary;
    std::string e = t.errors();
    EXPECT_TRUE(contains(e, "t.obj.aux:1:")) << e.substr(0, 300);
    for (char c : e) EXPECT_TRUE(c == '\n' || c == '\t' || (unsigned char)c >= 0x20) << int(c);

    TinyScene u("longtoken");
    u.obj += "v " + std::string(10000000, '1') + " 0 0\n";
    e = u.errors();
    EXPECT_TRUE(contains(e, "t.obj:23:3: error: '111")) << e.substr(0, 300);
    EXPECT_LT(e.size(), 4000u);
    EXPECT_TRUE(contains(e, "more bytes)")) << e.substr(0, 300);
}
