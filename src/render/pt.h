// `pt`: unidirectional path tracing with next-event estimation (NEE) and
// multiple importance sampling between BSDF sampling and light sampling
// (Veach 1997, Ch. 9; the estimator of SmallVCM's PathTracer).
//
// At every non-delta vertex x_k of a camera path the direct light is estimated
// twice:
//   * light sampling: one light chosen uniformly (p = 1/#lights), one point on
//     it from Light::illuminate, pdf p_light,W = directPdfW / #lights;
//   * BSDF sampling: the continuation direction, when it hits an emitter (an
//     area light or the environment through Scene::backgroundLightId), pdf
//     p_bsdf,W = BSDF pdf * Russian-roulette continuation probability.
// Each is weighted by the power heuristic (beta = 2, Veach eq. 9.13) or the
// balance heuristic (beta = 1, eq. 9.10; RenderOptions::heuristic):
//     w_light = p_light^b / (p_light^b + p_bsdf^b),  w_bsdf = p_bsdf^b / (p_light^b + p_bsdf^b).
// Area-light pdfs are converted to solid angle at the shading point with
// p_W = p_A d^2 / |cos theta_light|. Delta lights (point, directional) can only be
// reached by light sampling (weight 1); after a delta BSDF event (mirror, smooth
// glass) NEE is impossible and emitters hit next get weight 1.
//
// Path length counts segments (SmallVCM): a light seen directly from the camera
// is a path of length 1, one bounce off a diffuse wall is length 2. A path of
// length L contributes only if minPathLength <= L <= maxPathLength.
//
// Russian roulette (as SmallVCM): at every vertex, after NEE, the path continues
// with probability q = Bsdf::continuationProb() (the max RGB albedo, so white
// surfaces never terminate) and its throughput is divided by q. q is part of
// p_bsdf,W in the MIS weights, which keeps them consistent pdfs of the actual
// sampling process. No roulette below the minimum length is needed: it only
// loses efficiency, never correctness.
//
// Emitters are not terminal: a surface that both emits and has a material
// (e.g. the inside of a glowing furnace) adds its emission and keeps scattering.
//
// Determinism: pixel (x, y) of iteration i draws every random number from
// Rng::forPath(seed, i, y * width + x), and rows are rendered in parallel with
// TBB, so the image depends only on the seed.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "render/integrator.h"

namespace ub {

/// Optional recording of the rays an iteration traces (for benchmarks): per image row,
/// the closest-hit rays in tracing order and the number of shadow (occlusion) rays.
struct PtRayLog {
    std::vector<std::vector<Ray>> closestRays;  ///< [row] -> rays
    std::vector<uint64_t> shadowRays;           ///< [row] -> count
    uint64_t closestCount() const;
    uint64_t shadowCount() const;
};

/// Which direct-lighting strategies PathTracer combines. `Mis` is what `pt` uses; the
/// single-strategy variants exist for tests that check MIS against each strategy alone.
enum class PtStrategy {
    Mis,        ///< BSDF sampling + light sampling, MIS-weighted
    BsdfOnly,   ///< emitters only found by BSDF-sampled rays (delta lights are missed)
    LightOnly,  ///< direct light only by NEE (emitters hit after a non-delta bounce ignored)
};

class PathTracer : public Integrator {
  public:
    PathTracer(const Scene& scene, const RenderOptions& options,
               PtStrategy strategy = PtStrategy::Mis);
    void renderIteration(int iteration, Image& out) override;
    /// Records the rays of the following iterations into *log (nullptr to stop).
    void setRayLog(PtRayLog* log) { rayLog_ = log; }

    /// Radiance estimate of one camera path through a random point of pixel (x, y) in
    /// iteration `iteration`.
    Rgb tracePixel(int x, int y, int iteration) const;
    /// Technique options.algorithm: pixel estimates dropped by the guard.
    RejectionCounts rejectedContributions() const override;

  private:
    const Scene& scene_;
    RenderOptions options_;
    PtStrategy strategy_;
    float misBeta_;        ///< 2 power heuristic, 1 balance heuristic
    float lightPickProb_;  ///< 1 / #lights (0 without lights)
    PtRayLog* rayLog_ = nullptr;
    ContributionGuard guard_;
    std::vector<uint64_t> rowRejected_;  ///< per row, the last iteration
    uint64_t rejected_ = 0;              ///< all iterations
};

std::unique_ptr<Integrator> makePathTracer(const Scene& scene, const RenderOptions& options);

}  // namespace ub
