// Grid media with chromatic extinction (Medium::heterogeneousRgb, one density grid per
// channel): regular tracking and the trilinear tracker give each channel the transmittance
// of that channel's own grid, free-flight sampling follows the spectral-MIS pdf (the
// average over channels, scene/medium.h), and the throughput weights are unbiased per
// channel.
//
// References never call the chromatic code under test: the nearest-filtered optical depth
// is summed over the pieces of a brute-force walk (every crossing of a cell plane), and the
// trilinear one is the grey tracker run on the single channel.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/rng.h"
#include "scene/medium.h"
#include "scene/medium_trilinear.h"
#include "scene/vdb_grid.h"
#include "tests/support/chi2.h"

namespace ub {
namespace {

// A density block with random values and ~30% empty voxels (zeros stay inactive), the same
// placement for every seed so that the channels share the index transform.
DenseFloatGrid randomDense(int nx, int ny, int nz, uint64_t seed, float maxValue) {
    DenseFloatGrid dense(nx, ny, nz);
    dense.voxelSize = 0.1f;
    dense.origin = Vec3(0.2f, -0.1f, 0.05f);
    Rng rng(seed, 0);
    for (float& v : dense.values) v = rng.uniform() < 0.3f ? 0.0f : maxValue * rng.uniform();
    return dense;
}

// Optical depth of [0, t] of the ray o + s d through `dense` (nearest voxels, 0 outside),
// times scale: the crossings of every cell-boundary plane, sorted, with the voxel at each
// piece's midpoint.
double refOpticalDepth(const DenseFloatGrid& dense, const Vec3& o, const Vec3& d, double t,
                       double scale) {
    const int n[3] = {dense.nx, dense.ny, dense.nz};
    double c0[3], dc[3];
    for (int a = 0; a < 3; ++a) {
        c0[a] = (double(o[a]) - dense.origin[a]) / dense.voxelSize + 0.5;
        dc[a] = double(d[a]) / dense.voxelSize;
    }
    std::vector<double> ts = {0.0, t};
    for (int a = 0; a < 3; ++a) {
        if (dc[a] == 0) continue;
        for (int k = -1; k <= n[a] + 1; ++k) {
            const double tk = (k - c0[a]) / dc[a];
            if (tk > 0 && tk < t) ts.push_back(tk);
        }
    }
    std::sort(ts.begin(), ts.end());
    double tau = 0;
    for (size_t i = 0; i + 1 < ts.size(); ++i) {
        const double ta = ts[i], tb = ts[i + 1], tm = 0.5 * (ta + tb);
        int v[3];
        bool inside = true;
        for (int a = 0; a < 3; ++a) {
            v[a] = int(std::floor(c0[a] + dc[a] * tm));
            inside = inside && v[a] >= 0 && v[a] < n[a];
        }
        if (inside) tau += double(dense.at(v[0], v[1], v[2])) * (tb - ta);
    }
    return tau * scale;
}

// The voxel value of `dense` at point p (0 outside).
double voxelAt(const DenseFloatGrid& dense, const Vec3& p) {
    const int n[3] = {dense.nx, dense.ny, dense.nz};
    int v[3];
    for (int a = 0; a < 3; ++a) {
        v[a] = int(std::floor((double(p[a]) - dense.origin[a]) / dense.voxelSize + 0.5));
        if (v[a] < 0 || v[a] >= n[a]) return 0.0;
    }
    return dense.at(v[0], v[1], v[2]);
}

// Trilinear filtering over the full 12 x 10 x 9 extent of the fixture's grids (what the .vol
// loader passes), so that every channel and the chromatic medium share one domain.
GridMediumOptions trilinearOptions() {
    GridMediumOptions options;
    options.filter = GridFilter::kTrilinear;
    const int n[3] = {12, 10, 9};
    for (int a = 0; a < 3; ++a) {
        options.domainLo[a] = 0;
        options.domainHi[a] = n[a] - 1;
    }
    return options;
}

// A segment between two uniform points of a box a little larger than the fixture's grids
// (false when it is too short to have a direction).
bool randomSegment(Rng& rng, Vec3* p0, Vec3* dir, float* len) {
    const Vec3 lo(-0.1f, -0.3f, -0.2f);
    *p0 = lo + rng.uniform3() * 1.6f;
    const Vec3 p1 = lo + rng.uniform3() * 1.6f;
    *len = length(p1 - *p0);
    if (*len < 1e-3f) return false;
    *dir = (p1 - *p0) / *len;
    return true;
}

struct ChromaticFixture {
    DenseFloatGrid dense[3];
    std::shared_ptr<const VdbGrid> grids[3];
    ChromaticFixture() {
        // Channel means differ by a factor 6, so the channels' distance pdfs differ strongly.
        const float maxValue[3] = {0.8f, 2.5f, 5.0f};
        for (int c = 0; c < 3; ++c) {
            dense[c] = randomDense(12, 10, 9, 31 + uint64_t(c), maxValue[c]);
            grids[c] = VdbGrid::fromDense(dense[c], "density");
        }
    }
};

// Transmittance, end-point extinction and point lookups per channel against the
// brute-force reference. Bound: float accumulation over < 100 pieces, 2e-5 relative on T.
TEST(MediumChromatic, NearestTransmittanceMatchesReferencePerChannel) {
    ChromaticFixture f;
    const float scale = 1.5f;
    const Rgb albedo(0.9f, 0.5f, 0.2f);
    Medium m = Medium::heterogeneousRgb(f.grids, scale, albedo, 0.3f, Transform());
    ASSERT_TRUE(m.chromatic());
    Rng rng(5, 0);
    for (int i = 0; i < 500; ++i) {
        Vec3 p0, dir;
        float len = 0.0f;
        if (!randomSegment(rng, &p0, &dir, &len)) continue;
        const MediumSegment seg = evalMediumSegment(m, p0, dir, len);
        const Rgb T = transmittance(m, p0, dir, len);
        for (int c = 0; c < 3; ++c) {
            const double ref = std::exp(-refOpticalDepth(f.dense[c], p0, dir, len, scale));
            EXPECT_NEAR(seg.transmittance[c], ref, 2e-5 * ref + 1e-7) << i << " channel " << c;
            EXPECT_NEAR(T[c], ref, 2e-5 * ref + 1e-7) << i << " channel " << c;
        }
        // Interior points: the coefficients are those of the voxel, per channel.
        const Vec3 mid = p0 + dir * (0.37f * len);
        const MediumCoefficients co = mediumCoefficientsAt(m, mid);
        for (int c = 0; c < 3; ++c) {
            const double refSigma = scale * voxelAt(f.dense[c], mid);
            EXPECT_NEAR(co.sigmaT[c], refSigma, 1e-3 * refSigma + 1e-4) << i << " channel " << c;
            EXPECT_NEAR(co.sigmaS[c], albedo[c] * co.sigmaT[c], 1e-6f);
        }
    }
}

// Three copies of one grid make a chromatic medium that must behave exactly like the grey
// medium of that grid: same transmittance, pdfs and free-flight samples (the channel choice
// cannot move the distance when every channel has the same optical depth).
TEST(MediumChromatic, EqualChannelsMatchTheGreyMedium) {
    const DenseFloatGrid dense = randomDense(10, 10, 10, 9, 3.0f);
    std::shared_ptr<const VdbGrid> copies[3];
    for (int c = 0; c < 3; ++c) copies[c] = VdbGrid::fromDense(dense, "density");
    const Rgb albedo(0.9f, 0.4f, 0.1f);
    for (GridFilter filter : {GridFilter::kNearest, GridFilter::kTrilinear}) {
        GridMediumOptions options;
        options.filter = filter;
        Medium rgb = Medium::heterogeneousRgb(copies, 2.0f, albedo, 0.0f, Transform(), options);
        Medium grey = Medium::heterogeneous(copies[0], 2.0f, albedo, 0.0f, Transform(), options);
        ASSERT_TRUE(rgb.chromatic());
        Rng rng(11, int(filter));
        for (int i = 0; i < 300; ++i) {
            const Vec3 p0 = rng.uniform3() * 1.2f, p1 = rng.uniform3() * 1.2f;
            const float len = length(p1 - p0);
            if (len < 1e-3f) continue;
            const Vec3 dir = (p1 - p0) / len;
            const MediumSegment a = evalMediumSegment(rgb, p0, dir, len);
            const MediumSegment b = evalMediumSegment(grey, p0, dir, len);
            for (int c = 0; c < 3; ++c) {
                EXPECT_NEAR(a.transmittance[c], b.transmittance[c], 1e-6f);
                EXPECT_NEAR(a.sigmaT0[c], b.sigmaT0[c], 1e-5f);
                EXPECT_NEAR(a.sigmaT1[c], b.sigmaT1[c], 1e-5f);
            }
            const float uc = rng.uniform(), ud = rng.uniform();
            const FreeFlightSample fa = sampleFreeFlight(rgb, p0, dir, len, uc, ud);
            const FreeFlightSample fb = sampleFreeFlight(grey, p0, dir, len, uc, ud);
            ASSERT_EQ(fa.scattered, fb.scattered) << i;
            EXPECT_NEAR(fa.t, fb.t, 1e-5f * std::max(1.0f, fb.t)) << i;
            EXPECT_NEAR(fa.pdf, fb.pdf, 1e-4f * fb.pdf + 1e-7f) << i;
        }
    }
}

// The trilinear tracker with three different grids: each channel's transmittance and
// end-point extinction equal those of the grey trilinear medium of that channel alone.
// Bound: double accumulation, 1e-5 relative on T.
TEST(MediumChromatic, TrilinearChannelsMatchTheirGreyMedia) {
    ChromaticFixture f;
    const GridMediumOptions options = trilinearOptions();
    Medium rgb = Medium::heterogeneousRgb(f.grids, 1.5f, Rgb(0.8f), 0.0f, Transform(), options);
    Medium single[3];
    for (int c = 0; c < 3; ++c)
        single[c] = Medium::heterogeneous(f.grids[c], 1.5f, Rgb(0.8f), 0.0f, Transform(), options);
    Rng rng(13, 0);
    for (int i = 0; i < 300; ++i) {
        Vec3 p0, dir;
        float len = 0.0f;
        if (!randomSegment(rng, &p0, &dir, &len)) continue;
        const MediumSegment s = evalMediumSegment(rgb, p0, dir, len);
        const MediumCoefficients co = mediumCoefficientsAt(rgb, p0);
        for (int c = 0; c < 3; ++c) {
            const MediumSegment r = evalMediumSegment(single[c], p0, dir, len);
            EXPECT_NEAR(s.transmittance[c], r.transmittance[c], 1e-5f * r.transmittance[c] + 1e-7f);
            EXPECT_NEAR(s.sigmaT0[c], r.sigmaT0[c], 1e-5f * r.sigmaT0[c] + 1e-6f);
            EXPECT_NEAR(s.sigmaT1[c], r.sigmaT1[c], 1e-5f * r.sigmaT1[c] + 1e-6f);
            EXPECT_NEAR(co.sigmaT[c], mediumCoefficientsAt(single[c], p0).sigmaT[c], 1e-6f);
        }
    }
}

// Histogram of sampled distances (40 bins of [0, tMax) and one for passing) against the
// spectral-MIS mixture: bin [a, b) has mass (1/3) sum_c (T_c(a) - T_c(b)), passing
// (1/3) sum_c T_c(tMax), with T_c from the reference of that channel. Returns the p-value.
template <typename TauRef>
double chromaticChi2(const Medium& m, const Vec3& o, const Vec3& dir, float tMax, TauRef&& tauRef,
                     int samples, uint64_t seed) {
    const int nBins = 40;
    std::vector<double> observed(nBins + 1, 0.0), expected(nBins + 1, 0.0);
    Rng rng(seed, 0);
    for (int i = 0; i < samples; ++i) {
        const FreeFlightSample s = sampleFreeFlight(m, o, dir, tMax, rng.uniform(), rng.uniform());
        observed[s.scattered ? std::min(nBins - 1, int(s.t / tMax * nBins)) : nBins] += 1;
    }
    auto avgT = [&](double t) {
        double sum = 0;
        for (int c = 0; c < 3; ++c) sum += std::exp(-tauRef(c, t));
        return sum / 3.0;
    };
    for (int b = 0; b < nBins; ++b)
        expected[b] =
            samples * (avgT(double(tMax) * b / nBins) - avgT(double(tMax) * (b + 1) / nBins));
    expected[nBins] = samples * avgT(tMax);
    return test::chi2PooledPValue(observed, expected);
}

// Two chi-square tests in this file share an overall significance of 1% (Sidak).
const double kAlpha = test::sidak(0.01, 2);

TEST(MediumChromatic, FreeFlightChiSquareNearest) {
    ChromaticFixture f;
    Medium m = Medium::heterogeneousRgb(f.grids, 1.5f, Rgb(0.7f), 0.0f, Transform());
    const Vec3 o(-0.2f, 0.1f, 0.1f), end(1.6f, 0.6f, 0.7f);
    const float tMax = length(end - o);
    const Vec3 dir = (end - o) / tMax;
    const double p = chromaticChi2(
        m, o, dir, tMax,
        [&](int c, double t) { return refOpticalDepth(f.dense[c], o, dir, t, 1.5); }, 200000, 41);
    EXPECT_GT(p, kAlpha);
}

TEST(MediumChromatic, FreeFlightChiSquareTrilinear) {
    ChromaticFixture f;
    const GridMediumOptions options = trilinearOptions();
    Medium m = Medium::heterogeneousRgb(f.grids, 1.5f, Rgb(0.7f), 0.0f, Transform(), options);
    Medium single[3];
    for (int c = 0; c < 3; ++c)
        single[c] = Medium::heterogeneous(f.grids[c], 1.5f, Rgb(0.7f), 0.0f, Transform(), options);
    const Vec3 o(-0.2f, 0.1f, 0.1f), end(1.6f, 0.6f, 0.7f);
    const float tMax = length(end - o);
    const Vec3 dir = (end - o) / tMax;
    // The reference optical depth of channel c: the grey tracker on that channel's grid.
    const double p = chromaticChi2(
        m, o, dir, tMax,
        [&](int c, double t) {
            return -std::log(double(trilinearTransmittance(single[c], o, dir, float(t)).x));
        },
        200000, 43);
    EXPECT_GT(p, kAlpha);
}

// Unbiased throughput per channel: E[w 1_scattered]_c = albedo_c (1 - T_c) and
// E[w 1_passed]_c = T_c (4 standard errors), for both filters.
TEST(MediumChromatic, SamplingUnbiasedPerChannel) {
    ChromaticFixture f;
    const Rgb albedo(0.9f, 0.4f, 0.6f);
    const Vec3 o(0.1f, 0.0f, 0.1f), end(1.3f, 0.8f, 0.9f);
    const float L = length(end - o);
    const Vec3 dir = (end - o) / L;
    for (GridFilter filter : {GridFilter::kNearest, GridFilter::kTrilinear}) {
        GridMediumOptions options = trilinearOptions();
        options.filter = filter;
        Medium m = Medium::heterogeneousRgb(f.grids, 2.0f, albedo, 0.0f, Transform(), options);
        double T[3];
        for (int c = 0; c < 3; ++c) {
            Medium single =
                Medium::heterogeneous(f.grids[c], 2.0f, albedo, 0.0f, Transform(), options);
            T[c] = filter == GridFilter::kNearest
                       ? std::exp(-refOpticalDepth(f.dense[c], o, dir, L, 2.0))
                       : double(trilinearTransmittance(single, o, dir, L).x);
        }
        const int n = 200000;
        Rng rng(8, int(filter));
        double sS[3] = {0, 0, 0}, sS2[3] = {0, 0, 0}, sP[3] = {0, 0, 0}, sP2[3] = {0, 0, 0};
        for (int i = 0; i < n; ++i) {
            const FreeFlightSample s = sampleFreeFlight(m, o, dir, L, rng.uniform(), rng.uniform());
            for (int c = 0; c < 3; ++c) {
                const double w = s.weight[c];
                (s.scattered ? sS : sP)[c] += w;
                (s.scattered ? sS2 : sP2)[c] += w * w;
            }
        }
        for (int c = 0; c < 3; ++c) {
            const double meanS = sS[c] / n, varS = sS2[c] / n - meanS * meanS;
            EXPECT_NEAR(meanS, albedo[c] * (1 - T[c]), 4 * std::sqrt(varS / n) + 1e-7)
                << "filter " << int(filter) << " channel " << c;
            const double meanP = sP[c] / n, varP = sP2[c] / n - meanP * meanP;
            EXPECT_NEAR(meanP, T[c], 4 * std::sqrt(varP / n) + 1e-7)
                << "filter " << int(filter) << " channel " << c;
        }
    }
}

TEST(MediumChromatic, RejectsMismatchedChannels) {
    ChromaticFixture f;
    DenseFloatGrid moved = f.dense[1];
    moved.voxelSize = 0.2f;  // another index transform
    std::shared_ptr<const VdbGrid> bad[3] = {f.grids[0], VdbGrid::fromDense(moved, "density"),
                                             f.grids[2]};
    EXPECT_THROW(Medium::heterogeneousRgb(bad, 1.0f, Rgb(0.5f), 0.0f, Transform()),
                 std::invalid_argument);
    std::shared_ptr<const VdbGrid> missing[3] = {f.grids[0], nullptr, f.grids[2]};
    EXPECT_THROW(Medium::heterogeneousRgb(missing, 1.0f, Rgb(0.5f), 0.0f, Transform()),
                 std::invalid_argument);
}

}  // namespace
}  // namespace ub
