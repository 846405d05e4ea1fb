// The OpenCL backend of UPBP's estimate pass (src/cl/cl_runtime.h) on the first OpenCL
// device (PoCL on the CPU in CI; scripts/setup.sh installs it): the pp3d kernel and its host
// twin, given the same photons, queries and grid, return the same per-query results
// (relative 1e-5: the same per-pair function in the same order; the device compiler may
// contract multiply-adds differently), a whole upbp render agrees between the backends, the
// layout probe passes, and the error paths give their messages. A missing OpenCL platform
// fails these tests with the reason, never skips them.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cl/cl_runtime.h"
#include "core/error.h"
#include "estimators/beam_medium.h"
#include "estimators/bvh.h"
#include "estimators/hash_grid.h"
#include "estimators/volume_estimate.h"
#include "kernels/shared/ub_pp3d.h"
#include "render/integrator.h"
#include "render/vcm.h"
#include "scene/io/json_loader.h"

using namespace ub;

namespace {

std::unique_ptr<Scene> infiniteFog(int res) {
    const std::string dir = std::string(UNIBEAM_TEST_DATA_DIR) + "/scenes";
    std::ifstream in(dir + "/upbp-infinite-fog.json");
    EXPECT_TRUE(in.good());
    nlohmann::json j = nlohmann::json::parse(in);
    j["camera"]["resolution"] = {res, res};
    return loadJsonSceneFromString(j.dump(), "upbp-infinite-fog.json", dir);
}

/// The bundled VDB smoke (scenes/cornell-smoke.json) at 32x32.
std::unique_ptr<Scene> smoke32() {
    std::ifstream in(std::string(UNIBEAM_SOURCE_DIR) + "/scenes/cornell-smoke.json");
    EXPECT_TRUE(in.good());
    if (!in.good()) return nullptr;
    nlohmann::json j = nlohmann::json::parse(in);
    j["camera"]["resolution"] = {32, 32};
    return loadJsonSceneFromString(j.dump(), "cornell-smoke.json",
                                   std::string(UNIBEAM_SOURCE_DIR) + "/scenes");
}

/// upbp on smoke32() with the host backend: radii that find pairs at 32x32, 256 beam paths.
RenderOptions smokeOptions() {
    RenderOptions opt;
    opt.algorithm = "upbp";
    opt.backend = "host";
    opt.maxPathLength = 6;
    opt.radiusPP3D = 0.04f;
    opt.radiusPB2D = opt.radiusBP2D = opt.radiusBB1D = 0.02f;
    opt.beamPaths = 256;
    return opt;
}

/// The estimate pass's input for the records of `engine` after one iteration at 32 x 32
/// (32 x 32 light subpaths, beamPaths beam paths, lengths up to maxLength); the caller sets
/// the techniques, radii and MIS constants.
VolumeEstimateInput records32(const Scene* scene, const VertexCM& engine, float beamPaths,
                              uint32_t maxLength) {
    VolumeEstimateInput vin;
    vin.scene = scene;
    vin.lightPathCount = 32.0f * 32.0f;
    vin.beamPathCount = beamPaths;
    vin.minLength = 0;
    vin.maxLength = maxLength;
    vin.photonPoints = &engine.photonPoints();
    vin.photonBeams = &engine.photonBeams();
    vin.queryPoints = &engine.queryPoints();
    vin.queryBeams = &engine.queryBeams();
    return vin;
}

/// records32 for smoke32() after one iteration with smokeOptions (256 beam paths, lengths up
/// to 6).
VolumeEstimateInput smokeRecords(const Scene* scene, const VertexCM& engine) {
    return records32(scene, engine, 256.0f, 6);
}

RenderOptions pp3dOptions(const std::string& backend) {
    RenderOptions opt;
    opt.algorithm = "upbp:bpt+pp3d";
    opt.maxPathLength = 5;
    opt.seed = 41;
    opt.radiusIsRelative = false;
    opt.radiusPP3D = 0.25f;  // a few photons in every query ball at 1024 light subpaths
    opt.backend = backend;
    opt.clCache = "-";  // hermetic: no program cache in the user's folder
    return opt;
}

}  // namespace

TEST(OpenClEstimate, DeviceListedAndLayoutProbePasses) {
    std::string error;
    const auto devices = listClDevices(&error);
    ASSERT_FALSE(devices.empty()) << error;
    // The constructor runs the layout probe and throws on a mismatch.
    std::unique_ptr<ClRuntime> cl;
    ASSERT_NO_THROW(cl = std::make_unique<ClRuntime>(-1, -1));
    EXPECT_FALSE(cl->device().device.empty());
}

TEST(OpenClEstimate, Pp3dKernelEqualsHostTwinPerQuery) {
    auto scene = infiniteFog(32);
    RenderOptions opt = pp3dOptions("host");
    VertexCM engine(*scene, opt);
    Image img;
    engine.renderIteration(2, img);
    const auto& photons = engine.photonPoints();
    const auto& queries = engine.queryPoints();
    ASSERT_GT(photons.size(), 500u);
    ASSERT_GT(queries.size(), 500u);
    const float r = engine.volumeRadiusAt(UB_TECH_PP3D, 2);
    HashGrid grid;
    grid.build(reinterpret_cast<const Vec3*>(photons[0].pos), photons.size(),
               sizeof(ub_photon_point), r);
    VolumeEstimateInput in;
    in.scene = scene.get();
    in.mis = ub_mis_enable_volume(ub_mis_make_constants(0.01f, 1024.0f, 1, 0, UB_MIS_POWER), r, 0,
                                  0, 0, 64.0f, 1, 0);
    in.techniques.pp3d = true;
    in.radius[UB_TECH_PP3D] = r;
    in.lightPathCount = 1024.0f;
    in.minLength = 0;
    in.maxLength = 5;
    in.photonPoints = &photons;
    in.queryPoints = &queries;
    std::vector<Rgb> host(queries.size()), device;
    size_t pairs = 0;
    estimatePP3D(in, grid, &host, &pairs);
    ASSERT_GT(pairs, 1000u);
    ClRuntime cl(-1, -1);
    std::vector<ub_medium_info> media = {mediumInfo(scene->media[0])};
    ClRuntime::EstimateArgs args;
    args.media = &media;
    args.mis = in.mis;
    args.radius = r;
    args.normalization = ub_pp3d_normalization(1024.0f, r);
    args.minLength = 0;
    args.maxLength = 5;
    cl.estimatePP3D(photons, grid, queries, args, &device);
    ASSERT_EQ(device.size(), host.size());
    size_t nonzero = 0;
    for (size_t i = 0; i < host.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            ASSERT_NEAR(device[i][c], host[i][c], 1e-5f * std::fabs(host[i][c]) + 1e-12f)
                << "query " << i << " channel " << c;
            nonzero += host[i][c] != 0.0f;
        }
    EXPECT_GT(nonzero, 300u);

    // Batches: 256 queries each, and 2 launches failing with CL_OUT_OF_RESOURCES (each
    // answered by halving the batch): the same results, bit for bit.
    std::vector<Rgb> batched;
    cl.setMaxBatchForTest(256);
    cl.failLaunchesForTest(2);
    const size_t before = cl.batches();
    cl.estimatePP3D(photons, grid, queries, args, &batched);
    EXPECT_EQ(cl.batchRetries(), 2u);
    EXPECT_GT(cl.batches() - before, queries.size() / 256);
    ASSERT_EQ(batched.size(), device.size());
    for (size_t i = 0; i < device.size(); ++i)
        for (int c = 0; c < 3; ++c) ASSERT_EQ(batched[i][c], device[i][c]) << "query " << i;
    // Out of resources even at the smallest batch: a clear error, not a hang.
    cl.setMaxBatchForTest(64);
    cl.failLaunchesForTest(1);
    try {
        cl.estimatePP3D(photons, grid, queries, args, &batched);
        ADD_FAILURE() << "no error";
    } catch (const ClError& e) {
        EXPECT_NE(std::string(e.what()).find("out of resources"), std::string::npos) << e.what();
    }
}

/// Renders iteration 1 with both integrators and compares every technique layer and the
/// image per pixel and channel within rel * |host| + 1e-9; layers named in mustBeNonzero
/// must hold something.
void expectBackendsAgree(Integrator& host, Integrator& cl, float rel,
                         const std::vector<std::string>& mustBeNonzero) {
    Image a, b;
    host.renderIteration(1, a);
    cl.renderIteration(1, b);
    const auto& la = *host.iterationLayers();
    const auto& lb = *cl.iterationLayers();
    ASSERT_EQ(la.size(), lb.size());
    const std::vector<std::string> names = host.layerNames();
    for (size_t l = 0; l <= la.size(); ++l) {
        const Image& x = l < la.size() ? la[l] : a;
        const Image& y = l < la.size() ? lb[l] : b;
        const std::string what = l < la.size() ? names[l] : "image";
        double sum = 0;
        for (size_t i = 0; i < x.pixels.size(); ++i)
            for (int c = 0; c < 3; ++c) {
                ASSERT_NEAR(y.pixels[i][c], x.pixels[i][c], rel * std::fabs(x.pixels[i][c]) + 1e-9f)
                    << what << " pixel " << i;
                sum += x.pixels[i][c];
            }
        if (std::find(mustBeNonzero.begin(), mustBeNonzero.end(), what) != mustBeNonzero.end())
            EXPECT_GT(sum, 0.0) << what;
    }
}

// A whole upbp iteration (all six techniques; homogeneous medium, so every volumetric
// estimator runs as a kernel) with a fixed seed: every technique layer and the image agree
// between the backends per pixel within 1e-5 relative (seen: 8e-7).
/// pp3dOptions with algorithm `algorithm` and the beam estimators' radii and beam paths of
/// the whole-render tests in infiniteFog(24).
RenderOptions fogUpbpOptions(const std::string& backend, const std::string& algorithm) {
    RenderOptions opt = pp3dOptions(backend);
    opt.algorithm = algorithm;
    opt.radiusPB2D = 0.08f;
    opt.radiusBP2D = 0.08f;
    opt.radiusBB1D = 0.04f;
    opt.beamPaths = 256;
    return opt;
}

TEST(OpenClEstimate, WholeRenderAgreesBetweenBackends) {
    auto scene = infiniteFog(24);
    RenderOptions opt = fogUpbpOptions("host", "upbp");
    auto host = makeIntegrator(*scene, opt);
    opt.backend = "opencl";
    auto cl = makeIntegrator(*scene, opt);
    EXPECT_NE(cl->setupNote().find("on OpenCL device"), std::string::npos) << cl->setupNote();
    ASSERT_EQ(host->layerNames().size(), 6u);
    // No surfaces in this scene: surf stays empty.
    expectBackendsAgree(*host, *cl, 1e-5f, {"bpt", "pp3d", "pb2d", "bp2d", "bb1d", "image"});
}

// VertexCM::replayEstimate (bench_upbp --replay): the last iteration's estimate pass of one
// estimator, run again as the kernel (as the OpenCL render ran it), is that iteration's layer
// of the estimator bit for bit (same records, same order, nothing rejected by the guard
// here); run on the host twin it agrees within the per-query bound above; techniques the
// render does not run are refused.
TEST(OpenClEstimate, ReplayedEstimatesEqualTheIterationsLayers) {
    auto scene = infiniteFog(24);
    const RenderOptions opt = fogUpbpOptions("opencl", "upbp:bpt+pp3d+pb2d+bb1d");
    auto integrator = makeIntegrator(*scene, opt);
    auto* vcm = dynamic_cast<VertexCM*>(integrator.get());
    ASSERT_NE(vcm, nullptr);
    ASSERT_TRUE(vcm->hasDeviceEstimates());
    Image img;
    vcm->renderIteration(1, img);
    const std::vector<std::string> names = vcm->layerNames();
    for (const char* tech : {"pp3d", "pb2d", "bb1d"}) {
        const size_t l = size_t(std::find(names.begin(), names.end(), tech) - names.begin());
        ASSERT_LT(l, names.size()) << tech;
        const Image& layer = (*vcm->iterationLayers())[l];
        for (bool onDevice : {false, true}) {
            Image replay(img.width, img.height);
            const VertexCM::EstimateTiming t = vcm->replayEstimate(tech, onDevice, &replay);
            EXPECT_GT(t.queries, 0u) << tech;
            double sum = 0;
            for (size_t i = 0; i < layer.pixels.size(); ++i)
                for (int c = 0; c < 3; ++c) {
                    const float x = layer.pixels[i][c], y = replay.pixels[i][c];
                    if (!onDevice)
                        ASSERT_NEAR(y, x, 1e-5f * std::fabs(x) + 1e-9f) << tech << " " << i;
                    else
                        ASSERT_EQ(y, x) << tech << " pixel " << i;
                    sum += x;
                }
            EXPECT_GT(sum, 0.0) << tech;
        }
    }
    Image scratch(img.width, img.height);
    EXPECT_THROW(vcm->replayEstimate("bp2d", false, &scratch), std::invalid_argument);
    EXPECT_THROW(vcm->replayEstimate("surf", false, &scratch), std::invalid_argument);
    EXPECT_THROW(vcm->replayEstimate("bpt", false, &scratch), std::invalid_argument);
}

// Queue profiling (RenderOptions::clProfile, bench_upbp --cl-profile): a replayed pass on the
// device reports its kernel's device time and its start latency, the host twin and a render
// without profiling report none, and the image is the same bit for bit with and without it.
TEST(OpenClEstimate, QueueProfilingReportsKernelTimes) {
    auto scene = infiniteFog(24);
    Image plain, profiled;
    std::vector<VertexCM::EstimateTiming> device, host;
    for (bool profile : {false, true}) {
        RenderOptions opt = fogUpbpOptions("opencl", "upbp:bpt+pp3d+bb1d");
        opt.clProfile = profile;
        auto integrator = makeIntegrator(*scene, opt);
        auto* vcm = dynamic_cast<VertexCM*>(integrator.get());
        ASSERT_NE(vcm, nullptr);
        ASSERT_TRUE(vcm->hasDeviceEstimates());
        Image& img = profile ? profiled : plain;
        vcm->renderIteration(1, img);
        for (const char* tech : {"pp3d", "bb1d"}) {
            Image replay(img.width, img.height);
            device.push_back(vcm->replayEstimate(tech, true, &replay));
            host.push_back(vcm->replayEstimate(tech, false, &replay));
        }
    }
    ASSERT_EQ(plain.pixels.size(), profiled.pixels.size());
    for (size_t i = 0; i < plain.pixels.size(); ++i)
        for (int c = 0; c < 3; ++c) ASSERT_EQ(plain.pixels[i][c], profiled.pixels[i][c]) << i;
    for (size_t k = 0; k < device.size(); ++k) {
        EXPECT_EQ(host[k].deviceKernel, -1.0);
        EXPECT_EQ(host[k].deviceStartLatency, -1.0);
        if (k < 2) {  // without profiling
            EXPECT_EQ(device[k].deviceKernel, -1.0);
            EXPECT_EQ(device[k].deviceStartLatency, -1.0);
        } else {
            EXPECT_GT(device[k].deviceKernel, 0.0);
            EXPECT_GE(device[k].deviceStartLatency, 0.0);
            // The kernel runs within the pass that launched it.
            EXPECT_LE(device[k].deviceKernel, device[k].estimates);
        }
    }
}

// The same in a NanoVDB medium (the bundled smoke plume, nearest filtering): the beam
// kernels track through the grid with CNanoVDB.h (kernels/shared/ub_grid_medium.h), the
// host twins through their tabulated pieces (estimators/beam_medium.h), the kernels through
// the same tables (kernels/shared/ub_beam_table.h). Bound: 1e-4 relative per pixel and
// channel: the device may contract and order the float arithmetic differently, and
// exp(-tau) (tau up to ~10 here) and the MIS weights amplify the last bits of tau.
TEST(OpenClEstimate, WholeRenderAgreesBetweenBackendsInAGridMedium) {
    auto scene = smoke32();
    ASSERT_TRUE(scene);
    ASSERT_EQ(scene->media[0].type, MediumType::kGrid);
    RenderOptions opt = smokeOptions();
    auto host = makeIntegrator(*scene, opt);
    opt.backend = "opencl";
    auto cl = makeIntegrator(*scene, opt);
    EXPECT_NE(cl->setupNote().find("on OpenCL device"), std::string::npos) << cl->setupNote();
    EXPECT_EQ(cl->setupNote().find("on the host"), std::string::npos) << cl->setupNote();
    expectBackendsAgree(*host, *cl, 1e-4f, {"surf", "pb2d", "bp2d", "bb1d"});
}

// The beam kernels against their host twins in the VDB smoke, per pixel of each technique's
// layer, on the same photons, beams and queries (one recorded iteration): photon beams read
// the host's tables, query beams their own private tables (default UB_QUERY_PIECES) or, with
// UB_QUERY_PIECES=4, mostly overflow them and walk per pair. Bound: 1e-4 relative per pixel
// and channel (seen: 4e-6): tables and walks sum the optical depth in a different order,
// and exp(-tau) and the MIS weights amplify the last bits of tau.
TEST(OpenClEstimate, BeamKernelsInAGridMediumEqualTheirTwins) {
    auto scene = smoke32();
    ASSERT_TRUE(scene);
    RenderOptions opt = smokeOptions();
    VertexCM engine(*scene, opt);
    Image img;
    engine.renderIteration(1, img);
    ASSERT_GT(engine.photonBeams().size(), 100u);
    ASSERT_GT(engine.queryBeams().size(), 300u);
    VolumeEstimateInput vin = smokeRecords(scene.get(), engine);
    const float lightPaths = vin.lightPathCount;
    for (int t : {UB_TECH_PB2D, UB_TECH_BP2D, UB_TECH_BB1D})
        vin.radius[t] = engine.volumeRadiusAt(t, 1);
    vin.mis =
        ub_mis_enable_volume(ub_mis_make_constants(0.01f, lightPaths, 1, 1, UB_MIS_POWER),
                             engine.volumeRadiusAt(UB_TECH_PP3D, 1), vin.radius[UB_TECH_PB2D],
                             vin.radius[UB_TECH_BP2D], vin.radius[UB_TECH_BB1D], 256.0f, 1, 0);
    vin.techniques.pb2d = vin.techniques.bp2d = vin.techniques.bb1d = true;
    Image hostImage(32, 32);
    std::array<Image, 4> hostLayers;
    for (Image& l : hostLayers) l = Image(32, 32);
    estimateVolume(vin, &hostImage, &hostLayers);
    for (const char* options : {"", "-DUB_QUERY_PIECES=4"}) {
        ClRuntime cl(-1, -1, "-", options);
        std::vector<ub_medium_info> media;
        ASSERT_TRUE(prepareDeviceMedia(*scene, &cl, true, &media));
        VolumeEstimateInput din = vin;
        din.cl = &cl;
        din.deviceMedia = &media;
        din.beamKernels = true;
        Image deviceImage(32, 32);
        std::array<Image, 4> deviceLayers;
        for (Image& l : deviceLayers) l = Image(32, 32);
        estimateVolume(din, &deviceImage, &deviceLayers);
        for (int t : {UB_TECH_PB2D, UB_TECH_BP2D, UB_TECH_BB1D}) {
            const Image& a = hostLayers[size_t(t)];
            const Image& b = deviceLayers[size_t(t)];
            double sum = 0, worst = 0;
            for (size_t i = 0; i < a.pixels.size(); ++i)
                for (int c = 0; c < 3; ++c) {
                    const float x = a.pixels[i][c], y = b.pixels[i][c];
                    ASSERT_NEAR(y, x, 1e-4f * std::fabs(x) + 1e-9f)
                        << "technique " << t << " pixel " << i << " options '" << options << "'";
                    sum += x;
                    if (x != 0.0f) worst = std::max(worst, std::fabs(double(y - x) / x));
                }
            EXPECT_GT(sum, 0.0) << "technique " << t;
            std::printf("technique %d options '%s': max relative difference %.3g\n", t, options,
                        worst);
        }
    }
}

// The program cache: the first runtime builds and caches, the second loads the entry; a
// corrupt entry is rebuilt and replaced, never fatal.
// bb1d's host twin walks the part lines eight at a time where the CPU has AVX, else four
// (src/estimators/bb1d_walk.inc): both find the same candidates in the same order, so the
// bb1d layer is the same bit for bit (the VDB smoke, one iteration). Here because the kernel
// does the same in kernels/beams.cl, which the test above holds to this twin. On a CPU without
// AVX both passes take the four-lane walk, and the test checks that the AVX one is never chosen.
TEST(OpenClEstimate, Bb1dWideWalkEqualsTheFourLaneOne) {
    auto scene = smoke32();
    ASSERT_TRUE(scene);
    RenderOptions opt = smokeOptions();
    opt.algorithm = "upbp:bb1d";
    VertexCM engine(*scene, opt);
    Image img;
    engine.renderIteration(1, img);
    ASSERT_GT(engine.photonBeams().size(), 100u);
    ASSERT_GT(engine.queryBeams().size(), 300u);
    VolumeEstimateInput vin = smokeRecords(scene.get(), engine);
    vin.radius[UB_TECH_BB1D] = engine.volumeRadiusAt(UB_TECH_BB1D, 1);
    vin.mis = ub_mis_enable_volume(ub_mis_make_constants(0.01f, 1024.0f, 1, 1, UB_MIS_POWER), 0.0f,
                                   0.0f, 0.0f, vin.radius[UB_TECH_BB1D], 256.0f, 1, 0);
    vin.techniques.bb1d = true;
    std::array<Image, 2> layers;
    for (int pass = 0; pass < 2; ++pass) {
        setBb1dWideWalkForTests(pass == 0);
        EXPECT_EQ(bb1dWideWalk(), pass == 0 && bb1dWideWalkAvailable());
        Image image(32, 32);
        std::array<Image, 4> perTechnique;
        for (Image& l : perTechnique) l = Image(32, 32);
        estimateVolume(vin, &image, &perTechnique);
        layers[size_t(pass)] = perTechnique[UB_TECH_BB1D];
    }
    setBb1dWideWalkForTests(true);
    double sum = 0;
    for (size_t i = 0; i < layers[0].pixels.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            ASSERT_EQ(layers[0].pixels[i][c], layers[1].pixels[i][c]) << "pixel " << i;
            sum += layers[0].pixels[i][c];
        }
    EXPECT_GT(sum, 0.0);
}

// bb1d's and pb2d's query beams on lines through the camera's eye read the parts or photons of
// their screen tile (kernels/shared/ub_screen_tiles.h) in place of the BVH walk. The tiles must
// hold every part or photon such a query pairs with, so the host twins find as many pairs with
// them as without, and their layers differ only by the order of each query's sum (bound: 1e-5
// relative per pixel and channel). The VDB smoke's camera is outside the medium, so these
// queries start where their camera rays enter it, off the eye. The kernels read the same tiles
// in the same order, and BeamKernelsInAGridMediumEqualTheirTwins holds them to these twins.
TEST(OpenClEstimate, ScreenTilesFindTheBvhWalksPairs) {
    auto scene = smoke32();
    ASSERT_TRUE(scene);
    RenderOptions opt = smokeOptions();
    opt.algorithm = "upbp:pb2d+bb1d";
    VertexCM engine(*scene, opt);
    Image img;
    engine.renderIteration(1, img);
    VolumeEstimateInput vin = smokeRecords(scene.get(), engine);
    vin.radius[UB_TECH_PB2D] = engine.volumeRadiusAt(UB_TECH_PB2D, 1);
    vin.radius[UB_TECH_BB1D] = engine.volumeRadiusAt(UB_TECH_BB1D, 1);
    vin.mis = ub_mis_enable_volume(ub_mis_make_constants(0.01f, 1024.0f, 1, 1, UB_MIS_POWER), 0.0f,
                                   vin.radius[UB_TECH_PB2D], 0.0f, vin.radius[UB_TECH_BB1D], 256.0f,
                                   1, 0);
    vin.techniques.pb2d = vin.techniques.bb1d = true;
    std::array<std::array<Image, 4>, 2> layers;
    std::array<VolumeEstimateStats, 2> stats;
    for (int pass = 0; pass < 2; ++pass) {
        setScreenTilesForTests(pass == 0);
        Image image(32, 32);
        for (Image& l : layers[size_t(pass)]) l = Image(32, 32);
        estimateVolume(vin, &image, &layers[size_t(pass)], &stats[size_t(pass)]);
    }
    setScreenTilesForTests(true);
    EXPECT_EQ(stats[0].screenTiles.enabled, 1u);
    EXPECT_EQ(stats[0].photonScreenTiles.enabled, 1u);
    EXPECT_EQ(stats[1].screenTiles.enabled, 0u);
    EXPECT_EQ(stats[1].photonScreenTiles.enabled, 0u);
    size_t onTiles = 0;
    for (const ub_beam& q : engine.queryBeams())
        onTiles +=
            ub_screen_tile_of(stats[0].screenTiles, ub_f3_from(q.origin), ub_f3_from(q.dir)) >= 0;
    // The camera rays' pieces in the smoke, a quarter of the query beams or more.
    EXPECT_GT(onTiles, engine.queryBeams().size() / 4);
    std::printf("%zu of %zu query beams on screen tiles\n", onTiles, engine.queryBeams().size());
    for (int t : {UB_TECH_PB2D, UB_TECH_BB1D}) {
        EXPECT_GT(stats[0].pairs[t], 100u) << "technique " << t;
        EXPECT_EQ(stats[0].pairs[t], stats[1].pairs[t]) << "technique " << t;
        double sum = 0;
        const Image &a = layers[1][size_t(t)], &b = layers[0][size_t(t)];
        for (size_t i = 0; i < a.pixels.size(); ++i)
            for (int c = 0; c < 3; ++c) {
                const float x = a.pixels[i][c], y = b.pixels[i][c];
                ASSERT_NEAR(y, x, 1e-5f * std::fabs(x) + 1e-12f)
                    << "technique " << t << " pixel " << i;
                sum += x;
            }
        EXPECT_GT(sum, 0.0) << "technique " << t;
    }
}

// bb1d's screen tiles bin a photon beam whole where its box lies in front of the eye, and by
// its BVH parts otherwise (estimators/screen_tiles.h). In the infinite fog the camera stands
// among the beams, so both kinds are binned, and some parts cross the eye's plane into the
// list every tile reads. The host twin finds as many bb1d pairs with tiles as without, and its
// layer differs only by the order of each query's sum (bound: 1e-5 relative per pixel and
// channel); WholeRenderAgreesBetweenBackends holds the kernel to the twin in this scene.
TEST(OpenClEstimate, ScreenTilesWithBeamsAroundTheEye) {
    auto scene = infiniteFog(32);
    RenderOptions opt = fogUpbpOptions("host", "upbp:bb1d");
    opt.beamPaths = 1024;
    VertexCM engine(*scene, opt);
    Image img;
    engine.renderIteration(1, img);
    // Beams wholly in front of the eye, and beams with an end behind it.
    const Vec3 eye = scene->camera.position(), forward = scene->camera.forward();
    size_t front = 0, across = 0;
    for (const ub_beam& b : engine.photonBeams()) {
        const Vec3 o(b.origin[0], b.origin[1], b.origin[2]), d(b.dir[0], b.dir[1], b.dir[2]);
        const float d0 = dot(o - eye, forward), d1 = dot(o + d * b.length - eye, forward);
        (std::min(d0, d1) > 0.5f ? front : across) += 1;
    }
    EXPECT_GT(front, 100u);
    EXPECT_GT(across, 100u);
    VolumeEstimateInput vin = records32(scene.get(), engine, 1024.0f, uint32_t(opt.maxPathLength));
    vin.radius[UB_TECH_BB1D] = engine.volumeRadiusAt(UB_TECH_BB1D, 1);
    vin.mis = ub_mis_enable_volume(ub_mis_make_constants(0.01f, 1024.0f, 1, 1, UB_MIS_POWER), 0.0f,
                                   0.0f, 0.0f, vin.radius[UB_TECH_BB1D], 1024.0f, 1, 0);
    vin.techniques.bb1d = true;
    std::array<std::array<Image, 4>, 2> layers;
    std::array<VolumeEstimateStats, 2> stats;
    for (int pass = 0; pass < 2; ++pass) {
        setScreenTilesForTests(pass == 0);
        Image image(32, 32);
        for (Image& l : layers[size_t(pass)]) l = Image(32, 32);
        estimateVolume(vin, &image, &layers[size_t(pass)], &stats[size_t(pass)]);
    }
    setScreenTilesForTests(true);
    EXPECT_EQ(stats[0].screenTiles.enabled, 1u);
    EXPECT_EQ(stats[1].screenTiles.enabled, 0u);
    EXPECT_GT(stats[0].pairs[UB_TECH_BB1D], 1000u);
    EXPECT_EQ(stats[0].pairs[UB_TECH_BB1D], stats[1].pairs[UB_TECH_BB1D]);
    double sum = 0;
    const Image &a = layers[1][UB_TECH_BB1D], &b = layers[0][UB_TECH_BB1D];
    for (size_t i = 0; i < a.pixels.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            const float x = a.pixels[i][c], y = b.pixels[i][c];
            ASSERT_NEAR(y, x, 1e-5f * std::fabs(x) + 1e-12f) << "pixel " << i;
            sum += x;
        }
    EXPECT_GT(sum, 0.0);
}

// The beam estimators walk one BVH per medium (Bvh::build's groups): a query visits only the
// tree of its own medium, since every pair test rejects a photon or part of another medium.
// In the bundled glass sphere of juice in haze (two media, 32 x 32), the host twins find as
// many pb2d, bp2d and bb1d pairs with one tree per medium as with one tree over both media,
// and their layers differ only by the order of each query's sum (bound: 1e-5 relative per
// pixel and channel); the kernels, given the per-medium roots, agree with the twins within the
// same bound (homogeneous media: no grid walks whose sums could differ in order).
TEST(OpenClEstimate, MediumTreesFindTheSameBeamPairs) {
    std::ifstream in(std::string(UNIBEAM_SOURCE_DIR) + "/scenes/glass-medium-caustics.json");
    ASSERT_TRUE(in.good());
    nlohmann::json j = nlohmann::json::parse(in);
    j["camera"]["resolution"] = {32, 32};
    auto scene = loadJsonSceneFromString(j.dump(), "glass-medium-caustics.json",
                                         std::string(UNIBEAM_SOURCE_DIR) + "/scenes");
    ASSERT_TRUE(scene);
    ASSERT_EQ(scene->media.size(), 2u);
    RenderOptions opt;
    opt.algorithm = "upbp:pb2d+bp2d+bb1d";
    opt.backend = "host";
    opt.maxPathLength = 8;
    opt.radiusIsRelative = false;
    opt.radiusPB2D = opt.radiusBP2D = opt.radiusBB1D = 0.1f;
    opt.beamPaths = 1024;
    VertexCM engine(*scene, opt);
    Image img;
    engine.renderIteration(1, img);
    // Both media hold query beams, query points, photons and photon beams.
    for (uint32_t m = 0; m < 2; ++m) {
        auto inMedium = [m](const auto& v) {
            return std::count_if(v.begin(), v.end(),
                                 [m](const auto& x) { return x.mediumId == m; });
        };
        EXPECT_GT(inMedium(engine.queryBeams()), 50) << "medium " << m;
        EXPECT_GT(inMedium(engine.queryPoints()), 50) << "medium " << m;
        EXPECT_GT(inMedium(engine.photonPoints()), 50) << "medium " << m;
        EXPECT_GT(inMedium(engine.photonBeams()), 20) << "medium " << m;
    }
    VolumeEstimateInput vin = records32(scene.get(), engine, 1024.0f, 8);
    for (int t : {UB_TECH_PB2D, UB_TECH_BP2D, UB_TECH_BB1D}) vin.radius[t] = 0.1f;
    vin.mis = ub_mis_enable_volume(ub_mis_make_constants(0.01f, 1024.0f, 1, 1, UB_MIS_POWER), 0.0f,
                                   0.1f, 0.1f, 0.1f, 1024.0f, 1, 0);
    vin.techniques.pb2d = vin.techniques.bp2d = vin.techniques.bb1d = true;
    // pass 0: one tree per medium (host), 1: one tree (host), 2: one tree per medium (kernels)
    std::array<std::array<Image, 4>, 3> layers;
    std::array<VolumeEstimateStats, 3> stats;
    ClRuntime cl(-1, -1, "-", "");
    std::vector<ub_medium_info> media;
    ASSERT_TRUE(prepareDeviceMedia(*scene, &cl, true, &media));
    for (int pass = 0; pass < 3; ++pass) {
        setMediumTreesForTests(pass != 1);
        VolumeEstimateInput pin = vin;
        if (pass == 2) {
            pin.cl = &cl;
            pin.deviceMedia = &media;
            pin.beamKernels = true;
        }
        Image image(32, 32);
        for (Image& l : layers[size_t(pass)]) l = Image(32, 32);
        estimateVolume(pin, &image, &layers[size_t(pass)], &stats[size_t(pass)]);
    }
    setMediumTreesForTests(true);
    for (int t : {UB_TECH_PB2D, UB_TECH_BP2D, UB_TECH_BB1D}) {
        EXPECT_GT(stats[0].pairs[t], 100u) << "technique " << t;
        EXPECT_EQ(stats[0].pairs[t], stats[1].pairs[t]) << "technique " << t;
        for (int pass : {1, 2}) {
            double sum = 0;
            const Image &a = layers[0][size_t(t)], &b = layers[size_t(pass)][size_t(t)];
            for (size_t i = 0; i < a.pixels.size(); ++i)
                for (int c = 0; c < 3; ++c) {
                    const float x = a.pixels[i][c], y = b.pixels[i][c];
                    ASSERT_NEAR(y, x, 1e-5f * std::fabs(x) + 1e-12f)
                        << "technique " << t << " pass " << pass << " pixel " << i;
                    sum += x;
                }
            EXPECT_GT(sum, 0.0) << "technique " << t;
        }
    }
}

TEST(OpenClEstimate, ProgramCacheHitAndCorruptEntry) {
    const std::string dir =
        (std::filesystem::temp_directory_path() / ("unibeam-clcache-" + std::to_string(::getpid())))
            .string();
    std::filesystem::remove_all(dir);
    {
        ClRuntime a(-1, -1, dir);
        EXPECT_NE(a.programNote().find("cached as"), std::string::npos) << a.programNote();
    }
    {
        ClRuntime b(-1, -1, dir);
        EXPECT_NE(b.programNote().find("from cache"), std::string::npos) << b.programNote();
    }
    int entries = 0;
    for (const auto& e : std::filesystem::directory_iterator(dir)) {
        ++entries;
        std::ofstream(e.path(), std::ios::binary | std::ios::trunc) << "not a program binary";
    }
    EXPECT_EQ(entries, 1);
    {
        ClRuntime c(-1, -1, dir);
        EXPECT_NE(c.programNote().find("corrupt program cache entry"), std::string::npos)
            << c.programNote();
        EXPECT_NE(c.programNote().find("cached as"), std::string::npos) << c.programNote();
    }
    {
        ClRuntime d(-1, -1, dir);  // the replaced entry loads
        EXPECT_NE(d.programNote().find("from cache"), std::string::npos) << d.programNote();
    }
    std::filesystem::remove_all(dir);
}

TEST(OpenClEstimate, ErrorPaths) {
    // A forced build failure: the message has the build log and the options.
    try {
        ClRuntime cl(-1, -1, "-", "-DUB_FORCE_BUILD_ERROR");
        ADD_FAILURE() << "forced build failure not reported";
    } catch (const ClError& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("failed"), std::string::npos) << m;
        EXPECT_NE(m.find("-DUB_FORCE_BUILD_ERROR"), std::string::npos) << m;
        EXPECT_NE(m.find("build failure forced"), std::string::npos) << m;  // the log
    }
    // A device index that does not exist.
    try {
        ClRuntime cl(7, 3);
        ADD_FAILURE() << "device 7:3 accepted";
    } catch (const ClError& e) {
        EXPECT_NE(std::string(e.what()).find("no device 7:3"), std::string::npos) << e.what();
    }
    auto scene = infiniteFog(8);
    RenderOptions opt = pp3dOptions("opencl");
    opt.clPlatform = 7;
    opt.clDevice = 3;
    EXPECT_THROW(makeIntegrator(*scene, opt), InputError);  // --backend opencl: an error
    opt.backend = "auto";  // auto falls back to the host and says why
    auto fallback = makeIntegrator(*scene, opt);
    EXPECT_NE(fallback->setupNote().find("on the host (backend auto"), std::string::npos)
        << fallback->setupNote();
    // A kernel source that does not exist among the embedded ones.
    EXPECT_THROW(clProgramSource({"nope.cl"}), ClError);
    // Every embedded source expands its includes (each header once).
    const std::string src = clProgramSource({"pp3d.cl"});
    EXPECT_NE(src.find("ub_pp3d_contribution"), std::string::npos);
    EXPECT_EQ(src.find("#include \"ub_"), std::string::npos);
}
