// Hashed grid build: counting sort of point indices by bucket (see hash_grid.h).
#include "estimators/hash_grid.h"

#include <cmath>

namespace ub {

void HashGrid::build(const Vec3* positions, size_t count, size_t stride, float radius,
                     size_t cellCount) {
    radius_ = radius;
    if (cellCount == 0) cellCount = count > 0 ? count : 1;
    cellEnds_.assign(cellCount, 0);
    indices_.resize(count);
    Vec3 lo(kInf);
    for (size_t i = 0; i < count; ++i) lo = vmin(lo, at(positions, stride, i));
    params_ = ub_hash_grid{};
    for (int a = 0; a < 3; ++a) params_.lo[a] = lo[a];
    params_.invCellSize = 1.0f / (2.0f * radius);
    params_.radiusSqr = radius * radius;
    params_.cellCount = uint32_t(cellCount);
    if (count == 0) return;

    auto bucketOf = [&](const Vec3& p) {
        return ub_hash_point(params_, ub_make_float3(p.x, p.y, p.z));
    };
    // Histogram, exclusive prefix sum, scatter (stable: indices stay ascending per bucket).
    for (size_t i = 0; i < count; ++i) ++cellEnds_[bucketOf(at(positions, stride, i))];
    uint32_t sum = 0;
    for (auto& e : cellEnds_) {
        uint32_t n = e;
        e = sum;
        sum += n;
    }
    for (size_t i = 0; i < count; ++i) {
        uint32_t b = bucketOf(at(positions, stride, i));
        indices_[cellEnds_[b]++] = uint32_t(i);
    }
    // cellEnds_[b] now holds the end of bucket b.
}

}  // namespace ub
