// Next-event estimation (bpt; Veach 1997, Sec. 10.2; in media Lafortune & Willems 1996):
// from camera vertex z, a light sample x_0 chosen by the light's illuminate() (area or
// solid-angle pdf), weighted by the recursive MIS of kernels/shared/ub_mis.h.
//
// Estimates  L_e(x_0 -> z) f(z) |cos| T(z, x_0) / (p_pick p_W(x_0))  per camera vertex.
// pdfs:      the light's directPdfW (solid angle at z) and emissionPdfW; the camera
//            BSDF/phase in both directions (times the continuation probability); with
//            media the free-flight pdfs of the shadow chain in both directions.
// MIS:       ub_mis_weight_nee_media [TR (44), (45)], with the merging factor of z (UPBP,
//            ub_mis_volume.h), whose R_out is the photon beam along the shadow chain.
#include <cmath>

#include "core/rng.h"
#include "render/medium_walk.h"
#include "render/vcm.h"
#include "render/vertex_scatter.h"

namespace ub {

Rgb VertexCM::directIllumination(Rng& rng, const SubPath& state, const PathVertex& v,
                                 const VertexScatter& scatter) const {
    const int lightCount = int(scene_.lights.size());
    if (lightCount == 0) return Rgb(0.0f);
    const int lightId = std::min(int(rng.uniform() * float(lightCount)), lightCount - 1);
    const Light& light = scene_.lights[size_t(lightId)];
    const Vec2 rnd = rng.uniform2();
    Vec3 dirToLight;
    float distance = 0.0f, directPdfW = 0.0f, emissionPdfW = 0.0f, cosAtLight = 0.0f;
    Rgb le = light.illuminate(scene_.sceneSphere, v.pos, rnd, &dirToLight, &distance, &directPdfW,
                              &emissionPdfW, &cosAtLight);
    if (isBlack(le) || !(directPdfW > 0.0f)) return Rgb(0.0f);

    float cosToLight = 0.0f, bsdfDirPdfW = 0.0f, bsdfRevPdfW = 0.0f;
    Rgb f = scatter.evaluate(dirToLight, &cosToLight, &bsdfDirPdfW, &bsdfRevPdfW);
    if (isBlack(f)) return Rgb(0.0f);
    const float contProb = scatter.continuationProb();
    // BSDF sampling cannot hit a delta light.
    bsdfDirPdfW *= light.isDelta() ? 0.0f : contProb;
    bsdfRevPdfW *= contProb;

    const Vec3 lightPos = v.pos + dirToLight * distance;
    // Area-light points sit on geometry: offset them back along the segment.
    const Vec3 lightOffset = light.isDeltaPosition() ? Vec3(0.0f) : -dirToLight;
    if (!useMedia_) {
        // Weight of [TR (44), (45)].
        const float weight =
            ub_mis_weight_nee(mis_, state.mis, bsdfDirPdfW, bsdfRevPdfW, lightPickProb_, directPdfW,
                              emissionPdfW, cosToLight, cosAtLight);
        const Rgb contrib = le * f * (weight * cosToLight / (lightPickProb_ * directPdfW));
        if (isBlack(contrib)) return Rgb(0.0f);
        const bool blocked = light.isFinite()
                                 ? scene_.occluded(v.pos, v.hit.geoNormal, lightPos, lightOffset)
                                 : scene_.occludedToInfinity(v.pos, v.hit.geoNormal, dirToLight);
        return blocked ? Rgb(0.0f) : contrib;
    }
    // Media: transmittance of the shadow chain, the probability that BSDF/phase sampling
    // passes it, and the pdf of the light subpath stopping at v (ub_mis.h, MEDIA).
    MediumStack stack;
    if (!stackTowards(v, state, dirToLight, &stack)) return Rgb(0.0f);
    const MediumShadow sh =
        light.isFinite()
            ? scene_.shadowTransmittance(v.pos, v.geoNormal(), stack, lightPos, lightOffset)
            : scene_.shadowTransmittanceToInfinity(v.pos, v.geoNormal(), stack, dirToLight);
    if (sh.blocked || isBlack(sh.transmittance)) return Rgb(0.0f);
    // Merging factor of v, its R_out being the photon beam along the shadow chain.
    const float distPdfToZ = v.inMedium ? sh.pdfScatterRevL : sh.probPass;
    const ub_mis_factor factor = ub_mis_vertex_factor(mis_, v.inMedium, 0, 0, ratioIn(state, v),
                                                      length(cross(state.ray.dir, dirToLight)));
    const float merge =
        ub_mis_factor_total(mis_, factor, ub_mis_photon_ratio(mis_, sh.probPass, distPdfToZ));
    const float weight = ub_mis_weight_nee_media(
        mis_, state.mis, bsdfDirPdfW, bsdfRevPdfW, lightPickProb_, directPdfW, emissionPdfW,
        cosToLight, cosAtLight, sh.probPass, distPdfToZ, merge);
    return le * f * sh.transmittance * (weight * cosToLight / (lightPickProb_ * directPdfW));
}

}  // namespace ub
