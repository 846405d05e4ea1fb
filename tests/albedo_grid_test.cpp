// Spatially varying albedo of grid media (scene/albedo_grid.h):
//  * lookups (nearest, trilinear, clamp to the domain) against hand-computed values;
//  * free-flight sampling: tracking and pdfs do not change, the throughput weight carries
//    the albedo at the collision;
//  * a constant albedo grid renders bit-identically to the constant albedo (vpt, vbpt;
//    nearest and trilinear density and albedo);
//  * an independent check of a varying albedo: a grid medium whose albedo grid has two halves
//    against the same scene built from two homogeneous media split by an imaginary boundary
//    (block z-tests, vpt and vbpt);
//  * validation messages of albedo grids and .vdb albedo channels.
#include "scene/albedo_grid.h"

#include <gtest/gtest.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <string>

#include "core/error.h"
#include "render/integrator.h"
#include "scene/io/mitsuba_loader.h"
#include "scene/medium.h"
#include "scene/scene.h"
#include "scene/shapes.h"
#include "scene/vdb_grid.h"
#include "tests/support/render_stats.h"
#include "tests/support/temp_file.h"

using namespace ub;
using namespace ub::test;
namespace fs = std::filesystem;

namespace {

bool contains(const std::string& s, const std::string& part) {
    return s.find(part) != std::string::npos;
}

bool same(const Rgb& a, const Rgb& b) {
    return a.x == b.x && a.y == b.y && a.z == b.z;
}

/// Dense channels of an albedo along x: voxel i of `n` has albedo values[i] (per channel),
/// voxel size h, voxel i centred at x = x0 + i h (y = z = 0, one voxel thick).
std::vector<std::shared_ptr<const VdbGrid>> albedoAlongX(const std::vector<Rgb>& values, float h,
                                                         float x0, int channels = 3) {
    std::vector<std::shared_ptr<const VdbGrid>> out;
    for (int c = 0; c < channels; ++c) {
        DenseFloatGrid d(int(values.size()), 1, 1);
        d.voxelSize = h;
        d.origin = Vec3(x0, 0.0f, 0.0f);
        for (size_t i = 0; i < values.size(); ++i) d.at(int(i), 0, 0) = values[i][c];
        out.push_back(VdbGrid::fromDenseChecked(d, "albedo", "test", "albedo", 1.0f));
    }
    return out;
}

/// Constant density 1 over [-1.2, 1.2]^3 (2^3 voxels of size 1.2), scaled by sigmaT.
Medium constantGridMedium(float sigmaT, const Rgb& albedo, float g, GridFilter filter) {
    DenseFloatGrid d(2, 2, 2, 1.0f);
    d.voxelSize = 1.2f;
    d.origin = Vec3(-0.6f);
    GridMediumOptions o;
    o.filter = filter;
    return Medium::heterogeneous(VdbGrid::fromDense(d, "density"), sigmaT, albedo, g, Transform(),
                                 o);
}

}  // namespace

TEST(AlbedoGrid, NearestAndTrilinearLookupsClampToTheDomain) {
    // Voxels centred at x = 0, 1, 2 (size 1): cells [-0.5, 0.5), [0.5, 1.5), [1.5, 2.5).
    const std::vector<Rgb> v = {Rgb(0.1f, 0.2f, 0.3f), Rgb(0.5f, 0.6f, 0.7f),
                                Rgb(0.9f, 0.4f, 0.0f)};
    auto near = AlbedoGrid::make(albedoAlongX(v, 1.0f, 0.0f), GridFilter::kNearest, Transform());
    auto tri = AlbedoGrid::make(albedoAlongX(v, 1.0f, 0.0f), GridFilter::kTrilinear, Transform());
    for (int c = 0; c < 3; ++c) {
        EXPECT_FLOAT_EQ(albedoGridAt(*near, Vec3(0.2f, 0.0f, 0.0f))[c], v[0][c]);
        EXPECT_FLOAT_EQ(albedoGridAt(*near, Vec3(0.7f, 0.3f, -0.4f))[c], v[1][c]);
        EXPECT_FLOAT_EQ(albedoGridAt(*near, Vec3(2.2f, 0.0f, 0.0f))[c], v[2][c]);
        // Outside the box: the nearest edge voxel (Mitsuba's clamp), also along y and z.
        EXPECT_FLOAT_EQ(albedoGridAt(*near, Vec3(-7.0f, 0.0f, 0.0f))[c], v[0][c]);
        EXPECT_FLOAT_EQ(albedoGridAt(*near, Vec3(9.0f, 5.0f, -3.0f))[c], v[2][c]);
        EXPECT_FLOAT_EQ(albedoGridAt(*near, Vec3(1.0f, 40.0f, 0.0f))[c], v[1][c]);
        // Trilinear: voxel centres, linear in between, flat beyond the edge centres.
        EXPECT_NEAR(albedoGridAt(*tri, Vec3(1.0f, 0.0f, 0.0f))[c], v[1][c], 1e-6f);
        EXPECT_NEAR(albedoGridAt(*tri, Vec3(0.25f, 0.3f, 0.0f))[c],
                    0.75f * v[0][c] + 0.25f * v[1][c], 1e-6f);
        EXPECT_NEAR(albedoGridAt(*tri, Vec3(1.6f, 0.0f, 0.2f))[c], 0.4f * v[1][c] + 0.6f * v[2][c],
                    1e-6f);
        EXPECT_NEAR(albedoGridAt(*tri, Vec3(-0.3f, 0.0f, 0.0f))[c], v[0][c], 1e-6f);
        EXPECT_NEAR(albedoGridAt(*tri, Vec3(3.0f, -2.0f, 0.0f))[c], v[2][c], 1e-6f);
    }
    // A grey grid gives equal channels; the medium's own to_world moves the grid.
    auto grey = AlbedoGrid::make(albedoAlongX(v, 1.0f, 0.0f, 1), GridFilter::kNearest,
                                 Transform::translate(Vec3(10.0f, 0.0f, 0.0f)));
    EXPECT_EQ(grey->channelCount, 1);
    EXPECT_TRUE(same(albedoGridAt(*grey, Vec3(11.0f, 0.0f, 0.0f)), Rgb(v[1][0])));
    // Non-finite points do not crash (clamped).
    EXPECT_TRUE(isFinite(albedoGridAt(*tri, Vec3(NAN, 1e30f, -INFINITY))));
}

// wrap_mode repeat and mirror (Mitsuba's texture address modes): voxel indices wrapped after
// the filter picks them. Voxels centred at x = 0, 1, 2 (domain 0..2, period 3).
TEST(AlbedoGrid, RepeatAndMirrorWrapTheVoxelIndices) {
    const std::vector<Rgb> v = {Rgb(0.1f), Rgb(0.5f), Rgb(0.9f)};
    auto at = [&](GridFilter f, GridWrap w, float x) {
        auto g = AlbedoGrid::make(albedoAlongX(v, 1.0f, 0.0f, 1), f, Transform(), nullptr, nullptr,
                                  "test", w);
        return albedoGridAt(*g, Vec3(x, 0.0f, 0.0f)).x;
    };
    const GridFilter kN = GridFilter::kNearest, kT = GridFilter::kTrilinear;
    // nearest, repeat: cell [3.5, 4.5) is voxel 4 mod 3 = 1; [-1.5, -0.5) is voxel 2
    EXPECT_FLOAT_EQ(at(kN, GridWrap::kRepeat, 4.2f), v[1].x);
    EXPECT_FLOAT_EQ(at(kN, GridWrap::kRepeat, -1.0f), v[2].x);
    EXPECT_FLOAT_EQ(at(kN, GridWrap::kRepeat, 301.0f), v[1].x);
    // nearest, mirror: 3 -> 2, 4 -> 1, 5 -> 0, 6 -> 0 (period 6), -1 -> 0, -2 -> 1
    EXPECT_FLOAT_EQ(at(kN, GridWrap::kMirror, 3.0f), v[2].x);
    EXPECT_FLOAT_EQ(at(kN, GridWrap::kMirror, 4.0f), v[1].x);
    EXPECT_FLOAT_EQ(at(kN, GridWrap::kMirror, 6.0f), v[0].x);
    EXPECT_FLOAT_EQ(at(kN, GridWrap::kMirror, -1.0f), v[0].x);
    EXPECT_FLOAT_EQ(at(kN, GridWrap::kMirror, -2.0f), v[1].x);
    // trilinear, repeat: between the last voxel (x = 2) and the first one repeated (x = 3)
    EXPECT_NEAR(at(kT, GridWrap::kRepeat, 2.25f), 0.75f * v[2].x + 0.25f * v[0].x, 1e-6f);
    EXPECT_NEAR(at(kT, GridWrap::kRepeat, -0.5f), 0.5f * v[2].x + 0.5f * v[0].x, 1e-6f);
    EXPECT_NEAR(at(kT, GridWrap::kRepeat, 4.0f), v[1].x, 1e-6f);
    // trilinear, mirror: beyond x = 2 the edge voxel repeats (2 -> 2), then 1
    EXPECT_NEAR(at(kT, GridWrap::kMirror, 2.5f), v[2].x, 1e-6f);
    EXPECT_NEAR(at(kT, GridWrap::kMirror, 3.5f), 0.5f * v[2].x + 0.5f * v[1].x, 1e-6f);
    // inside the domain every mode agrees with clamp
    for (float x : {0.2f, 0.9f, 1.7f})
        for (GridFilter f : {kN, kT}) {
            EXPECT_FLOAT_EQ(at(f, GridWrap::kRepeat, x), at(f, GridWrap::kClamp, x));
            EXPECT_FLOAT_EQ(at(f, GridWrap::kMirror, x), at(f, GridWrap::kClamp, x));
        }
    // non-finite points do not crash
    EXPECT_TRUE(std::isfinite(at(kT, GridWrap::kRepeat, NAN)));
    EXPECT_TRUE(std::isfinite(at(kN, GridWrap::kMirror, INFINITY)));
}

TEST(AlbedoGrid, FreeFlightWeightCarriesTheAlbedoAtTheCollision) {
    // Tracking, transmittance and both distance pdfs are those of the medium without the
    // albedo grid, bit for bit; the weight T sigma_s / pdf uses the albedo at the collision.
    const std::vector<Rgb> v = {Rgb(0.2f, 0.5f, 0.9f), Rgb(0.8f, 0.3f, 0.1f)};
    for (GridFilter densityFilter : {GridFilter::kNearest, GridFilter::kTrilinear}) {
        for (GridFilter albedoFilter : {GridFilter::kNearest, GridFilter::kTrilinear}) {
            Medium plain = constantGridMedium(1.3f, Rgb(0.5f), 0.0f, densityFilter);
            Medium varying = plain;
            varying.albedoGrid =
                AlbedoGrid::make(albedoAlongX(v, 1.2f, -0.6f), albedoFilter, Transform());
            const Vec3 origin(-1.1f, 0.1f, -0.2f), dir = normalize(Vec3(1.0f, 0.1f, 0.05f));
            int scattered = 0;
            for (int i = 0; i < 64; ++i) {
                const float uc = (i % 3 + 0.5f) / 3.0f, ud = (i + 0.5f) / 64.0f;
                FreeFlightSample a = sampleFreeFlight(plain, origin, dir, 2.2f, uc, ud);
                FreeFlightSample b = sampleFreeFlight(varying, origin, dir, 2.2f, uc, ud);
                ASSERT_EQ(a.scattered, b.scattered);
                ASSERT_EQ(a.t, b.t);
                ASSERT_EQ(a.pdf, b.pdf);
                ASSERT_TRUE(same(a.segment.transmittance, b.segment.transmittance));
                ASSERT_EQ(a.segment.pdfScatterRevL(), b.segment.pdfScatterRevL());
                if (!b.scattered) {
                    EXPECT_TRUE(same(a.weight, b.weight));
                    continue;
                }
                ++scattered;
                const Vec3 x = origin + dir * b.t;
                const Rgb albedo = albedoGridAt(*varying.albedoGrid, x);
                const Rgb expected = b.segment.transmittance * albedo * b.segment.sigmaT1 / b.pdf;
                for (int c = 0; c < 3; ++c)
                    EXPECT_NEAR(b.weight[c], expected[c], 1e-5f * expected[c] + 1e-7f);
                const MediumCoefficients co = mediumCoefficientsAt(varying, x);
                for (int c = 0; c < 3; ++c)
                    EXPECT_NEAR(co.sigmaS[c], albedo[c] * co.sigmaT[c], 1e-6f);
                // The evaluated segment to the collision point agrees.
                MediumSegment seg = evalMediumSegment(varying, origin, dir, b.t);
                for (int c = 0; c < 3; ++c)
                    EXPECT_NEAR(seg.sigmaS1[c], albedo[c] * seg.sigmaT1[c], 1e-6f);
            }
            EXPECT_GT(scattered, 32);
        }
    }
}

namespace {

/// Closed black box [-1, 1]^3 whose inside emits Le (as tests/support/volume_scenes.h),
/// filled with `outer` (imaginary boundary [-1.001, 1.001]^3, priority 0); with `right`,
/// the half x > 0 holds `right` instead: an imaginary box [0, 1.5] x [-1.5, 1.5]^2 of
/// priority 1 (its other faces lie behind the walls, so only its x = 0 face is ever met).
std::unique_ptr<Scene> halvesScene(const Medium& outer, const Medium* right, int res) {
    auto scene = std::make_unique<Scene>();
    Material black;
    black.type = MaterialType::Diffuse;
    black.diffuse = Rgb(0.0f);
    int mat = scene->addMaterial(black);
    TriangleMesh cube = makeCube();
    for (size_t t = 0; t < cube.triangleCount(); ++t)
        std::swap(cube.indices[3 * t + 1], cube.indices[3 * t + 2]);  // normals inwards
    cube.normals.clear();
    Light light;
    light.type = LightType::Area;
    light.name = "walls";
    light.radiance = Rgb(1.0f, 2.0f, 0.5f);
    for (uint32_t i : cube.indices) light.triangles.push_back(cube.positions[i]);
    int lightId = scene->addLight(light);
    scene->addMesh(cube, mat, lightId, "emitting walls");
    int med = scene->addMedium(outer, "outer");
    TriangleMesh outward = makeCube();
    outward.normals.clear();
    transformMesh(outward, Transform::scale(Vec3(1.001f)));
    uint32_t b = scene->addMesh(outward, -1, -1, "outer boundary");
    scene->setMediumBoundary(b, med, 0, /*imaginary=*/true);
    if (right) {
        int rightMed = scene->addMedium(*right, "right");
        TriangleMesh half = makeCube();  // [-1, 1]^3 -> [0, 1.5] x [-1.5, 1.5]^2
        half.normals.clear();
        transformMesh(half, Transform::translate(Vec3(0.75f, 0.0f, 0.0f)) *
                                Transform::scale(Vec3(0.75f, 1.5f, 1.5f)));
        uint32_t h = scene->addMesh(half, -1, -1, "right half");
        scene->setMediumBoundary(h, rightMed, 1, /*imaginary=*/true);
    }
    scene->camera.setup(Vec3(0.1f, -0.05f, 0.0f), Vec3(0.3f, 0.2f, 1.0f), Vec3(0, 1, 0), 70.0f, res,
                        res);
    scene->commit();
    return scene;
}

Image renderOnce(const Scene& scene, const char* algorithm, int iteration) {
    RenderOptions opt;
    opt.algorithm = algorithm;
    opt.maxPathLength = 40;
    opt.seed = 5;
    auto integrator = makeIntegrator(scene, opt);
    Image img;
    integrator->renderIteration(iteration, img);
    return img;
}

}  // namespace

TEST(AlbedoGrid, ConstantGridRendersBitIdenticalToConstantAlbedo) {
    // With every albedo voxel equal to the constant albedo, lookups return that float exactly
    // (nearest: the stored value; trilinear: a + (b - a) w with a = b), so sigma_s, the
    // weights and the roulette probabilities are the same floats and the same random numbers
    // give the same image, bit for bit.
    const Rgb albedo(0.9f, 0.6f, 0.3f);
    for (GridFilter densityFilter : {GridFilter::kNearest, GridFilter::kTrilinear})
        for (GridFilter albedoFilter : {GridFilter::kNearest, GridFilter::kTrilinear}) {
            Medium plain = constantGridMedium(1.5f, albedo, 0.3f, densityFilter);
            Medium gridded = plain;
            gridded.albedo = Rgb(0.123f);  // must not be used
            gridded.albedoGrid = AlbedoGrid::make(albedoAlongX({albedo, albedo}, 1.2f, -0.6f),
                                                  albedoFilter, Transform());
            auto a = halvesScene(plain, nullptr, 16);
            auto b = halvesScene(gridded, nullptr, 16);
            for (const char* algorithm : {"vpt", "vbpt"}) {
                Image ia = renderOnce(*a, algorithm, 3), ib = renderOnce(*b, algorithm, 3);
                ASSERT_EQ(ia.pixels.size(), ib.pixels.size());
                size_t differing = 0;
                for (size_t i = 0; i < ia.pixels.size(); ++i)
                    differing += !same(ia.pixels[i], ib.pixels[i]);
                EXPECT_EQ(differing, 0u) << algorithm << " density filter " << int(densityFilter)
                                         << " albedo filter " << int(albedoFilter);
            }
        }
}

// Independent check of a spatially varying albedo. Scene A: one grid medium (constant
// sigma_t = 1.5 from a density grid) whose albedo grid is two voxels along x, albedo L for
// x < 0 and R for x > 0 (nearest, clamped: the two half-spaces). Scene B: the same box
// filled with a homogeneous medium of albedo L and an imaginary boundary around the half
// x > 0 holding a homogeneous medium of albedo R: different tracking (one grid walk
// against two homogeneous segments split at a boundary) and different sigma_s bookkeeping,
// the same radiance. Camera at x = 0.1 sees both halves.
//
// 24x24 pixels, blocks of 4x4: 36 blocks x 3 channels = 108 z-tests of block means between
// two independent renders (different seeds), standard errors from the spread of
// per-iteration block means (tests/support/render_stats.h). Family-wise level 1e-3 with the
// Sidak correction: per test alpha' = 9.3e-6 (|z| < 4.4). Image means: |z| < 3.9 per channel
// (family-wise 3e-4). A swapped or ignored albedo grid moves the image mean by tens of
// standard errors (checked by hand: rendering scene A with the halves swapped fails).
TEST(AlbedoGrid, TwoHalvesMatchTwoHomogeneousMedia) {
    const float sigmaT = 1.5f, g = 0.2f;
    const Rgb left(0.95f, 0.5f, 0.2f), right(0.3f, 0.85f, 0.97f);
    Medium gridMedium = constantGridMedium(sigmaT, Rgb(1.0f), g, GridFilter::kNearest);
    gridMedium.albedoGrid = AlbedoGrid::make(albedoAlongX({left, right}, 1.2f, -0.6f),
                                             GridFilter::kNearest, Transform());
    const Medium homLeft = Medium::homogeneous((Rgb(1.0f) - left) * sigmaT, left * sigmaT, g);
    const Medium homRight = Medium::homogeneous((Rgb(1.0f) - right) * sigmaT, right * sigmaT, g);
    const int res = 24, block = 4;
    auto gridScene = halvesScene(gridMedium, nullptr, res);
    auto refScene = halvesScene(homLeft, &homRight, res);
    ASSERT_TRUE(refScene->mediumIssues().empty()) << refScene->mediumIssues()[0].message;
    ASSERT_EQ(refScene->cameraMediumStack.mediumId(), 1);  // the camera is in the right half

    RenderOptions opt;
    opt.maxPathLength = 40;
    opt.algorithm = "vpt";
    opt.seed = 31;
    auto ref = makeIntegrator(*refScene, opt);
    BlockStats refStats = renderBlockStats(*ref, 48, block);
    const struct {
        const char* algorithm;
        int iterations;
    } cases[] = {{"vpt", 48}, {"vbpt", 24}};
    for (const auto& c : cases) {
        opt.algorithm = c.algorithm;
        opt.seed = 32;  // independent of the reference
        auto integrator = makeIntegrator(*gridScene, opt);
        BlockStats s = renderBlockStats(*integrator, c.iterations, block);
        Agreement a = compare(s, refStats);
        std::printf("[ albedo   ] %s, albedo grid halves vs two homogeneous media (vpt): %s\n",
                    c.algorithm, a.report.c_str());
        EXPECT_GT(a.minBlockP, sidakLevel(1e-3, a.tests)) << c.algorithm << ": " << a.report;
        for (int ch = 0; ch < 3; ++ch) EXPECT_LT(std::fabs(a.meanZ[ch]), 3.9) << c.algorithm;
        // The test has power: the image mean's standard error is below 1% of the mean.
        for (int ch = 0; ch < 3; ++ch)
            EXPECT_LT(s.imageStdErr(ch), 0.01 * refStats.imageMean(ch)) << c.algorithm;
    }
}

// End to end through the Mitsuba loader: the RGB albedo.vol and sigmat.vol of Mitsuba's
// participating-media tests (16^3, trilinear, scaled by 5) in a unit cube lit by an area
// light, rendered by vbpt against vpt. vbpt's light subpaths scatter in the medium (albedo
// looked up at light vertices, roulette with the local albedo in both directions of the
// MIS), so agreement checks the albedo grid in every technique of the bidirectional engine.
// 24x24 pixels, blocks of 4x4: 108 z-tests, Sidak family-wise level 1e-3 (|z| < 4.4), image
// means |z| < 3.9 per channel (bounds and standard errors as TwoHalvesMatchTwoHomogeneousMedia).
TEST(AlbedoGrid, MitsubaAlbedoVolSceneVbptAgreesWithVpt) {
    const std::string dir = std::string(UNIBEAM_MITSUBA_MEDIA_DIR);
    ASSERT_TRUE(fs::is_directory(dir)) << "test data not found: " << dir;
    const std::string toWorld = R"(<transform name="to_world">
        <scale x="1.5" y="1.5" z="1.5"/><translate x="-0.75" y="-0.75" z="-0.75"/></transform>)";
    const std::string xml = R"(<scene version="3.0.0">
  <integrator type="volpath"><integer name="max_depth" value="12"/></integrator>
  <sensor type="perspective"><float name="fov" value="45"/>
    <transform name="to_world"><lookat origin="0.3, 1.2, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="24"/></film>
  </sensor>
  <shape type="rectangle"><emitter type="area"><rgb name="radiance" value="6"/></emitter>
    <transform name="to_world"><rotate x="1" angle="90"/><translate y="2"/></transform></shape>
  <shape type="rectangle"><bsdf type="diffuse"><rgb name="reflectance" value="0.6"/></bsdf>
    <transform name="to_world"><scale value="4"/><rotate x="1" angle="-90"/><translate y="-0.8"/></transform></shape>
  <medium id="m" type="heterogeneous"><float name="scale" value="5"/>
    <volume name="sigma_t" type="gridvolume"><string name="filename" value="textures/sigmat.vol"/>)" +
                            toWorld + R"(</volume>
    <volume name="albedo" type="gridvolume"><string name="filename" value="textures/albedo.vol"/>)" +
                            toWorld + R"(</volume>
    <phase type="hg"><float name="g" value="0.3"/></phase>
  </medium>
  <shape type="cube"><bsdf type="null"/><ref id="m" name="interior"/>
    <transform name="to_world"><scale value="0.75"/></transform></shape>
</scene>
)";
    auto scene = loadMitsubaSceneFromString(xml, "albedo-scene.xml", dir, {});
    ASSERT_TRUE(scene->media[0].albedoGrid);
    RenderOptions opt;
    opt.maxPathLength = scene->settings.maxPathLength;
    opt.algorithm = "vpt";
    opt.seed = 41;
    auto vpt = makeIntegrator(*scene, opt);
    BlockStats ref = renderBlockStats(*vpt, 128, 4);
    opt.algorithm = "vbpt";
    opt.seed = 42;
    auto vbpt = makeIntegrator(*scene, opt);
    BlockStats s = renderBlockStats(*vbpt, 64, 4);
    Agreement a = compare(s, ref);
    std::printf("[ albedo   ] vbpt vs vpt, Mitsuba albedo.vol scene: %s\n", a.report.c_str());
    EXPECT_GT(a.minBlockP, sidakLevel(1e-3, a.tests)) << a.report;
    for (int ch = 0; ch < 3; ++ch) {
        EXPECT_LT(std::fabs(a.meanZ[ch]), 3.9);
        EXPECT_LT(s.imageStdErr(ch), 0.01 * ref.imageMean(ch));
    }
}

TEST(AlbedoGrid, ValidationMessages) {
    auto messageOf = [](auto&& f) -> std::string {
        try {
            f();
        } catch (const InputError& e) {
            return e.what();
        }
        return "";
    };
    DenseFloatGrid d(2, 1, 1, 0.5f);
    d.at(1, 0, 0) = 1.25f;
    std::string e =
        messageOf([&] { VdbGrid::fromDenseChecked(d, "albedo", "a.vol", "albedo", 1); });
    EXPECT_TRUE(contains(e, "a.vol")) << e;
    EXPECT_TRUE(contains(e,
                         "grid 'albedo' has an albedo 1.25 at voxel (1, 0, 0); albedo values "
                         "must be finite and lie in [0, 1]"))
        << e;
    // fromDense() does not bound values; make() does.
    e = messageOf([&] {
        AlbedoGrid::make({VdbGrid::fromDense(d, "a")}, GridFilter::kNearest, Transform(), nullptr,
                         nullptr, "'x.vdb' grid 'a'");
    });
    EXPECT_TRUE(contains(e, "'x.vdb' grid 'a'")) << e;
    EXPECT_TRUE(contains(e, "values up to 1.25")) << e;
    auto two = albedoAlongX({Rgb(0.5f)}, 1.0f, 0.0f, 2);
    e = messageOf([&] { AlbedoGrid::make(two, GridFilter::kNearest, Transform()); });
    EXPECT_TRUE(contains(e, "2 channels (expected 1: grey, or 3: RGB)")) << e;
    auto mixed = albedoAlongX({Rgb(0.5f)}, 1.0f, 0.0f, 3);
    mixed[2] = albedoAlongX({Rgb(0.5f)}, 2.0f, 0.0f, 1)[0];
    e = messageOf([&] { AlbedoGrid::make(mixed, GridFilter::kNearest, Transform()); });
    EXPECT_TRUE(contains(e, "different transforms")) << e;
    // All-zero albedo voxels are values (not an empty grid).
    DenseFloatGrid zeros(2, 2, 2, 0.0f);
    EXPECT_NO_THROW(VdbGrid::fromDenseChecked(zeros, "albedo", "z.vol", "albedo", 1));
    // An albedo grid on a homogeneous medium is a scene error.
    Scene scene;
    Medium hom = Medium::homogeneous(Rgb(0.1f), Rgb(0.2f), 0.0f);
    hom.albedoGrid =
        AlbedoGrid::make(albedoAlongX({Rgb(0.5f)}, 1.0f, 0.0f), GridFilter::kNearest, Transform());
    scene.addMedium(hom, "fog");
    auto issues = scene.mediumIssues();
    ASSERT_EQ(issues.size(), 1u);
    EXPECT_TRUE(contains(issues[0].message, "medium 'fog': an albedo grid needs a heterogeneous"))
        << issues[0].message;
}

TEST(AlbedoGrid, VdbFloatAndVec3GridsLoadAsChannels) {
    const fs::path dir = ub::test::scratchFolder("albedo_grid_vdb");
    const std::string path = (dir / "albedo.vdb").string();
    DenseFloatGrid r(3, 2, 2, 0.25f), gr(3, 2, 2, 0.5f), b(3, 2, 2, 0.75f);
    r.at(2, 1, 1) = 1.0f;
    b.at(0, 0, 0) = 0.0f;
    writeDenseVdb(
        path,
        {{"density", {DenseFloatGrid(2, 2, 2, 1.0f)}}, {"albedo", {r, gr, b}}, {"grey", {gr}}});
    auto rgb = loadVdbAlbedoChannels(path, "albedo");
    ASSERT_EQ(rgb.size(), 3u);
    auto grid = AlbedoGrid::make(rgb, GridFilter::kNearest, Transform());
    EXPECT_TRUE(same(albedoGridAt(*grid, Vec3(2.0f, 1.0f, 1.0f)), Rgb(1.0f, 0.5f, 0.75f)));
    EXPECT_TRUE(same(albedoGridAt(*grid, Vec3(0.0f, 0.0f, 0.0f)), Rgb(0.25f, 0.5f, 0.0f)));
    EXPECT_TRUE(same(albedoGridAt(*grid, Vec3(1.0f, 0.0f, 1.0f)), Rgb(0.25f, 0.5f, 0.75f)));
    auto grey = loadVdbAlbedoChannels(path, "grey");
    ASSERT_EQ(grey.size(), 1u);
    EXPECT_TRUE(same(albedoGridAt(*AlbedoGrid::make(grey, GridFilter::kNearest, Transform()),
                                  Vec3(1.0f, 1.0f, 0.0f)),
                     Rgb(0.5f)));

    auto messageOf = [&](const std::string& file, const std::string& name) -> std::string {
        try {
            loadVdbAlbedoChannels(file, name);
        } catch (const InputError& e) {
            return e.what();
        }
        return "";
    };
    std::string e = messageOf(path, "colour");
    EXPECT_TRUE(contains(e,
                         "cannot load grid 'colour': no grid of that name in the file; grids "
                         "present: 'albedo' (vec3s), 'density' (float), 'grey' (float)"))
        << e;
    {
        openvdb::initialize();
        auto ints = openvdb::Int32Grid::create(0);
        ints->setName("albedo");
        ints->tree().setValue(openvdb::Coord(0, 0, 0), 1);
        openvdb::GridPtrVec grids{ints};
        openvdb::io::File((dir / "ints.vdb").string()).write(grids);
    }
    e = messageOf((dir / "ints.vdb").string(), "albedo");
    EXPECT_TRUE(contains(e, "grid holds values of type 'int32'")) << e;
    EXPECT_TRUE(contains(e, "expected a float (1 channel) or vec3s (3 channels) albedo grid")) << e;
    DenseFloatGrid hot(2, 2, 2, 0.5f);
    hot.at(1, 1, 0) = 2.0f;
    writeDenseVdb((dir / "hot.vdb").string(), {{"albedo", {gr, gr, gr}}, {"hot", {hot}}});
    e = messageOf((dir / "hot.vdb").string(), "hot");
    EXPECT_TRUE(contains(e, "has an albedo 2 at voxel (1, 1, 0)")) << e;
    fs::remove_all(dir);
}
