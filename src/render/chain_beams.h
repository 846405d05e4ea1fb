// Beams of UPBP from a traced segment chain (Krivanek et al. 2014, Sec. 4;
// Jarosz et al. 2011 for photon beams): a subpath leaving vertex x along a
// chain (scene/medium_trace.h) emits one beam piece per medium segment it
// covers. Light subpaths emit photon beams, camera subpaths query beams.
//
//   short beam  ends where free-flight sampling stopped (the next vertex), so
//               it covers the segments the sampling visited, the last one up to
//               the vertex; its throughput at a piece start is the walk's
//               weight up to there (T / P per passed segment);
//   long beam   runs to the chain's real surface through every medium segment;
//               its throughput at a piece start is the product of the
//               transmittances before it.
// A long beam in a homogeneous medium ends where its transmittance is below 1e-7
// in every channel; along an escaping ray (an unbounded segment) in a grid medium
// it ends where the ray leaves the scene's bounding sphere (render/chain_beams.cpp).
//
// Each piece records what ub_beam_at (kernels/shared/ub_upbp_records.h) needs to
// complete the subpath's MIS partials at any point of it: the pending partials
// after scattering at x, the distance from x to the piece start, and the
// free-flight probabilities between x and the piece start in both directions.
// Pieces in media that cannot scatter (homogeneous, sigma_s = 0) are left out:
// no vertex and no merge can happen there.
#pragma once

#include <cstdint>
#include <vector>

#include "core/vec.h"
#include "kernels/shared/ub_upbp_records.h"
#include "render/medium_walk.h"

namespace ub {

class MemoryBudget;

class Scene;

/// The subpath that emits the beams of one chain.
struct ChainBeamSource {
    Rgb throughput{1.0f};      ///< at x, after scattering there (before the chain)
    ub_mis_partials mis{};     ///< after scattering at x (dOut pending)
    uint32_t pathLength = 1;   ///< segments from the subpath start to a point of the chain
    bool fromMedium = false;   ///< x is a medium vertex
    bool applyDistSqr = true;  ///< false on the first segment of a light at infinity
    bool shortBeams = true;
    uint32_t tag = 0;                  ///< ub_beam::pixel
    const char* budgetName = "beams";  ///< what the memory budget calls them
};

/// Appends the pieces of the beam along `trace` (direction dir), as free-flight sampling
/// visited it (`visit`, `cv`), to out.
void appendChainBeams(const Scene& scene, const MediumTrace& trace, const Vec3& dir,
                      const ChainVisit& visit, const ChainVertex& cv, const ChainBeamSource& src,
                      std::vector<ub_beam>* out, MemoryBudget* budget = nullptr);

}  // namespace ub
