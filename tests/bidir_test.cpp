// The surface bidirectional family (render/vcm.h: lt, bpt, ppm, bpm, vcm):
//  * Bidir/CornellAgreesWithPt: each algorithm converges to pt's image of the bundled
//    Cornell box (glossy floor, mirror and glass spheres: caustics included), compared
//    on 8x8-pixel blocks and on the image mean (statistics in tests/support/render_stats.h);
//  * Bidir/FurnaceMatchesAnalytic: closed emitting diffuse box (pt's furnace), exact
//    radiance Le sum_k rho^k;
//  * determinism for any thread count, thin-lens rejection, radius schedule.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "core/error.h"
#include "render/vcm.h"
#include "scene/io/json_loader.h"
#include "scene/shapes.h"
#include "tests/support/expect_means.h"
#include "tests/support/render_stats.h"

using namespace ub;
using namespace ub::test;

namespace {

const char* const kAlgorithms[] = {"lt", "bpt", "ppm", "bpm", "vcm"};

/// A bundled scene at a small square resolution; withoutSpheres drops the mirror and glass
/// spheres (light tracing cannot sample paths whose first camera vertex is specular).
std::unique_ptr<Scene> loadCornell(const std::string& name, int res, bool withoutSpheres = false) {
    const std::string dir = std::string(UNIBEAM_SOURCE_DIR) + "/scenes";
    std::ifstream in(dir + "/" + name);
    EXPECT_TRUE(in.good()) << "missing bundled scene " << name;
    nlohmann::json j = nlohmann::json::parse(in);
    j["camera"]["resolution"] = {res, res};
    if (withoutSpheres) {
        nlohmann::json shapes = nlohmann::json::array();
        for (const auto& s : j["shapes"])
            if (s.value("type", "") != "sphere") shapes.push_back(s);
        j["shapes"] = shapes;
    }
    return loadJsonSceneFromString(j.dump(), name, dir);
}

/// pt's furnace (tests/pt_test.cpp): closed cube [-1,1]^3, inside diffuse with albedo rho,
/// emitting Le inwards everywhere; camera near the centre.
std::unique_ptr<Scene> furnaceScene(const Rgb& rho, const Rgb& le, int res) {
    auto scene = std::make_unique<Scene>();
    Material mat;
    mat.type = MaterialType::Diffuse;
    mat.diffuse = rho;
    int matId = scene->addMaterial(mat);
    TriangleMesh cube = makeCube();
    for (size_t t = 0; t < cube.indices.size(); t += 3)
        std::swap(cube.indices[t + 1], cube.indices[t + 2]);  // normals point inwards
    Light light;
    light.type = LightType::Area;
    light.radiance = le;
    for (uint32_t i : cube.indices) light.triangles.push_back(cube.positions[i]);
    int lightId = scene->addLight(light);
    scene->addMesh(cube, matId, lightId, "furnace");
    scene->camera.setup(Vec3(0.1f, -0.05f, 0.0f), Vec3(0.3f, 0.2f, 1.0f), Vec3(0, 1, 0), 70.0f, res,
                        res);
    scene->commit();
    return scene;
}

RenderOptions bidirOptions(const std::string& algorithm, uint64_t seed) {
    RenderOptions opt;
    opt.algorithm = algorithm;
    opt.seed = seed;
    opt.maxPathLength = 10;
    return opt;
}

class Bidir : public ::testing::TestWithParam<const char*> {};

}  // namespace

// ---- Agreement with pt on the Cornell box ------------------------------------------
//
// cornell-large-light (glossy Phong floor, mirror and glass spheres, so caustics through
// the glass sphere onto the glossy floor are part of the image) at 48x48; lt renders the
// same box without the two spheres, since light tracing cannot sample paths seen through a
// specular surface. 6x6 blocks of 8x8 pixels, 3 channels: 108 z-tests of block means, plus
// 3 of the image mean. Standard errors come from the spread of the per-iteration block
// means (iterations are independent), for both renders.
// Blocks: family-wise level 1e-3 with the Sidak correction, i.e. per test
// alpha' = 1 - (1 - 1e-3)^(1/108) = 9.3e-6, |z| < 4.43. Image mean: |z| < 3.9 per channel
// (family-wise 3e-4 over 3 channels).
// Merging (ppm, bpm, vcm) is consistent but biased. The radius is 0.03 of the scene radius
// (6.6 cm in the 2.6 m box; alpha = 0.75): the blur over the disk moves energy across
// block borders only within r of them, and the corner bands where the disk leaves the
// surface cover a few % of a block. Measured with 4x the samples used here (256 iterations
// against 1024 of pt), bpm and vcm stay within 2.2 standard errors on every block, so the
// bias is below the resolution of this test. Smaller radii are less biased but their
// per-iteration estimates become heavy-tailed (most queries find no photon), which makes
// the standard error estimated from 100 iterations unreliable.
TEST_P(Bidir, CornellAgreesWithPt) {
    const std::string algorithm = GetParam();
    const int res = 48, block = 8;
    const bool lt = algorithm == "lt";
    auto scene = loadCornell("cornell-large-light.json", res, /*withoutSpheres=*/lt);

    RenderOptions ptOpt = bidirOptions("pt", 11);
    auto pt = makeIntegrator(*scene, ptOpt);
    BlockStats ref = renderBlockStats(*pt, 192, block);

    RenderOptions opt = bidirOptions(algorithm, 12);
    opt.radius = 0.03f;
    opt.alpha = 0.75f;
    auto integrator = makeIntegrator(*scene, opt);
    const int iterations = lt ? 160 : (algorithm == "bpt" || algorithm == "vcm") ? 96 : 128;
    BlockStats s = renderBlockStats(*integrator, iterations, block);

    Agreement g = compare(s, ref);
    std::printf("[ bidir    ] %s vs pt on cornell-large-light%s %dx%d: %s\n", algorithm.c_str(),
                lt ? " without spheres" : "", res, res, g.report.c_str());
    const double zBlock = criticalZ(sidakLevel(1e-3, g.tests));
    EXPECT_GT(g.sidakMinP, 1e-3) << "block " << g.worstBlock << " channel " << g.worstChannel
                                 << ": " << s.mean(g.worstBlock, g.worstChannel) << " +- "
                                 << s.stdErr(g.worstBlock, g.worstChannel) << " vs pt "
                                 << ref.mean(g.worstBlock, g.worstChannel) << " +- "
                                 << ref.stdErr(g.worstBlock, g.worstChannel) << " (|z| bound "
                                 << zBlock << ")";
    for (int c = 0; c < 3; ++c) {
        EXPECT_LT(std::fabs(g.meanZ[c]), 3.9)
            << "channel " << c << ": image mean " << s.imageMean(c) << " +- " << s.imageStdErr(c)
            << " vs pt " << ref.imageMean(c) << " +- " << ref.imageStdErr(c);
        // The test must resolve a 5% error of the mean: both standard errors below 1.25%.
        EXPECT_LT(s.imageStdErr(c), 0.0125 * ref.imageMean(c));
        EXPECT_LT(ref.imageStdErr(c), 0.0125 * ref.imageMean(c));
    }
}

// ---- White furnace -------------------------------------------------------------------
//
// Every vertex sees emission Le and reflects with albedo rho, so a path of k segments
// carries Le rho^(k-1): L = Le sum_{k=0}^{maxLength-1} rho^k exactly. Image mean per
// channel within 4 standard errors (over 128, or 256 for ppm, independent iterations; two-sided
// 6e-5 each) plus, for merging, a bound on the kernel bias: radiance and photon density are
// uniform, so merging is exact except for queries closer than r to an edge of the cube (the ball
// leaves the face and catches photons of the adjacent face). Those bands cover
// perimeter * r / area = 8 r / 4 = 2 r of each face, and there the estimate is off by at
// most its own value, so |bias| <= 2 r L, with r = 0.005 x scene radius (~0.009).
TEST_P(Bidir, FurnaceMatchesAnalytic) {
    const std::string algorithm = GetParam();
    const Rgb rho(0.3f, 0.55f, 0.8f), le(1.0f, 2.0f, 0.5f);
    const int maxLength = 5;
    auto scene = furnaceScene(rho, le, 32);
    RenderOptions opt = bidirOptions(algorithm, 5);
    opt.maxPathLength = maxLength;
    opt.radius = 0.005f;
    opt.alpha = 1.0f;  // fixed radius: the bias bound holds for every iteration
    auto integrator = makeIntegrator(*scene, opt);
    // ppm has the noisiest estimate here (merging only, at the first vertex): more iterations.
    BlockStats s = renderBlockStats(*integrator, algorithm == "ppm" ? 256 : 128, 32);
    const bool merging = algorithm == "ppm" || algorithm == "bpm" || algorithm == "vcm";
    const double r = opt.radius * scene->sceneSphere.radius;
    for (int c = 0; c < 3; ++c) {
        double exact = 0;
        for (int k = 0; k < maxLength; ++k) exact += le[c] * std::pow(double(rho[c]), k);
        double bias = merging ? 2.0 * r * exact : 0.0;
        std::printf("[ bidir    ] furnace %s channel %d: %.5f +- %.5f, exact %.5f (z = %.2f)\n",
                    algorithm.c_str(), c, s.imageMean(c), s.imageStdErr(c), exact,
                    (s.imageMean(c) - exact) / s.imageStdErr(c));
        EXPECT_NEAR(s.imageMean(c), exact, 4.0 * s.imageStdErr(c) + bias)
            << algorithm << " channel " << c << ", standard error " << s.imageStdErr(c);
        // The bound is meaningful: it resolves errors of a few percent.
        EXPECT_LT(s.imageStdErr(c), 0.01 * exact);
    }
}

INSTANTIATE_TEST_SUITE_P(Algorithms, Bidir, ::testing::ValuesIn(kAlgorithms),
                         [](const ::testing::TestParamInfo<const char*>& info) {
                             return std::string(info.param);
                         });

// ---- Determinism, errors, radius ---------------------------------------------------------

// vcm exercises every pass (light subpaths, splats, grid, connections, merging): the image
// of an iteration must be bit-identical with 1 and 4 worker threads.
// Without vertex connection (bpm, upbp without bpt) the camera pass stops a subpath before a
// vertex at the length limit unless the subpath is purely specular (render/vcm_camera.cpp): a
// specular chain may end on an emitter there, which SmallVCM's rule counts. The Cornell box with
// every diffuse and glossy surface black, so that the image is the light seen directly and
// through the mirror and glass spheres, at maximum length 2: bpm's image mean agrees with pt's
// within 5 standard errors, and pt's mean at length 1 (without the chains of length 2, which
// end at the limit: the light in the mirror) is below it by more than twice that bound, so that
// a bpm that dropped them would fail.
TEST(BidirEngine, MergingOnlyKeepsSpecularEmitterHitsAtTheLengthLimit) {
    const std::string dir = std::string(UNIBEAM_SOURCE_DIR) + "/scenes";
    std::ifstream in(dir + "/cornell-large-light.json");
    ASSERT_TRUE(in.good());
    nlohmann::json j = nlohmann::json::parse(in);
    j["camera"]["resolution"] = {32, 32};
    j["materials"]["black"] = {{"type", "diffuse"}, {"reflectance", 0.0}};
    for (auto& shape : j["shapes"]) {
        const std::string m = shape.value("material", "");
        if (m != "mirror" && m != "glass") shape["material"] = "black";
    }
    auto scene = loadJsonSceneFromString(j.dump(), "cornell-large-light.json", dir);
    auto means = [&](const char* algorithm, int maxLength) {
        RenderOptions opt = bidirOptions(algorithm, 41);
        opt.maxPathLength = maxLength;
        return renderImageMeans(*makeIntegrator(*scene, opt), 128, 8);
    };
    expectSkipKeepsPaths("light in the mirror, bpm against pt at length 2", means("pt", 2),
                         means("bpm", 2), means("pt", 1), 2.0);
}

TEST(BidirEngine, SameImageForAnyThreadCount) {
    auto scene = loadCornell("cornell-small-light.json", 24);
    RenderOptions opt = bidirOptions("vcm", 99);
    opt.radius = 0.01f;
    Image a, b;
    for (int threads : {1, 4}) {
        tbb::task_arena arena(threads);
        arena.execute([&] {
            auto integrator = makeIntegrator(*scene, opt);
            Image img;
            integrator->renderIteration(0, img);
            integrator->renderIteration(1, img);
            (threads == 1 ? a : b) = img;
        });
    }
    ASSERT_EQ(a.pixels.size(), b.pixels.size());
    for (size_t i = 0; i < a.pixels.size(); ++i)
        for (int c = 0; c < 3; ++c) ASSERT_EQ(a.pixels[i][c], b.pixels[i][c]) << "pixel " << i;
}

// Light tracing connects to a sampled lens point (estimators/light_tracing.cpp): every
// algorithm takes a thin-lens camera (images against Mitsuba's thinlens sensor:
// mitsuba_handwritten_test, interop_lens.xml); the orthographic camera's film too
// (mitsuba_handwritten_test, orthographic_media.xml).
TEST(BidirEngine, ThinLensCameraAcceptedByEveryAlgorithm) {
    auto scene = furnaceScene(Rgb(0.5f), Rgb(1.0f), 8);
    scene->camera.setup(Vec3(0, 0, 0), Vec3(0, 0, 1), Vec3(0, 1, 0), 60.0f, 8, 8, 0.05f, 1.0f);
    for (const char* name : {"lt", "bpt", "vcm", "ppm", "bpm"})
        EXPECT_NO_THROW(makeIntegrator(*scene, bidirOptions(name, 1))) << name;
}

TEST(BidirEngine, BadRadiusOrAlphaIsAnInputError) {
    auto scene = furnaceScene(Rgb(0.5f), Rgb(1.0f), 8);
    RenderOptions opt = bidirOptions("vcm", 1);
    opt.radius = 0.0f;
    EXPECT_THROW(makeIntegrator(*scene, opt), InputError);
    opt.radius = 0.01f;
    opt.alpha = 1.5f;
    EXPECT_THROW(makeIntegrator(*scene, opt), InputError);
}

// r_i = r_1 i^((alpha-1)/2), r_1 = radius x scene radius (relative) or radius (absolute).
TEST(BidirEngine, RadiusFollowsProgressiveSchedule) {
    auto scene = furnaceScene(Rgb(0.5f), Rgb(1.0f), 8);
    RenderOptions opt = bidirOptions("vcm", 1);
    opt.radius = 0.01f;
    opt.alpha = 0.5f;
    VertexCM relative(*scene, opt);
    const float r1 = 0.01f * scene->sceneSphere.radius;
    EXPECT_FLOAT_EQ(relative.radiusAt(0), r1);
    EXPECT_FLOAT_EQ(relative.radiusAt(3), r1 * std::pow(4.0f, -0.25f));
    EXPECT_FLOAT_EQ(relative.radiusAt(99), r1 * std::pow(100.0f, -0.25f));
    opt.radiusIsRelative = false;
    opt.alpha = 1.0f;  // constant radius
    VertexCM absolute(*scene, opt);
    EXPECT_FLOAT_EQ(absolute.radiusAt(0), 0.01f);
    EXPECT_FLOAT_EQ(absolute.radiusAt(50), 0.01f);
}

// The stored light vertices carry the partials of [TR (31)-(36)]: with vcm both connection
// and merging are on, so dVM (eta times SmallVCM's dVM, kernels/shared/ub_mis.h) = dVC at
// every vertex (same initial value and recursion; Moonen & Jalba 2023's d_pde = d_bpt).
TEST(BidirEngine, StoredLightVerticesKeepMergeToConnectRatio) {
    auto scene = loadCornell("cornell-small-light.json", 16);
    RenderOptions opt = bidirOptions("vcm", 3);
    VertexCM vcm(*scene, opt);
    Image img;
    vcm.renderIteration(0, img);
    ASSERT_GT(vcm.lightVertices().size(), 100u);
    for (const LightVertex& v : vcm.lightVertices()) {
        ASSERT_GE(v.pathLength, 1u);
        ASSERT_TRUE(std::isfinite(v.dVCM) && std::isfinite(v.dVC) && std::isfinite(v.dVM));
        ASSERT_NEAR(v.dVM, v.dVC, 1e-4 * v.dVM + 1e-30);
    }
}

// Lights at infinity (tech. rep. Sec. 5.1: emission from the scene disk, no distance
// factor on the first light segment, escaped camera rays hitting the environment):
// cornell-background is lit only by a constant environment through the open front.
// 32x32, 4x4 blocks of 8x8 pixels, 3 channels: 48 block z-tests, Sidak family-wise 1e-3
// (|z| < 4.19), image mean |z| < 3.9. vcm merges with r = 0.03 x scene radius (see
// CornellAgreesWithPt for the bias argument).
TEST(BidirEngine, EnvironmentLightAgreesWithPt) {
    auto scene = loadCornell("cornell-background.json", 32);
    auto pt = makeIntegrator(*scene, bidirOptions("pt", 21));
    BlockStats ref = renderBlockStats(*pt, 256, 8);
    for (const char* name : {"bpt", "vcm"}) {
        RenderOptions opt = bidirOptions(name, 22);
        opt.radius = 0.03f;
        auto integrator = makeIntegrator(*scene, opt);
        BlockStats s = renderBlockStats(*integrator, 128, 8);
        Agreement g = compare(s, ref);
        std::printf("[ bidir    ] %s vs pt on cornell-background 32x32: %s\n", name,
                    g.report.c_str());
        EXPECT_GT(g.sidakMinP, 1e-3)
            << name << " block " << g.worstBlock << " channel " << g.worstChannel;
        for (int c = 0; c < 3; ++c) {
            EXPECT_LT(std::fabs(g.meanZ[c]), 3.9) << name << " channel " << c;
            EXPECT_LT(s.imageStdErr(c), 0.0125 * ref.imageMean(c)) << name;
        }
    }
}
