#include "render/vpt.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "core/rng.h"
#include "kernels/shared/ub_mis_heuristic.h"
#include "kernels/shared/ub_phase.h"
#include "scene/bsdf.h"

namespace ub {

namespace {

inline ub_float3 toF3(const Vec3& v) {
    return ub_make_float3(v.x, v.y, v.z);
}
inline Vec3 fromF3(const ub_float3& v) {
    return Vec3(v.x, v.y, v.z);
}

inline float pdfAtoW(float pdfA, float dist, float cosAtLight) {
    return cosAtLight > 0.0f ? pdfA * dist * dist / cosAtLight : 0.0f;
}

/// Single-scattering albedo max_c sigma_s,c / sigma_t,c (0 where sigma_t = 0).
float maxAlbedo(const MediumCoefficients& c) {
    float a = 0.0f;
    for (int i = 0; i < 3; ++i)
        if (c.sigmaT[i] > 0.0f) a = std::max(a, c.sigmaS[i] / c.sigmaT[i]);
    return std::min(a, 1.0f);
}

}  // namespace

VolPathTracer::VolPathTracer(const Scene& scene, const RenderOptions& options)
    : scene_(scene), options_(options) {
    guard_ = ContributionGuard(options.algorithm, options.testFault);
    misBeta_ = options.heuristic == MisHeuristic::Balance ? 1.0f : 2.0f;
    lightPickProb_ = scene.lights.empty() ? 0.0f : 1.0f / float(scene.lights.size());
}

void VolPathTracer::renderIteration(int iteration, Image& out) {
    const int width = scene_.camera.width(), height = scene_.camera.height();
    if (out.width != width || out.height != height) out = Image(width, height);
    // Every pixel estimate passes the contribution guard; rejections are counted per row and
    // summed in row order.
    renderGuardedRows(width, height, guard_, rowRejected_, &rejected_, out,
                      [&](int x, int y) { return tracePixel(x, y, iteration); });
}

Rgb VolPathTracer::tracePixel(int x, int y, int iteration) const {
    const Camera& camera = scene_.camera;
    const SceneSphere& sphere = scene_.sceneSphere;
    const int maxLength = options_.maxPathLength;
    const int minLength = options_.minPathLength;
    const int lightCount = int(scene_.lights.size());
    // Mitsuba's depth: a null-lobe event (thin-sheet transmission) is not a vertex.
    const bool nullNotCounted = scene_.settings.depthCounting == DepthCounting::kNonNullVertices;

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
    MediumStack stack = scene_.cameraMediumStack;

    Rgb radiance(0.0f);
    if (pixelWeight <= 0.0f) return radiance;  // outside the image (ptracer convention)
    Rgb throughput(pixelWeight);
    float lastPdfW = 1.0f;  // solid-angle pdf (incl. roulette) of the last sampled direction
    bool lastDelta = true;  // last direction from the camera or a delta lobe: no NEE made it

    // MIS weight of an emitter reached by the sampled direction, with free-flight pass
    // probability passProb over the chain, where light sampling has pdf lightPdfW.
    auto emitterHitWeight = [&](int pathLength, float passProb, float lightPdfW) {
        if (pathLength == 1 || lastDelta) return 1.0f;
        return ub_mis_weight2(lastPdfW * passProb, lightPdfW, misBeta_);
    };

    // Next-event estimation from pos (geoNormal zero in a medium). evalDir(dir, &pdfW)
    // returns f * |cos| (phase: the phase value) and the direction pdf incl. roulette;
    // stackFor(dir, &s) sets the stack for a shadow ray along dir (false: overflow).
    auto nextEvent = [&](const Vec3& pos, const Vec3& geoNormal, auto&& evalDir, auto&& stackFor) {
        const int lightId = std::min(int(rng.uniform() * float(lightCount)), lightCount - 1);
        const Light& light = scene_.lights[size_t(lightId)];
        const Vec2 lightU = rng.uniform2();
        Vec3 dirToLight;
        float distance = 0.0f, directPdfW = 0.0f, emissionPdfW = 0.0f, cosAtLight = 0.0f;
        Rgb le = light.illuminate(sphere, pos, lightU, &dirToLight, &distance, &directPdfW,
                                  &emissionPdfW, &cosAtLight);
        if (isBlack(le) || !(directPdfW > 0.0f)) return;
        float dirPdfW = 0.0f;
        Rgb f = evalDir(dirToLight, &dirPdfW);
        if (isBlack(f)) return;
        MediumStack shadowStack;
        if (!stackFor(dirToLight, &shadowStack)) return;
        MediumShadow sh;
        if (light.isFinite()) {
            Vec3 lightPos = pos + dirToLight * distance;
            Vec3 lightOffsetDir = light.isDeltaPosition() ? Vec3(0.0f) : -dirToLight;
            sh = scene_.shadowTransmittance(pos, geoNormal, shadowStack, lightPos, lightOffsetDir);
        } else {
            sh = scene_.shadowTransmittanceToInfinity(pos, geoNormal, shadowStack, dirToLight);
        }
        if (sh.blocked || isBlack(sh.transmittance)) return;
        const float lightPdfW = directPdfW * lightPickProb_;
        const float weight =
            light.isDelta() ? 1.0f : ub_mis_weight2(lightPdfW, dirPdfW * sh.probPass, misBeta_);
        radiance += throughput * le * f * sh.transmittance * (weight / lightPdfW);
    };

    MediumTrace trace;
    for (int pathLength = 1;; ++pathLength) {
        const MediumStack stackAtStart = stack;
        Hit hit;
        // The ray may stop where the sampling below will (Scene::traceMedia's look-ahead).
        Rng lookahead = rng;
        scene_.traceMedia(ray, &stack, &trace, &hit,
                          options_.cutRaysAtFlight ? &lookahead : nullptr);
        if (trace.overflow) break;

        // ---- Free-flight sampling along the segment chain ----
        bool scattered = false;
        Vec3 scatterPos;
        int scatterMedium = -1;
        float passProb = 1.0f;
        for (int k = 0; k < trace.count; ++k) {
            const MediumTraceSegment& seg = trace.segments[k];
            if (seg.mediumId < 0) continue;
            const Medium& medium = scene_.media[size_t(seg.mediumId)];
            const float uChannel = rng.uniform(), uDistance = rng.uniform();
            FreeFlightSample ff =
                sampleFreeFlight(medium, seg.origin, ray.dir, seg.length, uChannel, uDistance);
            if (!(ff.pdf > 0.0f)) {
                throughput = Rgb(0.0f);
                break;
            }
            if (ff.scattered) {
                scatterPos = seg.origin + ray.dir * ff.t;
                scatterMedium = seg.mediumId;
                if (medium.hasEmission() && pathLength >= minLength) {
                    // Collision estimator of the source term sigma_a Le (weight 1).
                    MediumCoefficients c = mediumCoefficientsAt(medium, scatterPos);
                    radiance += throughput * ff.segment.transmittance * c.sigmaA * c.Le / ff.pdf;
                }
                throughput *= ff.weight;
                stack = stackAtStart;
                scene_.replayCrossings(trace, k, &stack);
                scattered = true;
                break;
            }
            throughput *= ff.weight;
            passProb *= ff.pdf;
        }
        if (isBlack(throughput) || !isFinite(throughput)) break;

        if (scattered) {
            // ---- Medium vertex ----
            if (pathLength >= maxLength) break;
            const Medium& medium = scene_.media[size_t(scatterMedium)];
            const Vec3 wFix = -ray.dir;
            const float contProb = maxAlbedo(mediumCoefficientsAt(medium, scatterPos));
            if (lightCount > 0 && pathLength + 1 >= minLength) {
                nextEvent(
                    scatterPos, Vec3(0.0f),
                    [&](const Vec3& dir, float* pdfW) {
                        float p = ub_hg_pdf(toF3(wFix), toF3(dir), medium.g);
                        *pdfW = p * contProb;
                        return Rgb(p);
                    },
                    [&](const Vec3&, MediumStack* s) {
                        *s = stack;
                        return true;
                    });
            }
            if (!(contProb > 0.0f)) break;
            if (contProb < 1.0f && rng.uniform() >= contProb) break;
            throughput /= contProb;
            float phasePdfW = 0.0f;
            const float u1 = rng.uniform(), u2 = rng.uniform();
            Vec3 dirGen = normalize(fromF3(ub_hg_sample(toF3(wFix), medium.g, u1, u2, &phasePdfW)));
            // HG sampling is exact: value / pdf = 1.
            lastPdfW = phasePdfW * contProb;
            lastDelta = false;
            ray.org = scatterPos;
            ray.dir = dirGen;
            ray.tMin = 0.0f;
            ray.tMax = kInf;
            continue;
        }

        if (trace.truncated) break;  // a cut trace scatters; never read it as an escape
        if (!trace.hitSurface) {
            // Escaped: environment light, if any.
            if (scene_.backgroundLightId >= 0 && pathLength >= minLength) {
                const Light& env = scene_.lights[size_t(scene_.backgroundLightId)];
                float directPdfW = 0.0f, emissionPdfW = 0.0f;
                Rgb le = env.radianceAlong(sphere, ray.dir, ray.org, Vec3(0.0f), Vec2(0.0f, 0.0f),
                                           &directPdfW, &emissionPdfW);
                if (!isBlack(le))
                    radiance += throughput * le *
                                emitterHitWeight(pathLength, passProb, directPdfW * lightPickProb_);
            }
            break;
        }

        // ---- Surface vertex ----
        scene_.completeHit(trace.hitRay, &hit);
        if (hit.lightId >= 0 && pathLength >= minLength) {
            const Light& light = scene_.lights[size_t(hit.lightId)];
            float directPdfA = 0.0f, emissionPdfW = 0.0f;
            Rgb le = light.radianceAlong(sphere, ray.dir, hit.pos, hit.geoNormal, hit.uv,
                                         &directPdfA, &emissionPdfW);
            if (!isBlack(le)) {
                float cosAtLight = std::fabs(dot(hit.geoNormal, ray.dir));
                float lightPdfW = pdfAtoW(directPdfA, trace.distance, cosAtLight) * lightPickProb_;
                radiance += throughput * le * emitterHitWeight(pathLength, passProb, lightPdfW);
            }
        }
        // At the length limit only a null lobe, which is not counted, may continue the path.
        const bool atLimit = pathLength >= maxLength;
        if ((atLimit && !nullNotCounted) || hit.materialId < 0) break;

        Bsdf bsdf;
        const Vec3 dirFix = -ray.dir;
        if (!scene_.setupBsdf(&bsdf, hit, dirFix, /*fromLight=*/false)) break;
        if (atLimit && !bsdf.hasNullLobe()) break;
        const float contProb = std::min(1.0f, bsdf.continuationProb());
        if (!atLimit && !bsdf.isDelta() && lightCount > 0 && pathLength + 1 >= minLength) {
            nextEvent(
                hit.pos, hit.geoNormal,
                [&](const Vec3& dir, float* pdfW) {
                    float cosGen = 0.0f, bsdfPdfW = 0.0f;
                    Rgb f = bsdf.evaluate(dir, &cosGen, &bsdfPdfW, nullptr);
                    *pdfW = bsdfPdfW * contProb;
                    return f * cosGen;
                },
                [&](const Vec3& dir, MediumStack* s) {
                    *s = stack;
                    return scene_.crossSurface(hit, dirFix, dir, s);
                });
        }

        if (!(contProb > 0.0f)) break;
        if (contProb < 1.0f && rng.uniform() >= contProb) break;
        Vec3 dirGen;
        float pdfW = 0.0f, cosThetaGen = 0.0f;
        uint32_t event = kEventNone;
        Rgb f = bsdf.sample(rng.uniform3(), &dirGen, &pdfW, &cosThetaGen, &event);
        if (isBlack(f) || !(pdfW > 0.0f)) break;
        const bool nullEvent = nullNotCounted && bsdf.isNullEvent(event);
        if (atLimit && !nullEvent) break;
        if (nullEvent) --pathLength;  // the loop's increment leaves the length unchanged
        throughput *= f * (cosThetaGen / (pdfW * contProb));
        if (isBlack(throughput) || !isFinite(throughput)) break;
        lastDelta = (event & kEventSpecular) != 0;
        lastPdfW = pdfW * contProb;
        if (!scene_.crossSurface(hit, dirFix, dirGen, &stack)) break;
        ray = scene_.spawnRay(hit, dirGen);
    }
    return radiance;
}

std::unique_ptr<Integrator> makeVolPathTracer(const Scene& scene, const RenderOptions& options) {
    return std::make_unique<VolPathTracer>(scene, options);
}

RejectionCounts VolPathTracer::rejectedContributions() const {
    return {{options_.algorithm, rejected_}};
}

}  // namespace ub
