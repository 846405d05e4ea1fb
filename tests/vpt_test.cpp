// Volumetric path tracer (`vpt`) tests:
//  * Vpt.VolumetricFurnaceIsLeEverywhere: closed emitting black box filled with a
//    non-absorbing medium (several sigma_s and g, power and balance heuristics);
//  * Vpt.EmittingAbsorbingMediumFurnace: the same box with an absorbing medium that emits
//    what the walls emit (Kirchhoff equilibrium), which exercises the medium emission
//    estimator and roulette at medium vertices;
//  * Vpt.ConstantVdbMatchesHomogeneous: a constant-density NanoVDB grid renders as the
//    equal homogeneous medium (image mean and per-block z-tests);
//  * Vpt.MatchesPtWithoutMedia: on a scene without media vpt and pt agree;
//  * Vpt.SameSeedSameImage: determinism.
#include "render/vpt.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "core/error.h"
#include "render/integrator.h"
#include "scene/io/json_loader.h"
#include "scene/scene.h"
#include "scene/shapes.h"
#include "scene/vdb_grid.h"

namespace ub {
namespace {

/// Cube [-h, h]^3 whose triangles face inwards.
TriangleMesh inwardCube(float halfSize) {
    TriangleMesh m = makeCube();
    transformMesh(m, Transform::scale(Vec3(halfSize)));
    for (size_t t = 0; t < m.triangleCount(); ++t)
        std::swap(m.indices[3 * t + 1], m.indices[3 * t + 2]);
    m.normals.clear();
    return m;
}

/// Image means per iteration and per-block means per iteration (blocks of b x b pixels).
struct Stats {
    int n = 0, block = 4, bw = 0, bh = 0;
    std::vector<double> imageMeans[3];
    std::vector<std::vector<double>>
        blockMeans;  // [block] -> per iteration (luminance-free: sum of RGB)
    void add(const Image& img) {
        bw = img.width / block;
        bh = img.height / block;
        if (blockMeans.empty()) blockMeans.assign(size_t(bw * bh), {});
        double m[3] = {0, 0, 0};
        std::vector<double> bm(size_t(bw * bh), 0.0);
        for (int y = 0; y < img.height; ++y)
            for (int x = 0; x < img.width; ++x) {
                const Rgb& p = img.at(x, y);
                for (int c = 0; c < 3; ++c) m[c] += p[c];
                if (x / block < bw && y / block < bh)
                    bm[size_t((y / block) * bw + x / block)] += (p.x + p.y + p.z) / 3.0;
            }
        for (int c = 0; c < 3; ++c) imageMeans[c].push_back(m[c] / double(img.width * img.height));
        for (size_t b = 0; b < bm.size(); ++b) blockMeans[b].push_back(bm[b] / (block * block));
        ++n;
    }
    static double meanOf(const std::vector<double>& v) {
        double s = 0;
        for (double x : v) s += x;
        return s / double(v.size());
    }
    /// Squared standard error of the mean of i.i.d. samples v.
    static double varOfMean(const std::vector<double>& v) {
        double m = meanOf(v), s2 = 0;
        for (double x : v) s2 += (x - m) * (x - m);
        return s2 / double(v.size() - 1) / double(v.size());
    }
};

Stats render(const Scene& scene, const RenderOptions& opt, int iterations) {
    auto integrator = makeIntegrator(scene, opt);
    Stats s;
    Image img;
    for (int it = 0; it < iterations; ++it) {
        integrator->renderIteration(it, img);
        s.add(img);
    }
    return s;
}

/// Furnace set-up: the walls of the cube [-1, 1]^3 are a real surface with a black diffuse
/// material whose inside emits Le (one-sided area light, triangles facing inwards). An
/// imaginary, outward-facing cube [-1.001, 1.001]^3 is the medium boundary that puts
/// `medium` inside. Vacuum outside; camera inside at (0.1, -0.05, 0), looking at
/// (0.3, 0.2, 1).
std::unique_ptr<Scene> volumeFurnace(const Medium& medium, const Rgb& le, int res) {
    auto scene = std::make_unique<Scene>();
    Material black;
    black.type = MaterialType::Diffuse;
    black.diffuse = Rgb(0.0f);
    int mat = scene->addMaterial(black);
    TriangleMesh cube = inwardCube(1.0f);
    Light light;
    light.type = LightType::Area;
    light.radiance = le;
    for (uint32_t i : cube.indices) light.triangles.push_back(cube.positions[i]);
    int lightId = scene->addLight(light);
    int med = scene->addMedium(medium, "furnace medium");
    scene->addMesh(cube, mat, lightId, "emitting walls");
    TriangleMesh outward = makeCube();
    outward.normals.clear();
    transformMesh(outward, Transform::scale(Vec3(1.001f)));
    uint32_t b = scene->addMesh(outward, -1, -1, "medium boundary");
    scene->setMediumBoundary(b, med, 0, /*imaginary=*/true);
    scene->camera.setup(Vec3(0.1f, -0.05f, 0.0f), Vec3(0.3f, 0.2f, 1.0f), Vec3(0, 1, 0), 70.0f, res,
                        res);
    scene->commit();
    return scene;
}

// Analytic answer. Inside the box the medium does not absorb (sigma_a = 0) and every wall
// point emits Le and absorbs everything, so L(x, w) = Le for every x and w (the radiance
// transport equation with L = Le is satisfied: sigma_s (phase * Le integrated) = sigma_s Le
// in-scatters what out-scattering removes). The renderer truncates paths at
// maxPathLength = L segments: a camera path reaches the wall within L segments unless it
// scatters L times first. Every flight from any point in any direction escapes the box
// (length <= 2 sqrt(3)) without scattering with probability >= exp(-sigma_s 2 sqrt(3)), so
// the truncated answer is Le (1 - eps) with eps <= (1 - exp(-2 sqrt(3) sigma_s))^L;
// for sigma_s <= 1 and L = 1000: eps <= (1 - 0.0313)^1000 < 1e-13.
void checkVolumeFurnace(float sigmaS, float g, MisHeuristic heuristic) {
    const Rgb le(1.0f, 2.0f, 0.5f);
    const int res = 24, iterations = 64;
    auto scene = volumeFurnace(Medium::homogeneous(Rgb(0.0f), Rgb(sigmaS), g), le, res);
    ASSERT_EQ(scene->cameraMediumStack.mediumId(), 0);
    RenderOptions opt;
    opt.algorithm = "vpt";
    opt.maxPathLength = 1000;
    opt.seed = 11;
    opt.heuristic = heuristic;
    Stats s = render(*scene, opt, iterations);
    // z-test of the image mean at 5 standard errors of the mean of 64 i.i.d. iteration
    // means (each over 576 paths; the standard error is 0.1-0.3% of Le, so a bias of ~1%
    // fails); the standard error is also bounded by 1% so that a noisy estimator cannot
    // pass through a wide bound.
    for (int c = 0; c < 3; ++c) {
        double m = Stats::meanOf(s.imageMeans[c]);
        double se = std::sqrt(Stats::varOfMean(s.imageMeans[c]));
        EXPECT_NEAR(m, le[c], 5.0 * se + 1e-6)
            << "sigma_s " << sigmaS << " g " << g << " channel " << c << " stderr " << se;
        EXPECT_LT(se, 0.01 * le[c]);
    }
}

TEST(Vpt, VolumetricFurnaceIsLeEverywhere) {
    for (float sigmaS : {0.25f, 1.0f})
        for (float g : {0.0f, 0.9f, -0.6f}) checkVolumeFurnace(sigmaS, g, MisHeuristic::Power);
    checkVolumeFurnace(1.0f, 0.3f, MisHeuristic::Balance);
}

// Absorbing, scattering and emitting medium (sigma_a = sigma_s = 0.6, emission Le, the
// source term sigma_a Le) in the box whose walls emit the same Le: in equilibrium
// L = Le everywhere (emission sigma_a Le balances absorption sigma_a L). Truncation at
// L = 1000 segments: eps <= (1 - exp(-1.2 * 2 sqrt(3)))^1000 < 1e-6.
TEST(Vpt, EmittingAbsorbingMediumFurnace) {
    const Rgb le(0.7f, 1.3f, 2.0f);
    auto scene = volumeFurnace(Medium::homogeneous(Rgb(0.6f), Rgb(0.6f), 0.5f, le), le, 24);
    RenderOptions opt;
    opt.algorithm = "vpt";
    opt.maxPathLength = 1000;
    opt.seed = 5;
    Stats s = render(*scene, opt, 24);
    for (int c = 0; c < 3; ++c) {
        double m = Stats::meanOf(s.imageMeans[c]);
        double se = std::sqrt(Stats::varOfMean(s.imageMeans[c]));
        EXPECT_NEAR(m, le[c], 5.0 * se + 1e-6 * le[c]) << "channel " << c;
        EXPECT_LT(se, 0.02 * le[c]);
    }
}

/// Floor, back wall, an area light and a medium in the box [-0.5, 0.5]^3 (imaginary
/// boundary), seen from the front. medium: the medium inside the box.
std::unique_ptr<Scene> mediumBoxScene(const Medium& medium, int res) {
    auto scene = std::make_unique<Scene>();
    Material white;
    white.diffuse = Rgb(0.7f);
    int mat = scene->addMaterial(white);
    TriangleMesh floor = makeRectangle();
    transformMesh(floor, Transform::translate(Vec3(0, -0.5f, 0)) *
                             Transform::rotate(-90.0f, Vec3(1, 0, 0)) *
                             Transform::scale(Vec3(2.0f)));
    scene->addMesh(floor, mat, -1, "floor");
    TriangleMesh back = makeRectangle();
    transformMesh(back, Transform::translate(Vec3(0, 0.5f, -1.5f)) * Transform::scale(Vec3(2.0f)));
    scene->addMesh(back, mat, -1, "back");
    TriangleMesh lamp = makeRectangle();
    transformMesh(lamp, Transform::translate(Vec3(0, 1.2f, 0)) *
                            Transform::rotate(90.0f, Vec3(1, 0, 0)) * Transform::scale(Vec3(0.3f)));
    Light light;
    light.type = LightType::Area;
    light.radiance = Rgb(15.0f);
    for (uint32_t i : lamp.indices) light.triangles.push_back(lamp.positions[i]);
    int lightId = scene->addLight(light);
    scene->addMesh(lamp, mat, lightId, "lamp");
    int med = scene->addMedium(medium, "box medium");
    TriangleMesh box = makeCube();
    box.normals.clear();
    transformMesh(box, Transform::scale(Vec3(0.5f)));
    uint32_t b = scene->addMesh(box, -1, -1, "box");
    scene->setMediumBoundary(b, med, 0, true);
    scene->camera.setup(Vec3(0, 0.3f, 3.0f), Vec3(0, 0, 0), Vec3(0, 1, 0), 45.0f, res, res);
    scene->commit();
    return scene;
}

TEST(Vpt, ConstantVdbMatchesHomogeneous) {
    // 8^3 voxels of density 1, voxel size 1/8, centred so that the cells cover [-0.5, 0.5]^3.
    DenseFloatGrid dense(8, 8, 8, 1.0f);
    dense.voxelSize = 0.125f;
    dense.origin = Vec3(-0.4375f);
    auto grid = VdbGrid::fromDense(dense, "density", "constant grid");
    const float sigmaT = 2.0f;
    const Rgb albedo(0.9f, 0.7f, 0.5f);
    auto gridScene = mediumBoxScene(Medium::heterogeneous(grid, sigmaT, albedo, 0.4f), 32);
    auto homScene = mediumBoxScene(
        Medium::homogeneous((Rgb(1.0f) - albedo) * sigmaT, albedo * sigmaT, 0.4f), 32);
    RenderOptions opt;
    opt.algorithm = "vpt";
    opt.maxPathLength = 12;
    const int iterations = 48;
    opt.seed = 101;
    Stats a = render(*gridScene, opt, iterations);
    opt.seed = 202;  // independent samples: a genuine two-sample test
    Stats b = render(*homScene, opt, iterations);
    // Image mean per channel: two-sample z-test at 5 standard errors.
    for (int c = 0; c < 3; ++c) {
        double d = Stats::meanOf(a.imageMeans[c]) - Stats::meanOf(b.imageMeans[c]);
        double se =
            std::sqrt(Stats::varOfMean(a.imageMeans[c]) + Stats::varOfMean(b.imageMeans[c]));
        EXPECT_LT(std::fabs(d), 5.0 * se) << "channel " << c;
        EXPECT_LT(se, 0.02 * Stats::meanOf(b.imageMeans[c]));
    }
    // Per 4x4 block (64 blocks): two-sample z-test at 4.5 standard errors (two-sided
    // p = 6.8e-6 each, < 5e-4 for all blocks together; the standard errors come from 48
    // i.i.d. iteration means per block, so the normal approximation is adequate).
    int failures = 0;
    for (size_t k = 0; k < a.blockMeans.size(); ++k) {
        double d = Stats::meanOf(a.blockMeans[k]) - Stats::meanOf(b.blockMeans[k]);
        double se =
            std::sqrt(Stats::varOfMean(a.blockMeans[k]) + Stats::varOfMean(b.blockMeans[k]));
        if (!(std::fabs(d) <= 4.5 * se + 1e-7) && failures++ < 5)
            ADD_FAILURE() << "block " << k << ": difference " << d << " stderr " << se;
    }
    EXPECT_EQ(failures, 0);
}

const char* kNoMediaScene = R"json({
  "camera": {"position": [0, 1, 4], "target": [0, 0.6, 0], "fov": 45, "resolution": [32, 32]},
  "settings": {"max_path_length": 8},
  "materials": {"white": {"type": "diffuse", "reflectance": 0.7},
                "red": {"type": "diffuse", "reflectance": [0.7, 0.1, 0.1]},
                "glass": {"type": "dielectric", "ior": 1.5},
                "metal": {"type": "rough_conductor", "metal": "gold", "alpha": 0.2}},
  "shapes": [
    {"type": "rectangle", "material": "white", "transform": {"scale": 2, "rotate": {"axis": [1, 0, 0], "angle": -90}}},
    {"type": "rectangle", "material": "red", "transform": {"scale": 2, "translate": [0, 1, -1.5]}},
    {"type": "sphere", "material": "glass", "center": [-0.5, 0.4, 0], "radius": 0.4},
    {"type": "sphere", "material": "metal", "center": [0.6, 0.35, 0.2], "radius": 0.35},
    {"type": "rectangle", "emission": 12, "transform": {"scale": 0.3, "rotate": {"axis": [1, 0, 0], "angle": 90}, "translate": [0, 2, 0]}}
  ],
  "lights": [{"type": "point", "position": [1, 1.5, 1], "intensity": 1}]
})json";

TEST(Vpt, MatchesPtWithoutMedia) {
    auto scene = loadJsonSceneFromString(kNoMediaScene, "no-media.json", "");
    ASSERT_FALSE(scene->hasMedia());
    RenderOptions opt;
    opt.maxPathLength = 8;
    opt.seed = 3;
    auto pt = makeIntegrator(*scene, opt);
    opt.algorithm = "vpt";
    auto vpt = makeIntegrator(*scene, opt);
    // Without media vpt draws the same random numbers in the same order as pt (no
    // free-flight sampling happens), so with the same seed the images agree up to float
    // rounding of the emitter distance in the MIS weights: per pixel within 1e-4 relative.
    const int iterations = 8;
    double sumPt = 0, sumVpt = 0;
    int failures = 0;
    Image a, b;
    for (int it = 0; it < iterations; ++it) {
        pt->renderIteration(it, a);
        vpt->renderIteration(it, b);
        for (size_t i = 0; i < a.pixels.size(); ++i)
            for (int c = 0; c < 3; ++c) {
                double x = a.pixels[i][c], y = b.pixels[i][c];
                sumPt += x;
                sumVpt += y;
                if (!(std::fabs(x - y) <= 1e-4 * std::max(std::fabs(x), 1.0)) && failures++ < 5)
                    ADD_FAILURE() << "iteration " << it << " pixel " << i << ": pt " << x << " vpt "
                                  << y;
            }
    }
    EXPECT_EQ(failures, 0);
    EXPECT_NEAR(sumVpt / sumPt, 1.0, 1e-5);
    EXPECT_GT(sumPt, 0.0);
}

TEST(Vpt, SameSeedSameImage) {
    auto scene = mediumBoxScene(Medium::homogeneous(Rgb(0.2f), Rgb(1.5f), 0.6f), 16);
    RenderOptions opt;
    opt.algorithm = "vpt";
    opt.seed = 9;
    auto x = makeIntegrator(*scene, opt);
    auto y = makeIntegrator(*scene, opt);
    Image a, b;
    x->renderIteration(3, a);
    y->renderIteration(3, b);
    ASSERT_EQ(a.pixels.size(), b.pixels.size());
    for (size_t i = 0; i < a.pixels.size(); ++i)
        for (int c = 0; c < 3; ++c) ASSERT_EQ(a.pixels[i][c], b.pixels[i][c]);
}

}  // namespace
}  // namespace ub
