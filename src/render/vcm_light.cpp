// VertexCM light pass: light subpaths, their stored vertices with MIS partials,
// and light tracing (connections of light vertices to the pinhole camera,
// splatted onto the film). See vcm.h and kernels/shared/ub_mis.h.
#include <cmath>

#include "core/rng.h"
#include "render/vcm.h"

namespace ub {

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
    // Light subpath MIS partials [TR (31)-(33)].
    state.mis = ub_mis_init_light(mis_, directPdfA, emissionPdfW, cosLight, light.isDelta(),
                                  light.isFinite());
    // Area-light points lie on emitting geometry: offset the origin along the ray (the
    // spawnRay offset is along the given "normal"); other lights start off-surface.
    Hit start;
    start.pos = origin;
    start.geoNormal = light.type == LightType::Area ? direction : Vec3(0.0f);
    state.ray = scene_.spawnRay(start, direction);
    return true;
}

void VertexCM::traceLightPaths(int iteration, size_t begin, size_t end, SplatBuffer::Chunk& splats,
                               std::vector<LightVertex>& vertices,
                               std::vector<uint32_t>& pathEnds) const {
    const int maxLength = options_.maxPathLength, minLength = options_.minPathLength;
    vertices.clear();
    pathEnds.assign(end - begin, 0);
    for (size_t pathIndex = begin; pathIndex < end; ++pathIndex) {
        Rng rng = Rng::forPath(options_.seed, uint64_t(iteration), uint64_t(pathIndex), kLightSalt);
        SubPath state;
        bool alive = startLightPath(rng, state);
        for (; alive; ++state.pathLength) {
            Hit hit;
            if (!scene_.intersect(state.ray, &hit)) break;
            if (hit.materialId < 0) break;  // pure emitter: absorbs
            Bsdf bsdf;
            if (!scene_.setupBsdf(&bsdf, hit, -state.ray.dir, /*fromLight=*/true)) break;
            // Complete the MIS partials at this vertex [TR (31)-(36)]; the first segment of a
            // light at infinity is in planar measure already [TR Sec. 5.1].
            state.mis = ub_mis_at_hit(mis_, state.mis, hit.dist, bsdf.cosThetaFix(),
                                      state.pathLength > 1 || state.isFiniteLight);

            // Store the vertex unless the BSDF is purely specular (no connection or merging).
            if (!bsdf.isDelta() && (useVC_ || useVM_)) {
                LightVertex v{};
                v.position = hit.pos;
                v.pathLength = uint32_t(state.pathLength);
                v.throughput = state.throughput;
                v.materialId = uint32_t(hit.materialId);
                v.dirFix = -state.ray.dir;
                v.continuationProb = vcmContinuationProb(bsdf);
                v.geoNormal = hit.geoNormal;
                v.shadingNormal = hit.shadingNormal;
                v.dVCM = state.mis.dVCM;
                v.dVC = state.mis.dVC;
                v.dVM = state.mis.dVM;
                v.uv = hit.uv;
                vertices.push_back(v);
            }
            // Light tracing: connect to the camera (a path of pathLength + 1 segments).
            if (!bsdf.isDelta() && (useVC_ || lightTraceOnly_) &&
                state.pathLength + 1 >= minLength && state.pathLength + 1 <= maxLength)
                connectToCamera(state, hit, bsdf, splats);

            // Stop if scattering would make the path too long even when connected directly.
            if (state.pathLength + 2 > maxLength) break;
            if (!sampleScattering(rng, bsdf, hit, state)) break;
        }
        pathEnds[pathIndex - begin] = uint32_t(vertices.size());
    }
}

void VertexCM::connectToCamera(const SubPath& state, const Hit& hit, const Bsdf& bsdf,
                               SplatBuffer::Chunk& splats) const {
    const Camera& camera = scene_.camera;
    Vec2 raster;
    if (!camera.worldToRaster(hit.pos, &raster)) return;
    Vec3 dirToCamera = camera.position() - hit.pos;
    const float distSqr = lengthSqr(dirToCamera);
    const float distance = std::sqrt(distSqr);
    dirToCamera /= distance;

    float cosToCamera = 0.0f, bsdfRevPdfW = 0.0f;
    Rgb f = bsdf.evaluate(dirToCamera, &cosToCamera, nullptr, &bsdfRevPdfW);
    if (isBlack(f)) return;
    bsdfRevPdfW *= vcmContinuationProb(bsdf);

    const float cosAtCamera = dot(camera.forward(), -dirToCamera);
    if (cosAtCamera <= 0.0f) return;
    // Image-plane area (unit pixel area) to surface area at hit.pos [TR Sec. 5.2]:
    // p_cam,W = d_img^2 / cos^3, and p_cam,A = p_cam,W cos_y / d^2.
    const float imagePointToCameraDist = camera.imagePlaneDist() / cosAtCamera;
    const float imageToSolidAngle = imagePointToCameraDist * imagePointToCameraDist / cosAtCamera;
    const float imageToSurface = imageToSolidAngle * cosToCamera / distSqr;
    const float cameraPdfA = imageToSurface;

    // Light tracing alone has no MIS; otherwise the weight of [TR (46), (47)].
    const float weight = lightTraceOnly_
                             ? 1.0f
                             : ub_mis_weight_light_trace(mis_, state.mis, cameraPdfA, bsdfRevPdfW);
    const Rgb contrib = state.throughput * f * (weight * imageToSurface / lightSubPathCount_);
    if (isBlack(contrib)) return;
    if (scene_.occluded(hit.pos, hit.geoNormal, camera.position(), Vec3(0.0f))) return;
    splats.add(raster, contrib);
}

}  // namespace ub
