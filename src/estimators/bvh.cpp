// Bvh build (see bvh.h): a binary tree of median splits, collapsed into four-wide nodes.
#include "estimators/bvh.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <atomic>
#include <limits>
#include <stdexcept>
#include <string>

namespace ub {

namespace {
std::atomic<bool> treesPerMedium{true};
}  // namespace

void setMediumTreesForTests(bool allowed) {
    treesPerMedium = allowed;
}
bool mediumTreesAllowed() {
    return treesPerMedium;
}

void Bvh::build(const std::vector<Bounds3>& boxes, uint32_t leafSize, int stackLimit,
                const std::vector<uint32_t>* groups) {
    leafSize_ = std::max(1u, leafSize);
    nodes_.clear();
    roots_.clear();
    grouped_ = groups != nullptr;
    prims_.resize(boxes.size());
    if (groups && groups->size() != boxes.size())
        throw std::logic_error("Bvh::build: one group per box expected");
    if (boxes.empty()) return;
    // The boxes group by group (a stable counting sort, so that the layout depends on the
    // input alone), each group's range [starts[g], starts[g + 1]).
    std::vector<uint32_t> starts(1, 0);
    if (groups) {
        const uint32_t highest = *std::max_element(groups->begin(), groups->end());
        if (highest >= (1u << 20))
            throw std::logic_error("Bvh::build: group " + std::to_string(highest) +
                                   " out of range (media ids expected)");
        const uint32_t count = highest + 1;
        starts.assign(count + 1, 0);
        for (uint32_t g : *groups) ++starts[g + 1];
        for (uint32_t g = 0; g < count; ++g) starts[g + 1] += starts[g];
        std::vector<uint32_t> next(starts.begin(), starts.end() - 1);
        for (uint32_t i = 0; i < boxes.size(); ++i) prims_[next[(*groups)[i]]++] = i;
    } else {
        starts.push_back(uint32_t(boxes.size()));
        for (uint32_t i = 0; i < boxes.size(); ++i) prims_[i] = i;
    }
    // The build partitions (centre, index) records in place; prims_ takes their order.
    std::vector<BuildRef> refs(boxes.size());
    tbb::parallel_for(size_t(0), boxes.size(), [&](size_t i) {
        refs[i] = BuildRef{boxes[prims_[i]].center(), prims_[i]};
    });
    std::vector<Node2> tree;
    tree.reserve(2 * boxes.size() / leafSize_ + starts.size());
    std::vector<uint32_t> binaryRoots(starts.size() - 1, UB_BVH_NONE);
    for (size_t g = 0; g + 1 < starts.size(); ++g)
        if (starts[g] < starts[g + 1])
            binaryRoots[g] = buildNode(boxes, refs, tree, starts[g], starts[g + 1]);
    for (size_t i = 0; i < refs.size(); ++i) prims_[i] = refs[i].index;
    nodes_.reserve(tree.size() / 3 + starts.size());
    stackNeed_ = collapseAll(tree, binaryRoots, false);
    if (stackNeed_ > std::min(stackLimit, kStackSize)) {
        // Opening the largest box first can leave a child one binary level down on a path of
        // small boxes; opening the shallowest first consumes two binary levels per four-wide
        // level (a leaf needs no entry), so with median splits (binary depth <= 33) the walk
        // holds at most 3 * 17 + 1 = 52 entries.
        stackNeed_ = collapseAll(tree, binaryRoots, true);
        if (stackNeed_ > std::min(stackLimit, kStackSize))
            throw std::logic_error("Bvh::build: a walk would need " + std::to_string(stackNeed_) +
                                   " stack entries, more than " + std::to_string(stackLimit));
    }
}

int Bvh::collapseAll(const std::vector<Node2>& tree, const std::vector<uint32_t>& binaryRoots,
                     bool shallowFirst) {
    nodes_.clear();
    roots_.assign(binaryRoots.size(), UB_BVH_NONE);
    int need = 0;
    for (size_t g = 0; g < binaryRoots.size(); ++g) {
        if (binaryRoots[g] == UB_BVH_NONE) continue;
        roots_[g] = collapse(tree, binaryRoots[g], shallowFirst);
        need = std::max(need, stackNeed(roots_[g], 0));
    }
    return need;
}

int Bvh::stackNeed(uint32_t node, int base) const {
    // The walk (walk() here, UB_BVH_WALK_* in kernels/beams.cl) pops this node with `base`
    // entries left, pushes its k inner children (child 0 on top), and pops the i-th of them
    // with k - 1 - i of its siblings still below it. The largest stack along any path.
    const BvhNode& n = nodes_[node];
    int k = 0;
    for (int c = 0; c < 4; ++c) k += n.count[c] == 0 ? 1 : 0;
    int need = base + k, i = 0;
    for (int c = 0; c < 4; ++c)
        if (n.count[c] == 0) need = std::max(need, stackNeed(n.child[c], base + k - 1 - i++));
    return std::max(need, 1);
}

namespace {

/// Ranges at least this large build their two halves in parallel (each into a vector of its
/// own, appended after the node in the order the sequential recursion would have made them,
/// so the tree is the same for any thread count). Measured on 2 cores: cornell-fog's
/// lookups per iteration (mostly this build) 0.071-0.078 -> 0.051 s for bp2d, 0.097-0.102 ->
/// 0.058 s for upbp (docs/performance.md, session 27).
constexpr uint32_t kParallelBuild = 8192;

}  // namespace

uint32_t Bvh::buildNode(const std::vector<Bounds3>& boxes, std::vector<BuildRef>& refs,
                        std::vector<Node2>& tree, uint32_t begin, uint32_t end) {
    const uint32_t self = uint32_t(tree.size());
    tree.emplace_back();
    Node2 node;
    // The split axis: the longest of the centres' box, read from the contiguous records. The
    // node's box is its children's union (computed after them), a leaf's its boxes' union.
    Bounds3 cbox;
    for (uint32_t i = begin; i < end; ++i) cbox.extend(refs[i].centre);
    const Vec3 ext = cbox.hi - cbox.lo;
    const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    // Depth stays below 34 for n < 2^32: median splits halve the range, and a range whose
    // centres coincide becomes a leaf however large it is.
    if (end - begin <= leafSize_ || !(ext[axis] > 0.0f)) {
        for (uint32_t i = begin; i < end; ++i) node.box.extend(boxes[refs[i].index]);
        node.first = begin;
        node.count = end - begin;
        tree[self] = node;
        return self;
    }
    // With leaves of a multiple of four, the left half takes a multiple of four too, so that
    // every leaf but the last holds whole blocks of four and starts at a multiple of four in
    // leaf order: the walks read a leaf's candidates four to a block (ub_beam_keys4,
    // ub_photon_keys4), and a leaf of 9.6 parts on average straddled 3.15 blocks (counted,
    // mirrorballs bb1d; 2.45 since).
    // The rounding is of the absolute position, so that a group's tree starting off a
    // multiple of four (Bvh::build's groups) has one straddling leaf at most; without groups
    // every range starts on a multiple of four and it is the same as rounding the half.
    uint32_t mid = begin + (end - begin) / 2;
    if (leafSize_ % 4 == 0 && ((mid + 3) & ~3u) < end) mid = (mid + 3) & ~3u;
    std::nth_element(
        refs.begin() + begin, refs.begin() + mid, refs.begin() + end,
        [axis](const BuildRef& a, const BuildRef& b) { return a.centre[axis] < b.centre[axis]; });
    if (end - begin >= kParallelBuild) {
        // The halves own disjoint ranges of refs. Appending a half moves its inner nodes'
        // right-child indices by its new first index (leaves index primitives, which stay).
        auto appendSubtree = [&tree](const std::vector<Node2>& sub) {
            const uint32_t base = uint32_t(tree.size());
            for (Node2 n : sub) {
                if (n.count == 0) n.first += base;
                tree.push_back(n);
            }
        };
        std::vector<Node2> left, right;
        tbb::parallel_invoke([&] { buildNode(boxes, refs, left, begin, mid); },
                             [&] { buildNode(boxes, refs, right, mid, end); });
        node.box = left[0].box;
        node.box.extend(right[0].box);
        appendSubtree(left);
        node.first = uint32_t(tree.size());
        appendSubtree(right);
    } else {
        const uint32_t l = buildNode(boxes, refs, tree, begin, mid);
        node.first = buildNode(boxes, refs, tree, mid, end);
        node.box = tree[l].box;
        node.box.extend(tree[node.first].box);
    }
    node.count = 0;
    tree[self] = node;
    return self;
}

uint32_t Bvh::collapse(const std::vector<Node2>& tree, uint32_t self, bool shallowFirst) {
    // The children: a binary inner node's two, then the inner child with the largest box
    // surface (shallowFirst: the one opened fewest times) opened until there are four (a
    // leaf root is the only child of the root).
    uint32_t kids[4] = {self, 0, 0, 0};
    int level[4] = {0, 0, 0, 0};
    int n = 1;
    while (n < 4) {
        int open = -1;
        float best = -std::numeric_limits<float>::max();
        for (int k = 0; k < n; ++k) {
            const Node2& t = tree[kids[k]];
            const Vec3 e = t.box.hi - t.box.lo;
            const float area = e.x * e.y + e.y * e.z + e.z * e.x;
            const float score = shallowFirst ? -float(level[k]) : area;
            if (t.count == 0 && score > best) {
                best = score;
                open = k;
            }
        }
        if (open < 0) break;
        const uint32_t parent = kids[open];
        for (int k = n; k > open + 1; --k) {  // keep the tree's order
            kids[k] = kids[k - 1];
            level[k] = level[k - 1];
        }
        kids[open] = parent + 1;
        kids[open + 1] = tree[parent].first;
        level[open] = level[open + 1] = level[open] + 1;
        ++n;
    }
    const uint32_t index = uint32_t(nodes_.size());
    nodes_.emplace_back();
    BvhNode node{};
    for (int c = 0; c < 4; ++c) {
        if (c >= n) {
            node.count[c] = UB_BVH_NONE;
            continue;
        }
        const Node2& t = tree[kids[c]];
        node.loX[c] = t.box.lo.x;
        node.loY[c] = t.box.lo.y;
        node.loZ[c] = t.box.lo.z;
        node.hiX[c] = t.box.hi.x;
        node.hiY[c] = t.box.hi.y;
        node.hiZ[c] = t.box.hi.z;
        node.count[c] = t.count;
        node.child[c] = t.count > 0 ? t.first : collapse(tree, kids[c], shallowFirst);
    }
    nodes_[index] = node;
    return index;
}

}  // namespace ub
