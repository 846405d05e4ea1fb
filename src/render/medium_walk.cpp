// Free-flight sampling along a segment chain with both distance pdfs (see medium_walk.h).
#include "render/medium_walk.h"

#include "core/rng.h"
#include "scene/medium.h"
#include "scene/scene.h"

namespace ub {

ChainVertex sampleChainVertex(const Scene& scene, const MediumTrace& trace, const Vec3& dir,
                              bool prevInMedium, Rng& rng, ChainVisit* visit) {
    ChainVertex v;
    float travelled = 0.0f;
    if (visit) visit->count = 0;
    for (int k = 0; k < trace.count; ++k) {
        const MediumTraceSegment& seg = trace.segments[k];
        if (visit) {
            visit->count = k + 1;
            visit->length[k] = seg.length;
            visit->passProb[k] = 1.0f;
            visit->stopRevStartL[k] = 0.0f;
            visit->transmittance[k] = Rgb(1.0f);
        }
        if (seg.mediumId < 0) {
            // Vacuum: passed with probability 1; a chain cannot start at a medium vertex here.
            if (k == 0 && prevInMedium) v.distPdfRev = 0.0f;
            travelled += seg.length;
            continue;
        }
        const Medium& medium = scene.media[size_t(seg.mediumId)];
        const float uChannel = rng.uniform(), uDistance = rng.uniform();
        const FreeFlightSample ff =
            sampleFreeFlight(medium, seg.origin, dir, seg.length, uChannel, uDistance);
        if (!(ff.pdf > 0.0f)) {
            v.weight = Rgb(0.0f);
            return v;
        }
        // Reverse direction: stop at a medium x_{i-1} (segment 0), else pass this (part of
        // the) segment.
        v.distPdfRev *=
            (k == 0 && prevInMedium) ? ff.segment.pdfScatterRevL() : ff.segment.probPass();
        v.distPdfFwd *= ff.pdf;
        v.passProb *= ff.segment.probPass();
        if (visit) {
            visit->length[k] = ff.scattered ? ff.t : seg.length;
            visit->passProb[k] = ff.segment.probPass();
            visit->stopRevStartL[k] = ff.segment.pdfScatterRevL();
            visit->transmittance[k] = ff.segment.transmittance;
        }
        if (ff.scattered) {
            v.scattered = true;
            v.pos = seg.origin + dir * ff.t;
            v.mediumId = seg.mediumId;
            v.segment = k;
            v.distance = travelled + ff.t;
            if (medium.hasEmission()) {
                const MediumCoefficients c = mediumCoefficientsAt(medium, v.pos);
                v.emission = v.weight * ff.segment.transmittance * c.sigmaA * c.Le / ff.pdf;
            }
            v.weight *= ff.weight;
            return v;
        }
        v.weight *= ff.weight;
        travelled += seg.length;
    }
    v.distance = trace.distance;
    return v;
}

}  // namespace ub
