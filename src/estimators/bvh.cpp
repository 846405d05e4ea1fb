// Bvh build (see bvh.h).
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
    nodes_.reserve(2 * boxes.size() / leafSize_ + 1);
    buildNode(boxes, centres, 0, uint32_t(boxes.size()));
}

uint32_t Bvh::buildNode(const std::vector<Bounds3>& boxes, std::vector<Vec3>& centres,
                        uint32_t begin, uint32_t end) {
    const uint32_t self = uint32_t(nodes_.size());
    nodes_.emplace_back();
    Bounds3 box, cbox;
    for (uint32_t i = begin; i < end; ++i) {
        box.extend(boxes[prims_[i]]);
        cbox.extend(centres[prims_[i]]);
    }
    BvhNode node{};
    for (int a = 0; a < 3; ++a) {
        node.lo[a] = box.lo[a];
        node.hi[a] = box.hi[a];
    }
    const Vec3 ext = cbox.hi - cbox.lo;
    const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    // Depth stays below 64 (the traversal stack): median splits halve the range, and a
    // range whose centres coincide becomes a leaf however large it is.
    if (end - begin <= leafSize_ || !(ext[axis] > 0.0f)) {
        node.first = begin;
        node.count = end - begin;
        nodes_[self] = node;
        return self;
    }
    const uint32_t mid = begin + (end - begin) / 2;
    std::nth_element(prims_.begin() + begin, prims_.begin() + mid, prims_.begin() + end,
                     [&](uint32_t a, uint32_t b) { return centres[a][axis] < centres[b][axis]; });
    buildNode(boxes, centres, begin, mid);
    node.first = buildNode(boxes, centres, mid, end);
    node.count = 0;
    nodes_[self] = node;
    return self;
}

}  // namespace ub
