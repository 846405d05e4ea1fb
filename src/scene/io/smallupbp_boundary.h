// Medium boundaries of SmallUPBP scenes as unibeam needs them.
//
// SmallUPBP identifies a medium boundary by its material, so one material may
// cover several separate closed objects (mirrorballs: a glass ball and two lamp
// glasses), and it tolerates open meshes (the Stanford bunny has holes in its
// base; a ray through a hole "leaves" a boundary it never entered, which its
// stack ignores). unibeam's scene validation (Scene::mediumIssues) wants each
// boundary closed and checks overlaps of equal priority by bounding boxes, so
// here a material's mesh is split into its connected pieces (vertices welded by
// exact position), each hole of a piece is closed by a fan around the hole's
// centroid, and pieces that are cavities (negative signed volume: faces turned
// inwards, e.g. the inner wall of a hollow object) stay with the piece around
// them, so that crossing into the cavity leaves the object as in SmallUPBP.
#pragma once

#include <vector>

#include "scene/scene.h"

namespace ub {

struct BoundarySplit {
    std::vector<TriangleMesh> pieces;
    size_t holes = 0;      ///< boundary loops closed
    size_t holeEdges = 0;  ///< boundary edges they had
    size_t cavities = 0;   ///< inward pieces kept with the piece around them
    size_t insideOut = 0;  ///< inward pieces with no piece around them (kept alone)
};

/// Splits `mesh` into closed pieces as described above. Triangles of the input are kept
/// as they are (same winding); fans are added for holes.
BoundarySplit splitMediumBoundary(const TriangleMesh& mesh);

}  // namespace ub
