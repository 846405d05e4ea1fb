/* Recursive MIS weights for the surface bidirectional family (lt, bpt, ppm,
 * bpm, vcm), shared by host C++ and OpenCL C.
 *
 * A NOTE ON THE MIS PARTIALS (dVCM, dVC, dVM)
 * -------------------------------------------
 * Georgiev et al. 2012, "Light Transport Simulation with Vertex Connection and
 * Merging", and its technical report "Implementing Vertex Connection and
 * Merging" (cited below as [TR (n)], n the equation number) show that the MIS
 * weight of a full path built by vertex connection (VC) or vertex merging (VM)
 * can be evaluated from three floats carried along each subpath, so that no
 * weight computation ever walks a path:
 *
 *   dVCM  the pdf ratio shared by connection and merging. After the subpath
 *         reaches vertex x_i (and the hit update below) it is 1/p(x_i), the
 *         inverse area pdf with which the subpath sampled its last vertex
 *         (for i = 1 on a light subpath: p_direct(x_0) / (p(x_0) p(x_1))).
 *   dVC   the sum over the techniques that would have sampled more vertices
 *         of this subpath from the other side by connection, as ratios of
 *         their pdfs to the current technique's pdf, with the last reverse
 *         pdf left out (it is only known once the next direction is fixed).
 *   dVM   the same sum for the merging techniques, each ratio times the
 *         merging technique's eta (so that the eta of the vertex where a merge
 *         happens divides it out in the merge weight).
 *
 * Each weight is w = 1 / (w_light + 1 + w_camera)  [TR (37)], where w_light and
 * w_camera are the partial weights of the two subpaths, built from these
 * quantities and the pdfs available at the two ends of the new edge.
 *
 * MERGING FACTORS PER VERTEX (UPBP). SmallVCM has one merging technique with
 * one constant eta_VCM = N_L * pi * r^2 [TR (20)] (N_L light subpaths per
 * iteration, one connection per camera subpath). UPBP (Krivanek et al. 2014,
 * Sec. 5) merges with different estimators on surfaces and in media, each with
 * its own eta: surface photon mapping (surf) eta_surf = N_L pi r_surf^2 at
 * non-specular surface vertices, photon points x query points (pp3d)
 * eta_pp3d = N_L (4/3) pi r_pp3d^3 at medium vertices (the kernel's support
 * measure; UPBP eq. (8) with the box kernel). The recursion therefore takes the
 * merging factor f(x) = Mis(eta) of the vertex where each update happens, as
 * in the recursive form of Moonen & Jalba 2023 (their d_bpt / d_pde with the
 * deferred factor f_i): dVC gains f(x_i) where SmallVCM adds eta_VCM [TR (34)],
 * and dVM (here eta times SmallVCM's dVM) gains f(x_i) where SmallVCM adds 1
 * [TR (35)], and n_bpt dVCM (n_bpt = 1 with connections, 0 without) where
 * SmallVCM adds dVCM / eta_VCM. With one constant eta this is SmallVCM's
 * recursion, with dVM scaled by eta. The merge weight divides by the eta of
 * its own technique, and every other merging technique possible at the same
 * vertex adds its eta ratio to the local term [Moonen & Jalba 2023, eq. (4.17)].
 * Mis(x) is x^beta: beta = 2 (power heuristic) or 1 (balance heuristic),
 * applied to every ratio factor, including eta and the pdfs (TR Sec. 3); a sum
 * of factors is the sum of the powered terms.
 *
 * MEDIA (vlt, vbpt). A vertex may lie in a participating medium. Following
 * Veach's path-space formulation extended to media (Pauly et al. 2000,
 * "Metropolis Light Transport for Participating Media"; Krivanek et al. 2014,
 * UPBP, Sec. 4), every area pdf of a vertex becomes a volume pdf there, and
 * every vertex pdf gains the distance-sampling pdf of the segment that led to
 * it (docs/mis.md, "Notation"):
 *   p(x_i) = p_W(x_{i-1}) * D_i * T_i / d_i^2,
 * with D_i = |cos| at a surface vertex and 1 at a medium vertex, and T_i the
 * free-flight pdf of the segment chain from x_{i-1} (scene/medium_trace.h):
 * the scatter density pdfScatter (per unit length) of stopping at x_i times
 * the pass probabilities of the segments before it if x_i is a medium vertex,
 * the product of the pass probabilities if x_i is a surface vertex (1 through
 * vacuum). The reverse pdf of the same segment (sampled from x_i towards
 * x_{i-1}) has its own T. With both, the recursion keeps its form: the hit
 * update divides all partials by the forward T and multiplies dVC and dVM by
 * the reverse T (ub_mis_at_hit_media); weights that take area pdfs of a new
 * edge (connection, light tracing) take them with the T of that edge, and NEE
 * takes the T of the shadow chain (ub_mis_weight_nee_media). At a medium
 * vertex the "BSDF" is sigma_s * phase (sigma_s is carried by the free-flight
 * throughput), its cosines are 1, its pdfs are the phase pdf times the
 * vertex's continuation probability, and it is never specular.
 *
 * Conventions: solid-angle pdfs end in W, area pdfs in A. Every BSDF pdf passed
 * here already includes the Russian-roulette continuation probability of the
 * vertex where the sampling would happen. "dir" pdfs sample the direction in
 * which the subpath is being extended; "rev" pdfs sample the opposite way.
 * Light pdfs (directPdfA, emissionPdfW) include the light selection
 * probability. See docs/mis.md for a derivation-level summary.
 */
#ifndef UB_MIS_H
#define UB_MIS_H

#include "ub_defs.h"

#define UB_MIS_BALANCE 0u
#define UB_MIS_POWER 1u

/* The MIS partials of a subpath (state while tracing, stored at light vertices).
 * dOut: the part of the merging factor of the vertex the subpath just left that waits for
 * Mis(R_out) of the segment being traced (the beam estimators, ub_mis_volume.h); 0 at
 * stored vertices and whenever no beam technique is enabled. */
typedef struct {
    float dVCM;
    float dVC;
    float dVM;
    float dOut;
} ub_mis_partials;

/* The partials a merge needs (dVCM, dVM), as stored in a UPBP record. */
UB_INLINE ub_mis_partials ub_mis_merge_partials(float dVCM, float dVM) {
    ub_mis_partials p;
    p.dVCM = dVCM;
    p.dVC = 0.0f; /* merges use dVCM and dVM only */
    p.dVM = dVM;
    p.dOut = 0.0f;
    return p;
}

/* Per-iteration constants. */
typedef struct {
    float vmWeightFactor;     /* Mis(eta_surf) if surface merging is enabled, else 0 [TR (20)] */
    float pp3dWeightFactor;   /* Mis(eta_pp3d) if pp3d is enabled, else 0 (see above) */
    float pb2dWeightFactor;   /* Mis(N_L pi r_pb2d^2) or 0 (ub_mis_volume.h) */
    float bp2dWeightFactor;   /* Mis(N_B pi r_bp2d^2) or 0 (ub_mis_volume.h) */
    float bb1dWeightFactor;   /* Mis(N_B 2 r_bb1d) or 0 (ub_mis_volume.h) */
    ub_uint shortPhotonBeams; /* 1: photon beams end at the sampled distance; 0: long */
    ub_uint shortQueryBeams;  /* 1: query beams end at the sampled distance; 0: long */
    float bptFactor;          /* n_bpt: 1 if connections are enabled, else 0 */
    float lightSubPathCount;  /* N_L, not raised to beta */
    ub_uint heuristic;        /* UB_MIS_POWER or UB_MIS_BALANCE */
} ub_mis_constants;

/* Mis(x): the heuristic's exponent applied to one ratio factor. */
UB_INLINE float ub_mis(ub_mis_constants c, float x) {
    return c.heuristic == UB_MIS_POWER ? x * x : x;
}

/* Constants of one iteration with surface merging radius `radius`. useVC / useVM enable
 * the connection (incl. light tracing and NEE) and surface merging techniques. */
UB_INLINE ub_mis_constants ub_mis_make_constants(float radius, float lightSubPathCount, int useVC,
                                                 int useVM, ub_uint heuristic) {
    ub_mis_constants c;
    c.heuristic = heuristic;
    c.lightSubPathCount = lightSubPathCount;
    /* eta_VCM = n_VM / n_VC * pi r^2, with n_VC = 1, n_VM = N_L [TR (20)] */
    float etaVCM = UB_PI * radius * radius * lightSubPathCount;
    c.vmWeightFactor = useVM ? ub_mis(c, etaVCM) : 0.0f;
    c.pp3dWeightFactor = 0.0f;
    c.pb2dWeightFactor = 0.0f;
    c.bp2dWeightFactor = 0.0f;
    c.bb1dWeightFactor = 0.0f;
    c.shortPhotonBeams = 1u;
    c.shortQueryBeams = 0u;
    c.bptFactor = useVC ? 1.0f : 0.0f;
    return c;
}

/* eta_pp3d = N_L (4/3) pi r^3: N_L photon points, each merged with a query point within
 * the ball of radius r (UPBP Sec. 5, Table 1, the 3D box kernel's support volume). */
UB_INLINE float ub_mis_eta_pp3d(float radius, float lightSubPathCount) {
    return lightSubPathCount * (4.0f / 3.0f) * UB_PI * radius * radius * radius;
}

/* Enables pp3d with radius `radius` in constants made by ub_mis_make_constants. */
UB_INLINE ub_mis_constants ub_mis_enable_pp3d(ub_mis_constants c, float radius) {
    c.pp3dWeightFactor = ub_mis(c, ub_mis_eta_pp3d(radius, c.lightSubPathCount));
    return c;
}

/* Merging factor f(x) = sum of Mis(eta) over the merging techniques possible at a vertex:
 * surface merging at a non-specular surface vertex, the volumetric point estimators at a
 * medium vertex. isDelta: the vertex has no non-specular lobe (nothing merges there). */
UB_INLINE float ub_mis_merge_factor(ub_mis_constants c, int inMedium, int isDelta) {
    if (isDelta) return 0.0f;
    return inMedium ? c.pp3dWeightFactor : c.vmWeightFactor;
}

/* ---- Initialisation ---------------------------------------------------------------- */

/* Light subpath start at x_0 sampled by emission.
 * directPdfA: pdf of NEE choosing x_0 (area, or solid angle for environments),
 * emissionPdfW: pdf of emitting (x_0, direction); both times the light pick probability.
 * cosLight: cosine at x_0 (ignored for lights at infinity). */
UB_INLINE ub_mis_partials ub_mis_init_light(ub_mis_constants c, float directPdfA,
                                            float emissionPdfW, float cosLight, int isDelta,
                                            int isFinite) {
    ub_mis_partials p;
    /* dVCM_1 = p_direct(x_0) / p_emit(x_0, w) [TR (31)] */
    p.dVCM = ub_mis(c, directPdfA / emissionPdfW);
    /* dVC_1 = cos(x_0) / p_emit(x_0, w) [TR (32)]; 0 for delta lights, which camera
     * paths cannot hit; cos := 1 for lights at infinity [TR Sec. 5.1] */
    float usedCos = isFinite ? cosLight : 1.0f;
    p.dVC = isDelta ? 0.0f : ub_mis(c, usedCos / emissionPdfW);
    /* dVM_1 = eta dVC_1 / eta [TR (33)], i.e. n_bpt dVC_1 (merging factors above) */
    p.dVM = p.dVC * c.bptFactor;
    p.dOut = 0.0f;
    return p;
}

/* Camera subpath start; cameraPdfW = solid-angle pdf of the primary ray direction
 * per unit image-plane area (imagePlaneDist^2 / cos^3). Completed by the first
 * ub_mis_at_hit [TR (31)-(33)]: the camera vertex is technique "light tracing"
 * with N_L samples, so dVCM_1 = N_L / p_cam(x_1). */
UB_INLINE ub_mis_partials ub_mis_init_camera(ub_mis_constants c, float cameraPdfW) {
    ub_mis_partials p;
    p.dVCM = ub_mis(c, c.lightSubPathCount / cameraPdfW); /* [TR (31)] */
    p.dVC = 0.0f;                                         /* [TR (32)] */
    p.dVM = 0.0f;                                         /* [TR (33)] */
    p.dOut = 0.0f;
    return p;
}

/* ---- Updates ------------------------------------------------------------------------ */

/* After tracing a segment of length `dist` to a new vertex with |cos| `cosFix` between
 * the segment and the surface normal (1 at a medium vertex): converts the solid-angle pdf
 * of the last direction to area (volume) measure, completing [TR (31)-(33)] or
 * [TR (34)-(36)]. applyDistSqr is 0 only on the first segment of a light at infinity,
 * whose emission pdf is already in a planar measure [TR Sec. 5.1].
 * Media: distPdfFwd is the free-flight pdf with which the subpath being traced reached the
 * new vertex over this segment (scatter density times pass probabilities for a medium
 * vertex, pass probability for a surface vertex), distPdfRev the pdf of the same segment
 * sampled the other way, from the new vertex back to the previous one (stopping there if
 * it is a medium vertex). The forward pdf completes p(x_i) in dVCM = 1/p(x_i) and in the
 * ratio p(x_{i-1} from x_i) / p(x_i) that dVC and dVM carry; the reverse pdf belongs to
 * that ratio's numerator (docs/mis.md, "Notation", a_i and b_{i-1}). rOut: R_out of this
 * segment for the deferred merging factor p.dOut of the previous vertex (ub_mis_volume.h). */
UB_INLINE ub_mis_partials ub_mis_at_hit_volume(ub_mis_constants c, ub_mis_partials p, float dist,
                                               float cosFix, int applyDistSqr, float distPdfFwd,
                                               float distPdfRev, float rOut) {
    /* Complete the merging factor of the previous vertex with R_out of this segment
     * (ub_mis_volume.h; Moonen & Jalba 2023, the deferred factor f_i of eq. (4.47)) */
    if (p.dOut != 0.0f) {
        float deferred = p.dOut * ub_mis(c, rOut);
        p.dVC += deferred;
        p.dVM += deferred;
        p.dOut = 0.0f;
    }
    if (applyDistSqr) p.dVCM *= ub_mis(c, dist * dist);
    float invFwd = 1.0f / ub_mis(c, cosFix * distPdfFwd);
    float revOverFwd = ub_mis(c, distPdfRev) * invFwd;
    p.dVCM *= invFwd;
    p.dVC *= revOverFwd;
    p.dVM *= revOverFwd;
    return p;
}

/* ub_mis_at_hit_volume without beam techniques (p.dOut is 0). */
UB_INLINE ub_mis_partials ub_mis_at_hit_media(ub_mis_constants c, ub_mis_partials p, float dist,
                                              float cosFix, int applyDistSqr, float distPdfFwd,
                                              float distPdfRev) {
    return ub_mis_at_hit_volume(c, p, dist, cosFix, applyDistSqr, distPdfFwd, distPdfRev, 0.0f);
}

/* The same without media (both distance pdfs 1). */
UB_INLINE ub_mis_partials ub_mis_at_hit(ub_mis_constants c, ub_mis_partials p, float dist,
                                        float cosFix, int applyDistSqr) {
    if (applyDistSqr) p.dVCM *= ub_mis(c, dist * dist);
    float invCos = 1.0f / ub_mis(c, cosFix);
    p.dVCM *= invCos;
    p.dVC *= invCos;
    p.dVM *= invCos;
    return p;
}

/* Scattering at a vertex: the new direction was sampled with dirPdfW, the reverse
 * direction would be sampled with revPdfW (both times the continuation probability),
 * cosOut = |cos| of the new direction. isSpecular: a delta lobe was sampled. mergeFactor:
 * ub_mis_merge_factor of the vertex. */
UB_INLINE ub_mis_partials ub_mis_scatter(ub_mis_constants c, ub_mis_partials p, float cosOut,
                                         float dirPdfW, float revPdfW, int isSpecular,
                                         float mergeFactor) {
    ub_mis_partials q;
    q.dOut = 0.0f;
    if (isSpecular) {
        /* For a delta lobe the forward and reverse pdfs are equal and cancel;
         * no connection or merging can use this vertex [TR (53)-(55)]. */
        q.dVCM = 0.0f;                     /* [TR (53)] */
        q.dVC = p.dVC * ub_mis(c, cosOut); /* [TR (54)] */
        q.dVM = p.dVM * ub_mis(c, cosOut); /* [TR (55)] */
        return q;
    }
    float g = ub_mis(c, cosOut / dirPdfW);
    float rev = ub_mis(c, revPdfW);
    q.dVC = g * (p.dVC * rev + p.dVCM + mergeFactor);               /* [TR (34)] */
    q.dVM = g * (p.dVM * rev + p.dVCM * c.bptFactor + mergeFactor); /* [TR (35)], x eta */
    q.dVCM = ub_mis(c, 1.0f / dirPdfW);                             /* [TR (36)] */
    return q;
}

/* ub_mis_scatter with a merging factor F0 + F1 Mis(R_out) (ub_mis_volume.h): F0 is added
 * now, F1 waits in dOut for the R_out of the segment about to be traced. */
UB_INLINE ub_mis_partials ub_mis_scatter_volume(ub_mis_constants c, ub_mis_partials p, float cosOut,
                                                float dirPdfW, float revPdfW, int isSpecular,
                                                float factorNow, float factorOut) {
    ub_mis_partials q = ub_mis_scatter(c, p, cosOut, dirPdfW, revPdfW, isSpecular, factorNow);
    if (!isSpecular) q.dOut = ub_mis(c, cosOut / dirPdfW) * factorOut;
    return q;
}

/* ---- Weights -------------------------------------------------------------------------- */

/* Vertex connection between light vertex y (partials l) and camera vertex z (partials e).
 * cameraDirPdfA: camera BSDF at z sampling y, in area measure at y;
 * lightRevPdfW: light BSDF at y sampling its previous vertex given the direction to z;
 * lightDirPdfA: light BSDF at y sampling z, in area measure at z;
 * cameraRevPdfW: camera BSDF at z sampling its previous vertex given the direction to y.
 * Media: both area pdfs include the free-flight pdf of the connecting chain in their
 * direction (stopping at the end vertex if it lies in a medium, passing otherwise).
 * lightMerge / cameraMerge: ub_mis_merge_factor of y and of z. */
UB_INLINE float ub_mis_weight_connect(ub_mis_constants c, ub_mis_partials l, ub_mis_partials e,
                                      float cameraDirPdfA, float lightRevPdfW, float lightDirPdfA,
                                      float cameraRevPdfW, float lightMerge, float cameraMerge) {
    /* Partial light subpath weight [TR (40)] */
    float wLight =
        ub_mis(c, cameraDirPdfA) * (lightMerge + l.dVCM + l.dVC * ub_mis(c, lightRevPdfW));
    /* Partial camera subpath weight [TR (41)] */
    float wCamera =
        ub_mis(c, lightDirPdfA) * (cameraMerge + e.dVCM + e.dVC * ub_mis(c, cameraRevPdfW));
    return 1.0f / (wLight + 1.0f + wCamera); /* [TR (37)] */
}

/* Next-event estimation from camera vertex z (partials e) to a light sample.
 * bsdfDirPdfW: camera BSDF sampling the light direction (0 for delta lights);
 * bsdfRevPdfW: camera BSDF sampling its previous vertex given the light direction;
 * lightPickProb, directPdfW (illuminate's solid-angle pdf, without pick probability),
 * emissionPdfW (without pick probability), cosToLight at z, cosAtLight at the light.
 * Media: passProb = probability that free-flight sampling from z passes the whole shadow
 * chain (what BSDF sampling needs to reach the light), distPdfToZ = free-flight pdf of the
 * light subpath stopping at z over that chain (scatter density times passes if z is a
 * medium vertex, passProb if z is on a surface). Both are 1 without media.
 * cameraMerge: ub_mis_merge_factor of z. */
UB_INLINE float ub_mis_weight_nee_media(ub_mis_constants c, ub_mis_partials e, float bsdfDirPdfW,
                                        float bsdfRevPdfW, float lightPickProb, float directPdfW,
                                        float emissionPdfW, float cosToLight, float cosAtLight,
                                        float passProb, float distPdfToZ, float cameraMerge) {
    /* Partial light subpath weight [TR (44)]: hitting the light by BSDF sampling */
    float wLight = ub_mis(c, bsdfDirPdfW * passProb / (lightPickProb * directPdfW));
    /* Partial camera subpath weight [TR (45)]: the light emitted towards z; the pick
     * probability cancels in the ratio emissionPdfW / directPdfW */
    float wCamera = ub_mis(c, emissionPdfW * cosToLight * distPdfToZ / (directPdfW * cosAtLight)) *
                    (cameraMerge + e.dVCM + e.dVC * ub_mis(c, bsdfRevPdfW));
    return 1.0f / (wLight + 1.0f + wCamera); /* [TR (37)] */
}

/* The same without media, at a surface vertex. */
UB_INLINE float ub_mis_weight_nee(ub_mis_constants c, ub_mis_partials e, float bsdfDirPdfW,
                                  float bsdfRevPdfW, float lightPickProb, float directPdfW,
                                  float emissionPdfW, float cosToLight, float cosAtLight) {
    return ub_mis_weight_nee_media(c, e, bsdfDirPdfW, bsdfRevPdfW, lightPickProb, directPdfW,
                                   emissionPdfW, cosToLight, cosAtLight, 1.0f, 1.0f,
                                   c.vmWeightFactor);
}

/* A camera subpath (partials e, after ub_mis_at_hit) hits an emitter, with pdfs of
 * the hit point/direction for NEE (directPdfA) and emission (emissionPdfW), both
 * times the light pick probability. Not for directly visible lights (weight 1). */
UB_INLINE float ub_mis_weight_hit_light(ub_mis_constants c, ub_mis_partials e, float directPdfA,
                                        float emissionPdfW) {
    /* Partial camera subpath weight [TR (43)]; the light part is 0 [TR (42)] */
    float wCamera = ub_mis(c, directPdfA) * e.dVCM + ub_mis(c, emissionPdfW) * e.dVC;
    return 1.0f / (1.0f + wCamera); /* [TR (37)] */
}

/* Light tracing: light vertex y (partials l) connected to the camera.
 * cameraPdfA: pdf of the camera sampling y, area measure (p_cam,W |cos_y| / d^2), times the
 * free-flight pdf of the camera ray reaching y (media; |cos_y| = 1 at a medium vertex);
 * bsdfRevPdfW: light BSDF at y sampling its previous vertex given the camera direction;
 * lightMerge: ub_mis_merge_factor of y. */
UB_INLINE float ub_mis_weight_light_trace(ub_mis_constants c, ub_mis_partials l, float cameraPdfA,
                                          float bsdfRevPdfW, float lightMerge) {
    /* Partial light subpath weight [TR (46)]; the camera part is 0 [TR (47)] */
    float wLight = ub_mis(c, cameraPdfA / c.lightSubPathCount) *
                   (lightMerge + l.dVCM + l.dVC * ub_mis(c, bsdfRevPdfW));
    return 1.0f / (wLight + 1.0f); /* [TR (37)] */
}

/* Vertex merging of light vertex y (partials l) at camera vertex z (partials e).
 * cameraDirPdfW: camera BSDF sampling the light vertex's incoming direction, times the
 * camera vertex's continuation probability; cameraRevPdfW: camera BSDF sampling the
 * camera's previous vertex given that direction, times the LIGHT vertex's continuation
 * probability (the light subpath would have continued there).
 * mergeFactor: Mis(eta) of this merging technique (c.vmWeightFactor for surface merging,
 * c.pp3dWeightFactor for pp3d); otherMerge: the sum of Mis(eta) of the other merging
 * techniques possible at the same vertex (0 with one). */
UB_INLINE float ub_mis_weight_merge_tech(ub_mis_constants c, ub_mis_partials l, ub_mis_partials e,
                                         float cameraDirPdfW, float cameraRevPdfW,
                                         float mergeFactor, float otherMerge) {
    float invEta = 1.0f / mergeFactor;
    /* Partial light subpath weight [TR (38)]; [Moonen & Jalba 2023, eq. (4.52)] */
    float wLight = (l.dVCM * c.bptFactor + l.dVM * ub_mis(c, cameraDirPdfW)) * invEta;
    /* Partial camera subpath weight [TR (39)]; [Moonen & Jalba 2023, eq. (4.53)] */
    float wCamera = (e.dVCM * c.bptFactor + e.dVM * ub_mis(c, cameraRevPdfW)) * invEta;
    /* Local term: this technique and the others at the same vertex [Moonen & Jalba, (4.17)] */
    float wLocal = 1.0f + otherMerge * invEta;
    return 1.0f / (wLight + wLocal + wCamera); /* [TR (37)] */
}

/* Surface merging (the only merging technique at a surface vertex). */
UB_INLINE float ub_mis_weight_merge(ub_mis_constants c, ub_mis_partials l, ub_mis_partials e,
                                    float cameraDirPdfW, float cameraRevPdfW) {
    return ub_mis_weight_merge_tech(c, l, e, cameraDirPdfW, cameraRevPdfW, c.vmWeightFactor, 0.0f);
}

#endif /* UB_MIS_H */
