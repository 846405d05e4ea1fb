/* MIS of the volumetric estimators of UPBP (Krivanek et al. 2014, "Unifying
 * points, beams, and paths in volumetric light transport simulation", Sec. 5),
 * in the constant-time recursive form of ub_mis.h (Moonen & Jalba 2023), shared by
 * host C++ and OpenCL C.
 *
 * THE FOUR VOLUMETRIC TECHNIQUES AT A MEDIUM VERTEX x_i
 * ----------------------------------------------------
 * A merge at x_i is a virtual path sample: both subpaths "sample" x_i, and the
 * kernel's support supplies the measure that neither subpath sampled. Its pdf,
 * relative to the vertex pdfs a_j (light) and b_j (camera) of docs/mis.md, is
 *   M_i = (prod_{j<=i} a_j) (prod_{j>=i} b_j) eta_i      (UPBP eq. (8), Sec. 5.1)
 * with, for box kernels of radius r (the measure of the kernel's support):
 *   pp3d  eta = N_L (4/3) pi r^3                      points x points, 3D
 *   pb2d  eta = N_L pi r^2 R_query                    points x query beams, 2D
 *   bp2d  eta = N_B pi r^2 R_photon                   photon beams x points, 2D
 *   bb1d  eta = N_B 2 r sin(theta) R_photon R_query   beams x beams, 1D
 * N_L is the number of light subpaths, N_B <= N_L the number of them that emit
 * photon beams (--beam-paths). A beam does not sample the distance to x_i: the
 * distance pdf T of the segment that reaches x_i (in a_i for photon beams, in
 * b_i for query beams) is replaced by the probability that the beam covers x_i,
 * which gives the ratio
 *   R = cover / T,  cover = 1 for a long beam (to the next surface),
 *                   cover = P_pass(x_i) for a short beam (ending at the sampled
 *                           distance: it covers x_i iff it passes it),
 * where T is the free-flight pdf of stopping at x_i and P_pass that of passing it
 * over the same segment chain (both exact in grids, render/medium_walk.h). For the
 * 1D kernel the two beams' parameters and the distance between their lines span
 * a volume element sin(theta) dt_l dt_c dd, theta the angle between the beams;
 * with the box kernel of width 2r that gives 2 r sin(theta) (SmallUPBP and
 * gpuupbp use r/2 sin(theta), the factor of their 1D kernel normalisation; any
 * positive constant keeps the MIS unbiased, only the variance differs).
 *
 * IN THE RECURSION
 * ----------------
 * The merging factor of a medium vertex x is f(x) = sum of Mis(eta) of the
 * enabled techniques (the power heuristic powers each term). The ratio of the
 * segment by which the subpath arrived at x (R_in) is known when x is reached, the
 * ratio of the segment by which it leaves (R_out, evaluated in the opposite
 * direction) only after that segment is traced, and sin(theta) once the new
 * direction is sampled. So f(x) = F0 + F1 Mis(R_out), with
 *   light subpath  (in: photon beam, out: query beam):
 *     F0 = pp3d + bp2d Mis(R_in),   F1 = pb2d + bb1d Mis(sin) Mis(R_in)
 *   camera subpath (in: query beam, out: photon beam):
 *     F0 = pp3d + pb2d Mis(R_in),   F1 = bp2d + bb1d Mis(sin) Mis(R_in)
 * (the constants Mis(N pi r^2) etc. are the WeightFactors of ub_mis_constants).
 * ub_mis_scatter_volume adds F0 at once and keeps g F1 in dOut, which
 * ub_mis_at_hit_volume multiplies by Mis(R_out) of the traced segment: Moonen &
 * Jalba's d = A f_i + B split (their eq. (4.47)-(4.49)), with the part of f_i that
 * is known early added early.
 *
 * THE MERGE WEIGHT
 * ----------------
 * For technique tau at vertex v, with the light partials and the camera partials
 * both completed at v (a beam end point is completed as the trace would complete a
 * real vertex there):
 *   w = 1 / (w_light + w_local + w_camera)                 (Moonen & Jalba (4.18))
 *   w_light  = (n_bpt dVCM_l + Mis(p_c(v -> y_prev)) dVM_l) / Mis(eta_tau)   (4.52)
 *   w_camera = (n_bpt dVCM_c + Mis(p_l(v -> z_prev)) dVM_c) / Mis(eta_tau)   (4.53)
 *   w_local  = 1 + sum_{tau' != tau} Mis(eta_tau') / Mis(eta_tau)             (4.17)
 * (ub_mis_weight_merge_tech of ub_mis.h), the etas evaluated at v with R_photon
 * (light side, R_in of the light at v), R_query (camera side) and the angle between
 * the two incoming directions.
 */
#ifndef UB_MIS_VOLUME_H
#define UB_MIS_VOLUME_H

#include "ub_mis.h"

#define UB_TECH_PP3D 0u
#define UB_TECH_PB2D 1u
#define UB_TECH_BP2D 2u
#define UB_TECH_BB1D 3u

/* Enables the volumetric techniques (radius <= 0: disabled). beamPathCount: N_B. */
UB_INLINE ub_mis_constants ub_mis_enable_volume(ub_mis_constants c, float radiusPP3D,
                                                float radiusPB2D, float radiusBP2D,
                                                float radiusBB1D, float beamPathCount,
                                                ub_uint shortPhotonBeams, ub_uint shortQueryBeams) {
    float nL = c.lightSubPathCount;
    /* eta constants of UPBP Sec. 5.1 (box kernels, see the banner) */
    c.pp3dWeightFactor =
        radiusPP3D > 0.0f
            ? ub_mis(c, nL * (4.0f / 3.0f) * UB_PI * radiusPP3D * radiusPP3D * radiusPP3D)
            : 0.0f;
    c.pb2dWeightFactor = radiusPB2D > 0.0f ? ub_mis(c, nL * UB_PI * radiusPB2D * radiusPB2D) : 0.0f;
    c.bp2dWeightFactor =
        radiusBP2D > 0.0f ? ub_mis(c, beamPathCount * UB_PI * radiusBP2D * radiusBP2D) : 0.0f;
    c.bb1dWeightFactor = radiusBB1D > 0.0f ? ub_mis(c, beamPathCount * 2.0f * radiusBB1D) : 0.0f;
    c.shortPhotonBeams = shortPhotonBeams;
    c.shortQueryBeams = shortQueryBeams;
    return c;
}

/* True if any beam technique is enabled (then subpaths carry dOut). */
UB_INLINE int ub_mis_uses_beams(ub_mis_constants c) {
    return c.pb2dWeightFactor > 0.0f || c.bp2dWeightFactor > 0.0f || c.bb1dWeightFactor > 0.0f;
}

/* R = cover / T of a beam of the given kind over a segment chain: stopPdf is the free-flight
 * density of stopping at the point, passProb that of passing it (UPBP Sec. 5.1, the
 * beam's probability of covering the point over the pdf it replaces).
 * R is capped at 1e12 (power heuristic: Mis(R) <= 1e24): where T is that small, R times the
 * T that the recursion multiplies it with would otherwise overflow float as inf * 0 = NaN.
 * Both subpaths compute R of a segment from the same two numbers, so a capped R is the same
 * on both sides and the weights of every path still sum to 1. */
UB_INLINE float ub_mis_beam_ratio(ub_uint shortBeam, float passProb, float stopPdf) {
    if (!(stopPdf > 0.0f)) return 0.0f;
    return ub_fmin((shortBeam ? passProb : 1.0f) / stopPdf, 1e12f);
}

/* R of a photon beam, and of a query beam, reaching a point (stopPdf, passProb as above). */
UB_INLINE float ub_mis_photon_ratio(ub_mis_constants c, float passProb, float stopPdf) {
    return ub_mis_beam_ratio(c.shortPhotonBeams, passProb, stopPdf);
}
UB_INLINE float ub_mis_query_ratio(ub_mis_constants c, float passProb, float stopPdf) {
    return ub_mis_beam_ratio(c.shortQueryBeams, passProb, stopPdf);
}

/* The two parts of the merging factor of a vertex, f = now + out Mis(R_out) (banner).
 * inMedium / isDelta: the vertex; fromLight: the subpath is a light subpath; rIn: R of the
 * segment that reached the vertex (photon beam kind for a light subpath, query beam kind for
 * a camera subpath); sinTheta: sine of the angle between the incoming and the outgoing
 * direction. Surface vertices: the surface merging factor, nothing deferred. */
typedef struct {
    float now;
    float out;
} ub_mis_factor;

UB_INLINE ub_mis_factor ub_mis_vertex_factor(ub_mis_constants c, int inMedium, int isDelta,
                                             int fromLight, float rIn, float sinTheta) {
    ub_mis_factor f;
    f.now = 0.0f;
    f.out = 0.0f;
    if (isDelta) return f;
    if (!inMedium) {
        f.now = c.vmWeightFactor;
        return f;
    }
    float mIn = ub_mis(c, rIn);
    float bb1d = c.bb1dWeightFactor * ub_mis(c, sinTheta) * mIn; /* UPBP eq. (8), 1D */
    if (fromLight) {
        f.now = c.pp3dWeightFactor + c.bp2dWeightFactor * mIn; /* R_in = R_photon */
        f.out = c.pb2dWeightFactor + bb1d;                     /* x Mis(R_query) */
    } else {
        f.now = c.pp3dWeightFactor + c.pb2dWeightFactor * mIn; /* R_in = R_query */
        f.out = c.bp2dWeightFactor + bb1d;                     /* x Mis(R_photon) */
    }
    return f;
}

/* f = now + out Mis(R_out), for a weight that takes the whole factor of a vertex at once
 * (connections, NEE, light tracing: R_out is that of the connecting segment). */
UB_INLINE float ub_mis_factor_total(ub_mis_constants c, ub_mis_factor f, float rOut) {
    return f.out != 0.0f ? f.now + f.out * ub_mis(c, rOut) : f.now;
}

/* Mis(eta) of the four techniques at a merge vertex (banner; 0 for disabled ones). */
typedef struct {
    float eta[4];
} ub_mis_etas;

UB_INLINE ub_mis_etas ub_mis_volume_etas(ub_mis_constants c, float rPhoton, float rQuery,
                                         float sinTheta) {
    ub_mis_etas e;
    float mP = ub_mis(c, rPhoton), mQ = ub_mis(c, rQuery);
    e.eta[UB_TECH_PP3D] = c.pp3dWeightFactor;
    e.eta[UB_TECH_PB2D] = c.pb2dWeightFactor * mQ;
    e.eta[UB_TECH_BP2D] = c.bp2dWeightFactor * mP;
    e.eta[UB_TECH_BB1D] = c.bb1dWeightFactor * ub_mis(c, sinTheta) * mP * mQ;
    return e;
}

/* MIS weight of volumetric technique `tech` at a merge vertex (banner): l and e are the
 * light and camera partials completed there; cameraDirPdfW: the phase function with the
 * camera's incoming direction sampling the light's, times the camera's continuation
 * probability; cameraRevPdfW: the reverse, times the light's continuation probability. */
UB_INLINE float ub_mis_weight_volume(ub_mis_constants c, ub_mis_partials l, ub_mis_partials e,
                                     float cameraDirPdfW, float cameraRevPdfW, ub_mis_etas etas,
                                     ub_uint tech) {
    float own = etas.eta[tech];
    if (!(own > 0.0f)) return 0.0f;
    float other = 0.0f;
    UB_UNROLL
    for (ub_uint t = 0u; t < 4u; ++t)
        if (t != tech) other += etas.eta[t];
    return ub_mis_weight_merge_tech(c, l, e, cameraDirPdfW, cameraRevPdfW, own, other);
}

#endif /* UB_MIS_VOLUME_H */
