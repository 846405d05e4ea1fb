// Perturbed shading normals (scene/normal_perturbation.h, Mitsuba 3's normalmap and bumpmap):
// the frame a texel or a height gradient defines, the texture's luminance gradient, the
// normals Scene::intersect returns, the BSDF's light-side rule and shadow-terminator factor in
// both transport directions, and the Mitsuba loader's reading and errors. The rendered check
// against Mitsuba 3 itself is normalmap.xml in mitsuba_handwritten_test.cpp.
#include "scene/normal_perturbation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "core/error.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "scene/bsdf.h"
#include "scene/io/mitsuba_loader.h"
#include "scene/scene.h"
#include "scene/shapes.h"

using namespace ub;

namespace {

void expectNear(const Vec3& a, const Vec3& b, float tol, const char* what) {
    EXPECT_NEAR(a.x, b.x, tol) << what;
    EXPECT_NEAR(a.y, b.y, tol) << what;
    EXPECT_NEAR(a.z, b.z, tol) << what;
}

Texture constantBitmap(const Rgb& c) {
    Texture t;
    t.type = TextureType::Bitmap;
    t.name = "texel";
    auto img = std::make_shared<Image>(1, 1);
    img->at(0, 0) = c;
    t.image = img;
    return t;
}

bool contains(const std::string& s, const std::string& part) {
    return s.find(part) != std::string::npos;
}

}  // namespace

// ---- the frame ----

// A flat texel (0.5, 0.5, 1) is the tangent-space normal (0, 0, 1): the unperturbed normal,
// whatever the tangent.
TEST(NormalPerturbation, FlatTexelGivesTheUnperturbedNormal) {
    const Vec3 normals[] = {{0, 0, 1}, normalize(Vec3(0.3f, -0.5f, 0.8f)), {-1, 0, 0}};
    const Vec3 tangents[] = {{1, 0, 0}, {0.2f, 3.0f, -1.0f}, {0, 0, 0}};
    for (const Vec3& n : normals)
        for (const Vec3& dpdu : tangents)
            expectNear(normalMapNormal(Rgb(0.5f, 0.5f, 1.0f), n, dpdu), n, 1e-6f, "flat texel");
}

// The texel's x axis is dp/du made orthogonal to n, its y axis n x s (Mitsuba's shading frame).
TEST(NormalPerturbation, TexelAxesFollowTheUvTangent) {
    const Vec3 n(0, 0, 1), dpdu(2.0f, 0.0f, 0.5f);  // the normal component is dropped
    expectNear(shadingTangent(n, dpdu), Vec3(1, 0, 0), 1e-6f, "s");
    expectNear(normalMapNormal(Rgb(1.0f, 0.5f, 0.5f), n, dpdu), Vec3(1, 0, 0), 1e-6f, "+x");
    expectNear(normalMapNormal(Rgb(0.5f, 1.0f, 0.5f), n, dpdu), Vec3(0, 1, 0), 1e-6f, "+y");
    expectNear(normalMapNormal(Rgb(0.5f, 0.0f, 0.5f), n, dpdu), Vec3(0, -1, 0), 1e-6f, "-y");
    // 45 degrees towards +s.
    expectNear(normalMapNormal(Rgb(1.0f, 0.5f, 1.0f), n, dpdu), normalize(Vec3(1, 0, 1)), 1e-6f,
               "tilt");
    // A zero tangent falls back to the basis of Frame(n).
    expectNear(shadingTangent(n, Vec3(0, 0, 3)), Frame(n).s, 1e-6f, "degenerate dpdu");
    // A zero tangent-space normal (texel 0.5 grey) keeps n.
    expectNear(normalMapNormal(Rgb(0.5f), n, dpdu), n, 0.0f, "zero texel");
}

// Bump map on the plane z = 0 with p = (u, v, h(u, v)): n' = normalize(-h_u, -h_v, 1); a
// smooth-shaded normal has its tangent components replaced (Mitsuba's convention), so a zero
// gradient gives the shading normal back; left-handed tangents are flipped to ng's side.
TEST(NormalPerturbation, BumpMapNormalIsTheHeightFieldNormal) {
    const Vec3 z(0, 0, 1);
    expectNear(bumpMapNormal(Vec2(0.5f, -0.25f), z, Vec3(1, 0, 0), Vec3(0, 1, 0), z),
               normalize(Vec3(-0.5f, 0.25f, 1.0f)), 1e-6f, "slope");
    expectNear(bumpMapNormal(Vec2(0, 0), z, Vec3(2, 0, 0), Vec3(0, 3, 0), z), z, 1e-6f, "flat");
    const Vec3 ns = normalize(Vec3(0.2f, 0.1f, 1.0f));
    expectNear(bumpMapNormal(Vec2(0, 0), ns, Vec3(1, 0, 0), Vec3(0, 1, 0), z), ns, 1e-6f,
               "smooth shaded, flat");
    expectNear(bumpMapNormal(Vec2(0.5f, 0.0f), z, Vec3(0, 1, 0), Vec3(1, 0, 0), z),
               normalize(Vec3(0.0f, -0.5f, 1.0f)), 1e-6f, "left-handed tangents");
}

// Estevez et al.'s a^2 = min(tan^2 / 8, 1): 0 for the unperturbed normal.
TEST(NormalPerturbation, ShadowTerminatorAlpha) {
    const Vec3 z(0, 0, 1);
    EXPECT_EQ(shadowTerminatorAlpha2(z, z), 0.0f);
    EXPECT_NEAR(shadowTerminatorAlpha2(normalize(Vec3(1, 0, 1)), z), 0.125f, 1e-6f);
    EXPECT_EQ(shadowTerminatorAlpha2(normalize(Vec3(10, 0, 1)), z), 1.0f);
}

// ---- the texture gradient ----

// Within a bilinear cell the luminance is bilinear in uv, so central differences of eval()
// match luminanceGradient (including to_uv's scale and a mirrored axis); nearest gives 0.
TEST(NormalPerturbation, LuminanceGradientMatchesFiniteDifferences) {
    Texture t;
    t.type = TextureType::Bitmap;
    t.name = "heights";
    auto img = std::make_shared<Image>(4, 3);
    Rng rng(7, 1);
    for (Rgb& p : img->pixels) p = Rgb(rng.uniform(), rng.uniform(), rng.uniform());
    t.image = img;
    t.toUv = UvTransform::scale(2.0f, -3.0f);
    t.toUv.m[0][2] = 0.1f;
    const float h = 1e-4f;
    for (int i = 0; i < 50; ++i) {
        const Vec2 uv(rng.uniform(), rng.uniform());
        const Vec2 g = t.luminanceGradient(uv);
        const float du =
            (luminance(t.eval(Vec2(uv.x + h, uv.y))) - luminance(t.eval(Vec2(uv.x - h, uv.y)))) /
            (2 * h);
        const float dv =
            (luminance(t.eval(Vec2(uv.x, uv.y + h))) - luminance(t.eval(Vec2(uv.x, uv.y - h)))) /
            (2 * h);
        // Skip points within h of a cell border (the derivative jumps there).
        const float px = (2.0f * uv.x + 0.1f) * 4 - 0.5f, py = (-3.0f * uv.y) * 3 - 0.5f;
        const float ex = std::fabs(px - std::round(px)), ey = std::fabs(py - std::round(py));
        if (ex < 0.01f || ey < 0.01f) continue;
        EXPECT_NEAR(g.x, du, 0.02f * (1 + std::fabs(du))) << "u at " << uv.x << ", " << uv.y;
        EXPECT_NEAR(g.y, dv, 0.02f * (1 + std::fabs(dv))) << "v at " << uv.x << ", " << uv.y;
    }
    t.filter = TextureFilter::Nearest;
    EXPECT_EQ(t.luminanceGradient(Vec2(0.3f, 0.4f)).x, 0.0f);
}

// ---- Scene::intersect ----

// The hit's shading normal is the perturbed one, in the rectangle's uv frame (dp/du = +x) and
// the sphere's (dp/du along +phi); a flat texel leaves the geometric normal.
TEST(NormalPerturbation, IntersectReturnsThePerturbedNormal) {
    Scene scene;
    const int tilted = scene.addTexture(constantBitmap(Rgb(0.75f, 0.5f, 0.9f)));
    const int flat = scene.addTexture(constantBitmap(Rgb(0.5f, 0.5f, 1.0f)));
    Material m;
    m.perturbation = NormalPerturbation::kNormalMap;
    m.perturbationTexture = tilted;
    const int mTilted = scene.addMaterial(m);
    m.perturbationTexture = flat;
    const int mFlat = scene.addMaterial(m);
    scene.addMesh(makeRectangle(), mTilted, -1, "rect");
    scene.addSphere(Vec3(0, 0, -10), 1.0f, mTilted, -1, "sphere");
    TriangleMesh far = makeRectangle();
    for (Vec3& p : far.positions) p = p + Vec3(10, 0, 0);
    scene.addMesh(far, mFlat, -1, "flat");
    scene.commit();
    Ray ray;
    ray.org = Vec3(0.3f, 0.2f, 5.0f);
    ray.dir = Vec3(0, 0, -1);
    Hit hit;
    ASSERT_TRUE(scene.intersect(ray, &hit));
    expectNear(hit.shadingNormal, normalize(Vec3(0.5f, 0.0f, 0.8f)), 1e-5f, "rectangle");
    // Sphere point (1, 0, 0) about its centre: n = +x, dp/du along +y, dp/dv along -z.
    ray.org = Vec3(5, 0, -10);
    ray.dir = Vec3(-1, 0, 0);
    ASSERT_TRUE(scene.intersect(ray, &hit));
    expectNear(hit.shadingNormal, normalize(Vec3(0.8f, 0.5f, 0.0f)), 1e-5f, "sphere");
    ray.org = Vec3(10.2f, -0.4f, 5.0f);
    ray.dir = Vec3(0, 0, -1);
    ASSERT_TRUE(scene.intersect(ray, &hit));
    expectNear(hit.shadingNormal, hit.geoNormal, 1e-6f, "flat texel");
}

// ---- the BSDF ----

namespace {

/// A Lambertian with a perturbation flag (the Bsdf reads only the flag and the terminator).
Material perturbedDiffuse(bool terminator) {
    Material m;
    m.type = MaterialType::Diffuse;
    m.diffuse = Rgb(0.8f);
    m.twoSided = false;
    m.perturbation = NormalPerturbation::kNormalMap;
    m.shadowTerminator = terminator;
    return m;
}

}  // namespace

// f(camera side, light side) is the same function in both transport directions: on a light
// subpath the adjoint carries Veach's shading-normal factor (bsdf.h) and the light-side rule
// and terminator apply to dirFix; where the light-side direction is below the perturbed normal
// but above the surface (or the reverse) f and both pdfs are 0.
TEST(NormalPerturbation, BsdfIsTheSameFunctionForBothTransportDirections) {
    const Vec3 ng(0, 0, 1), ns = normalize(Vec3(0.5f, 0.0f, 0.8f));
    for (bool terminator : {false, true}) {
        const Material m = perturbedDiffuse(terminator);
        Rng rng(3, terminator ? 2 : 1);
        int zeros = 0, compared = 0;
        for (int i = 0; i < 2000; ++i) {
            const Vec3 wc = sampleUniformSphere(rng.uniform2());
            const Vec3 wl = sampleUniformSphere(rng.uniform2());
            if (dot(wc, ns) <= 0.05f || dot(wc, ng) <= 0.05f) continue;  // seen from the front
            Bsdf cam, light;
            cam.setGeometricGuard(false);  // as in Mitsuba scenes (ShadingNormals::kShadingOnly)
            light.setGeometricGuard(false);
            ASSERT_TRUE(cam.setup(m, wc, ng, ns, false));
            float pdfCam = 0, revCam = 0;
            const Rgb fc = cam.evaluate(wl, nullptr, &pdfCam, &revCam);
            const bool lightSideOk = dot(wl, ns) * dot(wl, ng) > 0.0f;
            if (std::fabs(dot(wl, ns)) < 0.05f || std::fabs(dot(wl, ng)) < 0.05f) continue;
            if (!lightSideOk || dot(wl, ns) < 0.0f) {
                EXPECT_EQ(fc.x, 0.0f);
                EXPECT_EQ(pdfCam, 0.0f);
                EXPECT_EQ(revCam, 0.0f);
                ++zeros;
                if (!lightSideOk) {
                    light.setup(m, wl, ng, ns, true);
                    EXPECT_EQ(light.evaluate(wc, nullptr, nullptr, nullptr).x, 0.0f);
                    Vec3 dir;
                    float pdf;
                    EXPECT_EQ(light.sample(Vec3(0.3f, 0.6f, 0.2f), &dir, &pdf, nullptr, nullptr).x,
                              0.0f);
                }
                continue;
            }
            ASSERT_TRUE(light.setup(m, wl, ng, ns, true));
            float pdfLight = 0, revLight = 0;
            const Rgb fl = light.evaluate(wc, nullptr, &pdfLight, &revLight);
            const float adjoint = std::fabs(dot(wl, ns)) * std::fabs(dot(wc, ng)) /
                                  (std::fabs(dot(wl, ng)) * std::fabs(dot(wc, ns)));
            EXPECT_NEAR(fl.x, fc.x * adjoint, 1e-5f * (1 + fc.x * adjoint));
            EXPECT_NEAR(pdfLight, revCam, 1e-5f * (1 + revCam));
            EXPECT_NEAR(revLight, pdfCam, 1e-5f * (1 + pdfCam));
            if (terminator) {
                const float c = dot(wl, ng);
                const float a2 = shadowTerminatorAlpha2(ns, ng);
                const float g = 2.0f / (1.0f + std::sqrt(1.0f + a2 * (1 - c * c) / (c * c)));
                EXPECT_NEAR(fc.x, 0.8f / kPi * g, 1e-5f);
            } else {
                EXPECT_NEAR(fc.x, 0.8f / kPi, 1e-6f);
            }
            ++compared;
        }
        EXPECT_GT(zeros, 50);
        EXPECT_GT(compared, 200);
    }
}

// Sampling agrees with evaluate() and the albedo stays below the Lambertian's (the light-side
// rule and the terminator only remove energy).
TEST(NormalPerturbation, SamplingMatchesEvaluationAndConservesEnergy) {
    const Vec3 ng(0, 0, 1), ns = normalize(Vec3(0.5f, 0.0f, 0.8f));
    const Material m = perturbedDiffuse(true);
    const Vec3 fixes[] = {normalize(Vec3(0.1f, 0.2f, 1.0f)), normalize(Vec3(-0.6f, 0.0f, 0.5f)),
                          normalize(Vec3(0.9f, 0.1f, 0.3f))};
    for (const Vec3& fix : fixes) {
        Bsdf b;
        b.setGeometricGuard(false);
        ASSERT_TRUE(b.setup(m, fix, ng, ns, false));
        Rng rng(11, 5);
        double sum = 0;
        const int n = 20000;
        for (int i = 0; i < n; ++i) {
            Vec3 dir;
            float pdf = 0, cosGen = 0;
            const Rgb f = b.sample(Vec3(rng.uniform(), rng.uniform(), rng.uniform()), &dir, &pdf,
                                   &cosGen, nullptr);
            if (!(pdf > 0.0f)) continue;
            float pdfEval = 0, cosEval = 0;
            const Rgb fe = b.evaluate(dir, &cosEval, &pdfEval, nullptr);
            EXPECT_NEAR(f.x, fe.x, 1e-6f);
            EXPECT_NEAR(pdf, pdfEval, 1e-5f * pdf);
            EXPECT_GT(dot(dir, ng), 0.0f);  // the light-side rule
            sum += f.x * cosGen / pdf;
        }
        EXPECT_LT(sum / n, 0.8 + 0.01);
        EXPECT_GT(sum / n, 0.4);
    }
}

// ---- the Mitsuba loader ----

namespace {

const std::string kDataDir = std::string(UNIBEAM_TEST_DATA_DIR) + "/mitsuba";

std::string sceneWith(const std::string& bsdf) {
    return "<scene version=\"3.0.0\">\n"
           "<sensor type=\"perspective\"><film type=\"hdrfilm\"><integer name=\"width\" "
           "value=\"8\"/><integer name=\"height\" value=\"8\"/></film></sensor>\n"
           "<emitter type=\"constant\"/>\n"
           "<shape type=\"rectangle\">\n" +
           bsdf + "</shape>\n</scene>\n";
}

std::string errorsOf(const std::string& text) {
    try {
        loadMitsubaSceneFromString(text, "scene.xml", kDataDir, {});
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

const char* kNormalTexture =
    "<texture name=\"normalmap\" type=\"bitmap\"><boolean name=\"raw\" value=\"true\"/>"
    "<string name=\"filename\" value=\"textures/normalmap.png\"/></texture>";
const char* kHeightTexture =
    "<texture type=\"bitmap\"><boolean name=\"raw\" value=\"true\"/>"
    "<string name=\"filename\" value=\"textures/heights.png\"/></texture>";

}  // namespace

TEST(NormalPerturbation, LoaderReadsBothWrappers) {
    std::unique_ptr<Scene> s = loadMitsubaSceneFromString(
        sceneWith(std::string("<bsdf type=\"normalmap\" id=\"nm\">") + kNormalTexture +
                  "<bsdf type=\"roughplastic\"/></bsdf>\n"),
        "scene.xml", kDataDir, {});
    ASSERT_GE(s->materials.size(), 2u);  // the nested roughplastic and the wrapper
    const Material& nm = s->materials.back();
    EXPECT_EQ(nm.name, "nm");
    EXPECT_EQ(nm.type, MaterialType::RoughPlastic);
    EXPECT_EQ(nm.perturbation, NormalPerturbation::kNormalMap);
    EXPECT_TRUE(nm.shadowTerminator);
    ASSERT_GE(nm.perturbationTexture, 0);
    // raw: the texel is not sRGB-decoded (a flat-ish normal map is near (0.5, 0.5, 1)).
    EXPECT_GT(s->textures[size_t(nm.perturbationTexture)].mean().x, 0.45f);

    s = loadMitsubaSceneFromString(
        sceneWith(std::string("<bsdf type=\"twosided\"><bsdf type=\"bumpmap\">") +
                  "<float name=\"scale\" value=\"0.25\"/>"
                  "<boolean name=\"use_shadowing_function\" value=\"false\"/>" +
                  kHeightTexture + "<bsdf type=\"diffuse\"/></bsdf></bsdf>\n"),
        "scene.xml", kDataDir, {});
    const Material& bm = s->materials.back();
    EXPECT_EQ(bm.type, MaterialType::Diffuse);
    EXPECT_TRUE(bm.twoSided);
    EXPECT_EQ(bm.perturbation, NormalPerturbation::kBumpMap);
    EXPECT_FLOAT_EQ(bm.bumpScale, 0.25f);
    EXPECT_FALSE(bm.shadowTerminator);
}

// Bad input names the file and the position of the wrapper (or of the offending child); the
// command line exits with status 2 on these, as on every InputError.
TEST(NormalPerturbation, LoaderErrorsNameFileAndPosition) {
    std::string e =
        errorsOf(sceneWith("<bsdf type=\"normalmap\"><bsdf type=\"diffuse\"/></bsdf>\n"));
    EXPECT_TRUE(contains(e,
                         "scene.xml:5:1: error: <bsdf type=\"normalmap\">: needs a <texture "
                         "name=\"normalmap\">"))
        << e;
    e =
        errorsOf(sceneWith("<bsdf type=\"bumpmap\"><texture type=\"checkerboard\"/><bsdf "
                           "type=\"diffuse\"/></bsdf>\n"));
    EXPECT_TRUE(contains(e, "scene.xml:5:22: error:")) << e;
    EXPECT_TRUE(contains(e, "must be a 'bitmap' texture")) << e;
    e = errorsOf(sceneWith(std::string("<bsdf type=\"normalmap\">") + kNormalTexture +
                           "<bsdf type=\"diffuse\"/><bsdf type=\"diffuse\"/></bsdf>\n"));
    EXPECT_TRUE(contains(e, "scene.xml:5:1: error:")) << e;
    EXPECT_TRUE(contains(e, "expected exactly one nested <bsdf>, got 2")) << e;
    e = errorsOf(
        sceneWith(std::string("<bsdf type=\"bumpmap\"><bsdf type=\"diffuse\"/></bsdf>\n")));
    EXPECT_TRUE(contains(e, "expected exactly one nested <texture>")) << e;
    e = errorsOf(sceneWith(std::string("<bsdf type=\"normalmap\">") + kNormalTexture +
                           "<bsdf type=\"normalmap\">" + kNormalTexture +
                           "<bsdf type=\"diffuse\"/></bsdf></bsdf>\n"));
    EXPECT_TRUE(contains(e, "cannot wrap a 'normalmap' BSDF")) << e;
    e =
        errorsOf(sceneWith("<bsdf type=\"normalmap\"><texture name=\"normalmap\" type=\"bitmap\">"
                           "<string name=\"filename\" value=\"textures/missing.png\"/></texture>"
                           "<bsdf type=\"diffuse\"/></bsdf>\n"));
    EXPECT_TRUE(contains(e, "scene.xml:5:")) << e;
    EXPECT_TRUE(contains(e, "missing.png")) << e;
}
