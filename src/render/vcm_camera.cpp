// VertexCM camera pass: camera subpaths with emitter hits (here), next-event
// estimation (estimators/next_event.cpp), vertex connections to the paired light
// subpath (estimators/vertex_connection.cpp), surface merging
// (estimators/surface_merging.cpp), and the records of UPBP's query points and query
// beams. Each technique is MIS-weighted with the recursive partials of
// kernels/shared/ub_mis.h.
#include <cmath>

#include "core/memory_budget.h"
#include "core/rng.h"
#include "estimators/surface_merging.h"
#include "render/vcm.h"
#include "render/vertex_scatter.h"

namespace ub {

namespace {
constexpr uint64_t kCameraSalt = 2;
}  // namespace

Rgb VertexCM::traceCameraPath(int x, int y, int iteration, CameraRecords* records) const {
    const Camera& camera = scene_.camera;
    const int maxLength = options_.maxPathLength, minLength = options_.minPathLength;
    const size_t pixelIndex = size_t(y) * size_t(camera.width()) + size_t(x);
    Rng rng = Rng::forPath(options_.seed, uint64_t(iteration), uint64_t(pixelIndex), kCameraSalt);

    SubPath state;
    const Vec2 jitter = rng.uniform2();
    const Vec2 lensU = rng.uniform2();
    // Pixel position from the scene's reconstruction filter (box: pixel + jitter), and the
    // path's weight (1, or Mitsuba's ptracer convention at the borders: scene/pixel_filter.h).
    float pixelWeight = 1.0f;
    const Vec2 raster = scene_.settings.pixelFilter.sampleRaster(x, y, jitter, camera.width(),
                                                                 camera.height(), &pixelWeight);
    state.ray = camera.generateRay(raster, lensU);
    if (pixelWeight <= 0.0f) return Rgb(0.0f);  // outside the image (ptracer convention)
    state.throughput = Rgb(pixelWeight);
    // Camera subpath partials [TR (31)-(33)], completed at the first hit. Pinhole and thin
    // lens: the direction pdf (from the lens point, scene/camera.h). Orthographic: the area pdf
    // 1 / A_pixel of the ray's origin, the direction a delta, and the first hit converts it
    // without 1/d^2 (as a directional light's first segment [TR Sec. 5.1]).
    const bool ortho = camera.isOrthographic();
    const float cameraPdfW = ortho ? 1.0f / camera.orthoPixelArea() : camera.pdfW(state.ray.dir);
    state.mis = ub_mis_init_camera(mis_, cameraPdfW);
    state.isFiniteLight = !ortho;

    state.rayFromMedium = false;
    if (useMedia_) state.stack = scene_.cameraMediumStack;

    Rgb color(0.0f);
    LightScatterCache lightScatters;  // of the light subpath this one connects to
    for (;; ++state.pathLength) {
        // Without vertex connection (merging-only sets: upbp without bpt, bpm), a vertex at the
        // length limit adds nothing unless the subpath so far is purely specular (it may hit an
        // emitter, SmallVCM's rule in lightHitRadiance) or a medium emits: it merges with no
        // light vertex (each adds a segment), records no query and connects to nothing. Its
        // segment is not traced, and the image is unchanged bit for bit (each pixel draws its
        // own random numbers). SmallUPBP traces it (docs/performance.md, session 36).
        if (state.pathLength >= maxLength && !useVC_ && !state.specularPath && !mediaEmit_ &&
            !nullNotCounted_ && !lightTraceOnly_)
            break;
        PathVertex v;
        bool escaped = false;
        const Rgb throughputBefore = state.throughput;
        // UPBP query beams along this chain: their points merge with light lengths >= 1.
        const bool beamsHere = upbp_.queryBeams() && state.pathLength + 1 <= maxLength;
        if (!traceToVertex(rng, state, &v, &escaped, beamsHere ? &records->beams : nullptr,
                           uint32_t(pixelIndex))) {
            // Environment: no distance or cosine conversion for lights at infinity [TR 5.1];
            // with media, the free-flight pdfs of the escaping chain (ub_mis.h, MEDIA).
            if (escaped && scene_.backgroundLightId >= 0 && state.pathLength >= minLength) {
                SubPath atLight = state;
                atLight.mis = misAtHit(state, v, 1.0f, 0);
                color +=
                    state.throughput *
                    lightHitRadiance(scene_.lights[size_t(scene_.backgroundLightId)], atLight,
                                     state.ray.dir, state.ray.org, Vec3(0.0f), Vec2(0.0f, 0.0f));
            }
            break;
        }
        // Medium emission (sigma_a Le) at a medium vertex: collision estimator, weight 1 (no
        // light subpath starts in a medium). Not for vlt (rejected in the constructor).
        if (v.inMedium && !lightTraceOnly_ && state.pathLength >= minLength)
            color += throughputBefore * v.mediumEmission;
        // Emitter hit: the light endpoint's cosine is the geometric one, as in emission.
        if (!v.inMedium && v.hit.lightId >= 0 && state.pathLength >= minLength) {
            SubPath atLight = state;
            atLight.mis = misAtHit(state, v, std::fabs(dot(v.hit.geoNormal, state.ray.dir)),
                                   state.applyDistSqr());
            color += state.throughput * lightHitRadiance(scene_.lights[size_t(v.hit.lightId)],
                                                         atLight, state.ray.dir, v.hit.pos,
                                                         v.hit.geoNormal, v.hit.uv);
        }
        // Light tracing uses the camera pass only for directly visible emitters.
        if (lightTraceOnly_) break;
        // At the length limit only a null lobe (not counted) may continue the subpath.
        const bool atLimit = state.pathLength >= maxLength;
        if (atLimit && !nullNotCounted_) break;

        VertexScatter scatter;  // BSDF, or phase function at a medium vertex
        if (!setupScatter(v, state, /*fromLight=*/false, &scatter)) break;
        if (atLimit && !scatter.hasNullLobe()) break;
        // Complete the partials at this vertex [TR (31)-(36)] (ub_mis.h, MEDIA).
        state.mis = misAtHit(state, v, scatter.cosThetaFix(), state.applyDistSqr());

        // UPBP query point: merged with photon points (pp3d) and photon beams (bp2d).
        if (v.inMedium && upbp_.queryPoints() && !atLimit) {
            ub_query_point q{};
            for (int a = 0; a < 3; ++a) {
                q.pos[a] = v.pos[a];
                q.throughput[a] = state.throughput[a];
                q.dirFix[a] = -state.ray.dir[a];
            }
            q.pathLength = uint32_t(state.pathLength);
            q.mediumId = uint32_t(v.mediumId);
            q.rQueryL = ratioIn(state, v);
            q.dVCM = state.mis.dVCM;
            q.dVM = state.mis.dVM;
            q.contProb = scatter.continuationProb();
            q.pixel = uint32_t(pixelIndex);
            pushBudgeted(records->points, q, budget_.get(), "query points",
                         "a smaller --resolution or --max-length needs less");
        }

        if (!atLimit && !scatter.isDelta() && useVC_) {
            // Next-event estimation: a path of pathLength + 1 segments.
            if (state.pathLength + 1 >= minLength)
                color += state.throughput * directIllumination(rng, state, v, scatter);
            // Connections to the vertices of the light subpath with the same index.
            const uint32_t first = pixelIndex == 0 ? 0 : pathEnds_[pixelIndex - 1];
            for (uint32_t i = first; i < pathEnds_[pixelIndex]; ++i) {
                const LightVertex& lv = lightVertices_[i];
                const int length = int(lv.pathLength) + 1 + state.pathLength;
                if (length < minLength) continue;
                if (length > maxLength) break;  // vertices are stored in path order
                color += state.throughput * lv.throughput3() *
                         connectVertices(lv, i - first, lightScatters, state, v, scatter);
            }
        }
        if (!atLimit && !scatter.isDelta() && useVM_ && !v.inMedium) {
            if (surfBatch_) {
                // upbp: a surface query, estimated in batch after the camera pass
                // (estimators/surface_merging.h), on the OpenCL device when there is one.
                pushBudgeted(
                    records->surf,
                    makeSurfaceQuery(scatter.bsdf(), v.hit.pos, state.pathLength, state.throughput,
                                     uint32_t(pixelIndex), state.mis.dVCM, state.mis.dVM,
                                     scatter.continuationProb(), v.hit.materialId),
                    budget_.get(), "surface queries",
                    "a smaller --resolution or --max-length needs less");
            } else {
                color += state.throughput * mergeVertices(state, v.hit, scatter.bsdf());
            }
            if (ppm_) break;  // PPM merges at the first non-specular camera vertex only
        }
        if (!sampleScattering(rng, scatter, v, state, atLimit)) break;
    }
    return color;
}

Rgb VertexCM::lightHitRadiance(const Light& light, const SubPath& state, const Vec3& rayDir,
                               const Vec3& hitPos, const Vec3& hitNormal, const Vec2& hitUv) const {
    float directPdfA = 0.0f, emissionPdfW = 0.0f;
    Rgb le = light.radianceAlong(scene_.sceneSphere, rayDir, hitPos, hitNormal, hitUv, &directPdfA,
                                 &emissionPdfW);
    if (isBlack(le)) return Rgb(0.0f);
    // A directly visible light has no other technique.
    if (state.pathLength == 1) return le;
    // Merging-only algorithms: emitters count only at the end of purely specular camera
    // subpaths; other paths are covered by merging (SmallVCM).
    if (!useVC_) return state.specularPath ? le : Rgb(0.0f);
    directPdfA *= lightPickProb_;
    emissionPdfW *= lightPickProb_;
    // Camera subpath weight [TR (42), (43)].
    return le * ub_mis_weight_hit_light(mis_, state.mis, directPdfA, emissionPdfW);
}

}  // namespace ub
