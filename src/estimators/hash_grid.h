// Hashed uniform grid for fixed-radius range queries over points (surface
// photons / light vertices for vertex merging). After Teschner et al. 2003,
// "Optimized Spatial Hashing for Collision Detection of Deformable Objects",
// as used by SmallVCM and Georgiev et al. 2012 for VCM.
//
// Cells have edge 2r, so the ball of radius r around a query point overlaps at
// most the 2x2x2 block of cells nearest to it (cell hashing and bucket choice are
// kernels/shared/ub_hash_grid.h, shared with the OpenCL kernels). Cells are hashed into `cellCount`
// buckets; a counting sort lays the point indices out bucket by bucket. Unlike a
// plain hashed lookup, a query visits each distinct bucket of its 8 cells only
// once (two cells may hash to the same bucket), so every point within r is
// reported exactly once. Build is O(N), a query is O(points in 8 buckets).
// The grid stores indices only; positions stay with the caller.
#pragma once

#include <cstdint>
#include <vector>

#include "core/vec.h"
#include "kernels/shared/ub_hash_grid.h"

namespace ub {

class HashGrid {
  public:
    /// Builds the grid over positions[0..count) (the pointer is read during build only;
    /// `stride` is the distance in bytes between consecutive positions, so callers can
    /// pass a member of an array of structs). cellCount 0 picks max(count, 1); either is
    /// rounded up to a power of two.
    void build(const Vec3* positions, size_t count, size_t stride, float radius,
               size_t cellCount = 0);
    template <class T>
    void build(const std::vector<T>& items, const Vec3 T::*member, float radius) {
        const Vec3* first = items.empty() ? nullptr : &(items[0].*member);
        build(first, items.size(), sizeof(T), radius);
    }
    /// The same for records of kernels/shared, whose positions are float[3] fields.
    template <class T, class B>
    void build(const std::vector<T>& items, float (B::*member)[3], float radius) {
        const Vec3* first =
            items.empty() ? nullptr : reinterpret_cast<const Vec3*>(&(items[0].*member)[0]);
        build(first, items.size(), sizeof(T), radius);
    }

    /// Calls visit(index) for every point i with |positions[i] - q| <= radius, each once.
    /// `positions` must be the data the grid was built from (the test reads the grid's copy
    /// of them, keys()).
    template <class Visit>
    void query(const Vec3& q, const Vec3* positions, size_t stride, Visit&& visit) const;
    template <class T, class Visit>
    void query(const Vec3& q, const std::vector<T>& items, const Vec3 T::*member,
               Visit&& visit) const {
        if (items.empty()) return;
        query(q, &(items[0].*member), sizeof(T), visit);
    }
    template <class T, class B, class Visit>
    void query(const Vec3& q, const std::vector<T>& items, float (B::*member)[3],
               Visit&& visit) const {
        if (items.empty()) return;
        query(q, reinterpret_cast<const Vec3*>(&(items[0].*member)[0]), sizeof(T), visit);
    }

    /// Queries in blocks, in the phases the kernels run a work-group in (kernels/surf.cl):
    /// blockRanges finds the buckets of every query of the block, then reads every bucket's
    /// bounds, so that the bounds' cache misses of a block overlap where one query at a time
    /// waited on its own; candidates(r, k, visit) then visits query k's points within the
    /// radius (visit(index), each once, in the order query() visits them).
    static constexpr size_t kBlock = 64;
    struct BlockRanges {
        ub_float3 q[kBlock];
        int count[kBlock];
        uint32_t begins[kBlock][8], ends[kBlock][8];
    };
    /// Queries k = 0 .. n - 1 (n <= kBlock) at posOf(k).
    template <class PosOf>
    void blockRanges(size_t n, PosOf&& posOf, BlockRanges* r) const;
    template <class Visit>
    void candidates(const BlockRanges& r, size_t k, Visit&& visit) const;

    float radius() const { return radius_; }
    size_t cellCount() const { return cellEnds_.size(); }
    /// The flat data the OpenCL kernels read (kernels/shared/ub_hash_grid.h).
    const ub_hash_grid& params() const { return params_; }
    const std::vector<uint32_t>& cellEnds() const { return cellEnds_; }
    const std::vector<uint32_t>& indices() const { return indices_; }
    /// 4 floats per entry of indices(): the point's position and 0, in bucket order.
    const std::vector<float>& keys() const { return keys_; }

  private:
    static const Vec3& at(const Vec3* base, size_t stride, size_t i) {
        return *reinterpret_cast<const Vec3*>(reinterpret_cast<const char*>(base) + i * stride);
    }

    /// The points within the radius of q among the buckets' index ranges [begins[j], ends[j]),
    /// j < n (query() and candidates()).
    template <class Visit>
    void visitRanges(const uint32_t* begins, const uint32_t* ends, int n, ub_float3 q,
                     Visit&& visit) const;

    ub_hash_grid params_{};
    float radius_ = 0;
    std::vector<uint32_t> indices_;   ///< point indices sorted by bucket
    std::vector<uint32_t> cellEnds_;  ///< end offset in indices_ of each bucket
    /// The positions in bucket order, which queries test: a bucket's candidates are read one
    /// after the other, and a record (112-128 bytes) only for a point within the radius. Read
    /// through indices_, the first load of each candidate's record was a cache miss: 66% of
    /// the surf kernel's time on one load (perf, cornell-fog).
    std::vector<float> keys_;
};

template <class Visit>
void HashGrid::query(const Vec3& q, const Vec3* positions, size_t stride, Visit&& visit) const {
    if (indices_.empty()) return;
    uint32_t begins[8], ends[8];
    const ub_float3 qf = ub_make_float3(q.x, q.y, q.z);
    visitRanges(begins, ends, ub_hash_ranges(params_, qf, cellEnds_.data(), begins, ends), qf,
                visit);
}

template <class Visit>
void HashGrid::visitRanges(const uint32_t* begins, const uint32_t* ends, int n, ub_float3 q,
                           Visit&& visit) const {
    for (int j = 0; j < n; ++j)
        for (uint32_t i = begins[j]; i < ends[j]; ++i) {
            const float* p = &keys_[4 * size_t(i)];
            if (ub_hash_within(params_, ub_make_float3(p[0], p[1], p[2]), q)) visit(indices_[i]);
        }
}

template <class PosOf>
void HashGrid::blockRanges(size_t n, PosOf&& posOf, BlockRanges* r) const {
    uint32_t buckets[kBlock][8];
    int nb[kBlock];
    for (size_t k = 0; k < n; ++k) {
        const Vec3 q = posOf(k);
        r->q[k] = ub_make_float3(q.x, q.y, q.z);
        nb[k] = indices_.empty() ? 0 : ub_hash_buckets(params_, r->q[k], buckets[k]);
    }
    for (size_t k = 0; k < n; ++k)
        r->count[k] =
            ub_hash_bucket_ranges(buckets[k], nb[k], cellEnds_.data(), r->begins[k], r->ends[k]);
}

template <class Visit>
void HashGrid::candidates(const BlockRanges& r, size_t k, Visit&& visit) const {
    visitRanges(r.begins[k], r.ends[k], r.count[k], r.q[k], visit);
}

}  // namespace ub
