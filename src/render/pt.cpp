#include "render/pt.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "core/rng.h"
#include "kernels/shared/ub_mis_heuristic.h"
#include "scene/bsdf.h"

namespace ub {

uint64_t PtRayLog::closestCount() const {
    uint64_t n = 0;
    for (const auto& row : closestRays) n += row.size();
    return n;
}

uint64_t PtRayLog::shadowCount() const {
    uint64_t n = 0;
    for (uint64_t c : shadowRays) n += c;
    return n;
}

PathTracer::PathTracer(const Scene& scene, const RenderOptions& options, PtStrategy strategy)
    : scene_(scene), options_(options), strategy_(strategy) {
    guard_ = ContributionGuard(options.algorithm, options.testFault);
    misBeta_ = options.heuristic == MisHeuristic::Balance ? 1.0f : 2.0f;
    lightPickProb_ = scene.lights.empty() ? 0.0f : 1.0f / float(scene.lights.size());
}

void PathTracer::renderIteration(int iteration, Image& out) {
    const int width = scene_.camera.width(), height = scene_.camera.height();
    if (out.width != width || out.height != height) out = Image(width, height);
    if (rayLog_) {
        rayLog_->closestRays.assign(size_t(height), {});
        rayLog_->shadowRays.assign(size_t(height), 0);
    }
    // One task per block of rows; each pixel has its own random stream, so the
    // partitioning cannot change the result.
    // Every pixel estimate passes the contribution guard; rejections are counted per row and
    // summed in row order.
    renderGuardedRows(width, height, guard_, rowRejected_, &rejected_, out,
                      [&](int x, int y) { return tracePixel(x, y, iteration); });
}

namespace {

/// Solid-angle pdf at the shading point of an area-light point sampled with area pdf
/// pdfA, at distance dist, whose surface makes cosine cosAtLight with the segment.
inline float pdfAtoW(float pdfA, float dist, float cosAtLight) {
    return cosAtLight > 0.0f ? pdfA * dist * dist / cosAtLight : 0.0f;
}

}  // namespace

Rgb PathTracer::tracePixel(int x, int y, int iteration) const {
    const Camera& camera = scene_.camera;
    const SceneSphere& sphere = scene_.sceneSphere;
    const int maxLength = options_.maxPathLength;
    const int minLength = options_.minPathLength;
    const int lightCount = int(scene_.lights.size());
    std::vector<Ray>* closestLog = rayLog_ ? &rayLog_->closestRays[size_t(y)] : nullptr;
    uint64_t* shadowLog = rayLog_ ? &rayLog_->shadowRays[size_t(y)] : nullptr;

    Rng rng = Rng::forPath(options_.seed, uint64_t(iteration),
                           uint64_t(y) * uint64_t(camera.width()) + uint64_t(x));
    const Vec2 jitter = rng.uniform2();
    const Vec2 lensU = rng.uniform2();
    // Pixel position from the scene's reconstruction filter (box: pixel + jitter), and the
    // path's weight (1, or Mitsuba's ptracer convention at the borders: scene/pixel_filter.h).
    float pixelWeight = 1.0f;
    const Vec2 raster = scene_.settings.pixelFilter.sampleRaster(x, y, jitter, camera.width(),
                                                                 camera.height(), &pixelWeight);
    Ray ray = camera.generateRay(raster, lensU);

    Rgb radiance(0.0f);
    if (pixelWeight <= 0.0f) return radiance;  // outside the image (ptracer convention)
    Rgb throughput(pixelWeight);
    float lastPdfW = 1.0f;  // pdf (solid angle, incl. roulette) of the last sampled direction
    bool lastDelta = true;  // the last direction came from the camera or a delta lobe

    // MIS weight of an emitter found by the BSDF-sampled ray of segment `pathLength`,
    // where light sampling would have had solid-angle pdf lightPdfW (selection included).
    auto emitterHitWeight = [&](int pathLength, float lightPdfW) -> float {
        if (pathLength == 1 || lastDelta) return 1.0f;  // no NEE could have found it
        switch (strategy_) {
            case PtStrategy::BsdfOnly:
                return 1.0f;
            case PtStrategy::LightOnly:
                return 0.0f;
            case PtStrategy::Mis:
                break;
        }
        return ub_mis_weight2(lastPdfW, lightPdfW, misBeta_);
    };

    for (int pathLength = 1;; ++pathLength) {
        Hit hit;
        if (closestLog) closestLog->push_back(ray);
        if (!scene_.intersect(ray, &hit)) {
            // Escaping ray: environment light, if any.
            if (scene_.backgroundLightId >= 0 && pathLength >= minLength) {
                const Light& env = scene_.lights[size_t(scene_.backgroundLightId)];
                float directPdfW = 0.0f, emissionPdfW = 0.0f;
                // For environments radianceAlong's directPdfA is a solid-angle pdf.
                Rgb le = env.radianceAlong(sphere, ray.dir, ray.org, Vec3(0.0f), Vec2(0.0f, 0.0f),
                                           &directPdfW, &emissionPdfW);
                if (!isBlack(le))
                    radiance +=
                        throughput * le * emitterHitWeight(pathLength, directPdfW * lightPickProb_);
            }
            break;
        }

        // Emission of the surface hit (area lights; back faces of one-sided lights are black).
        if (hit.lightId >= 0 && pathLength >= minLength) {
            const Light& light = scene_.lights[size_t(hit.lightId)];
            float directPdfA = 0.0f, emissionPdfW = 0.0f;
            Rgb le = light.radianceAlong(sphere, ray.dir, hit.pos, hit.geoNormal, hit.uv,
                                         &directPdfA, &emissionPdfW);
            if (!isBlack(le)) {
                float cosAtLight = std::fabs(dot(hit.geoNormal, ray.dir));
                float lightPdfW = pdfAtoW(directPdfA, hit.dist, cosAtLight) * lightPickProb_;
                radiance += throughput * le * emitterHitWeight(pathLength, lightPdfW);
            }
        }

        if (pathLength >= maxLength || hit.materialId < 0) break;

        Bsdf bsdf;
        if (!scene_.setupBsdf(&bsdf, hit, -ray.dir, /*fromLight=*/false)) break;
        const float contProb = std::min(1.0f, bsdf.continuationProb());

        // ---- Next-event estimation: a path of length pathLength + 1 ----
        if (!bsdf.isDelta() && lightCount > 0 && strategy_ != PtStrategy::BsdfOnly &&
            pathLength + 1 >= minLength) {
            const int lightId = std::min(int(rng.uniform() * float(lightCount)), lightCount - 1);
            const Light& light = scene_.lights[size_t(lightId)];
            const Vec2 lightU = rng.uniform2();
            Vec3 dirToLight;
            float distance = 0.0f, directPdfW = 0.0f, emissionPdfW = 0.0f, cosAtLight = 0.0f;
            Rgb le = light.illuminate(sphere, hit.pos, lightU, &dirToLight, &distance, &directPdfW,
                                      &emissionPdfW, &cosAtLight);
            if (!isBlack(le) && directPdfW > 0.0f) {
                float cosThetaGen = 0.0f, bsdfPdfW = 0.0f;
                Rgb f = bsdf.evaluate(dirToLight, &cosThetaGen, &bsdfPdfW, nullptr);
                if (!isBlack(f)) {
                    const float lightPdfW = directPdfW * lightPickProb_;
                    // BSDF sampling would reach this point with bsdfPdfW * contProb; a delta
                    // light cannot be hit by it.
                    float weight = 1.0f;
                    if (!light.isDelta() && strategy_ == PtStrategy::Mis)
                        weight = ub_mis_weight2(lightPdfW, bsdfPdfW * contProb, misBeta_);
                    Rgb contrib = throughput * le * f * (weight * cosThetaGen / lightPdfW);
                    if (!isBlack(contrib)) {
                        if (shadowLog) ++*shadowLog;
                        bool blocked;
                        if (light.isFinite()) {
                            // The light end is offset back along the segment (light points
                            // sit on surfaces we must not hit; point lights need no offset).
                            Vec3 lightPos = hit.pos + dirToLight * distance;
                            Vec3 lightOffsetDir =
                                light.isDeltaPosition() ? Vec3(0.0f) : -dirToLight;
                            blocked =
                                scene_.occluded(hit.pos, hit.geoNormal, lightPos, lightOffsetDir);
                        } else {
                            blocked = scene_.occludedToInfinity(hit.pos, hit.geoNormal, dirToLight);
                        }
                        if (!blocked) radiance += contrib;
                    }
                }
            }
        }

        // ---- Russian roulette (SmallVCM: at every vertex, probability contProb) ----
        if (contProb <= 0.0f) break;
        if (contProb < 1.0f && rng.uniform() >= contProb) break;

        // ---- BSDF sampling: the next segment ----
        Vec3 dirGen;
        float pdfW = 0.0f, cosThetaGen = 0.0f;
        uint32_t event = kEventNone;
        Rgb f = bsdf.sample(rng.uniform3(), &dirGen, &pdfW, &cosThetaGen, &event);
        if (isBlack(f) || !(pdfW > 0.0f)) break;
        throughput *= f * (cosThetaGen / (pdfW * contProb));
        if (isBlack(throughput) || !isFinite(throughput)) break;
        lastDelta = (event & kEventSpecular) != 0;
        lastPdfW = pdfW * contProb;
        ray = scene_.spawnRay(hit, dirGen);
    }
    return radiance;
}

std::unique_ptr<Integrator> makePathTracer(const Scene& scene, const RenderOptions& options) {
    return std::make_unique<PathTracer>(scene, options);
}

RejectionCounts PathTracer::rejectedContributions() const {
    return {{options_.algorithm, rejected_}};
}

}  // namespace ub
