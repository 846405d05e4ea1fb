// VertexCM: set-up, one iteration (light pass, grid, camera pass, splats) and the
// scattering step shared by both subpaths. See vcm.h.
#include "render/vcm.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <string>

#include "core/error.h"
#include "core/rng.h"

namespace ub {

namespace {

VertexCM::Algorithm parseAlgorithm(const std::string& name) {
    if (name == "lt") return VertexCM::Algorithm::LightTrace;
    if (name == "bpt") return VertexCM::Algorithm::Bpt;
    if (name == "ppm") return VertexCM::Algorithm::Ppm;
    if (name == "bpm") return VertexCM::Algorithm::Bpm;
    if (name == "vcm") return VertexCM::Algorithm::Vcm;
    throw InputError("",
                     "VertexCM: unknown algorithm '" + name + "' (valid: lt, bpt, ppm, bpm, vcm)");
}

}  // namespace

VertexCM::VertexCM(const Scene& scene, const RenderOptions& options)
    : scene_(scene), options_(options), algorithm_(parseAlgorithm(options.algorithm)) {
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
            break;
    }
    if ((useVC_ || lightTraceOnly_) && !scene.camera.isPinhole())
        throw InputError(scene.sourceFile,
                         "algorithm '" + options.algorithm +
                             "' uses light tracing, which needs a pinhole camera; this scene's "
                             "camera has a thin lens (lens radius " +
                             std::to_string(scene.camera.lensRadius()) +
                             "): use pt, ppm or bpm, or set the lens radius to 0");
    if (useVM_) {
        if (!(options.radius > 0.0f) || !std::isfinite(options.radius))
            throw InputError(scene.sourceFile, "merging radius must be a positive number, got " +
                                                   std::to_string(options.radius));
        if (!(options.alpha > 0.0f && options.alpha <= 1.0f))
            throw InputError(scene.sourceFile, "radius reduction alpha must be in (0, 1], got " +
                                                   std::to_string(options.alpha));
    }
    baseRadius_ = options.radius * (options.radiusIsRelative ? scene.sceneSphere.radius : 1.0f);
    lightPickProb_ = scene.lights.empty() ? 0.0f : 1.0f / float(scene.lights.size());
    splats_.reset(scene.camera.width(), scene.camera.height());
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
    // Merging normalisation: density estimate with a disk kernel of radius r over N_L paths.
    vmNormalization_ = 1.0f / (kPi * radius * radius * lightSubPathCount_);

    // (1) Light pass: a fixed partition of the light subpaths into chunks, each traced by one
    // task in index order, so vertices and splats do not depend on the thread count.
    splats_.clear();
    const int chunkCount = SplatBuffer::kChunkCount;
    std::vector<std::vector<LightVertex>>& chunkVertices = chunkVertices_;
    std::vector<std::vector<uint32_t>>& chunkEnds = chunkEnds_;
    chunkVertices.resize(static_cast<size_t>(chunkCount));
    chunkEnds.resize(static_cast<size_t>(chunkCount));
    tbb::parallel_for(0, chunkCount, [&](int c) {
        auto range = SplatBuffer::chunkRange(c, pathCount);
        traceLightPaths(iteration, range.first, range.second, splats_.chunk(c),
                        chunkVertices[size_t(c)], chunkEnds[size_t(c)]);
    });
    lightVertices_.clear();
    pathEnds_.assign(pathCount, 0);
    for (int c = 0; c < chunkCount; ++c) {
        auto range = SplatBuffer::chunkRange(c, pathCount);
        uint32_t offset = uint32_t(lightVertices_.size());
        for (size_t i = range.first; i < range.second; ++i)
            pathEnds_[i] = offset + chunkEnds[size_t(c)][i - range.first];
        lightVertices_.insert(lightVertices_.end(), chunkVertices[size_t(c)].begin(),
                              chunkVertices[size_t(c)].end());
    }

    // (2) Hashed grid over the light vertices for merging.
    if (useVM_) grid_.build(lightVertices_, &LightVertex::position, radius);

    // (3) Camera pass: one subpath per pixel (lt traces only the primary ray, for
    // directly visible emitters). Each pixel has its own random stream.
    tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& r) {
        for (int y = r.begin(); y != r.end(); ++y)
            for (int x = 0; x < width; ++x) out.at(x, y) = traceCameraPath(x, y, iteration);
    });

    // (4) Light-tracing splats, added in a fixed order.
    splats_.resolve(out);
}

bool VertexCM::sampleScattering(Rng& rng, const Bsdf& bsdf, const Hit& hit, SubPath& state) const {
    Vec3 dirGen;
    float dirPdfW = 0.0f, cosThetaOut = 0.0f;
    uint32_t event = kEventNone;
    Rgb f = bsdf.sample(rng.uniform3(), &dirGen, &dirPdfW, &cosThetaOut, &event);
    if (isBlack(f) || !(dirPdfW > 0.0f)) return false;
    const bool specular = (event & kEventSpecular) != 0;
    // For a delta lobe the reverse pdf equals the forward one; otherwise evaluate it.
    float revPdfW = specular ? dirPdfW : bsdf.pdf(dirGen, /*reverse=*/true);

    // Russian roulette (SmallVCM): continue with probability q; q is part of both pdfs.
    const float contProb = vcmContinuationProb(bsdf);
    if (!(contProb > 0.0f)) return false;
    if (contProb < 1.0f && rng.uniform() >= contProb) return false;
    dirPdfW *= contProb;
    revPdfW *= contProb;

    // MIS partials after scattering [TR (34)-(36)], or [TR (53)-(55)] for specular events.
    state.mis = ub_mis_scatter(mis_, state.mis, cosThetaOut, dirPdfW, revPdfW, specular);
    state.specularPath = state.specularPath && specular;
    state.throughput *= f * (cosThetaOut / dirPdfW);
    if (isBlack(state.throughput) || !isFinite(state.throughput)) return false;
    state.ray = scene_.spawnRay(hit, dirGen);
    return true;
}

float vcmContinuationProb(const Bsdf& bsdf) {
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
