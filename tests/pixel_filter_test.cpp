// Reconstruction filters by filter importance sampling (scene/pixel_filter.h):
//  * PixelFilter/SampledOffsetsFollowTheFilter: chi-square of sampled raster positions
//    against the normalised filter, for interior and border pixels (where the filter is
//    restricted to the image), for tent and Gaussian filters;
//  * PixelFilter/SplatWeightIsTheSampledDensity: splatWeight() integrates to 1 over the
//    image for every pixel and is 0 outside the footprint;
//  * PixelFilter/BoxIsPixelPlusJitter: the box filter keeps pixel + u exactly;
//  * PixelFilter/CdfMatchesProfile: the analytic cdfs against numerical integrals;
//  * PixelFilterRender/LightTracingAgreesWithCameraSampling: lt and bpt (which splat with
//    the filter) converge to pt's (which samples it) filtered image of a Cornell box, and
//    that image differs from the box-filtered one (the test can see the filter).
#include "scene/pixel_filter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <vector>

#include "core/rng.h"
#include "render/integrator.h"
#include "scene/io/json_loader.h"
#include "tests/support/chi2.h"
#include "tests/support/render_stats.h"

using namespace ub;
using namespace ub::test;

namespace {

const PixelFilter kFilters[] = {PixelFilter::tent(1.0f), PixelFilter::tent(1.7f),
                                PixelFilter::gaussian(0.5f), PixelFilter::gaussian(0.8f)};

/// Chi-square test of sampleRaster(px, py) in a w x h image: the footprint, clipped to the
/// image, is divided into bins x bins cells; expected counts from the product of the 1D cdf
/// differences (the filter is separable), normalised over the clipped footprint.
double chi2SampledOffsets(const PixelFilter& f, int px, int py, int w, int h, int n, int bins,
                          uint64_t seed) {
    const double r = f.radius();
    const double cx = px + 0.5, cy = py + 0.5;
    const double x0 = std::max(0.0, cx - r), x1 = std::min(double(w), cx + r);
    const double y0 = std::max(0.0, cy - r), y1 = std::min(double(h), cy + r);
    std::vector<double> observed(size_t(bins * bins), 0.0);
    Rng rng = Rng::forPath(seed, 0, 0);
    int outside = 0;
    for (int i = 0; i < n; ++i) {
        const Vec2 p = f.sampleRaster(px, py, rng.uniform2(), w, h);
        if (!(p.x >= x0 && p.x < x1 && p.y >= y0 && p.y < y1)) {
            ++outside;
            continue;
        }
        const int bx = std::min(bins - 1, int((p.x - x0) / (x1 - x0) * bins));
        const int by = std::min(bins - 1, int((p.y - y0) / (y1 - y0) * bins));
        observed[size_t(by * bins + bx)] += 1;
    }
    EXPECT_EQ(outside, 0) << f.describe() << ": samples outside the clipped footprint";
    auto mass = [&](double a, double b, double c) { return f.cdf1(b - c) - f.cdf1(a - c); };
    const double zx = mass(x0, x1, cx), zy = mass(y0, y1, cy);
    double stat = 0;
    int dof = -1;
    double pooledObs = 0, pooledExp = 0;
    for (int by = 0; by < bins; ++by)
        for (int bx = 0; bx < bins; ++bx) {
            const double ax = x0 + (x1 - x0) * bx / bins, bxe = x0 + (x1 - x0) * (bx + 1) / bins;
            const double ay = y0 + (y1 - y0) * by / bins, bye = y0 + (y1 - y0) * (by + 1) / bins;
            const double e = n * mass(ax, bxe, cx) / zx * mass(ay, bye, cy) / zy;
            const double o = observed[size_t(by * bins + bx)];
            if (e < 5) {  // pooled
                pooledObs += o;
                pooledExp += e;
                continue;
            }
            stat += (o - e) * (o - e) / e;
            ++dof;
        }
    if (pooledExp > 0) {
        stat += (pooledObs - pooledExp) * (pooledObs - pooledExp) / std::max(pooledExp, 1e-9);
        ++dof;
    }
    return gammaQ(0.5 * dof, 0.5 * stat);
}

std::unique_ptr<Scene> cornellWithoutSpheres(int res) {
    const std::string dir = std::string(UNIBEAM_SOURCE_DIR) + "/scenes";
    std::ifstream in(dir + "/cornell-large-light.json");
    EXPECT_TRUE(in.good());
    nlohmann::json j = nlohmann::json::parse(in);
    j["camera"]["resolution"] = {res, res};
    nlohmann::json shapes = nlohmann::json::array();
    for (const auto& s : j["shapes"])
        if (s.value("type", "") != "sphere") shapes.push_back(s);
    j["shapes"] = shapes;
    return loadJsonSceneFromString(j.dump(), "cornell-large-light.json", dir);
}

}  // namespace

// 8 filters x pixels tests at level 1e-3 each (fixed seeds): 200 000 samples in 12 x 12
// cells. Pixels: interior (8, 8) of 16 x 12, the corner (0, 0), the edge pixels (15, 5)
// and (3, 11).
TEST(PixelFilter, SampledOffsetsFollowTheFilter) {
    uint64_t seed = 1;
    for (const PixelFilter& f : kFilters) {
        const int pixels[4][2] = {{8, 8}, {0, 0}, {15, 5}, {3, 11}};
        for (const auto& px : pixels) {
            const double p = chi2SampledOffsets(f, px[0], px[1], 16, 12, 200000, 12, seed++);
            EXPECT_GT(p, 1e-3) << f.describe() << " pixel (" << px[0] << ", " << px[1] << ")";
        }
    }
}

// Variance of the offset of an interior pixel against the numerically integrated second
// moment of the normalised profile (tolerance 4 standard errors of the sample variance).
TEST(PixelFilter, OffsetVarianceMatchesProfile) {
    for (const PixelFilter& f : kFilters) {
        const double r = f.radius();
        double m0 = 0, m2 = 0, m4 = 0;
        const int steps = 200000;
        for (int i = 0; i < steps; ++i) {
            const double x = -r + 2 * r * (i + 0.5) / steps;
            const double v = f.eval1(x);
            m0 += v;
            m2 += v * x * x;
            m4 += v * x * x * x * x;
        }
        const double var = m2 / m0, kurt = m4 / m0;
        Rng rng = Rng::forPath(77, 0, 0);
        const int n = 100000;
        double s2 = 0;
        for (int i = 0; i < n; ++i) {
            const double dx = f.sampleRaster(20, 20, rng.uniform2(), 40, 40).x - 20.5;
            s2 += dx * dx;
        }
        s2 /= n;
        const double se = std::sqrt((kurt - var * var) / n);
        EXPECT_NEAR(s2, var, 4 * se) << f.describe();
    }
}

TEST(PixelFilter, SplatWeightIsTheSampledDensity) {
    const int w = 9, h = 7, res = 200;  // midpoint rule, res^2 points per pixel
    for (const PixelFilter& f : kFilters) {
        for (const auto& px : {std::pair<int, int>{4, 3}, {0, 0}, {8, 6}, {1, 6}}) {
            double integral = 0;
            for (int y = 0; y < h * res; ++y)
                for (int x = 0; x < w * res; ++x) {
                    const Vec2 p((x + 0.5f) / res, (y + 0.5f) / res);
                    integral += f.splatWeight(px.first, px.second, p, w, h);
                }
            integral /= double(res) * res;
            EXPECT_NEAR(integral, 1.0, 2e-3)
                << f.describe() << " pixel " << px.first << "," << px.second;
        }
        // Outside the footprint and outside the image: 0.
        EXPECT_EQ(f.splatWeight(4, 3, Vec2(4.5f + f.radius() + 0.01f, 3.5f), w, h), 0.0f);
        EXPECT_EQ(f.splatWeight(0, 0, Vec2(-0.1f, 0.5f), w, h), 0.0f);
        // The footprint of a point covers every pixel with a non-zero weight.
        int x0, x1, y0, y1;
        const Vec2 p(3.3f, 2.9f);
        f.footprint(p, w, h, &x0, &x1, &y0, &y1);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                if (f.splatWeight(x, y, p, w, h) > 0)
                    EXPECT_TRUE(x >= x0 && x <= x1 && y >= y0 && y <= y1) << f.describe();
    }
}

// Mitsuba's ptracer convention: the camera-path weight integral(f) / S(p) (0 outside the
// image) times the sampled density equals splatWeight(). Weighted histograms of 400 000
// samples in 6 x 6 cells over the unclipped footprint against the integral of splatWeight
// over each cell, |z| < 4.5 per cell (standard error from the samples; 36 cells x 4 filters x
// 3 pixels); the expected total weight of a corner pixel is below 1 (no renormalisation).
TEST(PixelFilter, PartitionOfUnityWeightsMatchSplatWeight) {
    const int w = 10, h = 8, cells = 6, n = 400000, res = 40;
    for (const PixelFilter& base : kFilters) {
        const PixelFilter f = base.withBorder(PixelFilterBorder::kPartitionOfUnity);
        for (const auto& px : {std::pair<int, int>{5, 4}, {0, 0}, {9, 3}}) {
            const double r = f.radius(), x0 = px.first + 0.5 - r, y0 = px.second + 0.5 - r;
            const double cell = 2 * r / cells;
            std::vector<double> sum(cells * cells, 0.0), sum2(cells * cells, 0.0);
            Rng rng = Rng::forPath(5, uint64_t(px.first), uint64_t(px.second));
            double total = 0;
            for (int i = 0; i < n; ++i) {
                float wt = -1;
                const Vec2 p = f.sampleRaster(px.first, px.second, rng.uniform2(), w, h, &wt);
                ASSERT_GE(wt, 0.0f);
                total += wt;
                const int cx = std::min(cells - 1, int((p.x - x0) / cell));
                const int cy = std::min(cells - 1, int((p.y - y0) / cell));
                if (cx < 0 || cy < 0) continue;
                sum[size_t(cy * cells + cx)] += wt;
                sum2[size_t(cy * cells + cx)] += double(wt) * wt;
            }
            double expectedTotal = 0;
            for (int cy = 0; cy < cells; ++cy)
                for (int cx = 0; cx < cells; ++cx) {
                    double integral = 0;
                    for (int j = 0; j < res; ++j)
                        for (int i = 0; i < res; ++i)
                            integral +=
                                f.splatWeight(px.first, px.second,
                                              Vec2(float(x0 + cell * (cx + (i + 0.5) / res)),
                                                   float(y0 + cell * (cy + (j + 0.5) / res))),
                                              w, h);
                    integral *= cell * cell / (res * res);
                    expectedTotal += integral;
                    const size_t k = size_t(cy * cells + cx);
                    const double mean = sum[k] / n, var = sum2[k] / n - mean * mean;
                    const double se = std::sqrt(std::max(var, 0.0) / n) + 1e-4 * integral;
                    EXPECT_LT(std::fabs(mean - integral), 4.5 * se + 1e-9)
                        << f.describe() << " pixel " << px.first << "," << px.second << " cell "
                        << cx << "," << cy << ": " << mean << " vs " << integral;
                }
            if (px.first == 0) EXPECT_LT(expectedTotal, 0.95) << f.describe();
            EXPECT_NEAR(total / n, expectedTotal, 0.01) << f.describe();
        }
    }
}

TEST(PixelFilter, BoxIsPixelPlusJitter) {
    const PixelFilter box;
    EXPECT_TRUE(box.isBox());
    Rng rng = Rng::forPath(3, 0, 0);
    for (int i = 0; i < 1000; ++i) {
        const Vec2 u = rng.uniform2();
        const Vec2 p = box.sampleRaster(5, 7, u, 10, 10);
        EXPECT_EQ(p.x, 5.0f + u.x);
        EXPECT_EQ(p.y, 7.0f + u.y);
        EXPECT_EQ(box.splatWeight(5, 7, p, 10, 10), 1.0f);
        EXPECT_EQ(box.splatWeight(4, 7, p, 10, 10), 0.0f);
    }
}

TEST(PixelFilter, CdfMatchesProfile) {
    for (const PixelFilter& f : kFilters) {
        const double r = f.radius();
        const int steps = 100000;
        double total = 0;
        for (int i = 0; i < steps; ++i) total += f.eval1(-r + 2 * r * (i + 0.5) / steps);
        double acc = 0;
        for (int i = 0; i < steps; ++i) {
            const double x = -r + 2 * r * (i + 0.5) / steps;
            acc += f.eval1(x);
            if (i % 9973 == 0)
                EXPECT_NEAR(f.cdf1(-r + 2 * r * (i + 1.0) / steps), acc / total, 1e-4)
                    << f.describe() << " at " << x;
        }
        EXPECT_EQ(f.cdf1(-r), 0.0);
        EXPECT_EQ(f.cdf1(r), 1.0);
    }
    // Mitsuba's definitions: Gaussian cut off at 4 stddev, tent default radius 1.
    EXPECT_FLOAT_EQ(PixelFilter::gaussian(0.5f).radius(), 2.0f);
    EXPECT_DOUBLE_EQ(PixelFilter::gaussian(0.5f).eval1(2.0), 0.0);
    EXPECT_DOUBLE_EQ(PixelFilter::tent(1.0f).eval1(0.5), 0.5);
}

// Cornell box without spheres at 24x24 with a wide Gaussian (stddev 1 pixel, radius 4), with
// both border conventions: lt and bpt against pt, 4x4-pixel blocks (36 blocks x 3 channels,
// family-wise level 1e-3 with the Sidak correction) and image means (|z| < 3.9). Camera paths
// sample the filter, light tracing spreads its splats with splatWeight(), and bpt mixes both by
// MIS. Power: pt with the box filter differs from pt with the Gaussian at that level (the blurred
// edges of the light and the walls).
TEST(PixelFilterRender, LightTracingAgreesWithCameraSampling) {
    const int res = 24, block = 4;
    auto scene = cornellWithoutSpheres(res);
    BlockStats refRenormalized;
    auto options = [](const char* algorithm, uint64_t seed) {
        RenderOptions o;
        o.algorithm = algorithm;
        o.seed = seed;
        o.maxPathLength = 10;
        return o;
    };
    for (PixelFilterBorder border :
         {PixelFilterBorder::kRenormalized, PixelFilterBorder::kPartitionOfUnity}) {
        scene->settings.pixelFilter = PixelFilter::gaussian(1.0f).withBorder(border);
        auto pt = makeIntegrator(*scene, options("pt", 21));
        BlockStats ref = renderBlockStats(*pt, 256, block);
        if (border == PixelFilterBorder::kRenormalized) refRenormalized = ref;
        for (const char* algorithm : {"lt", "bpt"}) {
            auto integrator = makeIntegrator(*scene, options(algorithm, 22));
            BlockStats s = renderBlockStats(*integrator, algorithm[0] == 'l' ? 256 : 128, block);
            Agreement g = compare(s, ref);
            std::printf("[ filter   ] %s vs pt, %s: %s\n", algorithm,
                        scene->settings.pixelFilter.describe().c_str(), g.report.c_str());
            EXPECT_GT(g.sidakMinP, 1e-3)
                << algorithm << ": block " << g.worstBlock << " channel " << g.worstChannel << ": "
                << s.mean(g.worstBlock, 0) << " vs pt " << ref.mean(g.worstBlock, 0);
            for (int c = 0; c < 3; ++c) EXPECT_LT(std::fabs(g.meanZ[c]), 3.9) << algorithm;
        }
    }
    // Power: the box-filtered image is distinguishable from the Gaussian one.
    scene->settings.pixelFilter = PixelFilter::box();
    auto ptBox = makeIntegrator(*scene, options("pt", 23));
    BlockStats box = renderBlockStats(*ptBox, 256, block);
    Agreement g = compare(box, refRenormalized);
    std::printf("[ filter   ] pt box vs pt gaussian: %s\n", g.report.c_str());
    EXPECT_LT(g.sidakMinP, 1e-3) << "the test cannot tell the filters apart";
}
