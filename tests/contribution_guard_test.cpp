// The contribution guard (render/contribution_guard.h): no NaN, infinite or negative value
// reaches an image, and every dropped contribution is counted for its technique.
//  * the check itself, the guard with and without a fault;
//  * SplatBuffer and Film drop and count invalid values, the rest adds up as before;
//  * end to end: every algorithm, and each of upbp's techniques, with its contributions
//    faulted (NaN, +Inf, -Inf, negative) at every k-th pixel through RenderOptions::testFault:
//    the image and its layers stay finite and >= 0, the faulted technique counts rejections
//    (exactly the faulted pixels, where each pixel has one contribution per iteration), the
//    others none, the counts are the same on 1 thread, and they reach the summary line and
//    the EXR header as the render command writes them.
#include "render/contribution_guard.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "core/image.h"
#include "render/film.h"
#include "render/integrator.h"
#include "render/progressive.h"
#include "scene/io/json_loader.h"
#include "tests/support/temp_file.h"

using namespace ub;

namespace {

const float kNan = std::numeric_limits<float>::quiet_NaN();
const float kInfinity = std::numeric_limits<float>::infinity();

std::unique_ptr<Scene> loadBundled(const std::string& file, int res) {
    const std::string dir = std::string(UNIBEAM_SOURCE_DIR) + "/scenes";
    std::ifstream in(dir + "/" + file);
    EXPECT_TRUE(in.good()) << "missing scene " << dir << "/" << file;
    nlohmann::json j = nlohmann::json::parse(in);
    j["camera"]["resolution"] = {res, res};
    return loadJsonSceneFromString(j.dump(), file, dir);
}

void expectValidImage(const Image& img, const std::string& what) {
    for (size_t i = 0; i < img.pixels.size(); ++i)
        ASSERT_TRUE(isValidContribution(img.pixels[i]))
            << what << " pixel " << i << " = " << img.pixels[i].x << " " << img.pixels[i].y << " "
            << img.pixels[i].z;
}

uint64_t countOf(const RejectionCounts& counts, const std::string& technique) {
    for (const auto& [t, n] : counts)
        if (t == technique) return n;
    ADD_FAILURE() << "no technique '" << technique << "' in " << formatRejections(counts);
    return 0;
}

ProgressiveResult render(const Scene& scene, const RenderOptions& opt, int iterations) {
    auto integrator = makeIntegrator(scene, opt);
    ProgressiveOptions po;
    po.iterations = iterations;
    std::atomic<bool> stop{false};
    po.stop = &stop;
    return renderProgressive(*integrator, scene.camera.width(), scene.camera.height(), po);
}

}  // namespace

TEST(ContributionGuard, ChecksEveryChannel) {
    EXPECT_TRUE(isValidContribution(Rgb(0.0f)));
    EXPECT_TRUE(isValidContribution(Rgb(-0.0f)));
    EXPECT_TRUE(isValidContribution(Rgb(1.0f, 2.0f, std::numeric_limits<float>::max())));
    EXPECT_TRUE(isValidContribution(Rgb(std::numeric_limits<float>::denorm_min())));
    for (int c = 0; c < 3; ++c)
        for (float bad : {kNan, kInfinity, -kInfinity, -1e-30f, -1.0f}) {
            Rgb v(0.5f);
            v[c] = bad;
            EXPECT_FALSE(isValidContribution(v)) << "channel " << c << " value " << bad;
        }
}

TEST(ContributionGuard, FiltersAndFaultsOnlyItsTechnique) {
    uint64_t rejected = 0;
    ContributionGuard plain;
    Rgb v(1.0f, kNan, 0.0f);
    EXPECT_FALSE(plain.filter(3, &v, &rejected));
    EXPECT_EQ(rejected, 1u);
    EXPECT_EQ(v.x, 0.0f);  // replaced by black
    EXPECT_EQ(v.y, 0.0f);
    v = Rgb(0.25f);
    EXPECT_TRUE(plain.filter(3, &v, &rejected));
    EXPECT_EQ(v.x, 0.25f);
    EXPECT_EQ(rejected, 1u);

    ContributionFault fault;
    fault.technique = "pp3d";
    fault.every = 4;
    fault.value = -2.0f;
    ContributionGuard other("bb1d", fault), faulted("pp3d", fault);
    rejected = 0;
    for (uint32_t p = 0; p < 16; ++p) EXPECT_TRUE(other.accept(p, Rgb(1.0f), &rejected));
    EXPECT_EQ(rejected, 0u);
    for (uint32_t p = 0; p < 16; ++p)
        EXPECT_EQ(faulted.accept(p, Rgb(1.0f), &rejected), p % 4 != 0);
    EXPECT_EQ(rejected, 4u);
    // A fault with a valid value replaces the contribution, which is then accepted.
    fault.value = 7.0f;
    ContributionGuard replacing("pp3d", fault);
    v = Rgb(1.0f);
    EXPECT_TRUE(replacing.filter(8, &v, &rejected));
    EXPECT_EQ(v.y, 7.0f);
}

TEST(ContributionGuard, SplatBufferDropsAndCountsPerChunk) {
    SplatBuffer splats(4, 2);
    const float bad[] = {kNan, kInfinity, -kInfinity, -0.5f};
    // 64 chunks each add one good and (for every second chunk) one bad splat.
    splats.forEachChunk(128, [&](SplatBuffer::Chunk& chunk, size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i) {
            if (i % 2 == 0)
                chunk.add(Vec2(float(i % 4) + 0.5f, float((i / 4) % 2) + 0.5f), Rgb(1.0f));
            if (i % 4 == 1) chunk.addPixel(int(i % 4), 1, Rgb(0.1f, bad[(i / 4) % 4], 0.1f));
        }
    });
    EXPECT_EQ(splats.rejectedCount(), 32u);
    EXPECT_EQ(splats.splatCount(), 64u);
    Image img(4, 2);
    splats.resolve(img);
    expectValidImage(img, "splats");
    double sum = 0;
    for (const Rgb& p : img.pixels) sum += p.x + p.y + p.z;
    EXPECT_DOUBLE_EQ(sum, 64.0 * 3.0);  // only the good splats
    splats.clear();
    EXPECT_EQ(splats.rejectedCount(), 0u);
    EXPECT_EQ(splats.splatCount(), 0u);
}

TEST(ContributionGuard, FilmDropsAndCountsInvalidPixels) {
    Film film(3, 1);
    Image a(3, 1), b(3, 1);
    a.pixels = {Rgb(1.0f), Rgb(kNan, 1.0f, 1.0f), Rgb(2.0f)};
    b.pixels = {Rgb(-1.0f), Rgb(3.0f), Rgb(kInfinity)};
    film.addIteration(a);
    film.addIteration(b);
    EXPECT_EQ(film.rejected(), 3u);
    Image avg = film.average();
    expectValidImage(avg, "film");
    EXPECT_FLOAT_EQ(avg.pixels[0].x, 0.5f);
    EXPECT_FLOAT_EQ(avg.pixels[1].x, 1.5f);
    EXPECT_FLOAT_EQ(avg.pixels[2].x, 1.0f);
    film.reset(3, 1);
    EXPECT_EQ(film.rejected(), 0u);
}

// Every algorithm with its own contributions faulted: the image stays valid and the count is
// that of the faulted pixel estimates (each pixel has exactly one per iteration; light
// tracing's splats add more for the bidirectional ones).
TEST(ContributionGuard, EveryAlgorithmDropsItsFaultedContributions) {
    auto surfaces = loadBundled("cornell-large-light.json", 12);
    auto fog = loadBundled("cornell-fog.json", 12);
    const int iterations = 2;
    const uint32_t every = 5;
    const uint64_t pixels = 12 * 12;
    const uint64_t faultedPixels = (pixels + every - 1) / every;
    const float values[] = {kNan, kInfinity, -kInfinity, -1.0f};
    int k = 0;
    for (const char* algorithm : {"pt", "lt", "bpt", "ppm", "bpm", "vcm", "vpt", "vlt", "vbpt"}) {
        const bool media = algorithm[0] == 'v' && std::string(algorithm) != "vcm";
        const Scene& scene = media ? *fog : *surfaces;
        RenderOptions opt;
        opt.algorithm = algorithm;
        opt.seed = 3;
        opt.maxPathLength = 4;
        opt.testFault.technique = algorithm;
        opt.testFault.every = every;
        opt.testFault.value = values[k++ % 4];
        ProgressiveResult r = render(scene, opt, iterations);
        std::printf("[ guard    ] %s faulted: %s\n", algorithm,
                    formatRejections(r.rejected).c_str());
        expectValidImage(r.image, algorithm);
        ASSERT_EQ(r.rejected.size(), 2u) << formatRejections(r.rejected);
        EXPECT_EQ(r.rejected[0].first, algorithm);
        EXPECT_EQ(r.rejected[1].first, "film");
        EXPECT_EQ(r.rejected[1].second, 0u) << algorithm;
        // Camera-pass estimates of the faulted pixels, plus (light tracing) their splats.
        const uint64_t n = r.rejected[0].second;
        const std::string a = algorithm;
        if (a == "pt" || a == "vpt" || a == "ppm" || a == "bpm")
            EXPECT_EQ(n, faultedPixels * iterations) << algorithm;
        else
            EXPECT_GT(n, faultedPixels * iterations) << algorithm;
        // The faulted pixels got nothing from the camera pass of pt (their only technique).
        if (a == "pt")
            for (uint64_t p = 0; p < pixels; p += every)
                EXPECT_EQ(r.image.pixels[p].x, 0.0f) << "pixel " << p;
        // Unfaulted, the same render rejects nothing.
        opt.testFault = ContributionFault();
        ProgressiveResult clean = render(scene, opt, iterations);
        EXPECT_EQ(countOf(clean.rejected, algorithm), 0u) << algorithm;
    }
}

// Each of upbp's techniques faulted alone: the beauty image and every layer stay valid, only
// that technique counts, the counts are the same on one thread, and they reach the summary
// line and the EXR header.
TEST(ContributionGuard, UpbpCountsPerTechniqueAndWritesThem) {
    auto scene = loadBundled("cornell-fog.json", 16);
    const std::vector<std::string> techniques = {"bpt", "surf", "pp3d", "pb2d", "bp2d", "bb1d"};
    const float values[] = {kNan, kInfinity, -3.0f, -kInfinity, kNan, kInfinity};
    for (size_t t = 0; t < techniques.size(); ++t) {
        RenderOptions opt;
        opt.algorithm = "upbp";
        opt.seed = 5;
        opt.maxPathLength = 5;
        opt.testFault.technique = techniques[t];
        opt.testFault.every = 3;
        opt.testFault.value = values[t];
        ProgressiveResult r = render(*scene, opt, 2);
        std::printf("[ guard    ] upbp, %s faulted: %s\n", techniques[t].c_str(),
                    formatRejections(r.rejected).c_str());
        expectValidImage(r.image, techniques[t]);
        ASSERT_EQ(r.layers.size(), techniques.size());
        for (const auto& [name, layer] : r.layers)
            expectValidImage(layer, techniques[t] + ": " + name);
        ASSERT_EQ(r.rejected.size(), techniques.size() + 1) << formatRejections(r.rejected);
        for (size_t u = 0; u < techniques.size(); ++u) {
            EXPECT_EQ(r.rejected[u].first, techniques[u]);
            if (u == t)
                EXPECT_GT(r.rejected[u].second, 0u) << techniques[t];
            else
                EXPECT_EQ(r.rejected[u].second, 0u)
                    << "faulted " << techniques[t] << ", counted " << formatRejections(r.rejected);
        }
        EXPECT_EQ(countOf(r.rejected, "film"), 0u);
        // The faulted layer has nothing at the faulted pixels.
        const Image& layer = r.layers[t].second;
        for (size_t p = 0; p < layer.pixels.size(); p += 3)
            EXPECT_EQ(layer.pixels[p].x + layer.pixels[p].y + layer.pixels[p].z, 0.0f)
                << techniques[t] << " pixel " << p;

        // Thread-count independent.
        ProgressiveResult one;
        tbb::task_arena arena(1);
        arena.execute([&] { one = render(*scene, opt, 2); });
        EXPECT_EQ(formatRejections(one.rejected), formatRejections(r.rejected));

        // What the render command prints and writes (render_command.cpp).
        const std::string line = formatRejections(r.rejected);
        EXPECT_NE(line.find(techniques[t] + " " + std::to_string(r.rejected[t].second)),
                  std::string::npos)
            << line;
        ImageMetadata meta;
        for (const auto& [key, value] : rejectionAttributes(r.rejected)) meta[key] = value;
        const std::string path =
            (ub::test::processScratchDir() / ("guard_" + techniques[t] + ".exr")).string();
        writeExr(path, r.image, meta, r.layers);
        ImageMetadata back;
        Image read = readExr(path, &back);
        expectValidImage(read, "EXR of " + techniques[t]);
        for (size_t u = 0; u < techniques.size(); ++u)
            EXPECT_EQ(back["unibeam.rejected." + techniques[u]],
                      std::to_string(r.rejected[u].second));
        EXPECT_EQ(back["unibeam.rejected.film"], "0");
        std::filesystem::remove(path);
    }
}
