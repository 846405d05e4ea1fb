// Bounding volume hierarchy over axis-aligned boxes: the lookup of the beam
// estimators (UPBP). pb2d stores photon points as boxes of their kernel
// sphere (traversed by query beams); bp2d and bb1d store photon-beam pieces,
// diced along their axis into boxes of the cylinder of radius r (traversed by
// query points and query beams; src/estimators/volume_estimate.h).
//
// Built top-down: a node's primitives are split at the median of their box
// centres along the axis of largest centre extent, down to leaves of at most
// leafSize primitives (O(n log n) with nth_element; measured, docs/performance.md: 8
// for the beam parts, faster than 4 and 16 for bb1d, whose candidates are cheap; 4 for the
// photon spheres of pb2d, where 8 halved the kernel's speed). Median splits keep the
// tree balanced whatever the beam distribution; for the long, thin boxes of
// beams a SAH split would cut traversal cost further (not done).
//
// Own code rather than Embree's user geometry: the nodes are a flat array of
// fixed-size records, which the OpenCL backend uploads and traverses as they are
// (kernels cannot call Embree), so the host twin walks the same structure.
#pragma once

#include <cstdint>
#include <vector>

#include "core/vec.h"
#include "kernels/shared/ub_bvh.h"

namespace ub {

/// The flat node (kernels/shared/ub_bvh.h): leaf count > 0 at prims[first ..], inner nodes
/// count 0 with the left child next and the right child at `first`.
using BvhNode = ub_bvh_node;
static_assert(sizeof(BvhNode) == 32, "BvhNode layout");

class Bvh {
  public:
    /// Builds over boxes[i], i = 0..n-1, leaves of at most leafSize; visits report i.
    void build(const std::vector<Bounds3>& boxes, uint32_t leafSize = 4);
    bool empty() const { return nodes_.empty(); }
    size_t nodeCount() const { return nodes_.size(); }
    size_t bytes() const { return nodes_.size() * sizeof(BvhNode) + prims_.size() * 4; }
    const std::vector<BvhNode>& nodes() const { return nodes_; }
    const std::vector<uint32_t>& prims() const { return prims_; }

    /// Reorders items (one per box given to build) into leaf order and makes prims() the
    /// identity, so that a walk reads the items of a leaf one after the other; visits then
    /// report positions in the reordered items.
    template <class T>
    void permuteToLeafOrder(std::vector<T>* items);

    /// visit(i) for every primitive whose box contains p.
    template <class Visit>
    void queryPoint(const Vec3& p, Visit&& visit) const;
    /// visit(i) for every primitive whose box meets the segment o + t d, t in [0, len].
    template <class Visit>
    void querySegment(const Vec3& o, const Vec3& d, float len, Visit&& visit) const;

  private:
    /// Depth-first walk: visit(i) for the primitives of every leaf whose path accept()s.
    template <class Accept, class Visit>
    void traverse(Accept&& accept, Visit&& visit) const;
    uint32_t buildNode(const std::vector<Bounds3>& boxes, std::vector<Vec3>& centres,
                       uint32_t begin, uint32_t end);
    uint32_t leafSize_ = 4;

    std::vector<BvhNode> nodes_;
    std::vector<uint32_t> prims_;
};

template <class Accept, class Visit>
void Bvh::traverse(Accept&& accept, Visit&& visit) const {
    if (nodes_.empty()) return;
    uint32_t stack[64];  // median splits: depth <= log2(n) + 1 (bvh.cpp)
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const uint32_t self = stack[--top];
        const BvhNode& n = nodes_[self];
        if (!accept(n)) continue;
        if (n.count > 0) {
            for (uint32_t i = n.first; i < n.first + n.count; ++i) visit(prims_[i]);
        } else {
            stack[top++] = n.first;
            stack[top++] = self + 1;
        }
    }
}

template <class T>
void Bvh::permuteToLeafOrder(std::vector<T>* items) {
    std::vector<T> sorted(items->size());
    for (size_t i = 0; i < prims_.size(); ++i) {
        sorted[i] = (*items)[prims_[i]];
        prims_[i] = uint32_t(i);
    }
    items->swap(sorted);
}

template <class Visit>
void Bvh::queryPoint(const Vec3& p, Visit&& visit) const {
    const ub_float3 q = ub_make_float3(p.x, p.y, p.z);
    traverse([&](const BvhNode& n) { return ub_bvh_contains(n, q) != 0; }, visit);
}

template <class Visit>
void Bvh::querySegment(const Vec3& o, const Vec3& d, float len, Visit&& visit) const {
    const ub_float3 oo = ub_make_float3(o.x, o.y, o.z);
    const ub_float3 invD = ub_make_float3(1.0f / d.x, 1.0f / d.y, 1.0f / d.z);
    traverse([&](const BvhNode& n) { return ub_bvh_meets(n, oo, invD, len) != 0; }, visit);
}

}  // namespace ub
