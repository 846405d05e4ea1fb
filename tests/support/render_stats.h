// Statistics of progressive renders for agreement tests: per-iteration block
// means of a downsampled image, their mean and standard error over independent
// iterations, and z-tests between two renders with a Sidak-corrected
// per-block significance level.
//
// Why iterations: every iteration of a unibeam integrator uses fresh random
// streams (Rng::forPath(seed, iteration, ...)), so the per-iteration estimates of a
// block mean are independent; their sample standard deviation / sqrt(n) is the
// standard error of the block mean. (Merging algorithms change the radius between
// iterations, so their iterations are independent but not identically distributed;
// the spread then slightly overestimates the error, which makes tests conservative.)
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/image.h"
#include "render/integrator.h"

namespace ub::test {

struct BlockStats {
    int blocksX = 0, blocksY = 0, blockSize = 0, n = 0;
    std::vector<double> sum, sumSq;  ///< per block and channel: 3 * b + c
    double imageSum[3] = {0, 0, 0}, imageSumSq[3] = {0, 0, 0};

    int blockCount() const { return blocksX * blocksY; }
    double mean(int b, int c) const { return sum[size_t(3 * b + c)] / n; }
    double stdErr(int b, int c) const {
        double m = mean(b, c);
        double var = (sumSq[size_t(3 * b + c)] - n * m * m) / (n - 1);
        return std::sqrt(std::max(0.0, var) / n);
    }
    double imageMean(int c) const { return imageSum[c] / n; }
    double imageStdErr(int c) const {
        double m = imageMean(c);
        double var = (imageSumSq[c] - n * m * m) / (n - 1);
        return std::sqrt(std::max(0.0, var) / n);
    }

    void add(const Image& img) {
        if (sum.empty()) {
            blocksX = img.width / blockSize;
            blocksY = img.height / blockSize;
            sum.assign(size_t(3 * blockCount()), 0.0);
            sumSq = sum;
        }
        std::vector<double> block(size_t(3 * blockCount()), 0.0);
        double image[3] = {0, 0, 0};
        for (int y = 0; y < blocksY * blockSize; ++y)
            for (int x = 0; x < blocksX * blockSize; ++x) {
                int b = (y / blockSize) * blocksX + x / blockSize;
                for (int c = 0; c < 3; ++c) {
                    block[size_t(3 * b + c)] += img.at(x, y)[c];
                    image[c] += img.at(x, y)[c];
                }
            }
        const double perBlock = double(blockSize * blockSize);
        for (size_t i = 0; i < block.size(); ++i) {
            double v = block[i] / perBlock;
            sum[i] += v;
            sumSq[i] += v * v;
        }
        const double perImage = perBlock * blockCount();
        for (int c = 0; c < 3; ++c) {
            imageSum[c] += image[c] / perImage;
            imageSumSq[c] += (image[c] / perImage) * (image[c] / perImage);
        }
        ++n;
    }
};

inline BlockStats renderBlockStats(Integrator& integrator, int iterations, int blockSize) {
    BlockStats s;
    s.blockSize = blockSize;
    Image img;
    for (int it = 0; it < iterations; ++it) {
        integrator.renderIteration(it, img);
        s.add(img);
    }
    return s;
}

/// Image mean and its standard error per channel over `iterations` iterations
/// (renderBlockStats), and 5 standard errors of the difference of two such means.
struct ImageMeans {
    double mean[3] = {0, 0, 0}, stdErr[3] = {0, 0, 0};
    double fiveSigmaTo(const ImageMeans& o, int c) const {
        return 5.0 * std::sqrt(stdErr[c] * stdErr[c] + o.stdErr[c] * o.stdErr[c]);
    }
};
inline ImageMeans renderImageMeans(Integrator& integrator, int iterations, int blockSize) {
    const BlockStats s = renderBlockStats(integrator, iterations, blockSize);
    ImageMeans m;
    for (int c = 0; c < 3; ++c) {
        m.mean[c] = s.imageMean(c);
        m.stdErr[c] = s.imageStdErr(c);
    }
    return m;
}

/// Two-sided normal p-value of |z|.
inline double twoSidedP(double z) {
    return std::erfc(std::fabs(z) / std::sqrt(2.0));
}

/// Critical |z| for a two-sided test at level alpha (bisection on erfc).
inline double criticalZ(double alpha) {
    double lo = 0, hi = 40;
    for (int i = 0; i < 200; ++i) {
        double mid = 0.5 * (lo + hi);
        (twoSidedP(mid) > alpha ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

/// Sidak-corrected per-test level for m tests at family-wise level alpha.
inline double sidakLevel(double alpha, int m) {
    return 1.0 - std::pow(1.0 - alpha, 1.0 / m);
}

struct Agreement {
    double meanZ[3] = {0, 0, 0};  ///< image mean difference in standard errors, per channel
    double minBlockP = 1;         ///< smallest per-block two-sided p-value
    double sidakMinP = 1;         ///< the same, Sidak-adjusted: 1 - (1 - p)^m
    int worstBlock = -1, worstChannel = 0;
    int tests = 0;
    std::string report;  ///< one line for logs
};

/// Compares a render against a reference block by block (3 channels each) and by image mean.
inline Agreement compare(const BlockStats& a, const BlockStats& ref) {
    Agreement g;
    for (int c = 0; c < 3; ++c) {
        double se = std::sqrt(a.imageStdErr(c) * a.imageStdErr(c) +
                              ref.imageStdErr(c) * ref.imageStdErr(c));
        g.meanZ[c] = (a.imageMean(c) - ref.imageMean(c)) / se;
    }
    g.tests = 3 * a.blockCount();
    for (int b = 0; b < a.blockCount(); ++b)
        for (int c = 0; c < 3; ++c) {
            double se =
                std::sqrt(a.stdErr(b, c) * a.stdErr(b, c) + ref.stdErr(b, c) * ref.stdErr(b, c));
            double diff = a.mean(b, c) - ref.mean(b, c);
            double p = se > 0 ? twoSidedP(diff / se) : (diff == 0 ? 1.0 : 0.0);
            if (p < g.minBlockP) {
                g.minBlockP = p;
                g.worstBlock = b;
                g.worstChannel = c;
            }
        }
    g.sidakMinP = 1.0 - std::pow(1.0 - g.minBlockP, double(g.tests));
    char buf[256];
    std::snprintf(buf, sizeof(buf),
                  "mean z = (%.2f, %.2f, %.2f), min block p = %.3g (Sidak-adjusted %.3g, "
                  "%d tests), worst block %d channel %d",
                  g.meanZ[0], g.meanZ[1], g.meanZ[2], g.minBlockP, g.sidakMinP, g.tests,
                  g.worstBlock, g.worstChannel);
    g.report = buf;
    return g;
}

}  // namespace ub::test
