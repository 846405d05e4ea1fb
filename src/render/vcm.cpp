// VertexCM: set-up, one iteration (light pass, grid, camera pass, splats) and the
// scattering step shared by both subpaths. See vcm.h.
#include "render/vcm.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "cl/cl_runtime.h"
#include "core/error.h"
#include "core/parallel_gather.h"
#include "core/rng.h"
#include "core/seconds.h"
#include "estimators/grid_access.h"
#include "estimators/surface_merging.h"
#include "estimators/volume_estimate.h"
#include "render/chain_beams.h"
#include "render/medium_walk.h"
#include "render/vertex_scatter.h"

namespace ub {

namespace {

VertexCM::Algorithm parseAlgorithm(const std::string& name) {
    if (name == "lt" || name == "vlt") return VertexCM::Algorithm::LightTrace;
    if (name == "bpt" || name == "vbpt") return VertexCM::Algorithm::Bpt;
    if (name == "ppm") return VertexCM::Algorithm::Ppm;
    if (name == "bpm") return VertexCM::Algorithm::Bpm;
    if (name == "vcm") return VertexCM::Algorithm::Vcm;
    if (isUpbpAlgorithm(name)) return VertexCM::Algorithm::Upbp;
    throw InputError("", "VertexCM: unknown algorithm '" + name +
                             "' (valid: lt, bpt, ppm, bpm, vcm, vlt, vbpt, upbp, upbp:...)");
}

/// The media where subpaths of `light` start: at a point just off its emitting side (area
/// lights: the first triangle's centroid, or the sphere), its position (point, spot), the
/// global medium (lights at infinity). One stack per light: a light whose emitting surface
/// crosses a medium boundary is not supported (its subpaths would start in the medium of
/// that one point).
MediumStack lightStartStack(const Scene& scene, const Light& light) {
    MediumStack stack;
    stack.reset(scene.globalMediumId);
    const float eps = 1e-4f * std::max(scene.sceneSphere.radius, 1e-3f);
    if (light.isDeltaPosition()) return scene.mediumStackAt(light.position);
    if (light.type != LightType::Area) return stack;
    if (!light.triangles.empty()) {
        const Vec3& a = light.triangles[0];
        const Vec3& b = light.triangles[1];
        const Vec3& c = light.triangles[2];
        const Vec3 n = normalize(cross(b - a, c - a));
        return scene.mediumStackAt((a + b + c) / 3.0f + n * eps);
    }
    return scene.mediumStackAt(light.position + Vec3(light.sphereRadius + eps, 0.0f, 0.0f));
}

}  // namespace

VertexCM::VertexCM(const Scene& scene, const RenderOptions& options)
    : scene_(scene),
      options_(options),
      algorithm_(parseAlgorithm(options.algorithm)),
      budget_(std::make_unique<MemoryBudget>(options.maxMemoryBytes)) {
    switch (algorithm_) {
        case Algorithm::LightTrace:
            lightTraceOnly_ = true;
            break;
        case Algorithm::Bpt:
            useVC_ = true;
            break;
        case Algorithm::Ppm:
            ppm_ = true;
            useVM_ = true;
            break;
        case Algorithm::Bpm:
            useVM_ = true;
            break;
        case Algorithm::Vcm:
            useVC_ = true;
            useVM_ = true;
            // vcm on a scene with media is upbp:bpt+surf (connections and surface merging
            // through the media).
            if (scene.hasMedia()) {
                algorithm_ = Algorithm::Upbp;
                upbp_.bpt = upbp_.surf = true;
            }
            break;
        case Algorithm::Upbp:
            upbp_ = parseUpbpTechniques(options.algorithm);
            useVC_ = upbp_.bpt;
            useVM_ = upbp_.surf;
            break;
    }
    surfBatch_ = algorithm_ == Algorithm::Upbp && upbp_.surf;
    if (surfBatch_) {
        // The batch pass (and its OpenCL kernel) evaluates the recorded kernel-side BSDF
        // state (kernels/shared/ub_bsdf.h), which has no blends.
        for (const Material& m : scene.materials)
            if (m.type == MaterialType::Blend)
                throw InputError(scene.sourceFile,
                                 "material '" + m.name +
                                     "' is a blend (Mitsuba's blendbsdf or mask), which upbp's "
                                     "surface merging (surf) does not support; use vcm on a "
                                     "scene without media, bpt, pt, or upbp without surf");
        coatingTables_ = coatingTables(scene);
    }
    if (algorithm_ == Algorithm::Upbp) {
        const float radii[4] = {options.radiusPP3D, options.radiusPB2D, options.radiusBP2D,
                                options.radiusBB1D};
        const float alphas[4] = {options.alphaPP3D, options.alphaPB2D, options.alphaBP2D,
                                 options.alphaBB1D};
        const char* names[4] = {"pp3d", "pb2d", "bp2d", "bb1d"};
        for (int t = 0; t < 4; ++t) {
            if (!(radii[t] > 0.0f) || !std::isfinite(radii[t]))
                throw InputError(scene.sourceFile, std::string(names[t]) +
                                                       " radius must be a positive number, got " +
                                                       std::to_string(radii[t]));
            if (!(alphas[t] > 0.0f && alphas[t] <= 1.0f))
                throw InputError(scene.sourceFile,
                                 std::string(names[t]) +
                                     " radius reduction alpha must be in (0, 1], got " +
                                     std::to_string(alphas[t]));
        }
        if (options.backend != "host" && options.backend != "opencl" && options.backend != "auto")
            throw InputError("",
                             "backend must be host, opencl or auto, got '" + options.backend + "'");
        if (options.beamPaths < 0)
            throw InputError(scene.sourceFile, "beam paths must be >= 0 (0: N_L / 16), got " +
                                                   std::to_string(options.beamPaths));
    }
    if (useVM_) {
        if (!(options.radius > 0.0f) || !std::isfinite(options.radius))
            throw InputError(scene.sourceFile, "merging radius must be a positive number, got " +
                                                   std::to_string(options.radius));
        if (!(options.alpha > 0.0f && options.alpha <= 1.0f))
            throw InputError(scene.sourceFile, "radius reduction alpha must be in (0, 1], got " +
                                                   std::to_string(options.alpha));
    }
    nullNotCounted_ = scene.settings.depthCounting == DepthCounting::kNonNullVertices;
    for (const Medium& m : scene.media) mediaEmit_ = mediaEmit_ || m.hasEmission();
    const bool volumetric =
        options.algorithm == "vlt" || options.algorithm == "vbpt" || algorithm_ == Algorithm::Upbp;
    useMedia_ = volumetric && scene.hasMedia();
    if (useMedia_) {
        for (size_t m = 0; m < scene.media.size(); ++m)
            if (lightTraceOnly_ && scene.media[m].hasEmission())
                throw InputError(scene.sourceFile,
                                 "medium '" + scene.mediumNames[m] +
                                     "' emits light, which light tracing (vlt) cannot render "
                                     "(only camera subpaths find medium emission): use vbpt or "
                                     "vpt");
        for (const Light& light : scene.lights)
            if (!light.isFinite() && scene.globalMediumId >= 0)
                throw InputError(scene.sourceFile,
                                 "light '" + light.name +
                                     "' is at infinity but the scene has a "
                                     "global medium ('" +
                                     scene.mediumNames[size_t(scene.globalMediumId)] +
                                     "'), through which its light would have to travel an "
                                     "infinite distance; '" +
                                     options.algorithm +
                                     "' cannot start light subpaths there: bound the medium "
                                     "with a closed boundary shape, or use vpt");
        for (const Light& light : scene.lights)
            lightStacks_.push_back(lightStartStack(scene, light));
    }
    // UPBP radii are relative to the size of the media (the bounding sphere of the medium
    // boundaries, or of the scene with a global medium): a kernel must be small against the
    // medium it blurs, whatever else the scene holds (a room around a candle).
    mediaRadius_ = scene.sceneSphere.radius;
    if (scene.globalMediumId < 0) {
        Bounds3 media;
        for (const ShapeInfo& sh : scene.shapes)
            if (sh.isMediumBoundary && (sh.interiorMediumId >= 0 || sh.exteriorMediumId >= 0))
                media.extend(sh.bounds);
        if (!media.empty()) mediaRadius_ = std::max(0.5f * length(media.hi - media.lo), 1e-6f);
    }
    if (algorithm_ == Algorithm::Upbp) {
        layerNames_.push_back(upbp_.bpt ? "bpt" : "emitted");
        if (upbp_.surf) layerNames_.push_back("surf");
        if (upbp_.pp3d) layerNames_.push_back("pp3d");
        if (upbp_.pb2d) layerNames_.push_back("pb2d");
        if (upbp_.bp2d) layerNames_.push_back("bp2d");
        if (upbp_.bb1d) layerNames_.push_back("bb1d");
    }
    if (algorithm_ == Algorithm::Upbp) {
        // The estimate pass: OpenCL kernels for what has one (pp3d), the host for the rest.
        backendNote_ = "estimate pass on the host";
        if (options.backend != "host" && (upbp_.anyVolume() || upbp_.surf)) {
            try {
                // The program is specialised to the scene's material types (smaller surf
                // kernel; the program cache keeps one binary per set of types).
                cl_ = std::make_unique<ClRuntime>(options.clPlatform, options.clDevice,
                                                  options.clCache,
                                                  clBsdfTypesOption(scene.materials));
                if (options.clProfile) cl_->enableProfiling();
                beamKernels_ = prepareDeviceMedia(scene, cl_.get(),
                                                  upbp_.pb2d || upbp_.photonBeams(), &deviceMedia_);
                const bool beamKernels = beamKernels_ || (!upbp_.pb2d && !upbp_.photonBeams());
                backendNote_ = "estimate pass on OpenCL device '" + cl_->device().device + "' (" +
                               cl_->device().platform + ")" +
                               (beamKernels ? ""
                                            : ": pp3d and surf; pb2d, bp2d, bb1d on the host (a "
                                              "grid medium with an albedo grid, chromatic "
                                              "sigma_t or trilinear filtering has no beam "
                                              "kernel)") +
                               "; " + cl_->programNote();
            } catch (const ClError& e) {
                cl_.reset();
                beamKernels_ = false;
                if (options.backend == "opencl") throw InputError("", e.what());
                backendNote_ =
                    std::string("estimate pass on the host (backend auto: ") + e.what() + ")";
            }
        }
    }
    baseRadius_ = options.radius * (options.radiusIsRelative ? scene.sceneSphere.radius : 1.0f);
    lightPickProb_ = scene.lights.empty() ? 0.0f : 1.0f / float(scene.lights.size());
    techniques_ = layerNames_.empty() ? std::vector<std::string>{options.algorithm} : layerNames_;
    for (const std::string& t : techniques_) guards_.emplace_back(t, options.testFault);
    rejected_.assign(techniques_.size(), 0);
    const char* volumeNames[4] = {"pp3d", "pb2d", "bp2d", "bb1d"};
    for (size_t i = 0; i < layerNames_.size(); ++i) {
        if (layerNames_[i] == "surf") surfTechnique_ = int(i);
        for (int t = 0; t < 4; ++t)
            if (layerNames_[i] == volumeNames[t]) volumeTechnique_[t] = int(i);
    }
    splats_.reset(scene.camera.width(), scene.camera.height(), guards_[0],
                  scene.settings.pixelFilter);
}

RejectionCounts VertexCM::rejectedContributions() const {
    RejectionCounts counts;
    for (size_t i = 0; i < techniques_.size(); ++i)
        counts.emplace_back(techniques_[i], rejected_[i]);
    return counts;
}

VertexCM::~VertexCM() = default;

float VertexCM::volumeRadiusAt(int tech, int iteration) const {
    // r_i = r_1 i^((alpha - 1) / k) for a k-dimensional kernel (Knaus & Zwicker 2011, eq. 19
    // with the kernel's dimension; UPBP Sec. 6): k = 3 for pp3d, 2 for pb2d/bp2d, 1 for bb1d.
    const float r1[4] = {options_.radiusPP3D, options_.radiusPB2D, options_.radiusBP2D,
                         options_.radiusBB1D};
    const float alpha[4] = {options_.alphaPP3D, options_.alphaPB2D, options_.alphaBP2D,
                            options_.alphaBB1D};
    const float dims[4] = {3.0f, 2.0f, 2.0f, 1.0f};
    const float scale = options_.radiusIsRelative ? mediaRadius_ : 1.0f;
    float r = r1[tech] * scale * std::pow(float(iteration + 1), (alpha[tech] - 1.0f) / dims[tech]);
    return std::max(r, 1e-7f);
}

float VertexCM::radiusAt(int iteration) const {
    // r_i = r_1 i^((alpha - 1) / 2), i = iteration + 1 (Knaus & Zwicker 2011, eq. 19);
    // clamped only for numerical safety after very many iterations.
    float r = baseRadius_ * std::pow(float(iteration + 1), 0.5f * (options_.alpha - 1.0f));
    return std::max(r, 1e-7f);
}

void VertexCM::renderIteration(int iteration, Image& out) {
    const Camera& camera = scene_.camera;
    const int width = camera.width(), height = camera.height();
    if (out.width != width || out.height != height) out = Image(width, height);
    const size_t pathCount = size_t(width) * size_t(height);

    lightSubPathCount_ = float(pathCount);
    const float radius = radiusAt(iteration);
    mis_ = ub_mis_make_constants(
        radius, lightSubPathCount_, useVC_, useVM_,
        options_.heuristic == MisHeuristic::Balance ? UB_MIS_BALANCE : UB_MIS_POWER);
    if (algorithm_ == Algorithm::Upbp) {
        const bool on[4] = {upbp_.pp3d, upbp_.pb2d, upbp_.bp2d, upbp_.bb1d};
        for (int t = 0; t < 4; ++t) volumeRadius_[t] = on[t] ? volumeRadiusAt(t, iteration) : 0.0f;
        beamPaths_ = options_.beamPaths > 0
                         ? int(std::min<size_t>(size_t(options_.beamPaths), pathCount))
                         : int(std::max<size_t>(pathCount / 16, 1));
        mis_ = ub_mis_enable_volume(mis_, volumeRadius_[0], volumeRadius_[1], volumeRadius_[2],
                                    volumeRadius_[3], float(beamPaths_), options_.shortPhotonBeams,
                                    options_.shortQueryBeams);
    }
    // Merging normalisation: density estimate with a disk kernel of radius r over N_L paths.
    vmNormalization_ = 1.0f / (kPi * radius * radius * lightSubPathCount_);

    // (1) Light pass: a fixed partition of the light subpaths into chunks, each traced by one
    // task in index order, so vertices and splats do not depend on the thread count.
    // With photon beams as the only light-side technique (upbp:bb1d, upbp:bp2d+bb1d, ...) a
    // light subpath past the first N_B contributes nothing (no connection, light tracing,
    // photon point or surface photon), so only the N_B beam paths are traced. Each subpath
    // draws its own random numbers (Rng::forPath), so the image is the same as when all are
    // traced; N_L (lightSubPathCount_) stays the pixel count, as the estimators' normalisations
    // and MIS need.
    const bool beamsOnly = algorithm_ == Algorithm::Upbp && upbp_.photonBeams() && !upbp_.bpt &&
                           !upbp_.surf && !upbp_.photonPoints();
    const size_t tracedPaths = beamsOnly ? std::min(pathCount, size_t(beamPaths_)) : pathCount;
    const auto lightStart = std::chrono::steady_clock::now();
    splats_.clear();
    const int chunkCount = SplatBuffer::kChunkCount;
    lightChunks_.resize(static_cast<size_t>(chunkCount));
    tbb::parallel_for(0, chunkCount, [&](int c) {
        auto range = SplatBuffer::chunkRange(c, tracedPaths);
        traceLightPaths(iteration, range.first, range.second, splats_.chunk(c),
                        lightChunks_[size_t(c)]);
    });
    {
        const char* advice =
            "a smaller --resolution (fewer light subpaths) or --max-length needs less";
        const size_t chunks = lightChunks_.size();
        gatherParts(
            lightVertices_, chunks, [&](size_t c) -> auto& { return lightChunks_[c].vertices; },
            budget_.get(), "light vertices", advice);
        gatherParts(
            photonPoints_, chunks, [&](size_t c) -> auto& { return lightChunks_[c].photons; },
            budget_.get(), "photon points", advice);
        gatherParts(
            photonBeams_, chunks, [&](size_t c) -> auto& { return lightChunks_[c].beams; },
            budget_.get(), "photon beams",
            "fewer --beam-paths, a smaller --resolution or --max-length need less");
    }
    pathEnds_.resize(pathCount);
    {
        std::vector<uint32_t> first(size_t(chunkCount), 0);
        for (int c = 1; c < chunkCount; ++c)
            first[size_t(c)] =
                first[size_t(c - 1)] + uint32_t(lightChunks_[size_t(c - 1)].vertices.size());
        tbb::parallel_for(0, chunkCount, [&](int c) {
            auto range = SplatBuffer::chunkRange(c, tracedPaths);
            const LightChunk& chunk = lightChunks_[size_t(c)];
            for (size_t i = range.first; i < range.second; ++i)
                pathEnds_[i] = first[size_t(c)] + chunk.pathEnds[i - range.first];
        });
        // Subpaths not traced are empty.
        std::fill(pathEnds_.begin() + std::ptrdiff_t(tracedPaths), pathEnds_.end(),
                  uint32_t(lightVertices_.size()));
    }

    lastLightSeconds_ = secondsSince(lightStart);

    // (2) Hashed grid over the light vertices for merging (upbp: over the surface ones).
    if (surfBatch_) {
        // The surface vertices, in light-vertex order.
        gatherPartsIf(
            surfacePhotons_,
            lightChunks_.size(), [&](size_t c) -> auto& { return lightChunks_[c].vertices; },
            [](const LightVertex& lv) { return !lv.inMedium(); }, budget_.get(), "surface photons",
            "a smaller --resolution (fewer light subpaths) or --max-length needs less");
        grid_.build(surfacePhotons_, &LightVertex::position, radius);
    } else if (useVM_) {
        grid_.build(lightVertices_, &LightVertex::position, radius);
    }

    // (3) Camera pass: one subpath per pixel (lt traces only the primary ray, for
    // directly visible emitters). Each pixel has its own random stream.
    const bool layered = !layerNames_.empty();
    const auto cameraStart = std::chrono::steady_clock::now();
    cameraRows_.resize(size_t(height));
    tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& r) {
        for (int y = r.begin(); y != r.end(); ++y) {
            CameraRecords& rec = cameraRows_[size_t(y)];
            rec.points.clear();
            rec.beams.clear();
            rec.rejected = 0;
            rec.surf.clear();
            for (int x = 0; x < width; ++x) {
                Rgb c = traceCameraPath(x, y, iteration, &rec);
                guards_[0].filter(uint32_t(y) * uint32_t(width) + uint32_t(x), &c, &rec.rejected);
                out.at(x, y) = c;
            }
        }
    });
    for (const CameraRecords& rec : cameraRows_) rejected_[0] += rec.rejected;
    lastCameraSeconds_ = secondsSince(cameraStart);

    // (4) Light-tracing splats, added in a fixed order. UPBP layers: the camera pass without
    // surface merging plus the splats is the first layer, surface merging its own.
    Image* volumeLayers[4] = {nullptr, nullptr, nullptr, nullptr};
    if (layered) {
        layers_.resize(layerNames_.size());
        for (Image& l : layers_) l = Image(width, height);
        Image& first = layers_[0];
        first = out;
        // Resolved into both (rather than once and copied), so that the beauty image gets the
        // same additions in the same order as without layers (upbp:bpt is vbpt bit for bit).
        splats_.resolve(first);
        splats_.resolve(out);
        size_t next = 1;
        Image* surf = useVM_ ? &layers_[next++] : nullptr;
        const bool on[4] = {upbp_.pp3d, upbp_.pb2d, upbp_.bp2d, upbp_.bb1d};
        for (int t = 0; t < 4; ++t)
            if (on[t]) volumeLayers[t] = &layers_[next++];
        if (surf) estimateSurfaceQueries(out, surf);
    } else {
        splats_.resolve(out);
    }
    rejected_[0] += splats_.rejectedCount();

    // (5) UPBP estimate pass: the volumetric estimators over the recorded queries, added to
    // their pixels in query order (estimators/volume_estimate.h).
    if (upbp_.anyVolume()) {
        const char* advice = "a smaller --resolution or --max-length needs less";
        gatherParts(
            queryPoints_,
            cameraRows_.size(), [&](size_t y) -> auto& { return cameraRows_[y].points; },
            budget_.get(), "query points", advice);
        gatherParts(
            queryBeams_,
            cameraRows_.size(), [&](size_t y) -> auto& { return cameraRows_[y].beams; },
            budget_.get(), "query beams", advice);
        const VolumeEstimateInput in = volumeInput(upbp_, cl_.get(), beamKernels_);
        std::array<Image, 4> perTech;
        if (layered)
            for (int t = 0; t < 4; ++t)
                if (volumeLayers[t]) perTech[size_t(t)] = Image(width, height);
        VolumeEstimateStats stats;
        estimateVolume(in, &out, layered ? &perTech : nullptr, &stats);
        for (int t = 0; t < 4; ++t) {
            if (volumeLayers[t]) *volumeLayers[t] = std::move(perTech[size_t(t)]);
            lastPairs_[t] = stats.pairs[t];
            if (volumeTechnique_[t] >= 0)
                rejected_[size_t(volumeTechnique_[t])] += stats.rejected[t];
        }
        lastBuildSeconds_ = stats.buildSeconds;
        lastEstimateSeconds_ = stats.estimateSeconds;
    }
}

VolumeEstimateInput VertexCM::volumeInput(const UpbpTechniques& techniques, ClRuntime* cl,
                                          bool beamKernels) {
    VolumeEstimateInput in;
    in.scene = &scene_;
    in.mis = mis_;
    in.techniques = techniques;
    for (int t = 0; t < 4; ++t) in.radius[t] = volumeRadius_[t];
    in.lightPathCount = lightSubPathCount_;
    in.beamPathCount = float(beamPaths_);
    in.minLength = options_.minPathLength;
    in.maxLength = options_.maxPathLength;
    in.photonPoints = &photonPoints_;
    in.photonBeams = &photonBeams_;
    in.queryPoints = &queryPoints_;
    in.queryBeams = &queryBeams_;
    in.cl = cl;
    in.deviceMedia = &deviceMedia_;
    in.beamKernels = beamKernels;
    in.budget = budget_.get();
    for (int t = 0; t < 4; ++t)
        if (volumeTechnique_[t] >= 0) in.guards[t] = guards_[size_t(volumeTechnique_[t])];
    return in;
}

VertexCM::EstimateTiming VertexCM::replayEstimate(const std::string& technique, bool onDevice,
                                                  Image* out) {
    if (algorithm_ != Algorithm::Upbp)
        throw std::invalid_argument("replayEstimate: the render is not upbp");
    if (onDevice && !cl_)
        throw std::invalid_argument("replayEstimate: the render has no OpenCL device");
    UpbpTechniques one;
    try {
        one = parseUpbpTechniques("upbp:" + technique);
    } catch (const InputError&) {
        one.bpt = true;  // not one technique: refused below
    }
    const bool single =
        int(one.surf) + int(one.pp3d) + int(one.pb2d) + int(one.bp2d) + int(one.bb1d) == 1;
    const bool runs = (one.surf && upbp_.surf) || (one.pp3d && upbp_.pp3d) ||
                      (one.pb2d && upbp_.pb2d) || (one.bp2d && upbp_.bp2d) ||
                      (one.bb1d && upbp_.bb1d);
    if (one.bpt || !single || !runs)
        throw std::invalid_argument("replayEstimate: '" + technique +
                                    "' is not an estimator this render runs");
    EstimateTiming timing;
    if (cl_) cl_->clearKernelTiming();
    if (one.surf) {
        const auto t0 = std::chrono::steady_clock::now();
        std::vector<Rgb> perQuery;
        surfaceEstimates(onDevice ? cl_.get() : nullptr, &perQuery);
        timing.estimates =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        timing.queries = surfaceQueries_.size();
        const uint32_t width = uint32_t(out->width);
        for (size_t i = 0; i < surfaceQueries_.size(); ++i) {
            const uint32_t pixel = surfaceQueries_[i].pixel;
            out->at(int(pixel % width), int(pixel / width)) += perQuery[i];
        }
    } else {
        VolumeEstimateStats stats;
        estimateVolume(volumeInput(one, onDevice ? cl_.get() : nullptr, onDevice && beamKernels_),
                       out, nullptr, &stats);
        timing.lookups = stats.buildSeconds;
        timing.estimates = stats.estimateSeconds;
        timing.queries = one.pp3d || one.bp2d ? queryPoints_.size() : queryBeams_.size();
    }
    if (onDevice) {
        timing.deviceKernel = cl_->lastKernelTiming().kernelSeconds;
        timing.deviceStartLatency = cl_->lastKernelTiming().startLatencySeconds;
    }
    return timing;
}

bool VertexCM::traceToVertex(Rng& rng, SubPath& state, PathVertex* v, bool* escaped,
                             std::vector<ub_beam>* beams, uint32_t tag) const {
    *escaped = false;
    if (!useMedia_) {
        v->inMedium = false;
        if (!scene_.intersect(state.ray, &v->hit)) {
            *escaped = true;
            return false;
        }
        v->pos = v->hit.pos;
        v->dist = v->hit.dist;
        return true;
    }
    // Media: the chain to the next real surface, then free-flight sampling along it.
    // Long beams need the whole chain; otherwise the ray may stop where sampling will.
    const bool shortBeams = state.fromLight ? options_.shortPhotonBeams : options_.shortQueryBeams;
    Rng lookahead = rng;  // sampleChainVertex will draw these numbers again
    const bool cut = options_.cutRaysAtFlight && (!beams || shortBeams);
    const MediumStack stackAtStart = state.stack;
    MediumTrace trace;
    scene_.traceMedia(state.ray, &state.stack, &trace, &v->hit, cut ? &lookahead : nullptr);
    if (trace.overflow) return false;
    ChainVisit visit;
    const ChainVertex cv = sampleChainVertex(scene_, trace, state.ray.dir, state.rayFromMedium, rng,
                                             beams ? &visit : nullptr);
    if (beams) {
        ChainBeamSource src;
        src.throughput = state.throughput;
        src.mis = state.mis;
        src.pathLength = uint32_t(state.pathLength);
        src.fromMedium = state.rayFromMedium;
        src.applyDistSqr = state.applyDistSqr();
        src.shortBeams = shortBeams;
        src.tag = tag;
        src.budgetName = state.fromLight ? "photon beams" : "query beams";
        appendChainBeams(scene_, trace, state.ray.dir, visit, cv, src, beams, budget_.get());
    }
    state.throughput *= cv.weight;
    v->distPdfFwd = cv.distPdfFwd;
    v->distPdfRev = cv.distPdfRev;
    v->passProb = cv.passProb;
    v->mediumEmission = cv.emission;
    if (isBlack(state.throughput) || !isFinite(state.throughput)) return false;
    v->dist = cv.distance;
    if (cv.scattered) {
        v->inMedium = true;
        v->pos = cv.pos;
        v->mediumId = cv.mediumId;
        // The media at the vertex: those of its segment.
        state.stack = stackAtStart;
        scene_.replayCrossings(trace, cv.segment, &state.stack);
        return true;
    }
    v->inMedium = false;
    // A cut trace scatters in its last segment (sampling there runs to kMediumFarDistance);
    // should rounding ever pass it, the path ends rather than escape.
    if (trace.truncated) return false;
    if (!trace.hitSurface) {
        *escaped = true;
        return false;
    }
    scene_.completeHit(trace.hitRay, &v->hit);
    v->pos = v->hit.pos;
    return true;
}

bool VertexCM::setupScatter(const PathVertex& v, const SubPath& state, bool fromLight,
                            VertexScatter* scatter) const {
    if (v.inMedium) {
        const Medium& medium = scene_.media[size_t(v.mediumId)];
        scatter->setupMedium(medium.g, -state.ray.dir,
                             mediumContinuationProb(mediumCoefficientsAt(medium, v.pos)));
        return true;
    }
    if (v.hit.materialId < 0) return false;
    return scatter->setupSurface(scene_, v.hit, -state.ray.dir, fromLight);
}

bool VertexCM::stackTowards(const PathVertex& v, const SubPath& state, const Vec3& dir,
                            MediumStack* out) const {
    *out = state.stack;
    if (v.inMedium) return true;
    return scene_.crossSurface(v.hit, -state.ray.dir, dir, out);
}

bool VertexCM::sampleScattering(Rng& rng, const VertexScatter& scatter, const PathVertex& v,
                                SubPath& state, bool onlyNull) const {
    Vec3 dirGen;
    float dirPdfW = 0.0f, cosThetaOut = 0.0f, sampledRevPdfW = 0.0f;
    uint32_t event = kEventNone;
    Rgb f =
        scatter.sample(rng.uniform3(), &dirGen, &dirPdfW, &cosThetaOut, &event, &sampledRevPdfW);
    if (isBlack(f) || !(dirPdfW > 0.0f)) return false;
    const bool nullEvent = nullNotCounted_ && scatter.isNullEvent(event);
    if (onlyNull && !nullEvent) return false;
    const bool specular = (event & kEventSpecular) != 0;
    // For a delta lobe the reverse pdf equals the forward one; otherwise sample() computed it.
    float revPdfW = specular ? dirPdfW : sampledRevPdfW;

    // Russian roulette (SmallVCM): continue with probability q; q is part of both pdfs.
    const float contProb = scatter.continuationProb();
    if (!(contProb > 0.0f)) return false;
    if (contProb < 1.0f && rng.uniform() >= contProb) return false;
    dirPdfW *= contProb;
    revPdfW *= contProb;

    // MIS partials after scattering [TR (34)-(36)], or [TR (53)-(55)] for specular events,
    // with the merging factor of this vertex (ub_mis_volume.h: F0 now, F1 deferred).
    const ub_mis_factor factor =
        ub_mis_vertex_factor(mis_, v.inMedium, scatter.isDelta(), state.fromLight,
                             ratioIn(state, v), length(cross(state.ray.dir, dirGen)));
    state.mis = ub_mis_scatter_volume(mis_, state.mis, cosThetaOut, dirPdfW, revPdfW, specular,
                                      factor.now, factor.out);
    state.specularPath = state.specularPath && specular;
    state.throughput *= f * (cosThetaOut / dirPdfW);
    if (isBlack(state.throughput) || !isFinite(state.throughput)) return false;
    if (v.inMedium) {
        state.ray.org = v.pos;
        state.ray.dir = dirGen;
        state.ray.tMin = 0.0f;
        state.ray.tMax = kInf;
    } else {
        if (useMedia_ && !scene_.crossSurface(v.hit, -state.ray.dir, dirGen, &state.stack))
            return false;
        state.ray = scene_.spawnRay(v.hit, dirGen);
    }
    state.rayFromMedium = v.inMedium;
    if (nullEvent) --state.pathLength;  // not a vertex of the path's length
    return true;
}

std::string VertexCM::iterationSummary() const {
    if (algorithm_ != Algorithm::Upbp) return "";
    std::string pairs;
    const char* names[4] = {"pp3d", "pb2d", "bp2d", "bb1d"};
    for (int t = 0; t < 4; ++t) {
        pairs += std::string(t ? ", " : "") + names[t] + " ";
        pairs += lastPairs_[t] == VolumeEstimateStats::kNotCounted
                     ? std::string("(OpenCL, not counted)")
                     : std::to_string(lastPairs_[t]);
    }
    std::string surf;
    if (surfBatch_)
        surf = "; surf: " + std::to_string(surfacePhotons_.size()) + " surface photons, " +
               std::to_string(surfaceQueries_.size()) + " surface queries, pairs " +
               (lastSurfPairs_ == VolumeEstimateStats::kNotCounted
                    ? std::string("(OpenCL, not counted)")
                    : std::to_string(lastSurfPairs_)) +
               ", " + std::to_string(lastSurfSeconds_).substr(0, 5) + " s";
    char buf[512];
    std::snprintf(buf, sizeof(buf),
                  "upbp (%s), last iteration: %zu light vertices, %zu photon points, %zu photon "
                  "beam pieces (%d beam paths), %zu query points, %zu query beam pieces; kernel "
                  "pairs %s; light pass %.3f s, camera pass %.3f s, lookups %.3f s, estimates "
                  "%.3f s (%.3g queries/s)",
                  upbp_.describe().c_str(), lightVertices_.size(), photonPoints_.size(),
                  photonBeams_.size(), beamPaths_, queryPoints_.size(), queryBeams_.size(),
                  pairs.c_str(), lastLightSeconds_, lastCameraSeconds_, lastBuildSeconds_,
                  lastEstimateSeconds_,
                  lastEstimateSeconds_ > 0.0
                      ? double(queryPoints_.size() + queryBeams_.size()) / lastEstimateSeconds_
                      : 0.0);
    return buf + surf;
}

float VertexCM::ratioIn(const SubPath& state, const PathVertex& v) const {
    return state.fromLight ? ub_mis_photon_ratio(mis_, v.passProb, v.distPdfFwd)
                           : ub_mis_query_ratio(mis_, v.passProb, v.distPdfFwd);
}

float VertexCM::ratioOut(const SubPath& state, const PathVertex& v) const {
    if (state.mis.dOut == 0.0f) return 0.0f;
    return state.fromLight ? ub_mis_query_ratio(mis_, v.passProb, v.distPdfRev)
                           : ub_mis_photon_ratio(mis_, v.passProb, v.distPdfRev);
}

ub_mis_partials VertexCM::misAtHit(const SubPath& state, const PathVertex& v, float cosFix,
                                   int applyDistSqr) const {
    return ub_mis_at_hit_volume(mis_, state.mis, v.dist, cosFix, applyDistSqr, v.distPdfFwd,
                                v.distPdfRev, ratioOut(state, v));
}

float vcmContinuationProb(const Bsdf& bsdf) {
    if (bsdf.isBlend()) {
        // The parts' bounds mixed by the blend weight (direction-independent if theirs are).
        const float w = bsdf.blendWeight();
        return std::min(1.0f, (1.0f - w) * vcmContinuationProb(bsdf.blendPart(0)) +
                                  w * vcmContinuationProb(bsdf.blendPart(1)));
    }
    const float q = std::min(1.0f, std::max(0.0f, bsdf.continuationProb()));
    const Material* mat = bsdf.material();
    if (q > 0.0f && mat && mat->type == MaterialType::RoughConductor)
        return std::min(1.0f, std::max(0.0f, maxComponent(mat->specular)));
    return q;
}

std::unique_ptr<Integrator> makeVertexCM(const Scene& scene, const RenderOptions& options) {
    return std::make_unique<VertexCM>(scene, options);
}

}  // namespace ub
