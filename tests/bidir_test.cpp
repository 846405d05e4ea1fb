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
#include <memory>
#include <string>

#include "core/error.h"
#include "render/vcm.h"
#include "scene/io/scene_loader.h"
#include "scene/shapes.h"
#include "tests/support/render_stats.h"

using namespace ub;
using namespace ub::test;

namespace {

const char* const kAlgorithms[] = {"lt", "bpt", "ppm", "bpm", "vcm"};

/// A bundled scene re-targeted to a small square resolution (same view).
std::unique_ptr<Scene> loadCornell(const std::string& name, int res) {
    auto scene = loadScene(std::string(UNIBEAM_SOURCE_DIR) + "/scenes/" + name);
    Camera& cam = scene->camera;
    Camera small;
    small.setup(cam.position(), cam.position() + cam.forward(), cam.up(), cam.fovYDeg(), res,
                res);
    cam = small;
    return scene;
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
    scene->camera.setup(Vec3(0.1f, -0.05f, 0.0f), Vec3(0.3f, 0.2f, 1.0f), Vec3(0, 1, 0), 70.0f,
                        res, res);
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
// cornell-large-light at 48x48, 6x6 blocks of 8x8 pixels, 3 channels: 108 z-tests of
// block means plus 3 of the image mean. Standard errors come from the spread of the
// per-iteration block means (independent iterations), for both renders.
// Blocks: family-wise level 1e-3 with the Sidak correction, i.e. per test
// alpha' = 1 - (1 - 1e-3)^(1/108) = 9.3e-6, |z| < 4.43. Image mean: |z| < 3.9 per
// channel (family-wise 3e-4 over 3 channels).
// Merging (ppm, bpm, vcm) is consistent but biased: the radius is 0.002 of the scene
// radius (about 8 mm in a 2.6 m box, alpha = 0.75), so the kernel's bias (blurring of
// the illumination over the disk, and the wall-corner bands of width r where the disk
// leaves the surface) touches < 2% of a block's area and stays below the statistical
// resolution here (the block standard errors are 1-3% of the block means).
TEST_P(Bidir, CornellAgreesWithPt) {
    const std::string algorithm = GetParam();
    const int res = 48, block = 8;
    auto scene = loadCornell("cornell-large-light.json", res);

    RenderOptions ptOpt = bidirOptions("pt", 11);
    auto pt = makeIntegrator(*scene, ptOpt);
    BlockStats ref = renderBlockStats(*pt, 192, block);

    RenderOptions opt = bidirOptions(algorithm, 12);
    opt.radius = 0.002f;
    opt.alpha = 0.75f;
    auto integrator = makeIntegrator(*scene, opt);
    const int iterations = algorithm == "lt" ? 160 : 96;
    BlockStats s = renderBlockStats(*integrator, iterations, block);

    Agreement g = compare(s, ref);
    std::printf("[ bidir    ] %s vs pt on cornell-large-light %dx%d: %s\n", algorithm.c_str(),
                res, res, g.report.c_str());
    const double zBlock = criticalZ(sidakLevel(1e-3, g.tests));
    EXPECT_GT(g.sidakMinP, 1e-3) << "block " << g.worstBlock << " channel " << g.worstChannel
                                 << ": " << s.mean(g.worstBlock, g.worstChannel) << " +- "
                                 << s.stdErr(g.worstBlock, g.worstChannel) << " vs pt "
                                 << ref.mean(g.worstBlock, g.worstChannel) << " +- "
                                 << ref.stdErr(g.worstBlock, g.worstChannel) << " (|z| bound "
                                 << zBlock << ")";
    for (int c = 0; c < 3; ++c) {
        EXPECT_LT(std::fabs(g.meanZ[c]), 3.9)
            << "channel " << c << ": image mean " << s.imageMean(c) << " +- "
            << s.imageStdErr(c) << " vs pt " << ref.imageMean(c) << " +- " << ref.imageStdErr(c);
        // The test must be able to see a 5% error: both standard errors well below it.
        EXPECT_LT(s.imageStdErr(c), 0.01 * ref.imageMean(c));
    }
}

// ---- White furnace -------------------------------------------------------------------
//
// Every vertex sees emission Le and reflects with albedo rho, so a path of k segments
// carries Le rho^(k-1): L = Le sum_{k=0}^{maxLength-1} rho^k exactly. Image mean per
// channel within 4 standard errors (over independent iterations; two-sided 6e-5 each) plus,
// for merging, the kernel bias: radiance is uniform, so merging is exact except in the
// corner bands of width r (disk partly off the face, photons of the adjacent face
// counted); r = 0.002 x scene radius ~ 0.0035 covers 0.35% of a face, bounding that
// bias by 0.35% of L, added to the bound.
TEST_P(Bidir, FurnaceMatchesAnalytic) {
    const std::string algorithm = GetParam();
    const Rgb rho(0.3f, 0.55f, 0.8f), le(1.0f, 2.0f, 0.5f);
    const int maxLength = 5;
    auto scene = furnaceScene(rho, le, 16);
    RenderOptions opt = bidirOptions(algorithm, 5);
    opt.maxPathLength = maxLength;
    opt.radius = 0.002f;
    auto integrator = makeIntegrator(*scene, opt);
    BlockStats s = renderBlockStats(*integrator, 64, 16);
    const bool merging = algorithm == "ppm" || algorithm == "bpm" || algorithm == "vcm";
    for (int c = 0; c < 3; ++c) {
        double exact = 0;
        for (int k = 0; k < maxLength; ++k) exact += le[c] * std::pow(double(rho[c]), k);
        double bound = 4.0 * s.imageStdErr(c) + (merging ? 0.0035 * exact : 0.0);
        EXPECT_NEAR(s.imageMean(c), exact, bound)
            << algorithm << " channel " << c << ", standard error " << s.imageStdErr(c);
        EXPECT_LT(s.imageStdErr(c), 0.01 * exact);  // the bound is meaningful
    }
}

INSTANTIATE_TEST_SUITE_P(Algorithms, Bidir, ::testing::ValuesIn(kAlgorithms),
                         [](const ::testing::TestParamInfo<const char*>& info) {
                             return std::string(info.param);
                         });

// ---- Determinism, errors, radius ---------------------------------------------------------

// vcm exercises every pass (light subpaths, splats, grid, connections, merging): the image
// of an iteration must be bit-identical with 1 and 4 worker threads.
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

TEST(BidirEngine, ThinLensCameraRejectedForLightTracing) {
    auto scene = furnaceScene(Rgb(0.5f), Rgb(1.0f), 8);
    scene->camera.setup(Vec3(0, 0, 0), Vec3(0, 0, 1), Vec3(0, 1, 0), 60.0f, 8, 8, 0.05f, 1.0f);
    for (const char* name : {"lt", "bpt", "vcm"}) {
        try {
            makeIntegrator(*scene, bidirOptions(name, 1));
            ADD_FAILURE() << name << " accepted a thin-lens camera";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find("pinhole"), std::string::npos) << e.what();
        }
    }
    // Merging from the camera side needs no camera pdf: ppm and bpm accept thin lenses.
    EXPECT_NO_THROW(makeIntegrator(*scene, bidirOptions("ppm", 1)));
    EXPECT_NO_THROW(makeIntegrator(*scene, bidirOptions("bpm", 1)));
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
// and merging are on, so dVM = dVC / eta at every vertex (shared/notes/mis.md Sec. 2.3).
TEST(BidirEngine, StoredLightVerticesKeepMergeToConnectRatio) {
    auto scene = loadCornell("cornell-small-light.json", 16);
    RenderOptions opt = bidirOptions("vcm", 3);
    VertexCM vcm(*scene, opt);
    Image img;
    vcm.renderIteration(0, img);
    const float r = vcm.radiusAt(0);
    const double eta = kPi * double(r) * r * 16.0 * 16.0;
    ASSERT_GT(vcm.lightVertices().size(), 100u);
    for (const LightVertex& v : vcm.lightVertices()) {
        ASSERT_GE(v.pathLength, 1u);
        ASSERT_TRUE(std::isfinite(v.dVCM) && std::isfinite(v.dVC) && std::isfinite(v.dVM));
        // Power heuristic: factors are squared, dVM = dVC / eta^2.
        ASSERT_NEAR(v.dVM, v.dVC / (eta * eta), 1e-4 * v.dVM + 1e-30);
    }
}
