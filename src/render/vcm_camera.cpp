// VertexCM camera pass: camera subpaths with emitter hits, next-event estimation,
// vertex connections to the paired light subpath, and vertex merging with the
// light vertices of all light subpaths through the hashed grid. Each technique
// is MIS-weighted with the recursive partials of kernels/shared/ub_mis.h.
#include <cmath>

#include "core/rng.h"
#include "render/vcm.h"

namespace ub {

namespace {
constexpr uint64_t kCameraSalt = 2;
}  // namespace

Rgb VertexCM::traceCameraPath(int x, int y, int iteration) const {
    const Camera& camera = scene_.camera;
    const int maxLength = options_.maxPathLength, minLength = options_.minPathLength;
    const size_t pixelIndex = size_t(y) * size_t(camera.width()) + size_t(x);
    Rng rng = Rng::forPath(options_.seed, uint64_t(iteration), uint64_t(pixelIndex), kCameraSalt);

    SubPath state;
    const Vec2 jitter = rng.uniform2();
    const Vec2 lensU = rng.uniform2();
    state.ray = camera.generateRay(Vec2(float(x) + jitter.x, float(y) + jitter.y), lensU);
    // Camera subpath partials [TR (31)-(33)], completed at the first hit. Thin lenses (ppm and
    // bpm only) never use dVCM of the camera vertex: it is multiplied by vcWeightFactor = 0.
    const float cameraPdfW = camera.isPinhole() ? camera.pdfW(state.ray.dir) : 1.0f;
    state.mis = ub_mis_init_camera(mis_, cameraPdfW);

    Rgb color(0.0f);
    for (;; ++state.pathLength) {
        Hit hit;
        if (!scene_.intersect(state.ray, &hit)) {
            // Environment: no distance or cosine conversion for lights at infinity [TR 5.1].
            if (scene_.backgroundLightId >= 0 && state.pathLength >= minLength)
                color += state.throughput *
                         lightHitRadiance(scene_.lights[size_t(scene_.backgroundLightId)], state,
                                          state.ray.dir, state.ray.org, Vec3(0.0f));
            break;
        }
        // Emitter hit: the light endpoint's cosine is the geometric one, as in emission.
        if (hit.lightId >= 0 && state.pathLength >= minLength) {
            SubPath atLight = state;
            atLight.mis = ub_mis_at_hit(mis_, state.mis, hit.dist,
                                        std::fabs(dot(hit.geoNormal, state.ray.dir)), 1);
            color +=
                state.throughput * lightHitRadiance(scene_.lights[size_t(hit.lightId)], atLight,
                                                    state.ray.dir, hit.pos, hit.geoNormal);
        }
        // Light tracing uses the camera pass only for directly visible emitters.
        if (lightTraceOnly_) break;
        if (state.pathLength >= maxLength || hit.materialId < 0) break;

        Bsdf bsdf;
        if (!scene_.setupBsdf(&bsdf, hit, -state.ray.dir, /*fromLight=*/false)) break;
        // Complete the partials at this vertex [TR (31)-(36)].
        state.mis = ub_mis_at_hit(mis_, state.mis, hit.dist, bsdf.cosThetaFix(), 1);

        if (!bsdf.isDelta() && useVC_) {
            // Next-event estimation: a path of pathLength + 1 segments.
            if (state.pathLength + 1 >= minLength)
                color += state.throughput * directIllumination(rng, state, hit, bsdf);
            // Connections to the vertices of the light subpath with the same index.
            const uint32_t first = pixelIndex == 0 ? 0 : pathEnds_[pixelIndex - 1];
            for (uint32_t i = first; i < pathEnds_[pixelIndex]; ++i) {
                const LightVertex& lv = lightVertices_[i];
                const int length = int(lv.pathLength) + 1 + state.pathLength;
                if (length < minLength) continue;
                if (length > maxLength) break;  // vertices are stored in path order
                color += state.throughput * lv.throughput * connectVertices(lv, state, hit, bsdf);
            }
        }
        if (!bsdf.isDelta() && useVM_) {
            color += state.throughput * mergeVertices(state, hit, bsdf);
            if (ppm_) break;  // PPM merges at the first non-specular camera vertex only
        }
        if (!sampleScattering(rng, bsdf, hit, state)) break;
    }
    return color;
}

Rgb VertexCM::lightHitRadiance(const Light& light, const SubPath& state, const Vec3& rayDir,
                               const Vec3& hitPos, const Vec3& hitNormal) const {
    float directPdfA = 0.0f, emissionPdfW = 0.0f;
    Rgb le = light.radianceAlong(scene_.sceneSphere, rayDir, hitPos, hitNormal, &directPdfA,
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

Rgb VertexCM::directIllumination(Rng& rng, const SubPath& state, const Hit& hit,
                                 const Bsdf& bsdf) const {
    const int lightCount = int(scene_.lights.size());
    if (lightCount == 0) return Rgb(0.0f);
    const int lightId = std::min(int(rng.uniform() * float(lightCount)), lightCount - 1);
    const Light& light = scene_.lights[size_t(lightId)];
    const Vec2 rnd = rng.uniform2();
    Vec3 dirToLight;
    float distance = 0.0f, directPdfW = 0.0f, emissionPdfW = 0.0f, cosAtLight = 0.0f;
    Rgb le = light.illuminate(scene_.sceneSphere, hit.pos, rnd, &dirToLight, &distance, &directPdfW,
                              &emissionPdfW, &cosAtLight);
    if (isBlack(le) || !(directPdfW > 0.0f)) return Rgb(0.0f);

    float cosToLight = 0.0f, bsdfDirPdfW = 0.0f, bsdfRevPdfW = 0.0f;
    Rgb f = bsdf.evaluate(dirToLight, &cosToLight, &bsdfDirPdfW, &bsdfRevPdfW);
    if (isBlack(f)) return Rgb(0.0f);
    const float contProb = vcmContinuationProb(bsdf);
    // BSDF sampling cannot hit a delta light.
    bsdfDirPdfW *= light.isDelta() ? 0.0f : contProb;
    bsdfRevPdfW *= contProb;
    // Weight of [TR (44), (45)].
    const float weight =
        ub_mis_weight_nee(mis_, state.mis, bsdfDirPdfW, bsdfRevPdfW, lightPickProb_, directPdfW,
                          emissionPdfW, cosToLight, cosAtLight);
    const Rgb contrib = le * f * (weight * cosToLight / (lightPickProb_ * directPdfW));
    if (isBlack(contrib)) return Rgb(0.0f);
    bool blocked;
    if (light.isFinite()) {
        const Vec3 lightPos = hit.pos + dirToLight * distance;
        // Area-light points sit on geometry: offset them back along the segment.
        const Vec3 lightOffset = light.isDeltaPosition() ? Vec3(0.0f) : -dirToLight;
        blocked = scene_.occluded(hit.pos, hit.geoNormal, lightPos, lightOffset);
    } else {
        blocked = scene_.occludedToInfinity(hit.pos, hit.geoNormal, dirToLight);
    }
    return blocked ? Rgb(0.0f) : contrib;
}

Rgb VertexCM::connectVertices(const LightVertex& lv, const SubPath& state, const Hit& hit,
                              const Bsdf& bsdf) const {
    Vec3 dir = lv.position - hit.pos;
    const float distSqr = lengthSqr(dir);
    if (!(distSqr > 0.0f)) return Rgb(0.0f);
    const float distance = std::sqrt(distSqr);
    dir /= distance;

    float cosCamera = 0.0f, cameraDirPdfW = 0.0f, cameraRevPdfW = 0.0f;
    Rgb fCamera = bsdf.evaluate(dir, &cosCamera, &cameraDirPdfW, &cameraRevPdfW);
    if (isBlack(fCamera)) return Rgb(0.0f);
    const float cameraCont = vcmContinuationProb(bsdf);
    cameraDirPdfW *= cameraCont;
    cameraRevPdfW *= cameraCont;

    Bsdf lightBsdf;
    if (!scene_.setupBsdf(&lightBsdf, int(lv.materialId), lv.uv, lv.dirFix, lv.geoNormal,
                          lv.shadingNormal, /*fromLight=*/true))
        return Rgb(0.0f);
    float cosLight = 0.0f, lightDirPdfW = 0.0f, lightRevPdfW = 0.0f;
    Rgb fLight = lightBsdf.evaluate(-dir, &cosLight, &lightDirPdfW, &lightRevPdfW);
    if (isBlack(fLight)) return Rgb(0.0f);
    lightDirPdfW *= lv.continuationProb;
    lightRevPdfW *= lv.continuationProb;

    const float geometry = cosLight * cosCamera / distSqr;
    // Pdfs of sampling each end from the other, in area measure.
    const float cameraDirPdfA = cameraDirPdfW * cosLight / distSqr;
    const float lightDirPdfA = lightDirPdfW * cosCamera / distSqr;
    ub_mis_partials lightMis = {lv.dVCM, lv.dVC, lv.dVM};
    // Weight of [TR (40), (41)].
    const float weight = ub_mis_weight_connect(mis_, lightMis, state.mis, cameraDirPdfA,
                                               lightRevPdfW, lightDirPdfA, cameraRevPdfW);
    const Rgb contrib = fCamera * fLight * (weight * geometry);
    if (isBlack(contrib)) return Rgb(0.0f);
    if (scene_.occluded(hit.pos, hit.geoNormal, lv.position, lv.geoNormal)) return Rgb(0.0f);
    return contrib;
}

Rgb VertexCM::mergeVertices(const SubPath& state, const Hit& hit, const Bsdf& bsdf) const {
    const int maxLength = options_.maxPathLength, minLength = options_.minPathLength;
    const float cameraCont = vcmContinuationProb(bsdf);
    Rgb sum(0.0f);
    grid_.query(hit.pos, lightVertices_, &LightVertex::position, [&](uint32_t index) {
        const LightVertex& lv = lightVertices_[index];
        const int length = int(lv.pathLength) + state.pathLength;
        if (length > maxLength || length < minLength) return;
        float cameraDirPdfW = 0.0f, cameraRevPdfW = 0.0f;
        // The camera BSDF evaluated towards the light vertex's incoming direction.
        Rgb f = bsdf.evaluate(lv.dirFix, nullptr, &cameraDirPdfW, &cameraRevPdfW);
        if (isBlack(f)) return;
        float weight = 1.0f;  // PPM: no MIS
        if (!ppm_) {
            cameraDirPdfW *= cameraCont;
            // The reverse direction would be sampled by the light subpath: its roulette.
            cameraRevPdfW *= lv.continuationProb;
            ub_mis_partials lightMis = {lv.dVCM, lv.dVC, lv.dVM};
            // Weight of [TR (38), (39)].
            weight = ub_mis_weight_merge(mis_, lightMis, state.mis, cameraDirPdfW, cameraRevPdfW);
        }
        sum += f * lv.throughput * weight;
    });
    return sum * vmNormalization_;
}

}  // namespace ub
