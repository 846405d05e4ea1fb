// Media (src/scene/medium.h): exact regular tracking through NanoVDB grids,
// free-flight sampling against its pdf, spectral MIS with RGB coefficients,
// agreement of a constant grid with the equal homogeneous medium.
//
// The reference values here never call the tracker under test: pieces of a
// ray through a dense voxel block are found by brute force (every crossing of
// a cell-boundary plane, sorted), and optical depth is summed over them.
#include "scene/medium.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/rng.h"
#include "estimators/grid_access.h"
#include "scene/vdb_grid.h"
#include "tests/support/chi2.h"

namespace ub {
namespace {

struct RefPiece {
    double ta, tb, density;
};

// Pieces of the ray o + t d (grid-local space, t in [0, tMax]) through `dense`.
std::vector<RefPiece> referencePieces(const DenseFloatGrid& dense, const Vec3& o, const Vec3& d,
                                      double tMax) {
    const int n[3] = {dense.nx, dense.ny, dense.nz};
    double c0[3], dc[3];  // cell coordinates: voxel i covers [i, i + 1)
    for (int a = 0; a < 3; ++a) {
        c0[a] = (double(o[a]) - dense.origin[a]) / dense.voxelSize + 0.5;
        dc[a] = double(d[a]) / dense.voxelSize;
    }
    std::vector<double> ts = {0.0, tMax};
    for (int a = 0; a < 3; ++a) {
        if (dc[a] == 0) continue;
        for (int k = -1; k <= n[a] + 1; ++k) {
            double t = (k - c0[a]) / dc[a];
            if (t > 0 && t < tMax) ts.push_back(t);
        }
    }
    std::sort(ts.begin(), ts.end());
    std::vector<RefPiece> pieces;
    for (size_t i = 0; i + 1 < ts.size(); ++i) {
        double ta = ts[i], tb = ts[i + 1];
        if (tb <= ta) continue;
        double tm = 0.5 * (ta + tb);
        int v[3];
        bool inside = true;
        for (int a = 0; a < 3; ++a) {
            v[a] = int(std::floor(c0[a] + dc[a] * tm));
            inside = inside && v[a] >= 0 && v[a] < n[a];
        }
        pieces.push_back({ta, tb, inside ? double(dense.at(v[0], v[1], v[2])) : 0.0});
    }
    return pieces;
}

double refOpticalDepth(const std::vector<RefPiece>& pieces, double t, double scale) {
    double tau = 0;
    for (const RefPiece& p : pieces) tau += p.density * std::max(0.0, std::min(t, p.tb) - p.ta);
    return tau * scale;
}

// A density block with random values and ~30% empty voxels (zeros stay inactive).
DenseFloatGrid randomDense(int nx, int ny, int nz, uint64_t seed) {
    DenseFloatGrid dense(nx, ny, nz);
    dense.voxelSize = 0.1f;
    dense.origin = Vec3(0.2f, -0.1f, 0.05f);
    Rng rng(seed, 0);
    for (float& v : dense.values) v = rng.uniform() < 0.3f ? 0.0f : 3.0f * rng.uniform();
    return dense;
}

// ---------------------------------------------------------------------------
// Transmittance

// Density grows linearly along x: rho(i) = 0.2 + 0.15 i. With piecewise-constant voxels the
// exact optical depth is a sum over the cells the segment overlaps, computed here in closed
// form. The grid is placed in the world by a rotation, a uniform scale (2) and a translation,
// so world lengths are twice the local ones. Bound: float accumulation over < 100 pieces,
// relative 2e-5 on T.
TEST(Medium, TransmittanceLinearRamp) {
    const int n = 32;
    DenseFloatGrid dense(n, 32, 32);
    dense.voxelSize = 0.25f;
    dense.origin = Vec3(0.0f);
    for (int k = 0; k < 32; ++k)
        for (int j = 0; j < 32; ++j)
            for (int i = 0; i < n; ++i) dense.at(i, j, k) = 0.2f + 0.15f * i;
    auto grid = VdbGrid::fromDense(dense, "density");
    const float scale = 0.7f, worldScale = 2.0f;
    const Transform localToWorld = Transform::translate(Vec3(1.0f, -3.0f, 2.5f)) *
                                   Transform::rotate(37.0f, Vec3(0.3f, 1.0f, -0.2f)) *
                                   Transform::scale(Vec3(worldScale));
    Medium m = Medium::heterogeneous(grid, scale, Rgb(0.8f), 0.0f, localToWorld);

    // Segments in local space along x (y, z inside the grid), from x0 to x1.
    const double xs[][2] = {{0.3, 6.9}, {-1.0, 9.0}, {1.0, 1.1}, {2.625, 4.125}, {7.0, 0.37}};
    for (const auto& x : xs) {
        const double x0 = x[0], x1 = x[1];
        // Cell i covers [(i - 1/2) h, (i + 1/2) h]; the grid is empty outside [-h/2, (n-1/2) h].
        double tauLocal = 0;
        for (int i = 0; i < n; ++i) {
            double a = (i - 0.5) * 0.25, b = (i + 0.5) * 0.25;
            double lo = std::max(a, std::min(x0, x1)), hi = std::min(b, std::max(x0, x1));
            if (hi > lo) tauLocal += (0.2 + 0.15 * i) * (hi - lo);
        }
        const double expected = std::exp(-scale * worldScale * tauLocal);
        const Vec3 p0 = localToWorld.point(Vec3(float(x0), 3.1f, 4.4f));
        const Vec3 p1 = localToWorld.point(Vec3(float(x1), 3.1f, 4.4f));
        const float len = length(p1 - p0);
        const Vec3 dir = (p1 - p0) / len;
        Rgb T = transmittance(m, p0, dir, len);
        EXPECT_NEAR(T.x, expected, 2e-5 * expected + 1e-7) << x0 << " -> " << x1;
        EXPECT_EQ(T.x, T.y);
        EXPECT_EQ(T.x, T.z);
        // Reversing the segment gives the same transmittance.
        Rgb Tr = transmittance(m, p1, -dir, len);
        EXPECT_NEAR(Tr.x, expected, 2e-5 * expected + 1e-7);
    }
}

// Oblique segments through a random grid against the brute-force reference.
TEST(Medium, TransmittanceMatchesBruteForceReference) {
    DenseFloatGrid dense = randomDense(19, 11, 14, 7);
    auto grid = VdbGrid::fromDense(dense, "density");
    const float scale = 1.3f;
    Medium m = Medium::heterogeneous(grid, scale, Rgb(0.5f), 0.3f);
    Rng rng(11, 0);
    for (int i = 0; i < 500; ++i) {
        // End points in a box a little larger than the grid (rays start and end outside too).
        Vec3 lo(0.0f, -0.3f, -0.1f), ext(2.3f, 1.4f, 1.7f);
        Vec3 p0 = lo + rng.uniform3() * ext, p1 = lo + rng.uniform3() * ext;
        float len = length(p1 - p0);
        if (len < 1e-3f) continue;
        Vec3 dir = (p1 - p0) / len;
        double tau = refOpticalDepth(referencePieces(dense, p0, dir, len), len, scale);
        Rgb T = transmittance(m, p0, dir, len);
        EXPECT_NEAR(T.x, std::exp(-tau), 2e-5 * std::exp(-tau) + 1e-7) << i;
        MediumSegment seg = evalMediumSegment(m, p0, dir, len);
        EXPECT_EQ(seg.transmittance.x, T.x);
        // Reverse segment: same T, and the end-point extinctions swap.
        MediumSegment rev = evalMediumSegment(m, p1, -dir, len);
        double tauRev = refOpticalDepth(referencePieces(dense, p1, -dir, len), len, scale);
        EXPECT_NEAR(rev.transmittance.x, std::exp(-tauRev), 2e-5 * std::exp(-tauRev) + 1e-7)
            << i << " fwd tau " << tau << " rev tau " << tauRev << " fwdT " << T.x;
        EXPECT_NEAR(rev.pdfScatterFwdL(), seg.pdfScatterRevL(), 1e-4f * seg.pdfScatterRevL());
        EXPECT_NEAR(rev.pdfScatterRevL(), seg.pdfScatterFwdL(), 1e-4f * seg.pdfScatterFwdL());
        EXPECT_NEAR(rev.probPass(), seg.probPass(), 2e-5f);
    }
}

// The host's walk (forEachPiece, through gridPieces) and the kernels' (ub_grid_walk, here with
// the host's voxel fetch) are written separately, each with a loop that stays inside a leaf;
// both must give the same pieces, bit for bit: every piece's start and extinction, the count,
// and the optical depth. Chords start and end inside and outside the grid, some along the
// cell axes (a direction component of exactly 0), some through a rotated, scaled grid; the
// random block has leaves, part-filled leaves and 30% empty voxels. The pieces' boundaries
// are also checked against the brute-force reference (every boundary crossing, sorted).
TEST(Medium, HostAndKernelGridWalksGiveTheSamePieces) {
    DenseFloatGrid dense = randomDense(27, 19, 22, 5);
    auto grid = VdbGrid::fromDense(dense, "density");
    const Transform rotated = Transform::translate(Vec3(0.4f, -0.2f, 1.0f)) *
                              Transform::rotate(23.0f, Vec3(0.2f, 1.0f, 0.5f)) *
                              Transform::scale(Vec3(1.7f));
    Rng rng(17, 0);
    size_t pieces = 0, chords = 0;
    for (int placed = 0; placed < 2; ++placed) {
        const Transform toWorld = placed ? rotated : Transform();
        const Medium m = Medium::heterogeneous(grid, 1.1f, Rgb(0.6f), 0.0f, toWorld);
        const ub_grid_info info = gridInfo(m, 0);
        for (int i = 0; i < 1500; ++i) {
            // Local end points in a box a little larger than the grid ([0.15, 2.95] x ...).
            const Vec3 lo(-0.1f, -0.4f, -0.3f), ext(3.2f, 2.6f, 2.9f);
            Vec3 p0 = lo + rng.uniform3() * ext, p1 = lo + rng.uniform3() * ext;
            if (placed == 0 && i % 4 == 1) p1[i % 3] = p0[i % 3];  // along a cell plane's axes
            if (placed == 0 && i % 4 == 2) p1[(i + 1) % 3] = p0[(i + 1) % 3], p1[i % 3] = p0[i % 3];
            const float localLen = length(p1 - p0);
            if (localLen < 1e-3f) continue;
            const Vec3 w0 = toWorld.point(p0), w1 = toWorld.point(p1);
            const float len = length(w1 - w0);
            Vec3 dir = (w1 - w0) / len;
            if (placed == 0) dir = (p1 - p0) / localLen;  // exact zeros stay zero
            std::vector<std::pair<float, float>> host;    // (ta, sigmaT)
            std::vector<float> hostEnds;
            ASSERT_TRUE(gridPieces(m, w0, dir, len, [&](float ta, float tb, float sigmaT) {
                host.push_back({ta, sigmaT});
                hostEnds.push_back(tb);
            }));
            std::vector<ub_beam_piece> table(host.size() + 8);
            ub_grid_accessor acc{grid->grid().getAccessor()};
            float sFirst = 0.0f, sLast = 0.0f;
            ub_uint count = 0;
            const float tau = ub_grid_walk(info, &acc, ub_make_float3(w0.x, w0.y, w0.z),
                                           ub_make_float3(dir.x, dir.y, dir.z), len, len, &sFirst,
                                           &sLast, table.data(), ub_uint(table.size()), &count);
            ASSERT_EQ(size_t(count), host.size()) << placed << " " << i;
            float hostTau = 0.0f;
            for (size_t k = 0; k < host.size(); ++k) {
                ASSERT_EQ(table[k].t0, host[k].first) << placed << " " << i << " piece " << k;
                ASSERT_EQ(table[k].sigmaT, host[k].second) << placed << " " << i << " " << k;
                ASSERT_EQ(table[k].tau0, hostTau) << placed << " " << i << " piece " << k;
                hostTau += host[k].second * (hostEnds[k] - host[k].first);
                if (k + 1 < host.size()) ASSERT_EQ(hostEnds[k], host[k + 1].first);
            }
            ASSERT_EQ(tau, hostTau) << placed << " " << i;
            if (placed == 0) {
                // The boundaries against the brute-force pieces (local = world here).
                const std::vector<RefPiece> ref = referencePieces(dense, w0, dir, len);
                std::vector<double> refStarts;
                for (const RefPiece& r : ref) refStarts.push_back(r.ta);
                for (size_t k = 0; k < host.size(); ++k) {
                    const auto near = std::lower_bound(refStarts.begin(), refStarts.end(),
                                                       double(host[k].first) - 1e-5);
                    ASSERT_TRUE(near != refStarts.end() && std::fabs(*near - host[k].first) <= 1e-5)
                        << i << " piece " << k << " t " << host[k].first;
                }
            }
            pieces += host.size();
            ++chords;
        }
    }
    EXPECT_GT(chords, 2900u);
    EXPECT_GT(pieces, 15u * chords);  // mostly voxel steps through leaves (about 20 a chord)
}

// ---------------------------------------------------------------------------
// Constant grid == homogeneous medium

// 13^3 voxels of one density: the first 8^3 block is pruned into a tile, the partial blocks
// stay leaves, so both traversal paths (block skipping and voxel stepping) are exercised.
TEST(Medium, ConstantGridMatchesHomogeneous) {
    DenseFloatGrid dense(13, 13, 13, 0.8f);
    dense.voxelSize = 0.1f;
    dense.origin = Vec3(0.0f);  // covers [-0.05, 1.25]^3
    auto grid = VdbGrid::fromDense(dense, "density");
    const float scale = 1.5f, sigmaT = 0.8f * 1.5f;
    const Rgb albedo(0.9f, 0.5f, 0.2f);
    Medium mg = Medium::heterogeneous(grid, scale, albedo, 0.4f);
    Medium mh = Medium::homogeneous(Rgb(sigmaT) - albedo * sigmaT, albedo * sigmaT, 0.4f);
    Rng rng(3, 0);
    for (int i = 0; i < 2000; ++i) {
        Vec3 p0 = rng.uniform3() * 1.2f, p1 = rng.uniform3() * 1.2f;
        float len = length(p1 - p0);
        if (len < 1e-4f) continue;
        Vec3 dir = (p1 - p0) / len;
        MediumSegment sg = evalMediumSegment(mg, p0, dir, len);
        MediumSegment sh = evalMediumSegment(mh, p0, dir, len);
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(sg.transmittance[c], sh.transmittance[c], 1e-5f);
            EXPECT_NEAR(sg.sigmaT0[c], sh.sigmaT0[c], 1e-6f);
            EXPECT_NEAR(sg.sigmaT1[c], sh.sigmaT1[c], 1e-6f);
            EXPECT_NEAR(sg.sigmaS1[c], sh.sigmaS1[c], 1e-6f);
        }
        EXPECT_NEAR(sg.pdfScatterFwdL(), sh.pdfScatterFwdL(), 1e-5f);
        EXPECT_NEAR(sg.pdfScatterRevL(), sh.pdfScatterRevL(), 1e-5f);
        EXPECT_NEAR(sg.probPass(), sh.probPass(), 1e-5f);

        float uc = rng.uniform(), ud = rng.uniform();
        FreeFlightSample fg = sampleFreeFlight(mg, p0, dir, len, uc, ud);
        FreeFlightSample fh = sampleFreeFlight(mh, p0, dir, len, uc, ud);
        ASSERT_EQ(fg.scattered, fh.scattered) << i;
        EXPECT_NEAR(fg.t, fh.t, 1e-4f);
        EXPECT_NEAR(fg.pdf, fh.pdf, 1e-4f * fh.pdf);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(fg.weight[c], fh.weight[c], 1e-4f * fh.weight[c]);

        MediumCoefficients cg = mediumCoefficientsAt(mg, p0), ch = mediumCoefficientsAt(mh, p0);
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(cg.sigmaT[c], ch.sigmaT[c], 1e-6f);
            EXPECT_NEAR(cg.sigmaS[c], ch.sigmaS[c], 1e-6f);
        }
    }
}

// ---------------------------------------------------------------------------
// Free-flight sampling against its pdf (chi-square)

// Histogram of sampled distances over nBins equal bins of [0, tMax) plus one bin for
// "passed the segment". Expected mass of bin [a, b): (1/3) sum_c (T_c(a) - T_c(b)) because
// d/dt T_c = -sigma_t,c T_c; pass mass (1/3) sum_c T_c(tMax). tauRef(t) is the RGB optical
// depth of the reference. Returns the p-value.
template <typename TauRef>
double freeFlightChi2(const Medium& m, const Vec3& o, const Vec3& dir, float tMax, TauRef&& tauRef,
                      int samples, uint64_t seed) {
    const int nBins = 40;
    std::vector<double> observed(nBins + 1, 0.0), expected(nBins + 1, 0.0);
    Rng rng(seed, 0);
    for (int i = 0; i < samples; ++i) {
        FreeFlightSample s = sampleFreeFlight(m, o, dir, tMax, rng.uniform(), rng.uniform());
        int bin = s.scattered ? std::min(nBins - 1, int(s.t / tMax * nBins)) : nBins;
        observed[bin] += 1;
    }
    auto avgT = [&](double t) {
        Vec3 tau = tauRef(t);
        return (std::exp(-double(tau.x)) + std::exp(-double(tau.y)) + std::exp(-double(tau.z))) /
               3.0;
    };
    for (int b = 0; b < nBins; ++b)
        expected[b] =
            samples * (avgT(double(tMax) * b / nBins) - avgT(double(tMax) * (b + 1) / nBins));
    expected[nBins] = samples * avgT(tMax);
    return test::chi2PooledPValue(observed, expected);
}

// Three chi-square tests in this file share an overall significance of 1% (Sidak).
const double kFreeFlightAlpha = test::sidak(0.01, 3);

TEST(Medium, FreeFlightChiSquareInGrid) {
    DenseFloatGrid dense = randomDense(12, 10, 9, 21);
    auto grid = VdbGrid::fromDense(dense, "density");
    const float scale = 1.5f;
    Medium m = Medium::heterogeneous(grid, scale, Rgb(0.7f), 0.0f);
    // Oblique ray from outside the grid to beyond it (passes empty voxels and leaves).
    const Vec3 o(-0.2f, 0.1f, 0.1f), end(1.6f, 0.6f, 0.7f);
    const float tMax = length(end - o);
    const Vec3 dir = (end - o) / tMax;
    std::vector<RefPiece> pieces = referencePieces(dense, o, dir, tMax);
    auto tauRef = [&](double t) { return Vec3(float(refOpticalDepth(pieces, t, scale))); };
    double passMass = std::exp(-refOpticalDepth(pieces, tMax, scale));
    ASSERT_GT(passMass, 0.05);  // both outcomes well represented
    ASSERT_LT(passMass, 0.6);
    double p = freeFlightChi2(m, o, dir, tMax, tauRef, 200000, 1);
    EXPECT_GT(p, kFreeFlightAlpha);

    // The reported pdf is the reference density (1/3) sum_c sigma_t,c(t) T_c(t) at the
    // sampled t (skipping samples within 1e-5 of a piece boundary, where the piece is
    // ambiguous in float).
    Rng rng(2, 0);
    int checked = 0;
    for (int i = 0; i < 3000; ++i) {
        FreeFlightSample s = sampleFreeFlight(m, o, dir, tMax, rng.uniform(), rng.uniform());
        if (!s.scattered) {
            EXPECT_NEAR(s.pdf, passMass, 2e-5 * passMass);
            continue;
        }
        auto it = std::find_if(pieces.begin(), pieces.end(),
                               [&](const RefPiece& pc) { return s.t < pc.tb; });
        ASSERT_NE(it, pieces.end());
        if (s.t - it->ta < 1e-5 || it->tb - s.t < 1e-5) continue;
        double pdfRef = scale * it->density * std::exp(-refOpticalDepth(pieces, s.t, scale));
        EXPECT_NEAR(s.pdf, pdfRef, 1e-4 * pdfRef) << "t = " << s.t;
        EXPECT_NEAR(
            s.weight.x,
            0.7 * std::exp(-refOpticalDepth(pieces, s.t, scale)) * scale * it->density / pdfRef,
            1e-4);
        ++checked;
    }
    EXPECT_GT(checked, 1000);
}

TEST(Medium, FreeFlightChiSquareAxisAlignedInGrid) {
    DenseFloatGrid dense = randomDense(20, 6, 6, 5);
    auto grid = VdbGrid::fromDense(dense, "density");
    const float scale = 0.8f;
    Medium m = Medium::heterogeneous(grid, scale, Rgb(1.0f), 0.0f);
    // Along +x through voxel centres in y and z (two axes have zero direction), starting
    // inside the grid.
    const Vec3 o(0.53f, 0.2f, 0.25f), dir(1.0f, 0.0f, 0.0f);
    const float tMax = 1.9f;
    std::vector<RefPiece> pieces = referencePieces(dense, o, dir, tMax);
    auto tauRef = [&](double t) { return Vec3(float(refOpticalDepth(pieces, t, scale))); };
    EXPECT_GT(freeFlightChi2(m, o, dir, tMax, tauRef, 200000, 2), kFreeFlightAlpha);
}

// RGB extinction: the channel mixture (spectral MIS) against its analytic pdf.
TEST(Medium, FreeFlightChiSquareColouredHomogeneous) {
    const Rgb sigmaA(0.1f, 0.5f, 0.5f), sigmaS(0.2f, 0.5f, 2.0f);
    Medium m = Medium::homogeneous(sigmaA, sigmaS, 0.0f);
    const Rgb sigmaT = sigmaA + sigmaS;
    const float tMax = 2.0f;
    auto tauRef = [&](double t) { return sigmaT * float(t); };
    EXPECT_GT(freeFlightChi2(m, Vec3(0.0f), Vec3(0, 0, 1), tMax, tauRef, 200000, 3),
              kFreeFlightAlpha);
}

// ---------------------------------------------------------------------------
// Unbiasedness of coloured media

// Estimates, per channel, I = int_0^L T(t) sigma_s f(t) dt + T(L) h with the sampled
// weights (weight * f(t) when scattered, weight * h when passed). Analytic for f(t) = t,
// h = 1:  I = sigma_s / sigma_t^2 (1 - e^{-sigma_t L} (1 + sigma_t L)) + e^{-sigma_t L},
// and for sigma_t = 0: I = 1. Each channel must lie within 4 standard errors
// (sample standard deviation / sqrt(n)): a false failure has probability < 2e-4 per check.
TEST(Medium, ColouredSamplingUnbiased) {
    struct Case {
        Rgb sigmaA, sigmaS;
    };
    const Case cases[] = {
        {Rgb(0.05f, 0.3f, 1.0f), Rgb(0.15f, 0.7f, 2.0f)},  // strongly coloured
        {Rgb(0.0f, 0.5f, 0.1f), Rgb(0.0f, 0.5f, 3.0f)},    // a channel with sigma_t = 0
    };
    const float L = 1.7f;
    const int n = 400000;
    int caseIndex = 0;
    for (const Case& cs : cases) {
        Medium m = Medium::homogeneous(cs.sigmaA, cs.sigmaS, 0.0f);
        Rng rng(77, caseIndex++);
        double sum[3] = {0, 0, 0}, sum2[3] = {0, 0, 0};
        for (int i = 0; i < n; ++i) {
            FreeFlightSample s =
                sampleFreeFlight(m, Vec3(0.0f), Vec3(0, 1, 0), L, rng.uniform(), rng.uniform());
            for (int c = 0; c < 3; ++c) {
                double x = s.weight[c] * (s.scattered ? double(s.t) : 1.0);
                sum[c] += x;
                sum2[c] += x * x;
            }
        }
        for (int c = 0; c < 3; ++c) {
            double st = double(cs.sigmaA[c]) + cs.sigmaS[c], ss = cs.sigmaS[c];
            double analytic =
                st > 0 ? ss / (st * st) * (1 - std::exp(-st * L) * (1 + st * L)) + std::exp(-st * L)
                       : 1.0;
            double mean = sum[c] / n, var = std::max(0.0, sum2[c] / n - mean * mean);
            EXPECT_NEAR(mean, analytic, 4 * std::sqrt(var / n) + 1e-7)
                << "case " << caseIndex - 1 << " channel " << c;
        }
    }
}

// The same property for a grid with RGB albedo: E[weight] per channel equals
// 1 - T(L) (1 - albedo_c) ... more simply, E[w * 1_scattered] = albedo_c (1 - T(L)) and
// E[w * 1_passed] = T(L), with T from the brute-force reference.
TEST(Medium, GridSamplingUnbiased) {
    DenseFloatGrid dense = randomDense(10, 10, 10, 9);
    auto grid = VdbGrid::fromDense(dense, "density");
    const Rgb albedo(0.9f, 0.4f, 0.1f);
    Medium m = Medium::heterogeneous(grid, 2.0f, albedo, 0.0f);
    const Vec3 o(0.1f, 0.0f, 0.1f), end(1.3f, 0.8f, 0.9f);
    const float L = length(end - o);
    const Vec3 dir = (end - o) / L;
    const double T = std::exp(-refOpticalDepth(referencePieces(dense, o, dir, L), L, 2.0));
    const int n = 200000;
    Rng rng(8, 0);
    double sumS[3] = {0, 0, 0}, sumS2[3] = {0, 0, 0}, sumP = 0, sumP2 = 0;
    for (int i = 0; i < n; ++i) {
        FreeFlightSample s = sampleFreeFlight(m, o, dir, L, rng.uniform(), rng.uniform());
        if (s.scattered) {
            for (int c = 0; c < 3; ++c) {
                sumS[c] += s.weight[c];
                sumS2[c] += double(s.weight[c]) * s.weight[c];
            }
        } else {
            sumP += s.weight.x;
            sumP2 += double(s.weight.x) * s.weight.x;
        }
    }
    for (int c = 0; c < 3; ++c) {
        double mean = sumS[c] / n, var = sumS2[c] / n - mean * mean;
        EXPECT_NEAR(mean, albedo[c] * (1 - T), 4 * std::sqrt(var / n) + 1e-7) << c;
    }
    double mean = sumP / n, var = sumP2 / n - mean * mean;
    EXPECT_NEAR(mean, T, 4 * std::sqrt(var / n) + 1e-7);
}

// ---------------------------------------------------------------------------
// Parameter checks

TEST(Medium, RejectsInvalidParameters) {
    EXPECT_THROW(Medium::homogeneous(Rgb(-0.1f), Rgb(1.0f), 0.0f), std::invalid_argument);
    EXPECT_THROW(Medium::homogeneous(Rgb(0.1f), Rgb(1.0f), 1.0f), std::invalid_argument);
    DenseFloatGrid dense(2, 2, 2, 1.0f);
    auto grid = VdbGrid::fromDense(dense, "density");
    EXPECT_THROW(Medium::heterogeneous(grid, -1.0f, Rgb(0.5f), 0.0f), std::invalid_argument);
    EXPECT_THROW(Medium::heterogeneous(grid, 1.0f, Rgb(1.5f), 0.0f), std::invalid_argument);
    EXPECT_THROW(Medium::heterogeneous(nullptr, 1.0f, Rgb(0.5f), 0.0f), std::invalid_argument);
}

}  // namespace
}  // namespace ub
