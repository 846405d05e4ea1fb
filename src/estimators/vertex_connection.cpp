// Vertex connection (bpt; Veach 1997, Sec. 10.2): camera vertex z joined to every stored
// vertex y of the light subpath with the same index, surface or medium vertex.
//
// Estimates  f(y) G(y, z) T(y, z) f(z)  times both throughputs, G = cos_y cos_z / d^2
//            (cosines 1 at medium vertices).
// pdfs:      each end's BSDF/phase sampling the other, in area (volume) measure at the
//            other end, with the free-flight pdf of the connecting chain in that direction;
//            each end's reverse pdf towards its own previous vertex.
// MIS:       ub_mis_weight_connect [TR (40), (41)], with the merging factors of both ends
//            (UPBP, ub_mis_volume.h), whose R_out is the other kind of beam along the
//            connecting chain.
#include <cmath>

#include "render/medium_walk.h"
#include "render/vcm.h"
#include "render/vertex_scatter.h"

namespace ub {

Rgb VertexCM::connectVertices(const LightVertex& lv, uint32_t lightIndex,
                              LightScatterCache& lightScatters, const SubPath& state,
                              const PathVertex& v, const VertexScatter& scatter) const {
    Vec3 dir = lv.pos3() - v.pos;
    const float distSqr = lengthSqr(dir);
    if (!(distSqr > 0.0f)) return Rgb(0.0f);
    const float distance = std::sqrt(distSqr);
    dir /= distance;

    float cosCamera = 0.0f, cameraDirPdfW = 0.0f, cameraRevPdfW = 0.0f;
    Rgb fCamera = scatter.evaluate(dir, &cosCamera, &cameraDirPdfW, &cameraRevPdfW);
    if (isBlack(fCamera)) return Rgb(0.0f);
    const float cameraCont = scatter.continuationProb();
    cameraDirPdfW *= cameraCont;
    cameraRevPdfW *= cameraCont;

    // The light vertex's scattering function: its BSDF, or its medium's phase function, set
    // up at its first connection from this camera subpath.
    const VertexScatter* lightScatter = lightScatters.get(scene_, lv, lightIndex);
    if (!lightScatter) return Rgb(0.0f);
    float cosLight = 0.0f, lightDirPdfW = 0.0f, lightRevPdfW = 0.0f;
    Rgb fLight = lightScatter->evaluate(-dir, &cosLight, &lightDirPdfW, &lightRevPdfW);
    if (isBlack(fLight)) return Rgb(0.0f);
    lightDirPdfW *= lv.contProb;
    lightRevPdfW *= lv.contProb;

    // Visibility; with media the transmittance of the connecting chain (walked from the
    // camera vertex through imaginary boundaries) and its free-flight pdfs in both
    // directions, stopping at the end vertex if that lies in a medium (ub_mis.h, MEDIA).
    Rgb transmittance(1.0f);
    float distPdfToLight = 1.0f, distPdfToCamera = 1.0f, passProb = 1.0f;
    if (useMedia_) {
        MediumStack stack;
        if (!stackTowards(v, state, dir, &stack)) return Rgb(0.0f);
        const MediumShadow sh =
            scene_.shadowTransmittance(v.pos, v.geoNormal(), stack, lv.pos3(), lv.geoNormal3());
        if (sh.blocked || isBlack(sh.transmittance)) return Rgb(0.0f);
        transmittance = sh.transmittance;
        distPdfToLight = lv.inMedium() ? sh.pdfScatterFwdL : sh.probPass;
        distPdfToCamera = v.inMedium ? sh.pdfScatterRevL : sh.probPass;
        passProb = sh.probPass;
    }

    const float geometry = cosLight * cosCamera / distSqr;
    // Pdfs of sampling each end from the other, in area (volume) measure.
    const float cameraDirPdfA = cameraDirPdfW * cosLight * distPdfToLight / distSqr;
    const float lightDirPdfA = lightDirPdfW * cosCamera * distPdfToCamera / distSqr;
    ub_mis_partials lightMis = {lv.dVCM, lv.dVC, lv.dVM, 0.0f};
    // Merging factors of both ends; R_out of each is the other kind of beam along the
    // connecting chain (ub_mis_volume.h).
    const ub_mis_factor lightFactor =
        ub_mis_vertex_factor(mis_, lv.inMedium(), 0, 1, lv.rInL, length(cross(lv.dirFix3(), dir)));
    const ub_mis_factor cameraFactor = ub_mis_vertex_factor(
        mis_, v.inMedium, 0, 0, ratioIn(state, v), length(cross(state.ray.dir, dir)));
    const float lightMerge =
        ub_mis_factor_total(mis_, lightFactor, ub_mis_query_ratio(mis_, passProb, distPdfToLight));
    const float cameraMerge = ub_mis_factor_total(
        mis_, cameraFactor, ub_mis_photon_ratio(mis_, passProb, distPdfToCamera));
    // Weight of [TR (40), (41)].
    const float weight =
        ub_mis_weight_connect(mis_, lightMis, state.mis, cameraDirPdfA, lightRevPdfW, lightDirPdfA,
                              cameraRevPdfW, lightMerge, cameraMerge);
    const Rgb contrib = fCamera * fLight * transmittance * (weight * geometry);
    if (isBlack(contrib)) return Rgb(0.0f);
    if (!useMedia_ && scene_.occluded(v.pos, v.hit.geoNormal, lv.pos3(), lv.geoNormal3()))
        return Rgb(0.0f);
    return contrib;
}

}  // namespace ub
