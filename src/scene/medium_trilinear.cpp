// Exact transmittance and free-flight sampling for trilinear grid density
// (see scene/medium_trilinear.h for the construction). The albedo (constant or an
// albedo grid) is read once, at the end point (scene/albedo_grid.h).
#include "scene/medium_trilinear.h"

#include <algorithm>
#include <cmath>

namespace ub {

namespace {

/// density(t0 + s) = c[0] + c[1] s + c[2] s^2 + c[3] s^3 for s in [0, t1 - t0].
struct Cubic {
    double c[4] = {0, 0, 0, 0};
    double eval(double s) const { return ((c[3] * s + c[2]) * s + c[1]) * s + c[0]; }
    /// Integral over [0, s].
    double integral(double s) const {
        return (((c[3] * 0.25 * s + c[2] / 3.0) * s + c[1] * 0.5) * s + c[0]) * s;
    }
};

/// The voxels of one channel's density grid, clamped to the domain.
struct DualGrid {
    const Medium& m;
    nanovdb::DefaultReadAccessor<float> acc;
    DualGrid(const Medium& med, int channel)
        : m(med), acc(med.channelGrid(channel).grid().getAccessor()) {}
    float voxel(int i, int j, int k) {
        i = std::clamp(i, m.domainLo[0], m.domainHi[0]);
        j = std::clamp(j, m.domainLo[1], m.domainHi[1]);
        k = std::clamp(k, m.domainLo[2], m.domainHi[2]);
        return acc.getValue(nanovdb::Coord(i, j, k));
    }
};

/// Number of density channels: 1 (grey) or 3 (chromatic).
int channelCount(const Medium& m) {
    return m.chromatic() ? 3 : 1;
}

/// Product of linear polynomials a0 + a1 s.
void mulLinear(const double* p, int deg, double a0, double a1, double* out) {
    for (int i = 0; i <= deg + 1; ++i) out[i] = 0.0;
    for (int i = 0; i <= deg; ++i) {
        out[i] += p[i] * a0;
        out[i + 1] += p[i] * a1;
    }
}

/// Cubic of the trilinear density along q(s) = q0 + D s inside dual cell k.
Cubic cellCubic(DualGrid& g, const int k[3], const double q0[3], const double D[3]) {
    // Linear factors u_a(s) = a_a + b_a s (weight of the +1 corner) and 1 - u_a(s).
    double a[3], b[3];
    for (int i = 0; i < 3; ++i) {
        a[i] = q0[i] - k[i];
        b[i] = D[i];
    }
    // Interpolate along x (linear), then y (quadratic), then z (cubic).
    double h[2][3];  // per dz: quadratic in s
    for (int dz = 0; dz < 2; ++dz) {
        double gy[2][2];  // per dy: linear in s
        for (int dy = 0; dy < 2; ++dy) {
            double v0 = g.voxel(k[0], k[1] + dy, k[2] + dz);
            double v1 = g.voxel(k[0] + 1, k[1] + dy, k[2] + dz);
            // v0 (1 - u_x) + v1 u_x
            gy[dy][0] = v0 + (v1 - v0) * a[0];
            gy[dy][1] = (v1 - v0) * b[0];
        }
        double t0[3], t1[3];
        mulLinear(gy[0], 1, 1.0 - a[1], -b[1], t0);
        mulLinear(gy[1], 1, a[1], b[1], t1);
        for (int i = 0; i < 3; ++i) h[dz][i] = t0[i] + t1[i];
    }
    double f0[4], f1[4];
    mulLinear(h[0], 2, 1.0 - a[2], -b[2], f0);
    mulLinear(h[1], 2, a[2], b[2], f1);
    Cubic c;
    for (int i = 0; i < 4; ++i) c.c[i] = f0[i] + f1[i];
    return c;
}

/// Calls visit(t0, t1, cubics) for consecutive pieces covering [0, tMax] (zero density
/// outside the domain box) until visit returns false; cubics[c] is channel c's density for
/// c < channelCount(m).
template <typename Visit>
void forEachCubic(const Medium& m, const Vec3& origin, const Vec3& dir, float tMax, Visit&& visit) {
    if (!(tMax > 0.0f)) return;
    const Vec3 Pc = m.worldToCell.point(origin), Dc = m.worldToCell.vector(dir);
    double P[3], D[3], lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
        P[a] = double(Pc[a]) - 0.5;
        D[a] = Dc[a];
        lo[a] = m.domainLo[a] - 0.5;
        hi[a] = m.domainHi[a] + 0.5;
    }
    double tEnter = 0.0, tExit = tMax;
    for (int a = 0; a < 3; ++a) {
        if (D[a] == 0.0) {
            if (P[a] < lo[a] || P[a] >= hi[a]) tExit = -1.0;
            continue;
        }
        double t0 = (lo[a] - P[a]) / D[a], t1 = (hi[a] - P[a]) / D[a];
        if (t0 > t1) std::swap(t0, t1);
        tEnter = std::max(tEnter, t0);
        tExit = std::min(tExit, t1);
    }
    const Cubic zero[3];
    if (!(tEnter < tExit)) {
        visit(0.0, double(tMax), zero);
        return;
    }
    if (tEnter > 0.0 && !visit(0.0, tEnter, zero)) return;
    const int nc = channelCount(m);
    DualGrid g[3] = {DualGrid(m, 0), DualGrid(m, nc > 1 ? 1 : 0), DualGrid(m, nc > 1 ? 2 : 0)};
    Cubic cubics[3];
    double t = tEnter;
    while (t < tExit) {
        // Cell containing the midpoint of the next step: robust against round-off at planes.
        double tNext = tExit;
        int k[3];
        const double probe = t + 1e-9 * std::max(1.0, std::fabs(t));
        for (int a = 0; a < 3; ++a) {
            double q = P[a] + D[a] * probe;
            k[a] = int(std::floor(q));
            k[a] = std::clamp(k[a], m.domainLo[a] - 1, m.domainHi[a]);
            if (D[a] > 0)
                tNext = std::min(tNext, (k[a] + 1 - P[a]) / D[a]);
            else if (D[a] < 0)
                tNext = std::min(tNext, (k[a] - P[a]) / D[a]);
        }
        if (!(tNext > t)) tNext = std::min(tExit, t + 1e-9 * std::max(1.0, std::fabs(t)));
        double q0[3];
        for (int a = 0; a < 3; ++a) q0[a] = P[a] + D[a] * t;
        for (int c = 0; c < nc; ++c) cubics[c] = cellCubic(g[c], k, q0, D);
        if (!visit(t, tNext, cubics)) return;
        t = tNext;
    }
    if (tExit < tMax) visit(tExit, double(tMax), zero);
}

/// Solves F(s) = target for s in [0, L], F(s) = scale * integral of c over [0, s]
/// (non-decreasing): Newton steps kept inside a shrinking bracket, bisection otherwise.
double invertCubic(const Cubic& c, double scale, double L, double target) {
    double a = 0.0, b = L;
    double FL = scale * c.integral(L);
    double s = FL > 0 ? L * std::clamp(target / FL, 0.0, 1.0) : 0.5 * L;
    for (int it = 0; it < 100; ++it) {
        double f = scale * c.integral(s) - target;
        if (f < 0)
            a = s;
        else
            b = s;
        if (std::fabs(f) <= 1e-12 * std::max(target, 1e-30) || b - a <= 1e-12 * L) break;
        double d = scale * c.eval(s);
        double sn = d > 0 ? s - f / d : -1.0;
        s = (sn > a && sn < b) ? sn : 0.5 * (a + b);
    }
    return std::clamp(s, 0.0, L);
}

}  // namespace

float trilinearDensityAt(const Medium& m, const Vec3& p, int channel) {
    const Vec3 q = m.worldToCell.point(p);
    double qd[3], zeroD[3] = {0, 0, 0};
    int k[3];
    for (int a = 0; a < 3; ++a) {
        qd[a] = double(q[a]) - 0.5;
        if (qd[a] < m.domainLo[a] - 0.5 || qd[a] >= m.domainHi[a] + 0.5) return 0.0f;
        k[a] = std::clamp(int(std::floor(qd[a])), m.domainLo[a] - 1, m.domainHi[a]);
    }
    DualGrid g(m, m.chromatic() ? channel : 0);
    return float(std::max(0.0, cellCubic(g, k, qd, zeroD).c[0]));
}

Rgb trilinearDensityRgbAt(const Medium& m, const Vec3& p) {
    if (!m.chromatic()) return Rgb(trilinearDensityAt(m, p, 0));
    return Rgb(trilinearDensityAt(m, p, 0), trilinearDensityAt(m, p, 1),
               trilinearDensityAt(m, p, 2));
}

namespace {

/// sigma_t = densityScale * max(0, density) per channel (grey: channel 0 replicated).
Rgb sigmaFromDensity(const Medium& m, const double d[3]) {
    const double s = m.densityScale;
    if (!m.chromatic()) return Rgb(float(s * std::max(0.0, d[0])));
    return Rgb(float(s * std::max(0.0, d[0])), float(s * std::max(0.0, d[1])),
               float(s * std::max(0.0, d[2])));
}

/// exp(-tau) per channel from optical depths (grey: channel 0 replicated).
Rgb transmittanceFromTau(const Medium& m, const double tau[3]) {
    if (!m.chromatic()) return expNeg(Rgb(float(std::max(0.0, tau[0]))));
    return expNeg(Rgb(float(std::max(0.0, tau[0])), float(std::max(0.0, tau[1])),
                      float(std::max(0.0, tau[2]))));
}

}  // namespace

Rgb trilinearTransmittance(const Medium& m, const Vec3& origin, const Vec3& dir, float length) {
    const int nc = channelCount(m);
    double tau[3] = {0, 0, 0};
    forEachCubic(m, origin, dir, length, [&](double t0, double t1, const Cubic* c) {
        for (int ch = 0; ch < nc; ++ch) tau[ch] += m.densityScale * c[ch].integral(t1 - t0);
        return true;
    });
    return transmittanceFromTau(m, tau);
}

MediumSegment trilinearSegment(const Medium& m, const Vec3& origin, const Vec3& dir, float length) {
    const int nc = channelCount(m);
    MediumSegment seg;
    seg.length = length;
    double tau[3] = {0, 0, 0}, d0[3] = {0, 0, 0}, d1[3] = {0, 0, 0};
    bool first = true;
    forEachCubic(m, origin, dir, length, [&](double t0, double t1, const Cubic* c) {
        for (int ch = 0; ch < nc; ++ch) {
            if (first) d0[ch] = c[ch].eval(0.0);
            d1[ch] = c[ch].eval(t1 - t0);
            tau[ch] += m.densityScale * c[ch].integral(t1 - t0);
        }
        first = false;
        return true;
    });
    if (first) {
        const Rgb d = trilinearDensityRgbAt(m, origin);
        for (int ch = 0; ch < 3; ++ch) d0[ch] = d1[ch] = d[ch];
    }
    seg.sigmaT0 = sigmaFromDensity(m, d0);
    seg.sigmaT1 = sigmaFromDensity(m, d1);
    seg.sigmaS1 = mediumAlbedoAt(m, origin + dir * length) * seg.sigmaT1;
    seg.transmittance = transmittanceFromTau(m, tau);
    return seg;
}

FreeFlightSample trilinearFreeFlight(const Medium& m, const Vec3& origin, const Vec3& dir,
                                     float tMax, float uChannel, float uDistance) {
    // Spectral MIS (scene/medium.h): the distance is sampled in channel c; a grey sigma_t has
    // the same optical depth in every channel, so there the choice changes nothing.
    const int nc = channelCount(m);
    const int cs = nc == 1 ? 0 : std::min(2, int(uChannel * 3.0f));
    const double target = -std::log1p(-double(uDistance));
    const double scale = m.densityScale;
    FreeFlightSample s;
    double tau[3] = {0, 0, 0}, d0[3] = {0, 0, 0}, d1[3] = {0, 0, 0}, t = tMax;
    bool first = true, scattered = false;
    forEachCubic(m, origin, dir, tMax, [&](double t0, double t1, const Cubic* c) {
        if (first)
            for (int ch = 0; ch < nc; ++ch) d0[ch] = c[ch].eval(0.0);
        first = false;
        const double L = t1 - t0, piece = scale * c[cs].integral(L);
        if (scale > 0 && tau[cs] + piece >= target) {
            const double sLocal = invertCubic(c[cs], scale, L, target - tau[cs]);
            t = t0 + sLocal;
            for (int ch = 0; ch < nc; ++ch) {
                tau[ch] = ch == cs ? target : tau[ch] + scale * c[ch].integral(sLocal);
                d1[ch] = c[ch].eval(sLocal);
            }
            scattered = t < double(tMax);
            return false;
        }
        for (int ch = 0; ch < nc; ++ch) {
            tau[ch] += ch == cs ? piece : scale * c[ch].integral(L);
            d1[ch] = c[ch].eval(L);
        }
        return true;
    });
    if (first) {
        const Rgb d = trilinearDensityRgbAt(m, origin);
        for (int ch = 0; ch < 3; ++ch) d0[ch] = d1[ch] = d[ch];
    }
    MediumSegment& seg = s.segment;
    s.scattered = scattered;
    s.t = scattered ? float(t) : tMax;
    seg.length = s.t;
    seg.sigmaT0 = sigmaFromDensity(m, d0);
    seg.sigmaT1 = sigmaFromDensity(m, d1);
    seg.sigmaS1 = mediumAlbedoAt(m, origin + dir * s.t) * seg.sigmaT1;
    seg.transmittance = transmittanceFromTau(m, tau);
    s.pdf = s.scattered ? seg.pdfScatterFwdL() : seg.probPass();
    if (s.pdf > 0.0f)
        s.weight =
            s.scattered ? seg.transmittance * seg.sigmaS1 / s.pdf : seg.transmittance / s.pdf;
    return s;
}

}  // namespace ub
