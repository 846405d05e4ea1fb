// Bvh build (see bvh.h): a binary tree of median splits, collapsed into four-wide nodes.
#include "estimators/bvh.h"

#include <algorithm>

namespace ub {

void Bvh::build(const std::vector<Bounds3>& boxes, uint32_t leafSize) {
    leafSize_ = std::max(1u, leafSize);
    nodes_.clear();
    prims_.resize(boxes.size());
    if (boxes.empty()) return;
    std::vector<Vec3> centres(boxes.size());
    for (uint32_t i = 0; i < boxes.size(); ++i) {
        prims_[i] = i;
        centres[i] = boxes[i].center();
    }
    std::vector<Node2> tree;
    tree.reserve(2 * boxes.size() / leafSize_ + 1);
    buildNode(boxes, centres, tree, 0, uint32_t(boxes.size()));
    nodes_.reserve(tree.size() / 3 + 1);
    collapse(tree, 0);
}

uint32_t Bvh::buildNode(const std::vector<Bounds3>& boxes, std::vector<Vec3>& centres,
                        std::vector<Node2>& tree, uint32_t begin, uint32_t end) {
    const uint32_t self = uint32_t(tree.size());
    tree.emplace_back();
    Node2 node;
    Bounds3 cbox;
    for (uint32_t i = begin; i < end; ++i) {
        node.box.extend(boxes[prims_[i]]);
        cbox.extend(centres[prims_[i]]);
    }
    const Vec3 ext = cbox.hi - cbox.lo;
    const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    // Depth stays below 34 for n < 2^32: median splits halve the range, and a range whose
    // centres coincide becomes a leaf however large it is.
    if (end - begin <= leafSize_ || !(ext[axis] > 0.0f)) {
        node.first = begin;
        node.count = end - begin;
        tree[self] = node;
        return self;
    }
    const uint32_t mid = begin + (end - begin) / 2;
    std::nth_element(prims_.begin() + begin, prims_.begin() + mid, prims_.begin() + end,
                     [&](uint32_t a, uint32_t b) { return centres[a][axis] < centres[b][axis]; });
    buildNode(boxes, centres, tree, begin, mid);
    node.first = buildNode(boxes, centres, tree, mid, end);
    node.count = 0;
    tree[self] = node;
    return self;
}

uint32_t Bvh::collapse(const std::vector<Node2>& tree, uint32_t self) {
    // The children: a binary inner node's two, then the inner child with the largest box
    // surface opened until there are four (a leaf root is the only child of the root).
    uint32_t kids[4] = {self, 0, 0, 0};
    int n = 1;
    while (n < 4) {
        int open = -1;
        float best = -1.0f;
        for (int k = 0; k < n; ++k) {
            const Node2& t = tree[kids[k]];
            const Vec3 e = t.box.hi - t.box.lo;
            const float area = e.x * e.y + e.y * e.z + e.z * e.x;
            if (t.count == 0 && area > best) {
                best = area;
                open = k;
            }
        }
        if (open < 0) break;
        const uint32_t parent = kids[open];
        for (int k = n; k > open + 1; --k) kids[k] = kids[k - 1];  // keep the tree's order
        kids[open] = parent + 1;
        kids[open + 1] = tree[parent].first;
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
        node.child[c] = t.count > 0 ? t.first : collapse(tree, kids[c]);
    }
    nodes_[index] = node;
    return index;
}

}  // namespace ub
