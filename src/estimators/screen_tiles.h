// Screen tiles for bb1d's camera rays (kernels/shared/ub_screen_tiles.h): the photon-beam
// parts binned by the image tiles their boxes project to, read by the query beams whose lines
// pass through a pinhole camera's eye in place of the BVH walk, by the host twin
// (estimators/bb1d_walk.inc) and the kernel (kernels/beams.cl) alike.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "kernels/shared/ub_bvh.h"
#include "kernels/shared/ub_screen_tiles.h"
#include "kernels/shared/ub_upbp_records.h"

namespace ub {

class Camera;

struct ScreenTiles {
    ub_screen_tiles params{};  ///< params.enabled == 0: every query walks the BVH
    /// Block ranges of the lists: list k is blocks start[k] .. start[k + 1] - 1; lists 0 ..
    /// tilesX * tilesY - 1 are the tiles', list tilesX * tilesY the one every tile reads.
    std::vector<uint32_t> start;
    static constexpr uint32_t kNoItem = 0xffffffffu;
    std::vector<uint32_t> items;       ///< the item (part, photon) index of each lane, 4 a block
    std::vector<ub_beam_keys4> lines;  ///< bb1d: the parts' lines, as the BVH's leaves have them
    std::vector<ub_photon_keys4> photonKeys;  ///< pb2d: the photons' keys, as the BVH's leaves
    size_t bytes() const {
        return start.size() * 4 + items.size() * 4 + lines.size() * sizeof(ub_beam_keys4) +
               photonKeys.size() * sizeof(ub_photon_keys4);
    }
};

/// Bins parts (their index is their position) for the camera: nothing when the camera is not a
/// pinhole or the lists would exceed a bound (16 entries per part on average; then every query
/// walks the BVH). r: the radius the parts' boxes are grown by; sceneRadius sets the tolerance.
/// The parts' rows of tiles, their spans and the lists are computed in parallel (TBB): 10-40
/// ms on the bunny and mirrorballs at 256 x 256 with SmallUPBP's settings.
/// reserve(bytes) is called before the lists are allocated (the memory budget). The buffers
/// are never empty (the kernels are given one block at least).
void buildScreenTiles(const Camera& camera, float sceneRadius,
                      const std::vector<ub_beam_part>& parts, float r,
                      const std::function<void(size_t)>& reserve, ScreenTiles* out);

/// The same for pb2d's photon points (their index is their position), each binned by its cube
/// of half-width r (a photon within r of a camera ray lies in it).
void buildPhotonScreenTiles(const Camera& camera, float sceneRadius,
                            const std::vector<ub_photon_point>& photons, float r,
                            const std::function<void(size_t)>& reserve, ScreenTiles* out);

/// Lets the bb1d and pb2d estimates use screen tiles (the default) or not: the two find the same
/// pairs, which a test checks.
void setScreenTilesForTests(bool allowed);
bool screenTilesAllowed();

}  // namespace ub
