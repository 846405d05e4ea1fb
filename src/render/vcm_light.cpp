// VertexCM light pass: light subpaths, their stored vertices with MIS partials, UPBP's
// photon points and photon beams, and light tracing (estimators/light_tracing.cpp).
// See vcm.h and kernels/shared/ub_mis.h.
#include <cmath>

#include "core/memory_budget.h"
#include "core/rng.h"
#include "render/vcm.h"
#include "render/vertex_scatter.h"

namespace ub {

namespace {
const char* const kLightAdvice =
    "a smaller --resolution (fewer light subpaths) or --max-length needs less";
}  // namespace

namespace {
/// Random-stream salts: light subpaths and camera subpaths of the same index differ.
constexpr uint64_t kLightSalt = 1;
}  // namespace

bool VertexCM::startLightPath(Rng& rng, SubPath& state) const {
    const int lightCount = int(scene_.lights.size());
    if (lightCount == 0) return false;
    const int lightId = std::min(int(rng.uniform() * float(lightCount)), lightCount - 1);
    const Light& light = scene_.lights[size_t(lightId)];
    const Vec2 rndDir = rng.uniform2();
    const Vec2 rndPos = rng.uniform2();
    Vec3 origin, direction;
    float emissionPdfW = 0.0f, directPdfA = 0.0f, cosLight = 0.0f;
    Rgb le = light.emit(scene_.sceneSphere, rndDir, rndPos, &origin, &direction, &emissionPdfW,
                        &directPdfA, &cosLight);
    if (isBlack(le) || !(emissionPdfW > 0.0f)) return false;
    emissionPdfW *= lightPickProb_;
    directPdfA *= lightPickProb_;

    // emit() returns Le without the emission cosine (scene/light.h).
    state.throughput = le * (cosLight / emissionPdfW);
    state.pathLength = 1;
    state.isFiniteLight = light.isFinite();
    state.specularPath = true;
    state.fromLight = true;
    // Light subpath MIS partials [TR (31)-(33)].
    state.mis = ub_mis_init_light(mis_, directPdfA, emissionPdfW, cosLight, light.isDelta(),
                                  light.isFinite());
    // Area-light points lie on emitting geometry: offset the origin along the ray (the
    // spawnRay offset is along the given "normal"); other lights start off-surface.
    Hit start;
    start.pos = origin;
    start.geoNormal = light.type == LightType::Area ? direction : Vec3(0.0f);
    state.ray = scene_.spawnRay(start, direction);
    state.rayFromMedium = false;  // x_0 lies on the light, never a medium vertex
    if (useMedia_) state.stack = lightStacks_[size_t(lightId)];
    return true;
}

void VertexCM::traceLightPaths(int iteration, size_t begin, size_t end, SplatBuffer::Chunk& splats,
                               LightChunk& out) const {
    const int maxLength = options_.maxPathLength, minLength = options_.minPathLength;
    std::vector<LightVertex>& vertices = out.vertices;
    std::vector<uint32_t>& pathEnds = out.pathEnds;
    vertices.clear();
    out.photons.clear();
    out.beams.clear();
    pathEnds.assign(end - begin, 0);
    for (size_t pathIndex = begin; pathIndex < end; ++pathIndex) {
        Rng rng = Rng::forPath(options_.seed, uint64_t(iteration), uint64_t(pathIndex), kLightSalt);
        SubPath state;
        bool alive = startLightPath(rng, state);
        // UPBP: the first N_B light subpaths emit photon beams (their MIS counts N_B).
        const bool emitBeams = upbp_.photonBeams() && pathIndex < size_t(beamPaths_);
        for (; alive; ++state.pathLength) {
            PathVertex v;
            bool escaped = false;
            // A point of a beam at this length merges with camera lengths >= 1.
            const bool beamsHere = emitBeams && state.pathLength + 1 <= maxLength;
            if (!traceToVertex(rng, state, &v, &escaped, beamsHere ? &out.beams : nullptr,
                               uint32_t(pathIndex)))
                break;
            VertexScatter scatter;  // BSDF, or phase function at a medium vertex
            if (!setupScatter(v, state, /*fromLight=*/true, &scatter)) break;  // pure emitter
            // Complete the MIS partials at this vertex [TR (31)-(36)], with the free-flight
            // pdfs of the segment (ub_mis.h, MEDIA); the first segment of a light at infinity
            // is in planar measure already [TR Sec. 5.1].
            state.mis = misAtHit(state, v, scatter.cosThetaFix(), state.applyDistSqr());
            const float rIn = ratioIn(state, v);

            // Store the vertex unless the BSDF is purely specular (no connection or merging).
            if (!scatter.isDelta() && (useVC_ || useVM_)) {
                LightVertex lv{};
                storeF3(lv.position, v.pos);
                lv.pathLength = uint32_t(state.pathLength);
                storeF3(lv.throughput, state.throughput);
                storeF3(lv.dirFix, -state.ray.dir);
                lv.contProb = scatter.continuationProb();
                lv.dVCM = state.mis.dVCM;
                lv.dVC = state.mis.dVC;
                lv.dVM = state.mis.dVM;
                lv.rInL = rIn;
                if (v.inMedium) {
                    lv.flags = UB_LIGHT_VERTEX_IN_MEDIUM;
                    lv.materialId = uint32_t(v.mediumId);
                } else {
                    lv.materialId = uint32_t(v.hit.materialId);
                    storeF3(lv.geoNormal, v.hit.geoNormal);
                    storeF3(lv.shadingNormal, v.hit.shadingNormal);
                    lv.uv[0] = v.hit.uv.x;
                    lv.uv[1] = v.hit.uv.y;
                    storeF3(lv.attribute, v.hit.attribute);
                    storeF3(lv.tangent, v.hit.tangent);
                }
                // UPBP: surface vertices are connected and merged on surfaces; medium
                // vertices are connected, and merged through the photon points below.
                pushBudgeted(vertices, lv, budget_.get(), "light vertices", kLightAdvice);
            }
            if (v.inMedium && upbp_.photonPoints() && state.pathLength + 1 <= maxLength) {
                ub_photon_point ph{};
                const MediumCoefficients mc =
                    mediumCoefficientsAt(scene_.media[size_t(v.mediumId)], v.pos);
                for (int a = 0; a < 3; ++a) {
                    ph.pos[a] = v.pos[a];
                    ph.throughput[a] = state.throughput[a];
                    ph.sigmaS[a] = mc.sigmaS[a];
                    ph.dirFix[a] = -state.ray.dir[a];
                }
                ph.pathLength = uint32_t(state.pathLength);
                ph.mediumId = uint32_t(v.mediumId);
                ph.contProb = scatter.continuationProb();
                ph.rPhotonL = rIn;
                ph.dVCM = state.mis.dVCM;
                ph.dVM = state.mis.dVM;
                pushBudgeted(out.photons, ph, budget_.get(), "photon points", kLightAdvice);
            }
            // Light tracing: connect to the camera (a path of pathLength + 1 segments).
            if (!scatter.isDelta() && (useVC_ || lightTraceOnly_) &&
                state.pathLength + 1 >= minLength && state.pathLength + 1 <= maxLength)
                connectToCamera(rng, state, v, scatter, splats);

            // Stop if scattering would make the path too long even when connected directly
            // (unless the vertex may pass the ray on through a null lobe, not counted).
            const bool atLimit = state.pathLength + 2 > maxLength;
            if (atLimit && !(nullNotCounted_ && scatter.hasNullLobe())) break;
            if (!sampleScattering(rng, scatter, v, state, atLimit)) break;
        }
        pathEnds[pathIndex - begin] = uint32_t(vertices.size());
    }
}

}  // namespace ub
