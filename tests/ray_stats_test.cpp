// The Embree query counters (scene/ray_stats.h) that bench_upbp --ray-stats prints: each kind
// of query counted exactly, nothing counted while off, and the counts summed over threads.
#include "scene/ray_stats.h"

#include <gtest/gtest.h>

#include <thread>
#include <vector>

#include "scene/scene.h"

using namespace ub;

namespace {

/// A unit square at z = 0, facing +z, in a committed scene.
struct SquareScene {
    Scene scene;
    SquareScene() {
        TriangleMesh m;
        m.positions = {Vec3(-1, -1, 0), Vec3(1, -1, 0), Vec3(1, 1, 0), Vec3(-1, 1, 0)};
        m.indices = {0, 1, 2, 0, 2, 3};
        scene.addMesh(m, -1, -1, "square");
        scene.commit();
    }
};

Ray downFrom(float x, float y) {
    Ray r;
    r.org = Vec3(x, y, 1.0f);
    r.dir = Vec3(0, 0, -1);
    return r;
}

/// Counting stays global: every test leaves it off.
struct RayStatsTest : ::testing::Test {
    void TearDown() override { raystats::enable(false); }
};

TEST_F(RayStatsTest, CountsEachKindOfQuery) {
    SquareScene s;
    raystats::enable(true);
    Hit h;
    int hits = 0;
    for (int i = 0; i < 10; ++i) hits += s.scene.intersect(downFrom(0.1f * float(i), 0.0f), &h);
    EXPECT_EQ(hits, 10);  // x up to 0.9: all on the square
    for (int i = 0; i < 4; ++i) s.scene.anyHitWithin(Vec3(0, 0, 1), Vec3(0, 0, -1), 2.0f);
    EXPECT_TRUE(s.scene.occluded(Vec3(0, 0, 1), Vec3(0), Vec3(0, 0, -1), Vec3(0)));
    const raystats::Totals t = raystats::totals();
    EXPECT_EQ(t.calls[raystats::kNearest], 10u);
    EXPECT_EQ(t.calls[raystats::kAnyHit], 5u);
    EXPECT_EQ(t.calls[raystats::kCrossings], 0u);
    EXPECT_EQ(t.allCalls(), 15u);
    EXPECT_GT(t.seconds, 0.0);
    EXPECT_LT(t.seconds, 1.0);  // fifteen queries of a two-triangle scene
}

TEST_F(RayStatsTest, NothingCountedWhileOffAndResetZeroes) {
    SquareScene s;
    Hit h;
    raystats::enable(true);
    s.scene.intersect(downFrom(0, 0), &h);
    raystats::enable(false);
    for (int i = 0; i < 7; ++i) s.scene.intersect(downFrom(0, 0), &h);
    EXPECT_EQ(raystats::totals().calls[raystats::kNearest], 1u);  // readable after enable(false)
    raystats::enable(true);                                       // starts from zero
    EXPECT_EQ(raystats::totals().allCalls(), 0u);
    s.scene.intersect(downFrom(0, 0), &h);
    s.scene.intersect(downFrom(0, 0), &h);
    raystats::reset();
    s.scene.intersect(downFrom(0, 0), &h);
    EXPECT_EQ(raystats::totals().calls[raystats::kNearest], 1u);
}

TEST_F(RayStatsTest, SumsOverThreads) {
    SquareScene s;
    raystats::enable(true);
    std::vector<std::thread> threads;
    for (int k = 0; k < 4; ++k)
        threads.emplace_back([&s] {
            Hit h;
            for (int i = 0; i < 1000; ++i) s.scene.intersect(downFrom(0.0f, 0.0f), &h);
        });
    for (std::thread& t : threads) t.join();
    EXPECT_EQ(raystats::totals().calls[raystats::kNearest], 4000u);
}

}  // namespace
