// What Scene::traceMedia and Scene::shadowTransmittance return: the medium
// segments between two real surface vertices (rules of nested media in
// scene/medium_stack.h). Flat, fixed-size data, so bidirectional methods can
// keep them in their vertices and photon beams.
//
// A trace from a ray origin x0 to the next real surface hit (or to infinity)
// is a chain of segments; segment k runs from origin[k] for length[k] along
// the ray direction in medium mediumId[k] (-1 = vacuum). Consecutive segments
// are separated by crossings of imaginary or skipped boundaries (crossing k
// ends segment k). Free-flight sampling treats the segments one after the
// other; the path pdf of passing a segment chain is the product of the
// per-segment pass probabilities, and of stopping in segment k is
//   prod_{j<k} probPass_j * pdfScatterFwdL_k(t)     (per unit length)
// (Novak et al. 2018, Sec. 5.1 per segment).
#pragma once

#include <cstdint>
#include <string>

#include "core/vec.h"
#include "scene/camera.h"

namespace ub {

/// Length standing for "to infinity": media along an escaping ray are evaluated up to here
/// (a homogeneous medium with sigma_t > 0 has T = 0 there, one with sigma_t = 0 has T = 1).
constexpr float kMediumFarDistance = 1e30f;

struct MediumTraceSegment {
    Vec3 origin;
    float length = 0.0f;         ///< kMediumFarDistance for the last segment of an escaping ray
    int32_t mediumId = -1;       ///< -1 vacuum
    int32_t crossingShape = -1;  ///< boundary crossed at the end (-1: the real hit / infinity)
    int32_t crossingEntering = 0;
};

struct MediumTrace {
    static constexpr int kMaxSegments = 32;
    /// The segments are not initialised (a union member is not): traceMedia writes every field
    /// of segments[0 .. count) and nothing reads past count. Zeroing 900 bytes for each traced
    /// ray cost 3-5% of a bidirectional iteration (docs/performance.md).
    MediumTrace() {}
    int32_t count = 0;
    union {
        MediumTraceSegment segments[kMaxSegments];
    };
    bool hitSurface = false;  ///< a real surface ends the trace (else it escaped)
    bool overflow = false;    ///< more crossings than kMaxSegments or a full medium stack:
                              ///< the trace is unusable and the path must end
    float distance = 0.0f;    ///< from the ray origin to the real hit (sum of segment lengths)
    /// The trace was cut short by a look-ahead (Scene::traceMedia): its ray stopped where
    /// free-flight sampling with the look-ahead's numbers stops in the last segment, and met
    /// nothing before. That segment's length is unknown and stored as kMediumFarDistance;
    /// sampling with the same numbers scatters inside it, at the same distance as on the
    /// whole chain. hitSurface is false and the trace did not escape.
    bool truncated = false;
    /// The ray that met the real hit (hitSurface): Scene::completeHit's argument.
    Ray hitRay;
};

/// Transmittance of a segment chain a -> b and its distance pdfs (products over segments).
struct MediumShadow {
    bool blocked = false;     ///< a real surface lies between a and b (T = 0)
    Rgb transmittance{1.0f};  ///< T(a, b), per channel
    /// Probability that free-flight sampling passes every segment (either direction).
    float probPass = 1.0f;
    /// Density (per unit length) of free-flight sampling from a stopping at b:
    /// prod_{j<last} probPass_j * pdfScatterFwdL(last). 0 if b is in vacuum.
    float pdfScatterFwdL = 0.0f;
    /// Density of free-flight sampling from b towards a stopping at a:
    /// pdfScatterRevL(first) * prod_{j>first} probPass_j. 0 if a is in vacuum.
    float pdfScatterRevL = 0.0f;
    int32_t segmentCount = 0;
};

/// One problem of the media set-up found by Scene::mediumIssues().
struct MediumIssue {
    int32_t shapeId = -1;   ///< offending shape, or -1
    int32_t mediumId = -1;  ///< offending medium, or -1
    std::string message;    ///< names the shape/medium and what is wrong
    /// Not an error: what the scene does is defined, but maybe not what was meant (an open
    /// boundary mesh under Mitsuba's transitions). Scene::commit() does not refuse it.
    bool warning = false;
};

}  // namespace ub
