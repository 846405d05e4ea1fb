// Surface photon merging (surf; VCM's vertex merging, Georgiev et al. 2012): a camera
// vertex on a non-specular surface gathers the stored surface light vertices (photons)
// within radius r through the hashed grid.
//
// Estimates  sum_photons f(z; w_z, w_y) Phi_y / (N_L pi r^2)   (disk kernel, [TR (19)]).
// pdfs:      the camera BSDF towards the photon's incoming direction (times the camera's
//            continuation probability) and the reverse one (times the light's).
// MIS:       ub_mis_weight_merge [TR (38), (39)]. Per pair: ub_surf_contribution
//            (kernels/shared/ub_surf.h), shared with the kernel kernels/surf.cl. Medium
//            photons are merged by the volumetric estimators (estimators/volume_estimate.h).
//
// Two drivers of the same per-pair function: inline in the camera pass for vcm, bpm and
// ppm without media (VertexCM::mergeVertices), and the batch pass over recorded queries
// for upbp (estimateSurface here, or the OpenCL kernel).
#include "estimators/surface_merging.h"

#include <chrono>
#include <cstdio>
#include <cstring>

#include "cl/cl_runtime.h"
#include "core/memory_budget.h"
#include "core/parallel_gather.h"
#include "estimators/hash_grid.h"
#include "estimators/volume_estimate.h"
#include "render/medium_walk.h"
#include "render/vcm.h"
#include "render/vertex_scatter.h"
#include "scene/scene.h"

namespace ub {

ub_surface_query makeSurfaceQuery(const Bsdf& bsdf, const Vec3& pos, int pathLength,
                                  const Rgb& throughput, uint32_t pixel, float dVCM, float dVM,
                                  float contProb, int materialId) {
    ub_surface_query q;
    std::memset(&q, 0, sizeof(q));
    q.bsdf = bsdf.shared();
    q.bsdf.tableIndex = uint32_t(materialId >= 0 ? materialId : 0);
    storeF3(q.pos, pos);
    q.pathLength = uint32_t(pathLength);
    storeF3(q.throughput, throughput);
    q.pixel = pixel;
    q.dVCM = dVCM;
    q.dVM = dVM;
    q.contProb = contProb;
    return q;
}

std::vector<float> coatingTables(const Scene& scene) {
    const size_t n = UB_ROUGH_PLASTIC_TABLE_SIZE;
    std::vector<float> tables(std::max<size_t>(scene.materials.size(), 1) * n, 0.0f);
    for (size_t m = 0; m < scene.materials.size(); ++m)
        if (scene.materials[m].type == MaterialType::RoughPlastic)
            std::copy(scene.materials[m].coatingTransmittance.begin(),
                      scene.materials[m].coatingTransmittance.end(), tables.begin() + m * n);
    return tables;
}

std::string clBsdfTypesOption(const std::vector<Material>& materials) {
    uint32_t mask = 1u << UB_MATERIAL_DIFFUSE;
    for (const Material& m : materials) mask |= 1u << uint32_t(m.type);
    char text[40];
    std::snprintf(text, sizeof(text), "-DUB_BSDF_TYPES=0x%xu", mask);
    return text;
}

Rgb VertexCM::mergeVertices(const SubPath& state, const Hit& hit, const Bsdf& bsdf) const {
    if (bsdf.isBlend()) return mergeVerticesBlend(state, hit, bsdf);
    const ub_surface_query q =
        makeSurfaceQuery(bsdf, hit.pos, state.pathLength, Rgb(1.0f), 0, state.mis.dVCM,
                         state.mis.dVM, vcmContinuationProb(bsdf), hit.materialId);
    const float radiusSqr = grid_.radius() * grid_.radius();
    Rgb sum(0.0f);
    grid_.query(hit.pos, lightVertices_, &LightVertex::position, [&](uint32_t index) {
        const ub_float3 c = ub_surf_contribution(
            mis_, &lightVertices_[index], &q, bsdf.coatingTable(), radiusSqr,
            ub_uint(options_.minPathLength), ub_uint(options_.maxPathLength), ppm_ ? 1u : 0u);
        sum += Rgb(c.x, c.y, c.z);
    });
    return sum * vmNormalization_;
}

// The per-pair estimate of ub_surf_contribution with the BSDF evaluated through
// Bsdf::evaluate: a Blend (Mitsuba's blendbsdf, mask) has no kernel-side state. The pair
// test and the weighting are the shared ones (kernels/shared/ub_surf.h).
Rgb VertexCM::mergeVerticesBlend(const SubPath& state, const Hit& hit, const Bsdf& bsdf) const {
    const float radiusSqr = grid_.radius() * grid_.radius();
    const float contProb = vcmContinuationProb(bsdf);
    const float pos[3] = {hit.pos.x, hit.pos.y, hit.pos.z};
    Rgb sum(0.0f);
    grid_.query(hit.pos, lightVertices_, &LightVertex::position, [&](uint32_t index) {
        const LightVertex& lv = lightVertices_[index];
        if (!ub_surf_pair(&lv, pos, ub_uint(state.pathLength), radiusSqr,
                          ub_uint(options_.minPathLength), ub_uint(options_.maxPathLength)))
            return;
        float cosGen = 0.0f, dirPdfW = 0.0f, revPdfW = 0.0f;
        const Rgb f = bsdf.evaluate(lv.dirFix3(), &cosGen, &dirPdfW, &revPdfW);
        if (isBlack(f)) return;
        const ub_float3 c =
            ub_surf_weighted(mis_, &lv, ub_make_float3(f.x, f.y, f.z), dirPdfW, revPdfW,
                             state.mis.dVCM, state.mis.dVM, contProb, ppm_ ? 1u : 0u);
        sum += Rgb(c.x, c.y, c.z);
    });
    return sum * vmNormalization_;
}

void estimateSurface(const SurfaceMergeInput& in, const HashGrid& grid, std::vector<Rgb>* out,
                     size_t* pairs) {
    const std::vector<LightVertex>& photons = *in.photons;
    const std::vector<ub_surface_query>& queries = *in.queries;
    out->assign(queries.size(), Rgb(0.0f));
    *pairs = 0;
    if (photons.empty() || queries.empty()) return;
    const float radiusSqr = in.radius * in.radius;
    forEachQueryBlock(
        queries.size(), HashGrid::kBlock, out, pairs, [&](size_t begin, size_t end, size_t* found) {
            HashGrid::BlockRanges ranges;
            grid.blockRanges(
                end - begin, [&](size_t k) { return loadF3(queries[begin + k].pos); }, &ranges);
            for (size_t i = begin; i < end; ++i) {
                const ub_surface_query& q = queries[i];
                const float* coating =
                    in.tables->data() + size_t(q.bsdf.tableIndex) * UB_ROUGH_PLASTIC_TABLE_SIZE;
                Rgb sum(0.0f);
                grid.candidates(ranges, i - begin, [&](uint32_t j) {
                    const ub_float3 c =
                        ub_surf_contribution(in.mis, &photons[j], &q, coating, radiusSqr,
                                             ub_uint(in.minLength), ub_uint(in.maxLength), 0u);
                    sum += Rgb(c.x, c.y, c.z);
                    ++*found;
                });
                (*out)[i] = sum * loadF3(q.throughput) * in.normalization;
            }
        });
}

void VertexCM::estimateSurfaceQueries(Image& out, Image* layer) {
    const auto t0 = std::chrono::steady_clock::now();
    gatherParts(
        surfaceQueries_, cameraRows_.size(), [&](size_t y) -> auto& { return cameraRows_[y].surf; },
        budget_.get(), "surface queries", "a smaller --resolution or --max-length needs less");
    std::vector<Rgb> perQuery;
    surfaceEstimates(cl_.get(), &perQuery);
    // In query order (deterministic), each estimate through the technique's guard.
    const ContributionGuard& guard = guards_[size_t(surfTechnique_)];
    uint64_t& rejected = rejected_[size_t(surfTechnique_)];
    const uint32_t width = uint32_t(out.width);
    for (size_t i = 0; i < surfaceQueries_.size(); ++i) {
        Rgb m = perQuery[i];
        const uint32_t pixel = surfaceQueries_[i].pixel;
        if (!guard.filter(pixel, &m, &rejected)) continue;
        const int x = int(pixel % width), y = int(pixel / width);
        out.at(x, y) += m;
        if (layer) layer->at(x, y) += m;
    }
    lastSurfSeconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void VertexCM::surfaceEstimates(ClRuntime* cl, std::vector<Rgb>* perQuery) {
    if (cl) {
        ClRuntime::EstimateArgs a;
        const std::vector<ub_medium_info> noMedia(1, ub_medium_info{});
        a.media = &noMedia;
        a.mis = mis_;
        a.radius = grid_.radius();
        a.normalization = vmNormalization_;
        a.minLength = uint32_t(options_.minPathLength);
        a.maxLength = uint32_t(options_.maxPathLength);
        cl->estimateSurf(surfacePhotons_, grid_, coatingTables_, surfaceQueries_, a, perQuery);
        lastSurfPairs_ = VolumeEstimateStats::kNotCounted;
    } else {
        SurfaceMergeInput in;
        in.mis = mis_;
        in.radius = grid_.radius();
        in.normalization = vmNormalization_;
        in.minLength = options_.minPathLength;
        in.maxLength = options_.maxPathLength;
        in.photons = &surfacePhotons_;
        in.queries = &surfaceQueries_;
        in.tables = &coatingTables_;
        estimateSurface(in, grid_, perQuery, &lastSurfPairs_);
    }
}

}  // namespace ub
