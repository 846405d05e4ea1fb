// Integrator interface: a progressive renderer runs iterations of one
// sample per pixel each (and, for bidirectional methods, one light subpath per
// pixel). The virtual call is per iteration, never per sample.
//
// Determinism: iteration i of a render with seed s must produce bit-identical
// output regardless of thread count and scheduling. Use Rng::forPath(seed, i,
// pixelIndex, salt) per pixel/path, and accumulate light-tracing splats into a
// fixed number of chunk buffers (see SplatBuffer) summed in a fixed order.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/image.h"
#include "render/contribution_guard.h"
#include "scene/scene.h"

namespace ub {

enum class MisHeuristic { Power, Balance };

struct RenderOptions {
    std::string algorithm = "pt";
    int maxPathLength = 10;  ///< segments (SmallVCM semantics), from scene or CLI
    int minPathLength = 0;
    uint64_t seed = 1;
    MisHeuristic heuristic = MisHeuristic::Power;
    /// Merging radius: if radiusIsRelative, multiplied by the scene bounding sphere radius.
    float radius = 0.003f;
    bool radiusIsRelative = true;
    float alpha = 0.75f;  ///< progressive radius reduction exponent
    /// UPBP's volumetric estimators (render/upbp_techniques.h, docs/algorithms.md): initial
    /// radii (if radiusIsRelative, fractions of the radius of the media: half the diagonal of
    /// the bounding box of the medium boundaries, or the scene radius with a global medium) and
    /// reduction exponents, r_i = r_1 i^((alpha - 1) / k) for a k-dimensional kernel.
    float radiusPP3D = 0.005f, radiusPB2D = 0.0025f, radiusBP2D = 0.005f, radiusBB1D = 0.005f;
    float alphaPP3D = 0.75f, alphaPB2D = 0.75f, alphaBP2D = 0.75f, alphaBB1D = 0.75f;
    bool shortPhotonBeams = true;  ///< photon beams end at the sampled distance (else: surface)
    bool shortQueryBeams = false;  ///< query beams end at the sampled distance (else: surface)
    /// Light subpaths per iteration that emit photon beams (N_B, the first ones by index);
    /// 0: N_L / 16, at least 1 (SmallUPBP's -pbc).
    int beamPaths = 0;
    /// Where UPBP's estimate pass runs: "host" (the C++ twins), "opencl" (kernels; an error if
    /// no device works), "auto" (OpenCL when a device works, else the host, saying why).
    std::string backend = "host";
    /// Bound on the per-iteration records and lookups (core/memory_budget.h); 0: none.
    size_t maxMemoryBytes = 0;
    int clPlatform = -1, clDevice = -1;  ///< OpenCL device (-1, -1: the first one)
    std::string clCache;  ///< OpenCL program cache folder ("": the user's cache, "-": none)
    /// OpenCL queue profiling, for bench_upbp --cl-profile (VertexCM::replayEstimate reports
    /// the kernels' device times); the images are the same either way.
    bool clProfile = false;
    /// Cut rays through homogeneous media where free-flight sampling will stop
    /// (Scene::traceMedia's look-ahead) in vpt and the bidirectional engine (vlt, vbpt, vcm,
    /// upbp). The image is the same either way; tests and benchmarks turn it off to compare.
    bool cutRaysAtFlight = true;
    /// Tests only (never set by the command-line program): makes one technique's contributions
    /// invalid for some pixels, to check the contribution guard (render/contribution_guard.h).
    ContributionFault testFault;
};

class Integrator {
  public:
    virtual ~Integrator() = default;
    /// Renders iteration `iteration` (0-based) into `out` (width x height of the camera),
    /// overwriting it with this iteration's estimate (one sample per pixel).
    virtual void renderIteration(int iteration, Image& out) = 0;
    /// Names of the per-technique layers the integrator splits its image into (UPBP: its
    /// techniques); empty if none. The layers of an iteration sum to its image.
    virtual std::vector<std::string> layerNames() const { return {}; }
    /// The last iteration's layers, in layerNames() order (nullptr if none).
    virtual const std::vector<Image>* iterationLayers() const { return nullptr; }
    /// One line about the last iteration's work (counts of records etc.), or empty.
    virtual std::string iterationSummary() const { return ""; }
    /// Contributions dropped by the guard (render/contribution_guard.h) in the iterations
    /// rendered so far, per technique: every technique the integrator runs, zeros included,
    /// in a fixed order (the -a algorithm, or UPBP's layer names).
    virtual RejectionCounts rejectedContributions() const = 0;
    /// One line about how the integrator was set up (UPBP: where its estimate pass runs).
    virtual std::string setupNote() const { return ""; }
};

/// Names accepted by makeIntegrator, for help texts and error messages.
std::vector<std::string> integratorNames();
/// Creates the integrator named options.algorithm. Throws InputError naming the valid
/// algorithms if the name is unknown or the scene does not support it.
std::unique_ptr<Integrator> makeIntegrator(const Scene& scene, const RenderOptions& options);

}  // namespace ub
