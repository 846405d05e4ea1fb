// Light tracing (lt, and the light-tracing technique of bpt; Veach 1997, Sec. 10.2): each
// non-specular light vertex y is connected to the camera and splatted to the pixel it
// projects to. A thin lens: to a lens point sampled uniformly (the camera's own lens
// sampling, so its area pdf cancels against the importance's 1 / A_lens and appears in no
// MIS ratio), splatted where the line through it meets the focus plane; the camera's
// direction pdf from a lens point is the pinhole's d_img^2 / cos^3 (scene/camera.h). An
// orthographic camera: to the point of its near plane in front of y, along -forward; its
// importance is a delta in direction, so the image-to-surface factor is |cos_y| / A_pixel with
// no 1/d^2, the conversion of a directional light's emission [TR Sec. 5.1] mirrored.
//
// Estimates  Theta_y f(y) T(y, c) / (N_L p_cam,A)   with p_cam,A = p_cam,W |cos_y| / d^2,
//            the image-to-surface factor of [TR Sec. 5.2] (|cos_y| = 1 in a medium).
// pdfs:      the camera's area pdf of y with the free-flight pdf of the camera ray
//            stopping at y (media); the light BSDF/phase towards its previous vertex.
// MIS:       ub_mis_weight_light_trace [TR (46), (47)], with the merging factor of y (UPBP),
//            whose R_out is the query beam along the camera ray.
#include <cmath>

#include "core/rng.h"
#include "render/medium_walk.h"
#include "render/vcm.h"
#include "render/vertex_scatter.h"

namespace ub {

void VertexCM::connectToCamera(Rng& rng, const SubPath& state, const PathVertex& v,
                               const VertexScatter& scatter, SplatBuffer::Chunk& splats) const {
    const Camera& camera = scene_.camera;
    // The lens point (a pinhole draws no random numbers: its sequences stay as they were), or
    // the orthographic camera's film point.
    const bool ortho = camera.isOrthographic();
    const Vec3 eye = ortho                ? camera.orthoFilmPoint(v.pos)
                     : camera.isPinhole() ? camera.position()
                                          : camera.lensPoint(rng.uniform2());
    Vec2 raster;
    if (!camera.worldToRaster(v.pos, eye, &raster)) return;
    Vec3 dirToCamera = eye - v.pos;
    const float distSqr = lengthSqr(dirToCamera);
    const float distance = std::sqrt(distSqr);
    dirToCamera /= distance;

    float cosToCamera = 0.0f, bsdfRevPdfW = 0.0f;
    Rgb f = scatter.evaluate(dirToCamera, &cosToCamera, nullptr, &bsdfRevPdfW);
    if (isBlack(f)) return;
    bsdfRevPdfW *= scatter.continuationProb();

    const float cosAtCamera = dot(camera.forward(), -dirToCamera);
    if (cosAtCamera <= 0.0f) return;
    // Image-plane area (unit pixel area) to surface area at v.pos [TR Sec. 5.2]:
    // p_cam,W = d_img^2 / cos^3, and p_cam,A = p_cam,W cos_y / d^2 (cos_y = 1 in a medium).
    // Orthographic: p_cam,A = cos_y / A_pixel (scene/camera.h, orthoPixelArea).
    float imageToSurface;
    if (ortho) {
        imageToSurface = cosToCamera / camera.orthoPixelArea();
    } else {
        const float imagePointToCameraDist = camera.imagePlaneDist() / cosAtCamera;
        const float imageToSolidAngle =
            imagePointToCameraDist * imagePointToCameraDist / cosAtCamera;
        imageToSurface = imageToSolidAngle * cosToCamera / distSqr;
    }

    // Visibility, and with media the transmittance of the chain from the camera (walked from
    // the camera's media) with the pdf of the camera ray stopping at v (ub_mis.h, MEDIA).
    Rgb transmittance(1.0f);
    float distPdfToVertex = 1.0f, passToVertex = 1.0f;
    if (useMedia_) {
        const MediumShadow sh = scene_.shadowTransmittance(
            eye, Vec3(0.0f), scene_.cameraMediumStack, v.pos, v.geoNormal());
        if (sh.blocked || isBlack(sh.transmittance)) return;
        transmittance = sh.transmittance;
        distPdfToVertex = v.inMedium ? sh.pdfScatterFwdL : sh.probPass;
        passToVertex = sh.probPass;
    }
    const float cameraPdfA = imageToSurface * distPdfToVertex;

    // Light tracing alone has no MIS; otherwise the weight of [TR (46), (47)], with the
    // merging factor of v whose R_out is that of the camera ray (ub_mis_volume.h).
    const ub_mis_factor factor = ub_mis_vertex_factor(mis_, v.inMedium, 0, 1, ratioIn(state, v),
                                                      length(cross(state.ray.dir, dirToCamera)));
    const float merge =
        ub_mis_factor_total(mis_, factor, ub_mis_query_ratio(mis_, passToVertex, distPdfToVertex));
    const float weight = lightTraceOnly_ ? 1.0f
                                         : ub_mis_weight_light_trace(mis_, state.mis, cameraPdfA,
                                                                     bsdfRevPdfW, merge);
    const Rgb contrib =
        state.throughput * f * transmittance * (weight * imageToSurface / lightSubPathCount_);
    if (isBlack(contrib)) return;
    if (!useMedia_ && scene_.occluded(v.pos, v.geoNormal(), eye, Vec3(0.0f))) return;
    splats.add(raster, contrib);
}

}  // namespace ub
