// `vpt`: volumetric path tracing with next-event estimation and multiple
// importance sampling (Veach 1997, Ch. 9, extended to media as in SmallUPBP's
// volumetric path tracer and pbrt-v4's VolPathIntegrator).
//
// A camera path alternates between tracing to the next real surface
// (Scene::traceMedia: the segment chain through imaginary and skipped
// boundaries, see scene/medium_stack.h) and free-flight sampling along that
// chain (scene/medium.h, spectral MIS over RGB per segment). Free-flight
// sampling either stops at a medium vertex at distance t in segment k, with
// density  prod_{j<k} P_pass,j * p_k(t)  and throughput factor
// T sigma_s / p, or passes the whole chain with probability prod_j P_pass,j
// and factor T / P_pass, reaching the surface (or escaping).
//
// Vertices and their estimates:
//  * medium vertex x: emission of the medium (source term sigma_a Le, collision
//    estimator T sigma_a Le / p: unidirectional only, MIS weight 1); NEE to one
//    light picked uniformly, with transmittance of the whole shadow chain
//    (Scene::shadowTransmittance); continuation by sampling the
//    Henyey-Greenstein phase function (kernels/shared/ub_phase.h);
//  * surface vertex: emission of an area light / the environment when hit,
//    NEE, continuation by BSDF sampling; crossing a boundary surface updates
//    the medium stack (Scene::crossSurface).
// MIS between light sampling and phase/BSDF sampling (power heuristic beta = 2,
// or balance beta = 1) uses the solid-angle pdfs of the two ways of making the
// same last segment:
//     p_light,W = directPdfW / #lights,
//     p_dir,W   = p_phase|BSDF,W * q * prod_j P_pass,j(shadow chain),
// where q is the Russian-roulette continuation probability at the vertex and the
// product is the probability that free-flight sampling along the direction
// passes every medium segment up to the light (it must pass them to hit it).
// Delta lights take light sampling only; after a delta BSDF event emitters get
// weight 1 (no NEE could have made the path).
//
// Russian roulette: at a surface, q = Bsdf::continuationProb() (as `pt`); at a
// medium vertex q = max_c sigma_s,c / sigma_t,c (the single-scattering albedo),
// so a grey medium keeps the throughput constant (T sigma_s / p = albedo,
// divided by q).
//
// Path length counts segments, every vertex (surface or medium) ending one
// (SmallUPBP semantics): a medium vertex seen from the camera ends a path of
// length 1, its NEE makes length 2. A path of length L contributes only if
// minPathLength <= L <= maxPathLength. With DepthCounting::kNonNullVertices
// (Mitsuba scenes, scene.h) a surface vertex whose sampled lobe continues the
// ray unchanged (Bsdf::isNullEvent: thin-sheet transmission) ends no segment,
// like an imaginary boundary: the segments on both sides count as one. It stays
// a delta vertex for MIS. Medium transitions follow Scene::crossSurface and
// RenderSettings::mediumTransitions.
//
// Determinism: pixel (x, y) of iteration i draws every random number from
// Rng::forPath(seed, i, y * width + x); rows are rendered in parallel.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "render/integrator.h"

namespace ub {

class VolPathTracer : public Integrator {
  public:
    VolPathTracer(const Scene& scene, const RenderOptions& options);
    void renderIteration(int iteration, Image& out) override;
    /// Radiance estimate of one camera path through a random point of pixel (x, y).
    Rgb tracePixel(int x, int y, int iteration) const;
    /// Technique options.algorithm: pixel estimates dropped by the guard.
    RejectionCounts rejectedContributions() const override;

  private:
    const Scene& scene_;
    RenderOptions options_;
    float misBeta_;        ///< 2 power heuristic, 1 balance heuristic
    float lightPickProb_;  ///< 1 / #lights (0 without lights)
    ContributionGuard guard_;
    std::vector<uint64_t> rowRejected_;  ///< per row, the last iteration
    uint64_t rejected_ = 0;              ///< all iterations
};

std::unique_ptr<Integrator> makeVolPathTracer(const Scene& scene, const RenderOptions& options);

}  // namespace ub
