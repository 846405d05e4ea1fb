// Hashed grid build: counting sort of point indices by bucket (see hash_grid.h).
#include "estimators/hash_grid.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <cmath>

namespace ub {

void HashGrid::build(const Vec3* positions, size_t count, size_t stride, float radius,
                     size_t cellCount) {
    radius_ = radius;
    if (cellCount == 0) cellCount = count > 0 ? count : 1;
    // A power of two, so that a cell's bucket is a mask rather than an integer division
    // (ub_hash_cell): a query hashes eight cells, and the divisions were 3-6% of the surf and
    // pp3d passes (perf, cornell-fog; docs/performance.md).
    size_t buckets = 1;
    while (buckets < cellCount) buckets <<= 1;
    cellCount = buckets;
    cellEnds_.assign(cellCount, 0);
    indices_.resize(count);
    // The bounding corner and each point's bucket in parallel (min is exact in any order);
    // then the counting sort below over the stored buckets, serially, so the order of the
    // indices is the same for any thread count. Serial, the two hashing passes were 4-5 ms of
    // the candle's upbp iteration (130 k surface photons).
    auto lower = [&](size_t begin, size_t end, Vec3 lo) {
        for (size_t i = begin; i < end; ++i) lo = vmin(lo, at(positions, stride, i));
        return lo;
    };
    constexpr size_t kGrain = 16384;
    const Vec3 lo = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, count, kGrain), Vec3(kInf),
        [&](const tbb::blocked_range<size_t>& r, Vec3 m) { return lower(r.begin(), r.end(), m); },
        [](const Vec3& a, const Vec3& b) { return vmin(a, b); });
    params_ = ub_hash_grid{};
    for (int a = 0; a < 3; ++a) params_.lo[a] = lo[a];
    params_.invCellSize = 1.0f / (2.0f * radius);
    params_.radiusSqr = radius * radius;
    params_.cellCount = uint32_t(cellCount);
    if (count == 0) return;

    std::vector<uint32_t> bucket(count);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, count, kGrain),
                      [&](const tbb::blocked_range<size_t>& r) {
                          for (size_t i = r.begin(); i < r.end(); ++i) {
                              const Vec3& p = at(positions, stride, i);
                              bucket[i] = ub_hash_point(params_, ub_make_float3(p.x, p.y, p.z));
                          }
                      });
    // Histogram, exclusive prefix sum, scatter (stable: indices stay ascending per bucket).
    for (size_t i = 0; i < count; ++i) ++cellEnds_[bucket[i]];
    uint32_t sum = 0;
    for (auto& e : cellEnds_) {
        uint32_t n = e;
        e = sum;
        sum += n;
    }
    for (size_t i = 0; i < count; ++i) indices_[cellEnds_[bucket[i]]++] = uint32_t(i);
    // cellEnds_[b] now holds the end of bucket b. The positions in that order.
    keys_.resize(4 * count);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, count, kGrain),
                      [&](const tbb::blocked_range<size_t>& r) {
                          for (size_t i = r.begin(); i < r.end(); ++i) {
                              const Vec3& p = at(positions, stride, indices_[i]);
                              keys_[4 * i] = p.x;
                              keys_[4 * i + 1] = p.y;
                              keys_[4 * i + 2] = p.z;
                              keys_[4 * i + 3] = 0.0f;
                          }
                      });
}

}  // namespace ub
