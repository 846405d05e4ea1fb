// Screen tiles for bb1d's camera rays (kernels/shared/ub_screen_tiles.h): the photon beams
// (whole, or their parts near the eye's plane) binned by the image tiles their boxes project to,
// read by the query beams whose lines pass through a pinhole camera's eye in place of the BVH walk,
// by the host twin (estimators/bb1d_walk.inc) and the kernel (kernels/beams.cl) alike.
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
    std::vector<uint32_t> items;  ///< the item (beam part, photon) index of each lane, 4 a block
    /// bb1d: the items, a photon beam's whole length (t0 = 0, t1 = its length) or one of its
    /// BVH parts each; the pair tests read them as they read the BVH's parts.
    std::vector<ub_beam_part> itemParts;
    std::vector<ub_beam_keys4> lines;  ///< bb1d: the items' lines, as the BVH's leaves have them
    std::vector<ub_photon_keys4> photonKeys;  ///< pb2d: the photons' keys, as the BVH's leaves
    size_t bytes() const {
        return start.size() * 4 + items.size() * 4 + itemParts.size() * sizeof(ub_beam_part) +
               lines.size() * sizeof(ub_beam_keys4) + photonKeys.size() * sizeof(ub_photon_keys4);
    }
};

/// Bins the photon beams for the camera: nothing when the camera is not a pinhole or the lists
/// would exceed a bound (16 entries per item on average; then every query walks the BVH).
/// A beam whose box lies wholly in front of the eye is one item, its whole length; the others
/// are binned by their parts (`parts`, the BVH's), whose boxes across the eye's plane go to
/// the list every tile reads. Against binning every part, the lists of mirrorballs hold 40%
/// fewer entries (a beam's parts share tiles) and take a fifth of the hulls to build
/// (docs/performance.md, session 40). out->itemParts gets the items. r: the radius the boxes
/// are grown by; sceneRadius sets the tolerance. The items' rows of tiles, their spans and the
/// lists are computed in parallel (TBB). reserve(bytes) is called before the lists are
/// allocated (the memory budget). The buffers are never empty (the kernels are given one
/// block at least).
void buildScreenTiles(const Camera& camera, float sceneRadius, const std::vector<ub_beam>& beams,
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
