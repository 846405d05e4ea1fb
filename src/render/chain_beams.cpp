// Beam pieces of a traced chain (see chain_beams.h).
#include "render/chain_beams.h"

#include <algorithm>
#include <cmath>

#include "core/memory_budget.h"
#include "scene/medium.h"
#include "scene/scene.h"

namespace ub {

namespace {

/// A homogeneous medium without scattering holds no vertex, so no beam is useful there.
bool scatters(const Medium& m) {
    return m.type != MediumType::kHomogeneous || !isBlack(m.sigmaS);
}

/// Where a beam along an escaping ray (an unbounded last segment) ends: in a homogeneous
/// medium where the largest transmittance has fallen below 1e-7 (t = ln(1e7) / min sigma_t;
/// what lies beyond contributes less than 1e-7 of the beam's throughput), else where the ray
/// leaves the scene's bounding sphere (grid media are empty outside their bounds, which the
/// geometry encloses).
float escapingBeamLength(const Scene& scene, const Medium& m, const Vec3& o, const Vec3& d);

/// Distance along o + t d (unit d) at which the ray leaves the sphere; 0 if it never is
/// inside it ahead of o.
float sphereExit(const Vec3& o, const Vec3& d, const Vec3& centre, float radius) {
    const Vec3 oc = o - centre;
    const float b = dot(oc, d), c = dot(oc, oc) - radius * radius;
    const float disc = b * b - c;
    if (disc <= 0.0f) return 0.0f;
    return std::max(0.0f, -b + std::sqrt(disc));
}

float escapingBeamLength(const Scene& scene, const Medium& m, const Vec3& o, const Vec3& d) {
    if (m.type == MediumType::kHomogeneous) {
        const Rgb st = m.sigmaA + m.sigmaS;
        const float minSigma = std::min(st.x, std::min(st.y, st.z));
        if (minSigma > 0.0f) return std::log(1e7f) / minSigma;
    }
    return sphereExit(o, d, scene.sceneSphere.center, scene.sceneSphere.radius * 1.01f);
}

}  // namespace

void appendChainBeams(const Scene& scene, const MediumTrace& trace, const Vec3& dir,
                      const ChainVisit& visit, const ChainVertex& cv, const ChainBeamSource& src,
                      std::vector<ub_beam>* out, MemoryBudget* budget) {
    // Pieces: short beams the visited segments (the last one up to the vertex), long beams
    // every segment of the chain.
    const int count = src.shortBeams ? visit.count : trace.count;
    Rgb weight = src.throughput;  // at the start of segment k
    float fwdPass = 1.0f, revPdf = 1.0f, revPass = 1.0f, travelled = 0.0f;
    const float farLimit = 0.5f * kMediumFarDistance;
    for (int k = 0; k < count; ++k) {
        const MediumTraceSegment& seg = trace.segments[k];
        // What this segment contributes to the probabilities of the pieces after it.
        float length = seg.length, pass = 1.0f, stopRevStart = 0.0f;
        Rgb transmittance(1.0f);
        const bool visited = k < visit.count && !(cv.scattered && k == cv.segment);
        if (seg.mediumId >= 0) {
            const Medium& medium = scene.media[size_t(seg.mediumId)];
            if (length >= farLimit) length = escapingBeamLength(scene, medium, seg.origin, dir);
            // A long beam in a homogeneous medium ends where its transmittance is below 1e-7
            // in every channel (what lies beyond adds less than 1e-7 of its throughput).
            if (!src.shortBeams && medium.type == MediumType::kHomogeneous)
                length = std::min(length, escapingBeamLength(scene, medium, seg.origin, dir));
            if (src.shortBeams && k == visit.count - 1 && cv.scattered)
                length = visit.length[k];  // up to the vertex
            if (length > 0.0f && scatters(medium)) {
                ub_beam b{};
                for (int a = 0; a < 3; ++a) {
                    b.origin[a] = seg.origin[a];
                    b.dir[a] = dir[a];
                    b.throughput[a] = weight[a];
                }
                b.length = length;
                b.mediumId = uint32_t(seg.mediumId);
                b.pathLength = src.pathLength;
                b.dVCM = src.mis.dVCM;
                b.dVM = src.mis.dVM;
                b.dOut = src.mis.dOut;
                b.distBefore = travelled;
                b.fwdPassBefore = fwdPass;
                b.revPdfBeforeL = revPdf;
                b.revPassBefore = revPass;
                b.flags = (src.applyDistSqr ? UB_BEAM_APPLY_DIST2 : 0u) |
                          (k == 0 && src.fromMedium ? UB_BEAM_ORIGIN_IN_PIECE : 0u);
                b.pixel = src.tag;
                pushBudgeted(
                    *out, b, budget, src.budgetName,
                    "fewer --beam-paths, a smaller --resolution or --max-length need less");
            }
            if (k + 1 == count) break;  // nothing after the last piece needs its values
            if (visited) {
                pass = visit.passProb[k];
                stopRevStart = visit.stopRevStartL[k];
                transmittance = visit.transmittance[k];
            } else {
                const MediumSegment ms = evalMediumSegment(medium, seg.origin, dir, length);
                pass = ms.probPass();
                stopRevStart = ms.pdfScatterRevL();
                transmittance = ms.transmittance;
            }
        }
        // The walk from x passes segment k; from a later piece back to x it passes it too,
        // except that at a medium x (segment 0) the reverse walk stops there.
        fwdPass *= pass;
        revPdf *= (k == 0 && src.fromMedium) ? stopRevStart : pass;
        revPass *= pass;
        if (src.shortBeams) {
            if (pass > 0.0f)
                weight *= transmittance / pass;
            else
                weight = Rgb(0.0f);
        } else {
            weight *= transmittance;
        }
        travelled += seg.length;
        if (isBlack(weight)) break;
    }
}

}  // namespace ub
