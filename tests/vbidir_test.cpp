// Bidirectional volumetric integrators `vlt` and `vbpt` (render/vcm.h, media):
//  * VolBidir.VolumetricFurnaceIsLeEverywhere: closed emitter filled with a non-absorbing
//    medium, exact answer Le;
//  * agreement with `vpt` on every bundled media scene (vbpt) and where light tracing can
//    reach (vlt);
//  * determinism for any thread count, rejections, equality with lt/bpt without media.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "core/error.h"
#include "render/integrator.h"
#include "render/vcm.h"
#include "scene/io/json_loader.h"
#include "tests/support/render_stats.h"
#include "tests/support/volume_scenes.h"

using namespace ub;
using namespace ub::test;

namespace {

// Analytic answer (the argument of tests/vpt_test.cpp): inside the box the medium does not
// absorb and every wall point emits Le and absorbs everything, so L(x, w) = Le for every
// point and direction. Truncation at maxPathLength = L segments: every flight leaves the
// box without scattering with probability >= exp(-2 sqrt(3) sigma_s), so the truncated
// answer is Le (1 - eps) with eps <= (1 - exp(-2 sqrt(3) sigma_s))^L; for sigma_s <= 1 and
// L = 200, eps <= (1 - 0.0313)^200 < 0.0018 -- too large for a 0.3% test, so L = 1000:
// eps < 1e-13. Light tracing reaches the same paths: the walls are black, so every path
// other than a wall seen directly ends at medium vertices, which vlt connects to the camera.
void checkFurnace(const char* algorithm, float sigmaS, float g, MisHeuristic heuristic,
                  int iterations, float bubbleRadius, int res = 16) {
    const Rgb le(1.0f, 2.0f, 0.5f);
    auto scene =
        volumeFurnace(Medium::homogeneous(Rgb(0.0f), Rgb(sigmaS), g), le, res, bubbleRadius);
    RenderOptions opt;
    opt.algorithm = algorithm;
    opt.maxPathLength = 1000;
    opt.seed = 17;
    opt.heuristic = heuristic;
    auto integrator = makeIntegrator(*scene, opt);
    BlockStats s = renderBlockStats(*integrator, iterations, 4);
    // z-test of the image mean at 5 standard errors of the mean of i.i.d. iteration means;
    // the standard error must also be below 1% of Le, so that a noisy estimator cannot pass
    // through a wide bound (a 1% bias then fails).
    for (int c = 0; c < 3; ++c) {
        const double m = s.imageMean(c), se = s.imageStdErr(c);
        std::printf(
            "[ vbidir   ] furnace %s sigma_s %.2f g %.1f: channel %d mean %.5f (Le %.2f), "
            "stderr %.5f, z %.2f\n",
            algorithm, sigmaS, g, c, m, le[c], se, (m - le[c]) / se);
        EXPECT_NEAR(m, le[c], 5.0 * se + 1e-6)
            << algorithm << " sigma_s " << sigmaS << " g " << g << " channel " << c;
        EXPECT_LT(se, 0.01 * le[c]) << algorithm;
    }
}

}  // namespace

TEST(VolBidir, VolumetricFurnaceIsLeEverywhere) {
    // vbpt: camera in the medium, and in a vacuum bubble (nested imaginary boundaries).
    for (float sigmaS : {0.25f, 1.0f})
        for (float g : {0.0f, 0.8f}) {
            checkFurnace("vbpt", sigmaS, g, MisHeuristic::Power, 24, 0.0f);
            checkFurnace("vbpt", sigmaS, g, MisHeuristic::Power, 24, 0.3f);
        }
    checkFurnace("vbpt", 1.0f, -0.5f, MisHeuristic::Balance, 24, 0.0f);
    // vlt: only with the bubble (light tracing in a medium around the camera has infinite
    // variance: its 1/d^2 is not square-integrable over the volume near the camera), at
    // 32x32 (1024 light subpaths per iteration). Strongly forward-scattering media
    // (g = 0.8) need ~5x more samples for the 1% standard error; vbpt covers them.
    checkFurnace("vlt", 0.25f, 0.0f, MisHeuristic::Power, 192, 0.3f, 32);
    checkFurnace("vlt", 1.0f, 0.5f, MisHeuristic::Power, 192, 0.3f, 32);
}

// ---- Agreement with vpt on the bundled media scenes ---------------------------------
//
// Each scene at 32x32, 4x4 blocks of 8x8 pixels, 3 channels: 48 z-tests of block means
// plus 3 of the image mean; standard errors from the spread of the per-iteration block
// means of both renders (iterations are independent; tests/support/render_stats.h).
// Blocks: family-wise level 1e-3 with the Sidak correction, per test
// alpha' = 1 - (1 - 1e-3)^(1/48) = 2.1e-5, |z| < 4.25. Image mean: |z| < 3.9 per channel
// (family-wise 3e-4 over 3 channels). Bounds as in tests/bidir_test.cpp.
//
// glass-medium-caustics is rendered with its smooth glass replaced by rough glass
// (GGX alpha 0.3, same IOR): with the smooth sphere the light reaches the juice, and the
// caustic under the sphere, only through delta refractions, which vpt samples only by
// hitting the small emitting sphere through the glass, so within seconds its estimate
// misses most of the caustic while its sample spread looks small (vbpt finds the
// caustic: its image mean is ~20% higher at 48 iterations). With rough glass vpt's
// sampling reaches the light through the glass and the comparison is meaningful.

namespace {

struct MediaSceneCase {
    const char* file;
    int vptIterations, iterations;  ///< vpt (reference) and the tested algorithm
    bool roughGlass = false;        ///< smooth dielectrics become rough (see above)
    bool withoutSpheres = false;    ///< drop sphere shapes (light tracing and mirrors)
};

std::unique_ptr<Scene> loadMediaScene(const MediaSceneCase& c, int res) {
    const std::string dir = std::string(UNIBEAM_SOURCE_DIR) + "/scenes";
    std::ifstream in(dir + "/" + c.file);
    EXPECT_TRUE(in.good()) << "missing bundled scene " << c.file;
    nlohmann::json j = nlohmann::json::parse(in);
    j["camera"]["resolution"] = {res, res};
    if (c.roughGlass)
        for (auto& m : j["materials"])
            if (m.value("type", "") == "dielectric") {
                m["type"] = "rough_dielectric";
                m["alpha"] = 0.3;
            }
    if (c.withoutSpheres) {
        nlohmann::json shapes = nlohmann::json::array();
        for (const auto& s : j["shapes"])
            if (s.value("type", "") != "sphere") shapes.push_back(s);
        j["shapes"] = shapes;
    }
    return loadJsonSceneFromString(j.dump(), c.file, dir);
}

void checkAgreesWithVpt(const char* algorithm, const MediaSceneCase& c) {
    const int res = 32, block = 8;
    auto scene = loadMediaScene(c, res);
    ASSERT_TRUE(scene->hasMedia()) << c.file;
    RenderOptions opt;
    opt.algorithm = "vpt";
    opt.maxPathLength = scene->settings.maxPathLength;
    opt.seed = 21;
    auto vpt = makeIntegrator(*scene, opt);
    BlockStats ref = renderBlockStats(*vpt, c.vptIterations, block);
    opt.algorithm = algorithm;
    opt.seed = 22;  // independent of the reference
    auto integrator = makeIntegrator(*scene, opt);
    BlockStats s = renderBlockStats(*integrator, c.iterations, block);
    Agreement g = compare(s, ref);
    std::printf("[ vbidir   ] %s vs vpt on %s%s%s %dx%d: %s\n", algorithm, c.file,
                c.roughGlass ? " (rough glass)" : "", c.withoutSpheres ? " (no spheres)" : "", res,
                res, g.report.c_str());
    EXPECT_GT(g.minBlockP, sidakLevel(1e-3, g.tests))
        << algorithm << " on " << c.file << ": " << g.report;
    for (int ch = 0; ch < 3; ++ch)
        EXPECT_LT(std::fabs(g.meanZ[ch]), 3.9)
            << algorithm << " on " << c.file << " channel " << ch;
}

}  // namespace

TEST(VolBidir, VbptAgreesWithVptOnBundledMediaScenes) {
    const MediaSceneCase cases[] = {
        {"cornell-fog.json", 96, 48},
        {"cornell-smoke.json", 80, 40},
        {"glass-medium-caustics.json", 512, 64, /*roughGlass=*/true},
        {"forward-scattering.json", 128, 64},
        {"medium-specular-light.json", 128, 64},
    };
    for (const MediaSceneCase& c : cases) checkAgreesWithVpt("vbpt", c);
}

// Light tracing cannot sample paths whose first camera vertex is specular: cornell-fog
// without its mirror and glass spheres, cornell-smoke and forward-scattering (no specular
// surfaces). The camera is outside the media in all three, which keeps the 1/d^2 of the
// camera connection bounded.
TEST(VolBidir, VltAgreesWithVptWhereLightTracingReaches) {
    const MediaSceneCase cases[] = {
        {"cornell-fog.json", 96, 96, false, /*withoutSpheres=*/true},
        {"cornell-smoke.json", 80, 80},
        {"forward-scattering.json", 128, 128},
    };
    for (const MediaSceneCase& c : cases) checkAgreesWithVpt("vlt", c);
}

// Lights inside a medium: light subpaths start in the media at the light (the engine's
// per-light start stack, render/vcm.cpp). A point light and a spot light inside a fog box
// (imaginary boundary) above a diffuse floor, the camera outside; each light sits in a small
// vacuum bubble (nested imaginary sphere, higher priority), so its subpaths start with a
// three-entry stack and enter the fog when they leave the bubble. (Without the bubbles,
// NEE from medium vertices next to a delta light has a 1/d^2 factor whose variance over
// the volume around the light is infinite: vpt's estimated standard errors are then
// unreliable and the z-test is not valid.) Same bounds as above (48 block tests at
// family-wise 1e-3, image mean |z| < 3.9).
TEST(VolBidir, LightsInsideAMediumAgreeWithVpt) {
    const char* json = R"json({
      "camera": {"position": [0, 1, 4], "target": [0, 0.3, 0], "fov": 45, "resolution": [32, 32]},
      "settings": {"max_path_length": 8},
      "materials": {"white": {"type": "diffuse", "reflectance": 0.7}},
      "media": {"fog": {"type": "homogeneous", "sigma_s": [0.6, 0.8, 1.0], "sigma_a": 0.05,
                        "g": 0.4}},
      "shapes": [
        {"type": "rectangle", "material": "white",
         "transform": {"scale": 2, "rotate": {"axis": [1, 0, 0], "angle": -90}}},
        {"type": "cube", "name": "fog box", "interior_medium": "fog", "imaginary": true,
         "transform": {"scale": [1, 0.8, 1], "translate": [0, 0.81, 0]}},
        {"type": "sphere", "name": "bubble 1", "center": [-0.4, 0.9, 0.2], "radius": 0.2,
         "interior_medium": null, "priority": 1, "imaginary": true},
        {"type": "sphere", "name": "bubble 2", "center": [0.5, 1.4, 0], "radius": 0.2,
         "interior_medium": null, "priority": 1, "imaginary": true}
      ],
      "lights": [
        {"type": "point", "position": [-0.4, 0.9, 0.2], "intensity": 1.5},
        {"type": "spot", "position": [0.5, 1.4, 0], "target": [0.3, 0, 0.2], "intensity": 4,
         "cutoff_angle": 35, "beam_width": 25}
      ]
    })json";
    auto scene = loadJsonSceneFromString(json, "lights-in-fog.json", "");
    ASSERT_TRUE(scene->hasMedia());
    ASSERT_EQ(scene->cameraMediumStack.mediumId(), -1);
    RenderOptions opt;
    opt.algorithm = "vpt";
    opt.maxPathLength = 8;
    opt.seed = 31;
    auto vpt = makeIntegrator(*scene, opt);
    BlockStats ref = renderBlockStats(*vpt, 128, 8);
    for (const char* algorithm : {"vbpt", "vlt"}) {
        opt.algorithm = algorithm;
        opt.seed = 32;
        auto integrator = makeIntegrator(*scene, opt);
        BlockStats s = renderBlockStats(*integrator, 64, 8);
        Agreement g = compare(s, ref);
        std::printf("[ vbidir   ] %s vs vpt, point and spot light in fog 32x32: %s\n", algorithm,
                    g.report.c_str());
        EXPECT_GT(g.minBlockP, sidakLevel(1e-3, g.tests)) << algorithm << ": " << g.report;
        for (int ch = 0; ch < 3; ++ch) EXPECT_LT(std::fabs(g.meanZ[ch]), 3.9) << algorithm;
    }
}

// ---- Determinism, no-media equality, rejections ---------------------------------------

// Same seed, same image, whatever the number of threads (light-tracing splats are
// resolved in a fixed order, render/film.h).
TEST(VolBidir, SameSeedSameImageForAnyThreadCount) {
    MediaSceneCase c{"cornell-smoke.json", 0, 0};
    auto scene = loadMediaScene(c, 16);
    for (const char* algorithm : {"vbpt", "vlt"}) {
        RenderOptions opt;
        opt.algorithm = algorithm;
        opt.seed = 9;
        Image a, b;
        {
            tbb::task_arena one(1);
            one.execute([&] { makeIntegrator(*scene, opt)->renderIteration(2, a); });
        }
        makeIntegrator(*scene, opt)->renderIteration(2, b);
        ASSERT_EQ(a.pixels.size(), b.pixels.size());
        for (size_t i = 0; i < a.pixels.size(); ++i)
            for (int ch = 0; ch < 3; ++ch)
                ASSERT_EQ(a.pixels[i][ch], b.pixels[i][ch]) << algorithm << " pixel " << i;
    }
}

// Without media vlt and vbpt run exactly lt and bpt (no free-flight sampling, the same
// random numbers in the same order): bit-identical images.
TEST(VolBidir, WithoutMediaVltIsLtAndVbptIsBpt) {
    MediaSceneCase c{"cornell-small-light.json", 0, 0};
    const std::string dir = std::string(UNIBEAM_SOURCE_DIR) + "/scenes";
    auto scene = loadMediaScene(c, 16);
    ASSERT_FALSE(scene->hasMedia());
    for (auto pair : {std::make_pair("lt", "vlt"), std::make_pair("bpt", "vbpt")}) {
        RenderOptions opt;
        opt.seed = 4;
        opt.algorithm = pair.first;
        Image a, b;
        makeIntegrator(*scene, opt)->renderIteration(1, a);
        opt.algorithm = pair.second;
        makeIntegrator(*scene, opt)->renderIteration(1, b);
        double sum = 0;
        for (size_t i = 0; i < a.pixels.size(); ++i)
            for (int ch = 0; ch < 3; ++ch) {
                ASSERT_EQ(a.pixels[i][ch], b.pixels[i][ch]) << pair.second << " pixel " << i;
                sum += a.pixels[i][ch];
            }
        EXPECT_GT(sum, 0.0);
    }
}

TEST(VolBidir, RejectsWhatItCannotRender) {
    // Surface-only algorithms refuse media (the registry, render/integrator.cpp); vcm is
    // upbp:bpt+surf there (tests/upbp_test.cpp).
    MediaSceneCase fog{"cornell-fog.json", 0, 0};
    auto scene = loadMediaScene(fog, 8);
    for (const char* surfaceOnly : {"lt", "bpt", "bpm"}) {
        RenderOptions opt;
        opt.algorithm = surfaceOnly;
        try {
            makeIntegrator(*scene, opt);
            ADD_FAILURE() << surfaceOnly << " accepted a scene with media";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find("participating media"), std::string::npos)
                << e.what();
            EXPECT_NE(std::string(e.what()).find("vbpt"), std::string::npos) << e.what();
        }
    }
    // vlt cannot find medium emission.
    {
        auto emitting =
            volumeFurnace(Medium::homogeneous(Rgb(0.5f), Rgb(0.5f), 0.0f, Rgb(1.0f)), Rgb(1.0f), 8);
        RenderOptions opt;
        opt.algorithm = "vlt";
        try {
            makeIntegrator(*emitting, opt);
            ADD_FAILURE() << "vlt accepted an emitting medium";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find("emits light"), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find("furnace medium"), std::string::npos);
        }
        opt.algorithm = "vbpt";
        EXPECT_NO_THROW(makeIntegrator(*emitting, opt));
    }
    // Lights at infinity cannot start subpaths in a global medium.
    {
        const char* json = R"json({
          "camera": {"position": [0, 0, 3], "target": [0, 0, 0], "fov": 40, "resolution": [8, 8]},
          "materials": {"white": {"type": "diffuse", "reflectance": 0.5}},
          "media": {"air": {"type": "homogeneous", "sigma_s": 0.1, "sigma_a": 0.01}},
          "medium": "air",
          "shapes": [{"type": "sphere", "material": "white", "center": [0, 0, 0], "radius": 0.5}],
          "lights": [{"type": "directional", "name": "sun", "direction": [0, -1, 0],
                      "irradiance": 2}]
        })json";
        auto global = loadJsonSceneFromString(json, "global.json", "");
        RenderOptions opt;
        opt.algorithm = "vbpt";
        try {
            makeIntegrator(*global, opt);
            ADD_FAILURE() << "vbpt accepted a light at infinity in a global medium";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find("'sun' is at infinity"), std::string::npos)
                << e.what();
        }
    }
}
