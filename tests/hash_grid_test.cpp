// HashGrid range queries against brute force: every point within the radius is
// reported exactly once and nothing farther away, for clustered and spread
// points, small and large radii (many cells share buckets), and an empty grid.
#include "estimators/hash_grid.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>

#include "core/rng.h"

using namespace ub;

namespace {

struct Photon {
    float pad;  // the position is not the first member: exercises the stride path
    Vec3 pos;
};

void checkAgainstBruteForce(const std::vector<Photon>& pts, float radius, size_t cellCount,
                            uint64_t seed) {
    HashGrid grid;
    grid.build(&pts[0].pos, pts.size(), sizeof(Photon), radius, cellCount);
    Rng rng(seed, 1);
    for (int q = 0; q < 300; ++q) {
        // Half the queries sit on a point, the others anywhere in a slightly larger box.
        Vec3 x = (q % 2 == 0) ? pts[rng.nextU32() % pts.size()].pos
                              : Vec3(rng.uniform() * 1.2f - 0.1f, rng.uniform() * 1.2f - 0.1f,
                                     rng.uniform() * 1.2f - 0.1f);
        std::vector<uint32_t> found, expected;
        grid.query(x, &pts[0].pos, sizeof(Photon), [&](uint32_t i) { found.push_back(i); });
        for (uint32_t i = 0; i < pts.size(); ++i)
            if (lengthSqr(pts[i].pos - x) <= radius * radius) expected.push_back(i);
        std::sort(found.begin(), found.end());
        ASSERT_EQ(found, expected) << "radius " << radius << " cells " << cellCount;
    }
}

}  // namespace

TEST(HashGrid, RangeQueryEqualsBruteForce) {
    Rng rng(5, 5);
    std::vector<Photon> pts(3000);
    for (auto& p : pts) p.pos = Vec3(rng.uniform(), rng.uniform(), rng.uniform());
    // Clustered points on a plane (photons on a floor) with duplicates.
    for (int i = 0; i < 500; ++i) pts[i].pos = Vec3(0.3f + 0.01f * rng.uniform(), 0.5f, 0.2f);
    for (float r : {0.003f, 0.02f, 0.1f, 0.6f})
        for (size_t cells : {size_t(0), size_t(1), size_t(7), size_t(100000)})
            checkAgainstBruteForce(pts, r, cells, 11);
}

// The block queries of the estimate passes (HashGrid::blockRanges and candidates, as the surf
// and pp3d kernels run a work-group) visit each query's points in the order query() does, for
// a full block and a short last one; bucket counts are rounded up to powers of two (the bucket
// is a mask, ub_hash_cell).
TEST(HashGrid, BlockQueriesVisitWhatQueryVisitsInItsOrder) {
    Rng rng(9, 2);
    std::vector<Photon> pts(4000);
    for (auto& p : pts) p.pos = Vec3(rng.uniform(), rng.uniform(), rng.uniform());
    for (size_t cells : {size_t(0), size_t(7), size_t(1000)}) {
        HashGrid grid;
        grid.build(&pts[0].pos, pts.size(), sizeof(Photon), 0.05f, cells);
        const size_t c = grid.cellCount();
        EXPECT_EQ(c & (c - 1), 0u) << c << " buckets";
        EXPECT_GE(c, cells == 0 ? pts.size() : cells);
        std::vector<Vec3> queries(HashGrid::kBlock + 17);
        for (size_t i = 0; i < queries.size(); ++i)
            queries[i] = i % 3 == 0 ? pts[rng.nextU32() % pts.size()].pos
                                    : Vec3(rng.uniform(), rng.uniform(), rng.uniform());
        size_t visited = 0;
        for (size_t begin = 0; begin < queries.size(); begin += HashGrid::kBlock) {
            const size_t end = std::min(queries.size(), begin + HashGrid::kBlock);
            HashGrid::BlockRanges ranges;
            grid.blockRanges(
                end - begin, [&](size_t k) { return queries[begin + k]; }, &ranges);
            for (size_t i = begin; i < end; ++i) {
                std::vector<uint32_t> inBlock, alone;
                grid.candidates(ranges, i - begin, [&](uint32_t j) { inBlock.push_back(j); });
                grid.query(queries[i], &pts[0].pos, sizeof(Photon),
                           [&](uint32_t j) { alone.push_back(j); });
                ASSERT_EQ(inBlock, alone) << "query " << i << ", " << c << " buckets";
                visited += alone.size();
            }
        }
        EXPECT_GT(visited, queries.size() / 3);  // the queries on points find at least those
    }
}

TEST(HashGrid, EmptyGridFindsNothing) {
    HashGrid grid;
    std::vector<Photon> none;
    grid.build(nullptr, 0, sizeof(Photon), 0.1f);
    int n = 0;
    grid.query(Vec3(0, 0, 0), nullptr, sizeof(Photon), [&](uint32_t) { ++n; });
    EXPECT_EQ(n, 0);
}

TEST(HashGrid, VectorOfStructsOverload) {
    std::vector<Photon> pts(3);
    pts[0].pos = Vec3(0, 0, 0);
    pts[1].pos = Vec3(0.05f, 0, 0);
    pts[2].pos = Vec3(1, 1, 1);
    HashGrid grid;
    grid.build(pts, &Photon::pos, 0.1f);
    std::vector<uint32_t> found;
    grid.query(Vec3(0.01f, 0, 0), pts, &Photon::pos, [&](uint32_t i) { found.push_back(i); });
    std::sort(found.begin(), found.end());
    EXPECT_EQ(found, (std::vector<uint32_t>{0, 1}));
}

// The build hashes in parallel above 16,384 points (estimators/hash_grid.cpp): the grid is
// the one a single thread builds, entry for entry, its keys are the points' positions in
// bucket order, and its queries still equal brute force.
TEST(HashGrid, ParallelBuildEqualsTheBuildOnOneThread) {
    std::vector<Photon> pts(50000);
    Rng rng(91, 2);
    for (Photon& p : pts) p.pos = Vec3(rng.uniform(), rng.uniform(), rng.uniform());
    HashGrid many, one;
    many.build(&pts[0].pos, pts.size(), sizeof(Photon), 0.01f);
    tbb::task_arena single(1);
    single.execute([&] { one.build(&pts[0].pos, pts.size(), sizeof(Photon), 0.01f); });
    EXPECT_EQ(many.cellEnds(), one.cellEnds());
    EXPECT_EQ(many.indices(), one.indices());
    EXPECT_EQ(many.keys(), one.keys());
    ASSERT_EQ(many.keys().size(), 4 * pts.size());
    for (size_t i = 0; i < pts.size(); ++i) {
        const Vec3& p = pts[many.indices()[i]].pos;
        ASSERT_EQ(many.keys()[4 * i], p.x) << i;
        ASSERT_EQ(many.keys()[4 * i + 1], p.y) << i;
        ASSERT_EQ(many.keys()[4 * i + 2], p.z) << i;
    }
    for (int a = 0; a < 3; ++a) EXPECT_EQ(many.params().lo[a], one.params().lo[a]);
    checkAgainstBruteForce(pts, 0.01f, 0, 17);
}
