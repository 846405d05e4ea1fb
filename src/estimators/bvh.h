// Bounding volume hierarchy over axis-aligned boxes: the lookup of the beam
// estimators (UPBP). pb2d stores photon points as boxes of their kernel
// sphere (traversed by query beams); bp2d and bb1d store photon-beam pieces,
// diced along their axis into boxes of the cylinder of radius r (traversed by
// query points and query beams; src/estimators/volume_estimate.h).
//
// Built top-down as a binary tree: a node's primitives are split at the median of their box
// centres along the axis of largest centre extent, down to leaves of at most leafSize
// primitives (O(n log n) with nth_element; the leaf sizes are measured, docs/performance.md).
// Median splits keep the tree balanced whatever the beam distribution; with leaves of a
// multiple of four the left half takes a multiple of four, so leaves hold whole blocks of
// four candidates (ub_beam_keys4, ub_photon_keys4) and start on one in leaf order. The binary tree
// is then collapsed into four-wide nodes (kernels/shared/ub_bvh.h): each node takes its binary
// children and opens the inner one with the largest box surface until it holds four, so one node
// load tests four boxes. A walk here is bound by the latency of its node loads (bb1d on
// mirrorballs: about 300 nodes per query beam for 4.5 pairs), and the wide nodes halve the loads
// and the depth (measured, docs/performance.md).
//
// With groups (the medium of each photon or part), each group is built as a tree of its own
// over its range of the leaf order, and a walk starts at its query's medium's root (roots()
// for the kernels): the estimators' walks never visit another medium's nodes.
//
// Own code rather than Embree's user geometry: the nodes are a flat array of
// fixed-size records, which the OpenCL backend uploads and traverses as they are
// (kernels cannot call Embree), so the host twin walks the same structure.
#pragma once

#include <cstdint>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "core/vec.h"
#include "kernels/shared/ub_bvh.h"

namespace ub {

/// The flat four-wide node (kernels/shared/ub_bvh.h); the root is node 0.
using BvhNode = ub_bvh_node;
static_assert(sizeof(BvhNode) == 128, "BvhNode layout");

/// ub_bvh_meets (kernels/shared/ub_bvh.h) with the four boxes tested at once in SSE: the same
/// operations in the same order, and min/max with the operands ordered so that a NaN selects
/// what the shared selects select (minps/maxps return the second operand on NaN), so the
/// mask is the same bit for bit (tests/bvh_test.cpp). gcc does not vectorise the shared loop,
/// and the scalar version made the host walk 15% slower than the binary tree's.
inline uint32_t bvhMeets4(const BvhNode& n, const ub_float3& o, const ub_float3& invD, float len) {
#if defined(__SSE2__)
    const __m128 ox = _mm_set1_ps(o.x), oy = _mm_set1_ps(o.y), oz = _mm_set1_ps(o.z);
    const __m128 ix = _mm_set1_ps(invD.x), iy = _mm_set1_ps(invD.y), iz = _mm_set1_ps(invD.z);
    __m128 t0 = _mm_setzero_ps(), t1 = _mm_set1_ps(len);
    auto axis = [&](const float* lo, const float* hi, __m128 oa, __m128 ia) {
        const __m128 ta = _mm_mul_ps(_mm_sub_ps(_mm_loadu_ps(lo), oa), ia);
        const __m128 tb = _mm_mul_ps(_mm_sub_ps(_mm_loadu_ps(hi), oa), ia);
        const __m128 nearT = _mm_min_ps(tb, ta);  // ta > tb ? tb : ta
        const __m128 farT = _mm_max_ps(ta, tb);   // ta > tb ? ta : tb
        t0 = _mm_max_ps(nearT, t0);               // near > t0 ? near : t0
        t1 = _mm_min_ps(farT, t1);                // far < t1 ? far : t1
    };
    axis(n.loX, n.hiX, ox, ix);
    axis(n.loY, n.hiY, oy, iy);
    axis(n.loZ, n.hiZ, oz, iz);
    const __m128i none = _mm_set1_epi32(int(UB_BVH_NONE));
    const __m128i exists = _mm_xor_si128(
        _mm_cmpeq_epi32(_mm_loadu_si128((const __m128i*)n.count), none), _mm_set1_epi32(-1));
    const __m128 hit = _mm_and_ps(_mm_cmple_ps(t0, t1), _mm_castsi128_ps(exists));
    return uint32_t(_mm_movemask_ps(hit));
#else
    return ub_bvh_meets(&n, o, invD, len);
#endif
}

/// Bit c set when child c of n is an inner node (count 0).
inline uint32_t bvhInnerChildren(const BvhNode& n) {
    return uint32_t(n.count[0] == 0) | uint32_t(n.count[1] == 0) << 1 |
           uint32_t(n.count[2] == 0) << 2 | uint32_t(n.count[3] == 0) << 3;
}

/// Lets the volumetric estimates build one tree per medium (the default; Bvh::build's groups)
/// or one over all media: the two find the same pairs, which a test checks.
void setMediumTreesForTests(bool allowed);
bool mediumTreesAllowed();

class Bvh {
  public:
    /// Entries of a walk's stack: the walks here and in kernels/beams.cl (UB_BVH_STACK) hold
    /// kStackSize; build checks that the tree needs no more (stackNeed).
    static constexpr int kStackSize = 64;
    /// Node memory a build needs per box, at most: two binary nodes (32 bytes each; leaves
    /// hold at least one box) and one four-wide node.
    static constexpr size_t kNodeBytesPerBox = 2 * 32 + sizeof(BvhNode);
    /// Builds over boxes[i], i = 0..n-1, leaves of at most leafSize; visits report i. The
    /// walks' stack holds stackLimit entries (tests pass less to reach the fallback collapse).
    /// With groups (one id per box, e.g. the medium of a photon or beam part), each group gets
    /// a tree of its own, rooted at root(group), and the boxes are laid out group by group:
    /// a walk for one group then visits none of the other groups' nodes. Every pair test of
    /// the volumetric estimators rejects a photon or part of another medium than its query's,
    /// so walking the query's medium's tree finds the same pairs. Counted on the SmallUPBP
    /// bunny (`upbp:bb1d`): the query beams inside the bunny's medium, two thirds of them,
    /// made 70% of the walk's node visits for the 5.5% of the parts in their medium.
    void build(const std::vector<Bounds3>& boxes, uint32_t leafSize = 4,
               int stackLimit = kStackSize, const std::vector<uint32_t>* groups = nullptr);
    /// The node a walk for `group` starts at: UB_BVH_NONE if the group has no box. Without
    /// groups (and for an ungrouped build, any group) node 0, unless the tree is empty.
    uint32_t root(uint32_t group) const {
        if (!grouped_) return nodes_.empty() ? UB_BVH_NONE : 0u;
        return group < roots_.size() ? roots_[group] : UB_BVH_NONE;
    }
    /// root(g) for g = 0 .. n - 1 (what the kernels read, one entry per medium).
    std::vector<uint32_t> roots(uint32_t n) const {
        std::vector<uint32_t> r(n);
        for (uint32_t g = 0; g < n; ++g) r[g] = root(g);
        return r;
    }
    bool empty() const { return nodes_.empty(); }
    size_t nodeCount() const { return nodes_.size(); }
    size_t bytes() const { return nodes_.size() * sizeof(BvhNode) + prims_.size() * 4; }
    /// The most stack entries a walk of the last build needs, computed over the whole tree.
    int stackNeed() const { return stackNeed_; }
    const std::vector<BvhNode>& nodes() const { return nodes_; }

    /// Reorders items (one per box given to build) into leaf order, so that a walk reads the
    /// items of a leaf one after the other; visits then report positions in the reordered
    /// items, and the index array is emptied: a leaf's entry k is item k, read without the
    /// indirection (the OpenCL kernels require this order, src/cl/cl_runtime.cpp).
    template <class T>
    void permuteToLeafOrder(std::vector<T>* items);
    /// Whether permuteToLeafOrder has run since the last build (it empties the index array,
    /// which build fills with one entry per box).
    bool leafOrdered() const { return prims_.empty(); }

    /// visit(i) for every primitive whose box contains p (of every group, group by group).
    template <class Visit>
    void queryPoint(const Vec3& p, Visit&& visit) const;
    /// The same, for the primitives of one group only.
    template <class Visit>
    void queryPoint(const Vec3& p, uint32_t group, Visit&& visit) const;
    /// visit(i) for every primitive whose box meets the segment o + t d, t in [0, len].
    template <class Visit>
    void querySegment(const Vec3& o, const Vec3& d, float len, Visit&& visit) const;
    /// The walk of one group's tree, leaf by leaf: visitRange(first, end) for the leaf-order
    /// positions first .. end - 1 of each leaf met. Needs leafOrdered().
    template <class VisitRange>
    void querySegmentLeaves(const Vec3& o, const Vec3& d, float len, uint32_t group,
                            VisitRange&& visitRange) const;

  private:
    /// The walk of kernels/shared/ub_bvh.h: visit(i) for the primitives of every leaf whose
    /// path passes; childMask(node) gives the children that pass.
    template <class ChildMask, class Visit>
    void traverse(ChildMask&& childMask, Visit&& visit) const;
    /// The walk itself, of every group's tree: visit(i) with i the leaf-order position.
    template <class ChildMask, class Visit>
    void walk(ChildMask&& childMask, Visit&& visit) const;
    /// The walk of the tree at `root`, leaf by leaf: visitRange(first, end) over leaf-order
    /// positions.
    template <class ChildMask, class VisitRange>
    void walkLeaves(uint32_t root, ChildMask&& childMask, VisitRange&& visitRange) const;
    /// A node of the binary tree built first.
    struct Node2 {
        Bounds3 box;
        uint32_t first = 0;  // leaf: first primitive; inner: the right child (left is next)
        uint32_t count = 0;  // leaf: > 0
    };
    /// A box's centre and index, what the build partitions (contiguous, so that the splits
    /// read no box or centre through an index).
    struct BuildRef {
        Vec3 centre;
        uint32_t index;
    };
    static_assert(sizeof(BuildRef) == 16, "one record a 16-byte slot");
    uint32_t buildNode(const std::vector<Bounds3>& boxes, std::vector<BuildRef>& refs,
                       std::vector<Node2>& tree, uint32_t begin, uint32_t end);
    uint32_t collapse(const std::vector<Node2>& tree, uint32_t self, bool shallowFirst);
    int stackNeed(uint32_t node, int base) const;
    /// Collapses the binary trees at binaryRoots[g] into nodes_ (roots_[g]), and returns the
    /// largest stackNeed of their walks.
    int collapseAll(const std::vector<Node2>& tree, const std::vector<uint32_t>& binaryRoots,
                    bool shallowFirst);
    uint32_t leafSize_ = 4;
    int stackNeed_ = 0;
    bool grouped_ = false;
    std::vector<uint32_t> roots_;  ///< per group: its tree's root node, or UB_BVH_NONE

    std::vector<BvhNode> nodes_;
    std::vector<uint32_t> prims_;  ///< leaf entry -> box index; empty once leaf-ordered
};

template <class ChildMask, class Visit>
void Bvh::traverse(ChildMask&& childMask, Visit&& visit) const {
    // The order is decided once per walk, not per item (two instances of the loop).
    if (leafOrdered())
        walk(childMask, [&](uint32_t i) { visit(i); });
    else
        walk(childMask, [&](uint32_t i) { visit(prims_[i]); });
}

template <class ChildMask, class Visit>
void Bvh::walk(ChildMask&& childMask, Visit&& visit) const {
    auto visitRange = [&](uint32_t first, uint32_t end) {
        for (uint32_t i = first; i < end; ++i) visit(i);
    };
    if (!grouped_) return walkLeaves(root(0), childMask, visitRange);
    for (uint32_t r : roots_) walkLeaves(r, childMask, visitRange);
}

template <class ChildMask, class VisitRange>
void Bvh::walkLeaves(uint32_t root, ChildMask&& childMask, VisitRange&& visitRange) const {
    if (root == UB_BVH_NONE) return;
    uint32_t stack[kStackSize];  // stackNeed() <= kStackSize entries (checked by build)
    int top = 0;
    stack[top++] = root;
    while (top > 0) {
        const BvhNode& n = nodes_[stack[--top]];
        const uint32_t mask = childMask(n);
        if (mask == 0) continue;
        // The children from bit masks (leaves lowest bit first, pushes highest first), as
        // kernels/beams.cl does: fewer mispredicted branches than a loop over the four.
        const uint32_t inner = mask & bvhInnerChildren(n);
        for (uint32_t leaves = mask & ~inner; leaves != 0; leaves &= leaves - 1) {
            const int c = __builtin_ctz(leaves);
            visitRange(n.child[c], n.child[c] + n.count[c]);
        }
        for (uint32_t rest = inner; rest != 0;) {
            const int c = 31 - __builtin_clz(rest);
            rest &= ~(1u << c);
            stack[top++] = n.child[c];
        }
    }
}

template <class T>
void Bvh::permuteToLeafOrder(std::vector<T>* items) {
    std::vector<T> sorted(items->size());
    for (size_t i = 0; i < prims_.size(); ++i) {
        sorted[i] = (*items)[prims_[i]];
    }
    items->swap(sorted);
    prims_.clear();
    prims_.shrink_to_fit();
}

template <class Visit>
void Bvh::queryPoint(const Vec3& p, Visit&& visit) const {
    const ub_float3 q = ub_make_float3(p.x, p.y, p.z);
    traverse([&](const BvhNode& n) { return ub_bvh_contains(&n, q); }, visit);
}

template <class Visit>
void Bvh::queryPoint(const Vec3& p, uint32_t group, Visit&& visit) const {
    const ub_float3 q = ub_make_float3(p.x, p.y, p.z);
    auto mask = [&](const BvhNode& n) { return ub_bvh_contains(&n, q); };
    auto range = [&](uint32_t first, uint32_t end) {
        for (uint32_t i = first; i < end; ++i) visit(leafOrdered() ? i : prims_[i]);
    };
    walkLeaves(root(group), mask, range);
}

template <class Visit>
void Bvh::querySegment(const Vec3& o, const Vec3& d, float len, Visit&& visit) const {
    const ub_float3 oo = ub_make_float3(o.x, o.y, o.z);
    const ub_float3 invD = ub_make_float3(1.0f / d.x, 1.0f / d.y, 1.0f / d.z);
    traverse([&](const BvhNode& n) { return bvhMeets4(n, oo, invD, len); }, visit);
}

template <class VisitRange>
void Bvh::querySegmentLeaves(const Vec3& o, const Vec3& d, float len, uint32_t group,
                             VisitRange&& visitRange) const {
    const ub_float3 oo = ub_make_float3(o.x, o.y, o.z);
    const ub_float3 invD = ub_make_float3(1.0f / d.x, 1.0f / d.y, 1.0f / d.z);
    walkLeaves(
        root(group), [&](const BvhNode& n) { return bvhMeets4(n, oo, invD, len); }, visitRange);
}

/// ub_beam_lines_near4 (kernels/shared/ub_bvh.h) in SSE: the same operations in the same order
/// per lane, so the same mask.
inline uint32_t beamLinesNear4(const ub_beam_keys4& k, const ub_float3& o, const ub_float3& d,
                               float queryLength, float radiusSqr) {
#if defined(__SSE2__)
    const __m128 oBx = _mm_loadu_ps(k.ox), oBy = _mm_loadu_ps(k.oy), oBz = _mm_loadu_ps(k.oz);
    const __m128 dBx = _mm_loadu_ps(k.dx), dBy = _mm_loadu_ps(k.dy), dBz = _mm_loadu_ps(k.dz);
    const __m128 dx = _mm_set1_ps(d.x), dy = _mm_set1_ps(d.y), dz = _mm_set1_ps(d.z);
    const __m128 b =
        _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dBx), _mm_mul_ps(dy, dBy)), _mm_mul_ps(dz, dBz));
    const __m128 sin2 = _mm_sub_ps(_mm_set1_ps(1.0f), _mm_mul_ps(b, b));
    const __m128 wx = _mm_sub_ps(_mm_set1_ps(o.x), oBx), wy = _mm_sub_ps(_mm_set1_ps(o.y), oBy),
                 wz = _mm_sub_ps(_mm_set1_ps(o.z), oBz);
    const __m128 cx = _mm_sub_ps(_mm_mul_ps(dy, dBz), _mm_mul_ps(dz, dBy));
    const __m128 cy = _mm_sub_ps(_mm_mul_ps(dz, dBx), _mm_mul_ps(dx, dBz));
    const __m128 cz = _mm_sub_ps(_mm_mul_ps(dx, dBy), _mm_mul_ps(dy, dBx));
    const __m128 sep =
        _mm_add_ps(_mm_add_ps(_mm_mul_ps(wx, cx), _mm_mul_ps(wy, cy)), _mm_mul_ps(wz, cz));
    const __m128 e =
        _mm_add_ps(_mm_add_ps(_mm_mul_ps(dBx, wx), _mm_mul_ps(dBy, wy)), _mm_mul_ps(dBz, wz));
    const __m128 dw =
        _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, wx), _mm_mul_ps(dy, wy)), _mm_mul_ps(dz, wz));
    const __m128 num = _mm_sub_ps(e, _mm_mul_ps(b, dw));
    // sin2 > 1e-7, not sep^2 > r^2 sin2, not num < t0 sin2 and not num >= t1 sin2 (a NaN passes
    // either range test, as in the shared one).
    const __m128 held = _mm_andnot_ps(_mm_cmplt_ps(num, _mm_mul_ps(_mm_loadu_ps(k.t0), sin2)),
                                      _mm_cmpnge_ps(num, _mm_mul_ps(_mm_loadu_ps(k.t1), sin2)));
    // The query's range: not qNum < -slack and not qNum > length sin2 1.0001 + slack.
    const __m128 be = _mm_mul_ps(b, e), absMask = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
    const __m128 qNum = _mm_sub_ps(be, dw);
    const __m128 slack = _mm_mul_ps(_mm_set1_ps(1e-5f),
                                    _mm_add_ps(_mm_and_ps(be, absMask), _mm_and_ps(dw, absMask)));
    const __m128 qHi = _mm_add_ps(
        _mm_mul_ps(_mm_mul_ps(_mm_set1_ps(queryLength), sin2), _mm_set1_ps(1.0001f)), slack);
    const __m128 onQuery = _mm_andnot_ps(_mm_cmplt_ps(qNum, _mm_sub_ps(_mm_setzero_ps(), slack)),
                                         _mm_cmpngt_ps(qNum, qHi));
    const __m128 near = _mm_and_ps(
        _mm_and_ps(_mm_cmpgt_ps(sin2, _mm_set1_ps(1e-7f)),
                   _mm_cmpngt_ps(_mm_mul_ps(sep, sep), _mm_mul_ps(_mm_set1_ps(radiusSqr), sin2))),
        _mm_and_ps(held, onQuery));
    return uint32_t(_mm_movemask_ps(near));
#else
    return ub_beam_lines_near4(&k, o, d, queryLength, radiusSqr);
#endif
}

}  // namespace ub
