// Path tracer (`pt`) tests on scenes built in code:
//  * Pt.SurfaceFurnaceMatchesAnalyticRadiance: closed emitting diffuse cube seen from the inside;
//  * Pt.MinPathLengthDropsShortPaths: the same furnace with a minimum path length;
//  * Pt.SameSeedSameImageAnyThreadCount: determinism with 1 and 2 threads;
//  * Pt.MisHeuristicsAgreeWithSingleStrategies: MIS (power, balance), BSDF sampling
//    alone and light sampling alone converge to the same image;
//  * Pt.EnvironmentMisAgreesWithBsdfSampling: the same for a constant environment light;
//  * Film/SplatBuffer/Progressive unit tests.
#include "render/pt.h"

#include <gtest/gtest.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <memory>
#include <vector>

#include "core/error.h"
#include "render/film.h"
#include "render/integrator.h"
#include "render/progressive.h"
#include "scene/scene.h"
#include "scene/shapes.h"

namespace ub {
namespace {

/// Cube [-1,1]^3 (scaled by halfSize) whose triangles face inwards.
TriangleMesh inwardCube(float halfSize) {
    TriangleMesh m = makeCube();
    transformMesh(m, Transform::scale(Vec3(halfSize)));
    for (size_t t = 0; t < m.triangleCount(); ++t)
        std::swap(m.indices[3 * t + 1], m.indices[3 * t + 2]);
    for (auto& n : m.normals) n = -n;
    return m;
}

/// World-space triangle soup of a mesh (3 vertices per triangle) for an area light.
std::vector<Vec3> triangleSoup(const TriangleMesh& m) {
    std::vector<Vec3> tris;
    for (uint32_t i : m.indices) tris.push_back(m.positions[i]);
    return tris;
}

/// Closed cube, inside diffuse with albedo rho, emitting Le everywhere (inwards); camera at
/// the centre. Every ray from the camera hits the wall.
std::unique_ptr<Scene> furnaceScene(const Rgb& rho, const Rgb& le, int res) {
    auto scene = std::make_unique<Scene>();
    Material mat;
    mat.type = MaterialType::Diffuse;
    mat.diffuse = rho;
    int matId = scene->addMaterial(mat);
    TriangleMesh cube = inwardCube(1.0f);
    Light light;
    light.type = LightType::Area;
    light.radiance = le;
    light.triangles = triangleSoup(cube);
    int lightId = scene->addLight(light);
    scene->addMesh(cube, matId, lightId, "furnace");
    scene->camera.setup(Vec3(0.1f, -0.05f, 0.0f), Vec3(0.3f, 0.2f, 1.0f), Vec3(0, 1, 0), 70.0f, res,
                        res);
    scene->commit();
    return scene;
}

/// Per-pixel running statistics over iterations (double precision).
struct PixelStats {
    int n = 0;
    std::vector<double> sum, sumSq;
    std::vector<double> imageMeans[3];  ///< per iteration, per channel
    void add(const Image& img) {
        if (sum.empty()) {
            sum.assign(img.pixels.size() * 3, 0.0);
            sumSq.assign(img.pixels.size() * 3, 0.0);
        }
        double m[3] = {0, 0, 0};
        for (size_t i = 0; i < img.pixels.size(); ++i)
            for (int c = 0; c < 3; ++c) {
                double v = img.pixels[i][c];
                sum[3 * i + c] += v;
                sumSq[3 * i + c] += v * v;
                m[c] += v;
            }
        for (int c = 0; c < 3; ++c) imageMeans[c].push_back(m[c] / double(img.pixels.size()));
        ++n;
    }
    double mean(size_t i, int c) const { return sum[3 * i + c] / n; }
    /// Standard error of the mean of pixel i (sample variance / n).
    double stdErr(size_t i, int c) const {
        double m = mean(i, c);
        double var = (sumSq[3 * i + c] / n - m * m) * n / (n - 1);
        return std::sqrt(std::max(0.0, var) / n);
    }
    double imageMean(int c) const {
        double s = 0;
        for (double v : imageMeans[c]) s += v;
        return s / n;
    }
    /// Standard error of the image mean: iterations are independent, so the per-iteration
    /// image means are i.i.d. samples.
    double imageStdErr(int c) const {
        double m = imageMean(c), s2 = 0;
        for (double v : imageMeans[c]) s2 += (v - m) * (v - m);
        return std::sqrt(s2 / (n - 1) / n);
    }
};

PixelStats renderStats(Integrator& integrator, const Scene& scene, int iterations) {
    PixelStats stats;
    Image img;
    for (int it = 0; it < iterations; ++it) {
        integrator.renderIteration(it, img);
        EXPECT_EQ(img.width, scene.camera.width());
        EXPECT_EQ(img.height, scene.camera.height());
        stats.add(img);
    }
    return stats;
}

// Exact radiance in the furnace: every path vertex sees emission Le and reflects with
// albedo rho, so a path of k segments carries Le rho^(k-1); summing the lengths
// minLength..maxLength gives Le * sum_{k=max(1,min)-1}^{max-1} rho^k.
Rgb furnaceRadiance(const Rgb& rho, const Rgb& le, int minLength, int maxLength) {
    Rgb sum(0.0f);
    for (int k = std::max(1, minLength) - 1; k <= maxLength - 1; ++k)
        for (int c = 0; c < 3; ++c) sum[c] += le[c] * std::pow(rho[c], float(k));
    return sum;
}

void checkFurnace(int minLength, int maxLength, MisHeuristic heuristic) {
    const Rgb rho(0.3f, 0.55f, 0.8f), le(1.0f, 2.0f, 0.5f);
    const int res = 16, iterations = 256;
    auto scene = furnaceScene(rho, le, res);
    RenderOptions opt;
    opt.maxPathLength = maxLength;
    opt.minPathLength = minLength;
    opt.seed = 7;
    opt.heuristic = heuristic;
    auto pt = makeIntegrator(*scene, opt);
    PixelStats s = renderStats(*pt, *scene, iterations);
    const Rgb exact = furnaceRadiance(rho, le, minLength, maxLength);
    // Per pixel and channel: z-test at 5 standard errors (two-sided p = 5.7e-7 each, so the
    // 16*16*3 = 768 tests reject a correct renderer with probability < 5e-4). The standard
    // error is estimated from 256 independent samples per pixel.
    int failures = 0;
    for (size_t i = 0; i < size_t(res * res); ++i)
        for (int c = 0; c < 3; ++c) {
            double err = std::fabs(s.mean(i, c) - exact[c]);
            double bound = 5.0 * s.stdErr(i, c) + 1e-6 * exact[c];
            if (!(err <= bound) && failures++ < 10)
                ADD_FAILURE() << "pixel " << i << " channel " << c << ": mean " << s.mean(i, c)
                              << " exact " << exact[c] << " bound " << bound;
        }
    EXPECT_EQ(failures, 0);
    // Image mean: 5 standard errors of the mean over 256 i.i.d. iteration means; with
    // 65536 paths this resolves a bias of ~0.5% of the radiance.
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(s.imageMean(c), exact[c], 5.0 * s.imageStdErr(c) + 1e-6)
            << "channel " << c << ", standard error " << s.imageStdErr(c);
        // The estimator must be noisy only through roulette/sampling, not wildly: a
        // sanity bound that the bound above is meaningful (stdErr below 2% of the value).
        EXPECT_LT(s.imageStdErr(c), 0.02 * exact[c]);
    }
}

TEST(Pt, SurfaceFurnaceMatchesAnalyticRadiance) {
    checkFurnace(0, 5, MisHeuristic::Power);
    checkFurnace(0, 1, MisHeuristic::Power);  // emission seen directly only
    checkFurnace(0, 3, MisHeuristic::Balance);
}

TEST(Pt, MinPathLengthDropsShortPaths) {
    checkFurnace(3, 6, MisHeuristic::Power);
}

/// Box with coloured diffuse walls, a small downward-facing area light under the ceiling,
/// a glossy Phong sphere and a diffuse sphere.
std::unique_ptr<Scene> boxScene(int res) {
    auto scene = std::make_unique<Scene>();
    Material wall;
    wall.diffuse = Rgb(0.7f, 0.6f, 0.5f);
    int wallId = scene->addMaterial(wall);
    Material glossy;
    glossy.type = MaterialType::Phong;
    glossy.diffuse = Rgb(0.2f, 0.3f, 0.4f);
    glossy.glossy = Rgb(0.5f, 0.5f, 0.5f);
    glossy.exponent = 20.0f;
    int glossyId = scene->addMaterial(glossy);
    Material red;
    red.diffuse = Rgb(0.8f, 0.2f, 0.1f);
    int redId = scene->addMaterial(red);

    scene->addMesh(inwardCube(1.0f), wallId, -1, "walls");
    TriangleMesh quad = makeRectangle();
    transformMesh(quad, Transform::translate(Vec3(0, 0.95f, 0.1f)) *
                            Transform::rotate(90.0f, Vec3(1, 0, 0)) *
                            Transform::scale(Vec3(0.35f)));
    Light light;
    light.type = LightType::Area;
    light.radiance = Rgb(6.0f, 5.0f, 4.0f);
    light.triangles = triangleSoup(quad);
    int lightId = scene->addLight(light);
    scene->addMesh(quad, -1, lightId, "light");
    scene->addSphere(Vec3(0.35f, -0.6f, 0.3f), 0.38f, glossyId, -1, "glossy sphere");
    scene->addSphere(Vec3(-0.45f, -0.7f, -0.1f), 0.28f, redId, -1, "red sphere");
    scene->camera.setup(Vec3(0, 0, -0.95f), Vec3(0, 0, 1), Vec3(0, 1, 0), 75.0f, res, res);
    scene->commit();
    return scene;
}

TEST(Pt, SameSeedSameImageAnyThreadCount) {
    auto scene = boxScene(32);
    RenderOptions opt;
    opt.seed = 12345;
    auto render = [&](int threads) {
        Image img;
        tbb::task_arena arena(threads);
        arena.execute([&] {
            auto pt = makeIntegrator(*scene, opt);
            pt->renderIteration(3, img);
        });
        return img;
    };
    Image a = render(1), b = render(2), c = render(1);
    ASSERT_EQ(a.pixels.size(), b.pixels.size());
    EXPECT_EQ(0, std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(Rgb)));
    EXPECT_EQ(0, std::memcmp(a.pixels.data(), c.pixels.data(), a.pixels.size() * sizeof(Rgb)));
    // A different seed gives a different image (the seed is actually used).
    opt.seed = 12346;
    Image d = render(2);
    EXPECT_NE(0, std::memcmp(a.pixels.data(), d.pixels.data(), a.pixels.size() * sizeof(Rgb)));
    EXPECT_GT(luminance(a.mean()), 0.0f);
}

/// Compares two renders of the same scene on 4x4 blocks of pixels and on the whole image:
/// the difference of two independent estimates must be within 5 standard errors of the
/// difference (sqrt(se1^2 + se2^2), estimated from the per-pixel sample variances).
/// 16 blocks * 3 channels + 3 image tests at 5 sigma: a correct pair fails with
/// probability < 1e-4.
void expectAgree(const PixelStats& a, const PixelStats& b, int res, const char* what) {
    const int blocks = 4, bs = res / blocks;
    for (int by = 0; by < blocks; ++by)
        for (int bx = 0; bx < blocks; ++bx)
            for (int c = 0; c < 3; ++c) {
                double ma = 0, mb = 0, va = 0, vb = 0;
                for (int y = by * bs; y < (by + 1) * bs; ++y)
                    for (int x = bx * bs; x < (bx + 1) * bs; ++x) {
                        size_t i = size_t(y) * res + x;
                        ma += a.mean(i, c);
                        mb += b.mean(i, c);
                        va += a.stdErr(i, c) * a.stdErr(i, c);
                        vb += b.stdErr(i, c) * b.stdErr(i, c);
                    }
                double n = double(bs) * bs;
                double diff = std::fabs(ma - mb) / n, se = std::sqrt(va + vb) / n;
                EXPECT_LE(diff, 5.0 * se + 1e-7)
                    << what << ": block (" << bx << "," << by << ") channel " << c << ": " << ma / n
                    << " vs " << mb / n;
            }
    for (int c = 0; c < 3; ++c) {
        double se = std::hypot(a.imageStdErr(c), b.imageStdErr(c));
        EXPECT_NEAR(a.imageMean(c), b.imageMean(c), 5.0 * se + 1e-7) << what << " channel " << c;
    }
}

TEST(Pt, MisHeuristicsAgreeWithSingleStrategies) {
    const int res = 32, iterations = 128;
    auto scene = boxScene(res);
    RenderOptions opt;
    opt.maxPathLength = 4;
    opt.seed = 3;
    PathTracer power(*scene, opt, PtStrategy::Mis);
    opt.heuristic = MisHeuristic::Balance;
    opt.seed = 4;
    PathTracer balance(*scene, opt, PtStrategy::Mis);
    opt.seed = 5;
    PathTracer bsdfOnly(*scene, opt, PtStrategy::BsdfOnly);
    opt.seed = 6;
    PathTracer lightOnly(*scene, opt, PtStrategy::LightOnly);
    PixelStats sPower = renderStats(power, *scene, iterations);
    PixelStats sBalance = renderStats(balance, *scene, iterations);
    PixelStats sBsdf = renderStats(bsdfOnly, *scene, iterations);
    PixelStats sLight = renderStats(lightOnly, *scene, iterations);
    expectAgree(sPower, sBsdf, res, "power vs BSDF sampling");
    expectAgree(sBalance, sBsdf, res, "balance vs BSDF sampling");
    expectAgree(sPower, sLight, res, "power vs light sampling");
    expectAgree(sPower, sBalance, res, "power vs balance");
    // MIS must actually help: its image-mean standard error is below BSDF sampling's.
    EXPECT_LT(sPower.imageStdErr(1), sBsdf.imageStdErr(1));
}

/// Ground quad and two spheres under a constant environment.
TEST(Pt, EnvironmentMisAgreesWithBsdfSampling) {
    const int res = 32, iterations = 96;
    Scene scene;
    Material ground;
    ground.diffuse = Rgb(0.6f, 0.6f, 0.6f);
    int groundId = scene.addMaterial(ground);
    Material glossy;
    glossy.type = MaterialType::Phong;
    glossy.diffuse = Rgb(0.1f, 0.2f, 0.5f);
    glossy.glossy = Rgb(0.4f);
    glossy.exponent = 50.0f;
    int glossyId = scene.addMaterial(glossy);
    TriangleMesh quad = makeRectangle();
    transformMesh(quad, Transform::rotate(-90.0f, Vec3(1, 0, 0)) * Transform::scale(Vec3(3.0f)));
    scene.addMesh(quad, groundId, -1, "ground");
    scene.addSphere(Vec3(0, 0.5f, 0), 0.5f, glossyId, -1, "sphere");
    Light env;
    env.type = LightType::ConstantEnv;
    env.radiance = Rgb(0.8f, 0.9f, 1.2f);
    int envId = scene.addLight(env);
    scene.backgroundLightId = envId;
    scene.camera.setup(Vec3(0, 1.5f, -3.0f), Vec3(0, 0.3f, 0), Vec3(0, 1, 0), 50.0f, res, res);
    scene.commit();
    RenderOptions opt;
    opt.maxPathLength = 3;
    opt.seed = 11;
    PathTracer mis(scene, opt, PtStrategy::Mis);
    opt.seed = 12;
    PathTracer bsdfOnly(scene, opt, PtStrategy::BsdfOnly);
    opt.seed = 13;
    PathTracer lightOnly(scene, opt, PtStrategy::LightOnly);
    PixelStats sMis = renderStats(mis, scene, iterations);
    PixelStats sBsdf = renderStats(bsdfOnly, scene, iterations);
    PixelStats sLight = renderStats(lightOnly, scene, iterations);
    expectAgree(sMis, sBsdf, res, "env: MIS vs BSDF sampling");
    expectAgree(sMis, sLight, res, "env: MIS vs light sampling");
}

// Delta lights (which only NEE can reach): a diffuse plane z = 0 of albedo rho seen straight
// down through a 0.5 degree field of view, so every pixel sees a point within
// r = h tan(0.25 deg) of the origin. The exact radiance there is
//   point light of intensity I at height h:   L = rho/pi * I cos(theta) / d^2,
//   directional light of irradiance E:        L = rho/pi * E cos(theta_light),
// and cos(theta) / d^2 varies over the visible disc by < 3 (r/h)^2 = 6e-5 (relative), the
// only difference allowed besides float rounding: bound 2e-4 relative. There is no noise:
// each light has one sample, and the plane reflects into the empty sky.
TEST(Pt, DeltaLightsMatchAnalyticDirectLight) {
    for (LightType type : {LightType::Point, LightType::Directional}) {
        Scene scene;
        Material plane;
        plane.diffuse = Rgb(0.2f, 0.5f, 0.8f);
        int planeId = scene.addMaterial(plane);
        TriangleMesh quad = makeRectangle();
        transformMesh(quad, Transform::scale(Vec3(10.0f)));
        scene.addMesh(quad, planeId, -1, "plane");
        Light light;
        light.type = type;
        const float h = 2.0f;
        Rgb expected;
        if (type == LightType::Point) {
            light.position = Vec3(0, 0, h);
            light.intensity = Rgb(3.0f, 2.0f, 1.0f);
            expected = plane.diffuse * light.intensity * (kInvPi / (h * h));
        } else {
            light.direction = normalize(Vec3(0.6f, 0.0f, -0.8f));
            light.radiance = Rgb(1.0f, 2.0f, 3.0f);
            expected = plane.diffuse * light.radiance * (kInvPi * 0.8f);
        }
        scene.addLight(light);
        scene.camera.setup(Vec3(0.0f, 0.0f, h), Vec3(0, 0, 0), Vec3(0, 1, 0), 0.5f, 8, 8);
        scene.commit();
        RenderOptions opt;
        opt.seed = 21;
        auto pt = makeIntegrator(scene, opt);
        Image img;
        for (int it = 0; it < 2; ++it) {
            pt->renderIteration(it, img);
            for (const Rgb& p : img.pixels)
                for (int c = 0; c < 3; ++c)
                    ASSERT_NEAR(p[c], expected[c], 2e-4f * expected[c])
                        << (type == LightType::Point ? "point" : "directional")
                        << " light, channel " << c;
        }
    }
}

TEST(Integrator, UnknownNameListsValidNames) {
    auto scene = furnaceScene(Rgb(0.5f), Rgb(1.0f), 4);
    RenderOptions opt;
    opt.algorithm = "nope";
    try {
        makeIntegrator(*scene, opt);
        FAIL() << "no InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("unknown algorithm 'nope'"), std::string::npos);
        EXPECT_NE(std::string(e.what()).find("pt"), std::string::npos);
    }
    auto names = integratorNames();
    EXPECT_NE(std::find(names.begin(), names.end(), "pt"), names.end());
}

TEST(Film, AverageOfIterations) {
    Film film(2, 1);
    Image a(2, 1), b(2, 1);
    a.pixels = {Rgb(1, 2, 3), Rgb(0.5f)};
    b.pixels = {Rgb(3, 2, 1), Rgb(1.5f)};
    film.addIteration(a);
    film.addIteration(b);
    Image avg = film.average();
    EXPECT_EQ(film.iterations(), 2);
    EXPECT_FLOAT_EQ(avg.pixels[0].x, 2.0f);
    EXPECT_FLOAT_EQ(avg.pixels[0].z, 2.0f);
    EXPECT_FLOAT_EQ(avg.pixels[1].y, 1.0f);
}

// Splats made by many paths onto few pixels, with values whose float sums depend on the
// order: the resolved image must be bit-identical with 1, 2 and 4 threads.
TEST(SplatBuffer, DeterministicRegardlessOfThreads) {
    const size_t paths = 10007;
    auto run = [&](int threads) {
        SplatBuffer buf(3, 2);
        Image img(3, 2);
        tbb::task_arena arena(threads);
        arena.execute([&] {
            buf.clear();
            buf.forEachChunk(paths, [&](SplatBuffer::Chunk& chunk, size_t begin, size_t end) {
                for (size_t i = begin; i < end; ++i) {
                    float v = 1.0f / float(i + 1) + float(i % 7) * 1e3f;
                    chunk.add(Vec2(float(i % 3) + 0.5f, float(i % 2) + 0.25f), Rgb(v));
                    chunk.add(Vec2(-1.0f, 0.0f), Rgb(1.0f));  // outside: ignored
                    chunk.add(Vec2(3.0f, 0.0f), Rgb(1.0f));   // outside: ignored
                }
            });
        });
        EXPECT_EQ(buf.splatCount(), paths);
        buf.resolve(img);
        return img;
    };
    Image a = run(1), b = run(2), c = run(1);
    EXPECT_EQ(0, std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(Rgb)));
    EXPECT_EQ(0, std::memcmp(a.pixels.data(), c.pixels.data(), a.pixels.size() * sizeof(Rgb)));
    // Chunks cover every path exactly once.
    size_t covered = 0, expectedBegin = 0;
    for (int k = 0; k < SplatBuffer::kChunkCount; ++k) {
        auto [b0, e0] = SplatBuffer::chunkRange(k, paths);
        EXPECT_EQ(b0, expectedBegin);
        covered += e0 - b0;
        expectedBegin = e0;
    }
    EXPECT_EQ(covered, paths);
}

/// Integrator that counts calls and writes the iteration index.
class CountingIntegrator : public Integrator {
  public:
    std::atomic<bool>* stopAfterFirst = nullptr;
    int calls = 0;
    void renderIteration(int iteration, Image& out) override {
        ++calls;
        for (auto& p : out.pixels) p = Rgb(float(iteration));
        if (stopAfterFirst) stopAfterFirst->store(true);
    }
    RejectionCounts rejectedContributions() const override { return {{"counting", 0}}; }
};

TEST(Progressive, StopsAtIterationCountAndAverages) {
    CountingIntegrator integ;
    std::atomic<bool> stop{false};
    ProgressiveOptions po;
    po.iterations = 5;
    po.stop = &stop;
    int callbacks = 0;
    po.progress = [&](const ProgressInfo& info) {
        ++callbacks;
        EXPECT_EQ(info.iteration, callbacks);
        EXPECT_EQ(info.targetIterations, 5);
        EXPECT_GE(info.etaSeconds, 0.0);
    };
    ProgressiveResult r = renderProgressive(integ, 4, 3, po);
    EXPECT_EQ(r.iterations, 5);
    EXPECT_EQ(integ.calls, 5);
    EXPECT_EQ(callbacks, 5);
    EXPECT_FALSE(r.interrupted);
    EXPECT_FLOAT_EQ(r.image.at(3, 2).x, 2.0f);  // mean of 0..4
}

TEST(Progressive, StopFlagFinishesCurrentIteration) {
    CountingIntegrator integ;
    std::atomic<bool> stop{false};
    integ.stopAfterFirst = &stop;
    ProgressiveOptions po;
    po.iterations = 100;
    po.stop = &stop;
    ProgressiveResult r = renderProgressive(integ, 2, 2, po);
    EXPECT_EQ(r.iterations, 1);
    EXPECT_TRUE(r.interrupted);
    EXPECT_FLOAT_EQ(r.image.at(0, 0).x, 0.0f);
}

TEST(Progressive, TimeLimitEndsRender) {
    CountingIntegrator integ;
    std::atomic<bool> stop{false};
    ProgressiveOptions po;
    po.timeLimitSeconds = 0.05;
    po.stop = &stop;
    ProgressiveResult r = renderProgressive(integ, 2, 2, po);
    EXPECT_GE(r.iterations, 1);
    EXPECT_GE(r.seconds, 0.05);
    EXPECT_FALSE(r.interrupted);
    ProgressiveOptions none;
    EXPECT_THROW(renderProgressive(integ, 2, 2, none), std::invalid_argument);
}

}  // namespace
}  // namespace ub
