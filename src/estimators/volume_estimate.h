// The estimate pass of UPBP: the volumetric estimators evaluated in batch over
// the query points and query beams the camera pass recorded, against the photon
// points and photon beams of the light pass (render/vcm.h, step 5 of an
// iteration). This is the host twin of the pass the OpenCL backend runs; the
// per-pair math is kernels/shared/ub_pp3d.h, ub_pb2d.h, ub_bp2d.h, ub_bb1d.h.
//
// Lookups, built per iteration:
//   pp3d  hashed grid over photon points, cell 2 r (estimators/hash_grid.h);
//   pb2d  BVH over photon points as boxes of their kernel sphere, traversed by
//         each query beam (estimators/bvh.h);
//   bp2d, bb1d  one BVH over photon-beam pieces diced along their axis into at
//         most 32 parts of length >= 32 r, each part's box enclosing its cylinder
//         of radius max(r_bp2d, r_bb1d); traversed by query points and query
//         beams. A beam meets a query in several parts' boxes; only the part whose
//         parameter range holds the closest-approach parameter counts it, so each
//         pair is counted once without mailboxes.
// The medium along a beam up to a point (transmittance, sigma_s, free-flight pdfs)
// is evaluated by regular tracking (scene/medium.h evalMediumSegment): exact in
// NanoVDB grids as in homogeneous media.
//
// Results: every query's estimate is computed in parallel into its own slot, then
// added to its pixel in query order, so images do not depend on the thread count.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <array>
#include <atomic>
#include <cstddef>
#include <vector>

#include "core/image.h"
#include "estimators/screen_tiles.h"
#include "kernels/shared/ub_bvh.h"
#include "kernels/shared/ub_medium_homogeneous.h"
#include "kernels/shared/ub_upbp_records.h"
#include "render/contribution_guard.h"
#include "render/upbp_techniques.h"

namespace ub {

class MemoryBudget;

class Scene;
class ClRuntime;

struct VolumeEstimateInput {
    const Scene* scene = nullptr;
    ub_mis_constants mis{};
    UpbpTechniques techniques;
    float radius[4] = {0, 0, 0, 0};  ///< UB_TECH_* radii of this iteration
    float lightPathCount = 1;        ///< N_L
    float beamPathCount = 1;         ///< N_B
    int minLength = 0, maxLength = 1;
    const std::vector<ub_photon_point>* photonPoints = nullptr;
    const std::vector<ub_beam>* photonBeams = nullptr;
    const std::vector<ub_query_point>* queryPoints = nullptr;
    const std::vector<ub_beam>* queryBeams = nullptr;
    ClRuntime* cl = nullptr;  ///< the OpenCL backend (kernels for what it has), or host only
    /// With cl: the media as the kernels see them, and whether the beam kernels can run in
    /// every medium (prepareDeviceMedia, once per render).
    const std::vector<ub_medium_info>* deviceMedia = nullptr;
    bool beamKernels = false;
    MemoryBudget* budget = nullptr;  ///< lookups reserve here while they live (--max-memory)
    /// Contribution guards per technique (UB_TECH_*; render/contribution_guard.h): each
    /// query's estimate passes its technique's guard before it is added to its pixel.
    ContributionGuard guards[4];
};

/// Per-iteration counts and times of the estimate pass.
struct VolumeEstimateStats {
    /// Photon-query pairs within the kernel, per technique; kNotCounted where a technique ran
    /// as an OpenCL kernel (the kernels do not count).
    size_t pairs[4] = {0, 0, 0, 0};
    static constexpr size_t kNotCounted = ~size_t(0);
    double buildSeconds = 0, estimateSeconds = 0;
    size_t lookupBytes = 0;
    /// Query estimates dropped by the guard (NaN, infinite or negative), per technique.
    uint64_t rejected[4] = {0, 0, 0, 0};
    /// The screen tiles bb1d and pb2d read (enabled == 0: none; estimators/screen_tiles.h).
    ub_screen_tiles screenTiles{}, photonScreenTiles{};
};

/// The media as the kernels see them (one ub_medium_info per medium, at least one entry), and
/// with needGrids (pb2d or photon beams) the grid media uploaded to cl's device
/// (ClRuntime::setGridMedia). Returns false if a grid medium has no beam kernel (an albedo
/// grid, trilinear filtering): pb2d, bp2d and bb1d then run on the host.
bool prepareDeviceMedia(const Scene& scene, ClRuntime* cl, bool needGrids,
                        std::vector<ub_medium_info>* media);

/// Adds every enabled volumetric technique's estimate to its query's pixel of `image` (and
/// of layers[UB_TECH_*] if layers is given; each layer the size of the image).
void estimateVolume(const VolumeEstimateInput& in, Image* image, std::array<Image, 4>* layers,
                    VolumeEstimateStats* stats = nullptr);

/// Runs estimate(begin, end, &found) over [0, n) in blocks of at most `block` queries, in
/// parallel (TBB): it writes (*out)[i] for i in [begin, end), and *pairs gets the sum of what
/// the calls add to `found` (the kernel pairs they evaluated). The hashed-grid estimators take
/// their queries a block at a time (HashGrid::blockRanges).
template <class EstimateBlock>
void forEachQueryBlock(size_t n, size_t block, std::vector<Rgb>* out, size_t* pairs,
                       EstimateBlock&& estimate) {
    std::atomic<size_t> total{0};
    tbb::parallel_for(tbb::blocked_range<size_t>(0, (n + block - 1) / block),
                      [&](const tbb::blocked_range<size_t>& range) {
                          size_t found = 0;
                          for (size_t b = range.begin(); b != range.end(); ++b)
                              estimate(b * block, std::min(n, (b + 1) * block), &found);
                          total += found;
                      });
    *pairs = total;
}

/// Runs estimate(i, &found) for every query i in [0, n) (forEachQueryBlock, blocks of
/// `grain`), writing its result to (*out)[i].
template <class Estimate>
void forEachQuery(size_t n, size_t grain, std::vector<Rgb>* out, size_t* pairs,
                  Estimate&& estimate) {
    forEachQueryBlock(n, grain, out, pairs, [&](size_t begin, size_t end, size_t* found) {
        for (size_t i = begin; i < end; ++i) (*out)[i] = estimate(i, found);
    });
}

// The host twins, one per estimator (estimators/*_estimator.cpp): each adds its estimate of
// query i to out[i].
class HashGrid;
class Bvh;
class BeamMedium;
using BeamPart = ub_beam_part;  ///< a diced part of a photon beam (kernels/shared/ub_bvh.h)
void estimatePP3D(const VolumeEstimateInput& in, const HashGrid& grid, std::vector<Rgb>* out,
                  size_t* pairs);
/// photons: the photon points in the leaf order of photonSpheres (Bvh::permuteToLeafOrder);
/// keys: the photons' keys four to a block (ub_photon_keys4), in the same order.
void estimatePB2D(const VolumeEstimateInput& in, const Bvh& photonSpheres,
                  const std::vector<ub_photon_point>& photons,
                  const std::vector<ub_photon_keys4>& keys, const ScreenTiles& tiles,
                  std::vector<Rgb>* out, size_t* pairs);
/// The host's SSE form of ub_pb2d_near4 (kernels/shared/ub_pb2d.h), for tests.
uint32_t pb2dNear4ForTests(const ub_photon_keys4& k, const ub_float3& o, const ub_float3& d,
                           float length, uint32_t mediumId, float radiusSqr, float* t);
/// photonMedia[i]: the medium along photon beam i, built (estimators/beam_medium.h).
void estimateBP2D(const VolumeEstimateInput& in, const Bvh& beamParts,
                  const std::vector<BeamPart>& parts, const std::vector<BeamMedium>& photonMedia,
                  std::vector<Rgb>* out, size_t* pairs);
/// lines: the parts' lines four to a block, in leaf order (kernels/shared/ub_bvh.h).
void estimateBB1D(const VolumeEstimateInput& in, const Bvh& beamParts,
                  const std::vector<BeamPart>& parts, const std::vector<ub_beam_keys4>& lines,
                  const std::vector<BeamMedium>& photonMedia, const ScreenTiles& tiles,
                  std::vector<Rgb>* out, size_t* pairs);
/// Whether estimateBB1D tests part lines eight at a time (the CPU has AVX; bb1d_walk.inc).
bool bb1dWideWalk();
/// Lets estimateBB1D use the AVX walk where the CPU has it (the default) or not: the two give
/// the same sums bit for bit, which a test checks.
void setBb1dWideWalkForTests(bool allowed);
/// The AVX walk's test of blocks k[0] and k[1] (bits 0-3 and 4-7); throws where
/// bb1dWideWalk() could never be true (no AVX).
uint32_t bb1dLinesNear8ForTests(const ub_beam_keys4* k, const ub_float3& o, const ub_float3& d,
                                float queryLength, float radiusSqr);
/// Whether this CPU and build have the AVX walk (whatever setBb1dWideWalkForTests says).
bool bb1dWideWalkAvailable();

}  // namespace ub
