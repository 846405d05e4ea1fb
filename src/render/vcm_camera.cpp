// VertexCM camera pass: camera subpaths with emitter hits, next-event estimation,
// vertex connections to the paired light subpath, and vertex merging with the
// light vertices of all light subpaths through the hashed grid. Each technique
// is MIS-weighted with the recursive partials of kernels/shared/ub_mis.h.
#include <cmath>

#include "core/rng.h"
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
    state.ray = camera.generateRay(Vec2(float(x) + jitter.x, float(y) + jitter.y), lensU);
    // Camera subpath partials [TR (31)-(33)], completed at the first hit. Thin lenses (ppm and
    // bpm only) never use dVCM of the camera vertex: it is multiplied by bptFactor = 0.
    const float cameraPdfW = camera.isPinhole() ? camera.pdfW(state.ray.dir) : 1.0f;
    state.mis = ub_mis_init_camera(mis_, cameraPdfW);

    state.rayFromMedium = false;
    if (useMedia_) state.stack = scene_.cameraMediumStack;

    Rgb color(0.0f);
    for (;; ++state.pathLength) {
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
                color += state.throughput *
                         lightHitRadiance(scene_.lights[size_t(scene_.backgroundLightId)], atLight,
                                          state.ray.dir, state.ray.org, Vec3(0.0f));
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
            atLight.mis = misAtHit(state, v, std::fabs(dot(v.hit.geoNormal, state.ray.dir)), 1);
            color +=
                state.throughput * lightHitRadiance(scene_.lights[size_t(v.hit.lightId)], atLight,
                                                    state.ray.dir, v.hit.pos, v.hit.geoNormal);
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
        state.mis = misAtHit(state, v, scatter.cosThetaFix(), 1);

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
            records->points.push_back(q);
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
                color += state.throughput * lv.throughput * connectVertices(lv, state, v, scatter);
            }
        }
        if (!atLimit && !scatter.isDelta() && useVM_ && !v.inMedium) {
            const Rgb merged = state.throughput * mergeVertices(state, v.hit, scatter.bsdf());
            if (!records->surf.empty())  // UPBP layers: kept apart, added by the caller
                records->surf[size_t(x)] += merged;
            else
                color += merged;
            if (ppm_) break;  // PPM merges at the first non-specular camera vertex only
        }
        if (!sampleScattering(rng, scatter, v, state, atLimit)) break;
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

Rgb VertexCM::connectVertices(const LightVertex& lv, const SubPath& state, const PathVertex& v,
                              const VertexScatter& scatter) const {
    Vec3 dir = lv.position - v.pos;
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

    // The light vertex's scattering function: its BSDF, or its medium's phase function.
    VertexScatter lightScatter;
    if (lv.inMedium())
        lightScatter.setupMedium(scene_.media[size_t(lv.mediumId())].g, lv.dirFix,
                                 lv.continuationProb);
    else if (!lightScatter.setupSurface(scene_, int(lv.materialId), lv.uv, lv.dirFix, lv.geoNormal,
                                        lv.shadingNormal, /*fromLight=*/true))
        return Rgb(0.0f);
    float cosLight = 0.0f, lightDirPdfW = 0.0f, lightRevPdfW = 0.0f;
    Rgb fLight = lightScatter.evaluate(-dir, &cosLight, &lightDirPdfW, &lightRevPdfW);
    if (isBlack(fLight)) return Rgb(0.0f);
    lightDirPdfW *= lv.continuationProb;
    lightRevPdfW *= lv.continuationProb;

    // Visibility; with media the transmittance of the connecting chain (walked from the
    // camera vertex through imaginary boundaries) and its free-flight pdfs in both
    // directions, stopping at the end vertex if that lies in a medium (ub_mis.h, MEDIA).
    Rgb transmittance(1.0f);
    float distPdfToLight = 1.0f, distPdfToCamera = 1.0f, passProb = 1.0f;
    if (useMedia_) {
        MediumStack stack;
        if (!stackTowards(v, state, dir, &stack)) return Rgb(0.0f);
        const MediumShadow sh =
            scene_.shadowTransmittance(v.pos, v.geoNormal(), stack, lv.position, lv.geoNormal);
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
        ub_mis_vertex_factor(mis_, lv.inMedium(), 0, 1, lv.rInL, length(cross(lv.dirFix, dir)));
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
    if (!useMedia_ && scene_.occluded(v.pos, v.hit.geoNormal, lv.position, lv.geoNormal))
        return Rgb(0.0f);
    return contrib;
}

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
        Rgb f = bsdf.evaluate(lv.dirFix, nullptr, &cameraDirPdfW, &cameraRevPdfW);
        if (isBlack(f)) return;
        float weight = 1.0f;  // PPM: no MIS
        if (!ppm_) {
            cameraDirPdfW *= cameraCont;
            // The reverse direction would be sampled by the light subpath: its roulette.
            cameraRevPdfW *= lv.continuationProb;
            ub_mis_partials lightMis = {lv.dVCM, lv.dVC, lv.dVM, 0.0f};
            // Weight of [TR (38), (39)].
            weight = ub_mis_weight_merge(mis_, lightMis, state.mis, cameraDirPdfW, cameraRevPdfW);
        }
        sum += f * lv.throughput * weight;
    });
    return sum * vmNormalization_;
}

}  // namespace ub
