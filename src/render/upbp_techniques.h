// The technique set of UPBP (Krivanek et al. 2014), named as in SmallUPBP:
//   bpt   every vertex connection: camera hits, NEE, connections, light tracing
//   surf  surface photon merging (VCM's merging)
//   pp3d  photon points x query points (3D kernel)
//   pb2d  photon points x query beams (2D kernel, the beam radiance estimate)
//   bp2d  photon beams x query points (2D kernel)
//   bb1d  photon beams x query beams (1D kernel)
// Algorithm names: `upbp` (all six) or `upbp:T1+T2+...` (any non-empty subset, MIS
// renormalised over exactly those); `vcm` on a scene with media is `upbp:bpt+surf`.
#pragma once

#include <string>

namespace ub {

struct UpbpTechniques {
    bool bpt = false, surf = false, pp3d = false, pb2d = false, bp2d = false, bb1d = false;
    bool anyVolume() const { return pp3d || pb2d || bp2d || bb1d; }
    bool photonPoints() const { return pp3d || pb2d; }
    bool photonBeams() const { return bp2d || bb1d; }
    bool queryPoints() const { return pp3d || bp2d; }
    bool queryBeams() const { return pb2d || bb1d; }
    /// "bpt+surf+pp3d" in the canonical order.
    std::string describe() const;
};

/// True for "upbp" and "upbp:...".
bool isUpbpAlgorithm(const std::string& algorithm);
/// Parses "upbp" / "upbp:T1+T2+...". Throws InputError naming the bad part (unknown or
/// repeated technique, empty set).
UpbpTechniques parseUpbpTechniques(const std::string& algorithm);

}  // namespace ub
