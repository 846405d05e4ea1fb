// Test support for the surface MIS weights (kernels/shared/ub_mis.h): a full
// path x_0 (light) ... x_k (pinhole camera) described by the primitive
// quantities the renderer sees (solid-angle pdfs, cosines, distances), and two
// ways to compute the MIS weight of every technique that could have produced it:
//
//  * bruteForceWeights: from explicit area pdfs of every technique (Veach 1997,
//    Ch. 10; docs/mis.md, "Brute-force weights"), in double precision:
//      connection s (s light vertices): P_s = (prod_{j<s} a~_j) (prod_{j>=s} b_j),
//      merging at x_i:                  M_i = (prod_{j<=i} a_j) (prod_{j>=i} b_j) eta,
//    with a~_0 = a_0^NEE for s = 1, eta = N_L pi r^2, counts n = 1 (connections),
//    N_L (light tracing), and w_T = (n_T p_T)^beta / sum_T' (n_T' p_T')^beta.
//  * recursiveWeights: the dVCM/dVC/dVM recursion of ub_mis.h run along the two
//    subpaths exactly as the renderer runs it.
//
// Media (vlt, vbpt): a vertex may be a medium vertex (cosines 1, phase pdfs, never
// specular), and each segment x_{i-1} x_i carries the free-flight pdfs of both
// directions, distFwd[i] (from x_{i-1}, stopping at x_i if it is a medium vertex,
// passing otherwise) and distRev[i] (from x_i, stopping at or passing x_{i-1}); then
// a_i gains distFwd[i] and b_{i-1} gains distRev[i] (ub_mis.h, MEDIA; docs/mis.md,
// "Notation"). Merging (surface photon mapping) is not a technique at medium vertices.
//
// Only tests use this file.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "kernels/shared/ub_mis_volume.h"

namespace ub::test {

/// Intermediate vertex x_i, 1 <= i <= k-1. "Fwd" is the light direction
/// (x_{i-1} -> x_i -> x_{i+1}), "Rev" the camera direction.
struct MisVertex {
    float cosIn = 1;        ///< |cos| at x_i of the segment to x_{i-1}
    float cosOut = 1;       ///< |cos| at x_i of the segment to x_{i+1}
    float pdfFwdW = 1;      ///< p(dir to x_{i+1} | from x_{i-1}), without continuation probability
    float pdfRevW = 1;      ///< p(dir to x_{i-1} | from x_{i+1}), without continuation probability
    float cont = 1;         ///< Russian-roulette continuation probability at x_i
    bool specular = false;  ///< delta lobe: pdfs are the discrete lobe probability (equal)
    bool medium = false;    ///< medium vertex: cosines 1, phase pdfs, not specular
    float sinTheta = 1;     ///< medium vertex: sine of the angle x_{i-1} -> x_i -> x_{i+1}
};

enum class MisLightKind { Area, Point, Directional, Environment };

struct MisPath {
    MisLightKind lightKind = MisLightKind::Area;
    float lightPickProb = 1;
    /// Emission: position pdf (area; scene disk for lights at infinity) and direction pdf
    /// (solid angle), without pick probability. emissionPdfW = posPdf * dirPdf.
    float emitPosPdf = 1, emitDirPdfW = 1;
    /// NEE: illuminate()'s pdf of choosing x_0 in area measure (finite lights) or solid
    /// angle (environment), without pick probability; 1 for delta lights.
    float directPdfA = 1;
    float cosLight = 1;        ///< cosine at x_0 of the segment x_0 x_1 (finite area lights)
    std::vector<float> dist;   ///< dist[i] = |x_i - x_{i-1}|, i = 1..k (dist[0] unused)
    std::vector<MisVertex> v;  ///< v[i], i = 1..k-1 (v[0] unused)
    float cameraPdfW = 1;      ///< p_cam,W of the direction from the camera to x_{k-1}
    /// Free-flight pdfs of segment i (x_{i-1} x_i), i = 1..k, in the light (Fwd) and camera
    /// (Rev) directions; empty: no media (all 1).
    std::vector<float> distFwd, distRev;
    /// Probability that free-flight sampling passes segment i (up to x_i, or x_{i-1} in the
    /// camera direction) without stopping; empty: equal to distFwd / distRev (that is the
    /// distance pdf of a surface end).
    std::vector<float> passFwd, passRev;
    float pFwd(int i) const { return passFwd.empty() ? tFwd(i) : passFwd[size_t(i)]; }
    float pRev(int i) const { return passRev.empty() ? tRev(i) : passRev[size_t(i)]; }
    int k() const { return int(dist.size()) - 1; }
    float tFwd(int i) const { return distFwd.empty() ? 1.0f : distFwd[size_t(i)]; }
    float tRev(int i) const { return distRev.empty() ? 1.0f : distRev[size_t(i)]; }
    bool lightIsDelta() const {
        return lightKind == MisLightKind::Point || lightKind == MisLightKind::Directional;
    }
    bool lightIsFinite() const {
        return lightKind == MisLightKind::Area || lightKind == MisLightKind::Point;
    }
};

struct MisConfig {
    bool useVC = true, useVM = true;
    bool usePP3D = false;  ///< photon points x query points at medium vertices (UPBP)
    bool usePB2D = false, useBP2D = false, useBB1D = false;  ///< the beam estimators (UPBP)
    bool shortPhotonBeams = true, shortQueryBeams = false;
    float radius = 0.05f;
    float radiusPP3D = 0.05f, radiusPB2D = 0.05f, radiusBP2D = 0.05f, radiusBB1D = 0.05f;
    float beamPathCount = 100;  ///< N_B
    float lightSubPathCount = 1000;
    ub_uint heuristic = UB_MIS_POWER;
};

/// A technique: connection with s light vertices (s = 0: camera hits the light,
/// s = 1: NEE, s = k: light tracing), or merging at x_i (surface merging on a surface
/// vertex, tech = -1; a volumetric technique UB_TECH_* on a medium vertex).
struct MisTechnique {
    bool merge = false;
    int index = 0;  ///< s for connections, i for merges
    int tech = -1;  ///< merges at medium vertices: UB_TECH_PP3D ... UB_TECH_BB1D
    double weight = 0;
    std::string name() const {
        return (merge ? "merge" + std::to_string(tech) + "@x" : "connect s=") +
               std::to_string(index);
    }
};

inline bool volumeTechEnabled(const MisConfig& cfg, int tech) {
    switch (tech) {
        case UB_TECH_PP3D:
            return cfg.usePP3D;
        case UB_TECH_PB2D:
            return cfg.usePB2D;
        case UB_TECH_BP2D:
            return cfg.useBP2D;
        default:
            return cfg.useBB1D;
    }
}

/// Which techniques the renderer has for `path` under `cfg` (SmallVCM's semantics: BPM/PPM
/// count a camera subpath hitting a light only for purely specular camera subpaths).
inline std::vector<MisTechnique> validTechniques(const MisPath& p, const MisConfig& cfg) {
    const int k = p.k();
    std::vector<MisTechnique> out;
    auto connectible = [&](int i) { return i >= 1 && i <= k - 1 && !p.v[i].specular; };
    bool allSpecular = true;
    for (int i = 1; i < k; ++i) allSpecular &= p.v[i].specular;
    bool hitValid = !p.lightIsDelta() && (cfg.useVC || allSpecular);
    // Without connections, a light hit counts only after purely specular camera vertices
    // (render/vcm.h); with pp3d but neither VC nor surface merging that stays the rule.
    if (hitValid) out.push_back({false, 0});
    if (cfg.useVC) {
        for (int s = 1; s <= k - 1; ++s)
            if (connectible(s) && (s == 1 || connectible(s - 1))) out.push_back({false, s});
        if (k >= 2 && connectible(k - 1)) out.push_back({false, k});
    }
    for (int i = 1; i <= k - 1; ++i) {
        if (!connectible(i)) continue;
        if (!p.v[size_t(i)].medium) {
            if (cfg.useVM) out.push_back({true, i, -1});
            continue;
        }
        for (int t = 0; t < 4; ++t)
            if (volumeTechEnabled(cfg, t)) out.push_back({true, i, t});
    }
    return out;
}

/// Explicit per-vertex area pdfs and the weights w_T = (n p_T)^beta / sum (n p_T')^beta.
inline std::vector<MisTechnique> bruteForceWeights(const MisPath& p, const MisConfig& cfg) {
    const int k = p.k();
    // Forward (light-direction) pdfs a_0..a_{k-1} and a_0^NEE.
    std::vector<double> a(k, 0), b(k, 0);
    const bool finite = p.lightIsFinite();
    double pick = p.lightPickProb;
    // x_0: for finite lights the emitted position; for lights at infinity the direction
    // (the planar position is then part of a_1, TR Sec. 5.1).
    a[0] = pick * (finite ? p.emitPosPdf : p.emitDirPdfW);
    double a0Nee = pick * p.directPdfA;
    if (k >= 2) {
        a[1] = finite ? double(p.emitDirPdfW) * p.v[1].cosIn / (double(p.dist[1]) * p.dist[1])
                      : double(p.emitPosPdf) * p.v[1].cosIn;
        a[1] *= p.tFwd(1);
    }
    for (int i = 2; i <= k - 1; ++i) {
        const MisVertex& prev = p.v[i - 1];
        a[i] = double(prev.pdfFwdW) * prev.cont * p.v[i].cosIn * p.tFwd(i) /
               (double(p.dist[i]) * p.dist[i]);
    }
    // Backward (camera-direction) pdfs b_0..b_{k-1}; b_k = 1 (pinhole).
    for (int i = 0; i <= k - 1; ++i) {
        double cosHere = i == 0 ? (finite ? p.cosLight : 1.0) : p.v[i].cosOut;
        double d2 = double(p.dist[i + 1]) * p.dist[i + 1];
        if (i == 0 && !finite) d2 = 1;  // solid-angle measure at infinity
        double pw =
            i + 1 == k ? double(p.cameraPdfW) : double(p.v[i + 1].pdfRevW) * p.v[i + 1].cont;
        b[i] = pw * cosHere * p.tRev(i + 1) / d2;
    }
    if (p.lightIsDelta()) b[0] = 0;

    const double eta = M_PI * double(cfg.radius) * cfg.radius * cfg.lightSubPathCount;
    const double etaPP3D = 4.0 / 3.0 * M_PI * double(cfg.radiusPP3D) * cfg.radiusPP3D *
                           cfg.radiusPP3D * cfg.lightSubPathCount;
    std::vector<MisTechnique> techs = validTechniques(p, cfg);
    double beta = cfg.heuristic == UB_MIS_POWER ? 2.0 : 1.0;
    double sum = 0;
    for (MisTechnique& t : techs) {
        double pdf = 1;
        if (!t.merge) {
            int s = t.index;
            for (int j = 0; j < s; ++j) pdf *= (j == 0 && s == 1) ? a0Nee : a[j];
            for (int j = s; j <= k - 1; ++j) pdf *= b[j];
            if (s == k) pdf *= cfg.lightSubPathCount;  // light tracing: N_L samples
        } else {
            int i = t.index;
            for (int j = 0; j <= i; ++j) pdf *= a[j];
            for (int j = i; j <= k - 1; ++j) pdf *= b[j];
            if (!p.v[size_t(i)].medium) {
                pdf *= eta;
            } else {
                // UPBP eq. (8) (kernels/shared/ub_mis_volume.h): R = cover / T of the photon
                // beam reaching x_i (segment i) and of the query beam (segment i+1, reverse).
                double rPhoton = (cfg.shortPhotonBeams ? p.pFwd(i) : 1.0) / p.tFwd(i);
                double rQuery = (cfg.shortQueryBeams ? p.pRev(i + 1) : 1.0) / p.tRev(i + 1);
                double nL = cfg.lightSubPathCount, nB = cfg.beamPathCount;
                double sinT = p.v[size_t(i)].sinTheta;
                auto sq = [](double x) { return x * x; };
                switch (t.tech) {
                    case UB_TECH_PP3D:
                        pdf *= etaPP3D;
                        break;
                    case UB_TECH_PB2D:
                        pdf *= nL * M_PI * sq(cfg.radiusPB2D) * rQuery;
                        break;
                    case UB_TECH_BP2D:
                        pdf *= nB * M_PI * sq(cfg.radiusBP2D) * rPhoton;
                        break;
                    default:
                        pdf *= nB * 2.0 * cfg.radiusBB1D * sinT * rPhoton * rQuery;
                }
            }
        }
        t.weight = std::pow(pdf, beta);
        sum += t.weight;
    }
    for (MisTechnique& t : techs) t.weight /= sum;
    return techs;
}

/// The recursive weights of ub_mis.h, evaluated with the quantities each subpath has
/// at the vertex where the technique is applied (as the renderer does).
inline std::vector<MisTechnique> recursiveWeights(const MisPath& p, const MisConfig& cfg) {
    const int k = p.k();
    ub_mis_constants c = ub_mis_make_constants(cfg.radius, cfg.lightSubPathCount, cfg.useVC,
                                               cfg.useVM, cfg.heuristic);
    c = ub_mis_enable_volume(
        c, cfg.usePP3D ? cfg.radiusPP3D : 0.0f, cfg.usePB2D ? cfg.radiusPB2D : 0.0f,
        cfg.useBP2D ? cfg.radiusBP2D : 0.0f, cfg.useBB1D ? cfg.radiusBB1D : 0.0f, cfg.beamPathCount,
        cfg.shortPhotonBeams, cfg.shortQueryBeams);
    // R of the photon beam reaching x_i over segment i, of the query beam over segment i+1.
    auto rPhoton = [&](int i) { return ub_mis_photon_ratio(c, p.pFwd(i), p.tFwd(i)); };
    auto rQuery = [&](int i) { return ub_mis_query_ratio(c, p.pRev(i + 1), p.tRev(i + 1)); };
    // Merging factor parts of x_i as each subpath sees it (R_in of its own arrival).
    auto lightFactor = [&](int i) {
        const MisVertex& x = p.v[size_t(i)];
        return ub_mis_vertex_factor(c, x.medium, 0, 1, rPhoton(i), x.sinTheta);
    };
    auto cameraFactor = [&](int i) {
        const MisVertex& x = p.v[size_t(i)];
        return ub_mis_vertex_factor(c, x.medium, 0, 0, rQuery(i), x.sinTheta);
    };
    const bool finite = p.lightIsFinite();
    const float pick = p.lightPickProb;
    const float emissionPdfW = p.emitPosPdf * p.emitDirPdfW;  // without pick probability
    auto sq = [](float x) { return x * x; };

    // Light subpath: partials stored at x_1..x_{k-1} (after the hit update).
    std::vector<ub_mis_partials> L(k), E(k + 1);
    ub_mis_partials lp = ub_mis_init_light(c, p.directPdfA * pick, emissionPdfW * pick, p.cosLight,
                                           p.lightIsDelta(), finite);
    for (int i = 1; i <= k - 1; ++i) {
        const MisVertex& x = p.v[i];
        // R_out of x_{i-1}: the query beam over segment i.
        lp = ub_mis_at_hit_volume(c, lp, p.dist[i], x.cosIn, i > 1 || finite, p.tFwd(i), p.tRev(i),
                                  ub_mis_query_ratio(c, p.pRev(i), p.tRev(i)));
        L[i] = lp;
        ub_mis_factor f = lightFactor(i);
        lp = ub_mis_scatter_volume(c, lp, x.cosOut, x.pdfFwdW * x.cont, x.pdfRevW * x.cont,
                                   x.specular, f.now, f.out);
    }
    // Camera subpath: partials at x_{k-1}..x_1, and at x_0 when it hits the light.
    ub_mis_partials ep = ub_mis_init_camera(c, p.cameraPdfW);
    for (int i = k - 1; i >= 1; --i) {
        const MisVertex& x = p.v[i];
        // R_out of x_{i+1} on the camera side: the photon beam over segment i+1.
        ep = ub_mis_at_hit_volume(c, ep, p.dist[i + 1], x.cosOut, 1, p.tRev(i + 1), p.tFwd(i + 1),
                                  rPhoton(i + 1));
        E[i] = ep;
        ub_mis_factor f = cameraFactor(i);
        ep = ub_mis_scatter_volume(c, ep, x.cosIn, x.pdfRevW * x.cont, x.pdfFwdW * x.cont,
                                   x.specular, f.now, f.out);
    }
    // Lights at infinity are "hit" by escaping rays: no distance and no cosine.
    E[0] = finite ? ub_mis_at_hit_volume(c, ep, p.dist[1], p.cosLight, 1, p.tRev(1), p.tFwd(1),
                                         rPhoton(1))
                  : ub_mis_at_hit_volume(c, ep, 0.0f, 1.0f, 0, p.tRev(1), p.tFwd(1), rPhoton(1));
    // Whole merging factor of a vertex for the connection weights, R_out being that of the
    // connecting segment.
    auto lightTotal = [&](int i) { return ub_mis_factor_total(c, lightFactor(i), rQuery(i)); };
    auto cameraTotal = [&](int i) { return ub_mis_factor_total(c, cameraFactor(i), rPhoton(i)); };

    std::vector<MisTechnique> techs = validTechniques(p, cfg);
    for (MisTechnique& t : techs) {
        float w = 0;
        if (t.merge) {
            const MisVertex& x = p.v[t.index];
            if (t.tech < 0) {
                w = ub_mis_weight_merge(c, L[t.index], E[t.index], x.pdfRevW * x.cont,
                                        x.pdfFwdW * x.cont);
            } else {
                ub_mis_etas etas =
                    ub_mis_volume_etas(c, rPhoton(t.index), rQuery(t.index), x.sinTheta);
                w = ub_mis_weight_volume(c, L[t.index], E[t.index], x.pdfRevW * x.cont,
                                         x.pdfFwdW * x.cont, etas, ub_uint(t.tech));
            }
        } else if (t.index == 0) {
            w = ub_mis_weight_hit_light(c, E[0], p.directPdfA * pick, emissionPdfW * pick);
        } else if (t.index == 1 && k > 1) {
            // NEE at x_1: illuminate()'s solid-angle pdf from the area pdf.
            const MisVertex& x = p.v[1];
            float cosAtLight = finite && !p.lightIsDelta() ? p.cosLight : 1.0f;
            float directPdfW = finite ? p.directPdfA * sq(p.dist[1]) / cosAtLight : p.directPdfA;
            float bsdfDirPdfW = p.lightIsDelta() ? 0.0f : x.pdfRevW * x.cont;
            w = ub_mis_weight_nee_media(c, E[1], bsdfDirPdfW, x.pdfFwdW * x.cont, pick, directPdfW,
                                        emissionPdfW, x.cosIn, cosAtLight, p.tRev(1), p.tFwd(1),
                                        cameraTotal(1));
        } else if (t.index == k) {
            const MisVertex& y = p.v[k - 1];
            float cameraPdfA = p.cameraPdfW * y.cosOut * p.tRev(k) / sq(p.dist[k]);
            w = ub_mis_weight_light_trace(c, L[k - 1], cameraPdfA, y.pdfRevW * y.cont,
                                          lightTotal(k - 1));
        } else {
            int s = t.index;
            const MisVertex& y = p.v[s - 1];  // light vertex
            const MisVertex& z = p.v[s];      // camera vertex
            float d2 = sq(p.dist[s]);
            float cameraDirPdfA = z.pdfRevW * z.cont * y.cosOut * p.tRev(s) / d2;
            float lightDirPdfA = y.pdfFwdW * y.cont * z.cosIn * p.tFwd(s) / d2;
            w = ub_mis_weight_connect(c, L[s - 1], E[s], cameraDirPdfA, y.pdfRevW * y.cont,
                                      lightDirPdfA, z.pdfFwdW * z.cont, lightTotal(s - 1),
                                      cameraTotal(s));
        }
        t.weight = w;
    }
    return techs;
}

}  // namespace ub::test
