// Surface photon merging (surf; VCM's vertex merging, Georgiev et al. 2012): a camera
// vertex on a non-specular surface gathers the stored surface light vertices (photons)
// within radius r through the hashed grid.
//
// Estimates  sum_photons f(z; w_z, w_y) Phi_y / (N_L pi r^2)   (disk kernel, [TR (19)]).
// pdfs:      the camera BSDF towards the photon's incoming direction (times the camera's
//            continuation probability) and the reverse one (times the light's).
// MIS:       ub_mis_weight_merge [TR (38), (39)]. Medium photons are merged by the
//            volumetric estimators (estimators/volume_estimate.h), not here.
#include <cmath>

#include "render/medium_walk.h"
#include "render/vcm.h"
#include "render/vertex_scatter.h"

namespace ub {

Rgb VertexCM::mergeVertices(const SubPath& state, const Hit& hit, const Bsdf& bsdf) const {
    const int maxLength = options_.maxPathLength, minLength = options_.minPathLength;
    const float cameraCont = vcmContinuationProb(bsdf);
    Rgb sum(0.0f);
    grid_.query(hit.pos, lightVertices_, &LightVertex::position, [&](uint32_t index) {
        const LightVertex& lv = lightVertices_[index];
        if (lv.inMedium()) return;  // medium photons merge through the volumetric estimators
        const int length = int(lv.pathLength) + state.pathLength;
        if (length > maxLength || length < minLength) return;
        float cameraDirPdfW = 0.0f, cameraRevPdfW = 0.0f;
        // The camera BSDF evaluated towards the light vertex's incoming direction.
        Rgb f = bsdf.evaluate(lv.dirFix3(), nullptr, &cameraDirPdfW, &cameraRevPdfW);
        if (isBlack(f)) return;
        float weight = 1.0f;  // PPM: no MIS
        if (!ppm_) {
            cameraDirPdfW *= cameraCont;
            // The reverse direction would be sampled by the light subpath: its roulette.
            cameraRevPdfW *= lv.contProb;
            ub_mis_partials lightMis = {lv.dVCM, lv.dVC, lv.dVM, 0.0f};
            // Weight of [TR (38), (39)].
            weight = ub_mis_weight_merge(mis_, lightMis, state.mis, cameraDirPdfW, cameraRevPdfW);
        }
        sum += f * lv.throughput3() * weight;
    });
    return sum * vmNormalization_;
}

}  // namespace ub
