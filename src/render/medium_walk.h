// Free-flight sampling along a traced segment chain for the bidirectional
// engine (render/vcm.h: vlt, vbpt), with the distance pdfs of both directions
// that its MIS needs (kernels/shared/ub_mis.h, ub_mis_at_hit_media).
//
// Scene::traceMedia gives the chain of medium segments from a vertex x_{i-1} to
// the next real surface (or infinity), split at imaginary and skipped boundaries
// (scene/medium_trace.h). Free-flight sampling (scene/medium.h, spectral MIS per
// segment) visits the segments in order and either stops in segment k at
// distance t, making a medium vertex x_i, or passes them all and x_i is the real
// hit. With P_j the pass probability of segment j and p_k(t) the scatter density
// of segment k (Novak et al. 2018, Sec. 5.1; docs/mis.md, "Notation"):
//   forward  (x_{i-1} -> x_i):  prod_{j<k} P_j * p_k(t)   medium vertex
//                               prod_j P_j                surface / escape
//   reverse  (x_i -> x_{i-1}):  the same product over the segments between the
//                               two vertices, the segment at x_{i-1} contributing
//                               its reverse scatter density (stop at x_{i-1}) if
//                               x_{i-1} is a medium vertex, its pass probability
//                               otherwise; the segment at a medium x_i contributes
//                               the pass probability of its part [0, t].
// The throughput factor is T sigma_s / pdf (medium vertex) or T / pdf (passed),
// per segment, as in `vpt`.
#pragma once

#include "core/vec.h"
#include "scene/medium_trace.h"

namespace ub {

class Rng;
class Scene;

/// The next vertex of a subpath along a traced chain.
struct ChainVertex {
    bool scattered = false;  ///< medium vertex (else: the chain's real hit, or escaped)
    Vec3 pos;                ///< medium vertex position
    int mediumId = -1;       ///< medium of the medium vertex
    int segment = -1;        ///< chain segment holding the medium vertex
    float distance = 0.0f;   ///< from the chain start to the vertex (trace.distance if passed)
    Rgb weight{1.0f};        ///< throughput factor of the whole walk
    /// Collision estimate of the medium source term sigma_a Le at a medium vertex, relative to
    /// the throughput at the chain start: (prod passed T / P) * T sigma_a Le / p.
    Rgb emission{0.0f};
    float distPdfFwd = 1.0f;  ///< free-flight pdf of reaching the vertex (see the banner)
    float distPdfRev = 1.0f;  ///< free-flight pdf of the reverse direction
    /// Probability of passing the chain up to the vertex without stopping (either direction:
    /// the product of the pass probabilities of the visited parts of the segments; equals
    /// distPdfFwd when the chain is passed to its real hit). Beam estimators' cover.
    float passProb = 1.0f;
};

/// What free-flight sampling saw of each segment it visited (for the beams of UPBP): the
/// visited part of segment k is [0, length[k]) (the whole segment if it was passed).
struct ChainVisit {
    ChainVisit() {}  // entries past count are not initialised (as MediumTrace's segments)
    int count = 0;   ///< segments visited: 0 .. count-1 (the last holds the vertex if scattered)
    float length[MediumTrace::kMaxSegments];
    float passProb[MediumTrace::kMaxSegments];       ///< probPass of the visited part
    float stopRevStartL[MediumTrace::kMaxSegments];  ///< pdfScatterRevL of the visited part
    union {
        Rgb transmittance[MediumTrace::kMaxSegments];  ///< T of the visited part
    };
};

/// Samples the vertex that follows a chain traced along unit direction dir. prevInMedium:
/// the chain starts at a medium vertex (its reverse pdf then stops there). Draws two random
/// numbers per medium segment visited. A black weight means the path ends (a pdf
/// underflowed, or the vertex does not scatter).
/// visit (optional) receives what was seen of each visited segment.
ChainVertex sampleChainVertex(const Scene& scene, const MediumTrace& trace, const Vec3& dir,
                              bool prevInMedium, Rng& rng, ChainVisit* visit = nullptr);

/// Free-flight pdf of the connecting chain a -> b (Scene::shadowTransmittance from a)
/// in the direction a -> b: stopping at b if b is a medium vertex, passing otherwise.
inline float distPdfToB(const MediumShadow& s, bool bInMedium) {
    return bInMedium ? s.pdfScatterFwdL : s.probPass;
}
/// The same in the direction b -> a.
inline float distPdfToA(const MediumShadow& s, bool aInMedium) {
    return aInMedium ? s.pdfScatterRevL : s.probPass;
}

}  // namespace ub
