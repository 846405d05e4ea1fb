// The beam estimators' four-wide BVH (src/estimators/bvh.h) against brute force: a walk reports
// every primitive of the leaves whose boxes pass, each once, so with leaves of one box exactly
// the boxes that contain a point or meet a segment, and with larger leaves a superset of them;
// for thin diagonal boxes (beam parts), small cubes (photon spheres), a single box and
// coincident centres; and the
// host's SSE node test (bvhMeets4) gives the shared ub_bvh_meets mask bit for bit, NaN cases
// (origins on slab planes, axis-parallel segments) included.
#include "estimators/bvh.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include "core/rng.h"
#include "core/sampling.h"
#include "estimators/volume_estimate.h"
#include "kernels/shared/ub_beam_geometry.h"
#include "kernels/shared/ub_pb2d.h"

using namespace ub;

namespace {

Vec3 randomIn(Rng& rng, float lo, float hi) {
    return Vec3(lo + (hi - lo) * rng.uniform(), lo + (hi - lo) * rng.uniform(),
                lo + (hi - lo) * rng.uniform());
}

// Slab test in double precision, as the reference of which boxes a segment meets.
bool segmentMeetsBox(const Vec3& o, const Vec3& d, float len, const Bounds3& b) {
    double t0 = 0.0, t1 = len;
    for (int a = 0; a < 3; ++a) {
        if (d[a] == 0.0f) {
            if (o[a] < b.lo[a] || o[a] > b.hi[a]) return false;
            continue;
        }
        double ta = (double(b.lo[a]) - o[a]) / d[a], tb = (double(b.hi[a]) - o[a]) / d[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
    }
    return t0 <= t1;
}

// Whether the test's rounding may differ from the double reference: the segment passes
// within a relative 1e-4 of a box face.
bool nearBoundary(const Vec3& o, const Vec3& d, float len, const Bounds3& b) {
    Bounds3 grown = b, shrunk = b;
    const Vec3 e = (b.hi - b.lo) * 1e-4f + Vec3(1e-5f, 1e-5f, 1e-5f);
    grown.lo = b.lo - e;
    grown.hi = b.hi + e;
    shrunk.lo = b.lo + e;
    shrunk.hi = b.hi - e;
    return segmentMeetsBox(o, d, len * 1.0001f, grown) != segmentMeetsBox(o, d, len, shrunk);
}

std::vector<Bounds3> beamBoxes(Rng& rng, int n) {
    std::vector<Bounds3> boxes;
    for (int i = 0; i < n; ++i) {
        const Vec3 a = randomIn(rng, 0.0f, 1.0f);
        const Vec3 b = a + randomIn(rng, -0.2f, 0.2f);
        Bounds3 box;
        box.extend(a - Vec3(0.01f, 0.01f, 0.01f));
        box.extend(b + Vec3(0.01f, 0.01f, 0.01f));
        boxes.push_back(box);
    }
    return boxes;
}

void checkWalks(const std::vector<Bounds3>& boxes, uint32_t leafSize, uint64_t seed) {
    Bvh bvh;
    bvh.build(boxes, leafSize);
    Rng rng(seed, 3);
    for (int q = 0; q < 400; ++q) {
        const Vec3 p = randomIn(rng, -0.1f, 1.1f);
        std::vector<uint32_t> found, expected;
        bvh.queryPoint(p, [&](uint32_t i) { found.push_back(i); });
        for (uint32_t i = 0; i < boxes.size(); ++i)
            if (p.x >= boxes[i].lo.x && p.x <= boxes[i].hi.x && p.y >= boxes[i].lo.y &&
                p.y <= boxes[i].hi.y && p.z >= boxes[i].lo.z && p.z <= boxes[i].hi.z)
                expected.push_back(i);
        std::sort(found.begin(), found.end());
        ASSERT_TRUE(std::adjacent_find(found.begin(), found.end()) == found.end());
        if (leafSize == 1)
            ASSERT_EQ(found, expected) << "point query " << q;
        else
            ASSERT_TRUE(std::includes(found.begin(), found.end(), expected.begin(), expected.end()))
                << "point query " << q;

        Vec3 d = randomIn(rng, -1.0f, 1.0f);
        if (q % 5 == 0) d[q % 3] = 0.0f;  // axis-parallel segments: infinite 1 / d
        d = normalize(d);
        const float len = 0.05f + 1.5f * rng.uniform();
        std::vector<uint32_t> hit;
        bvh.querySegment(p, d, len, [&](uint32_t i) { hit.push_back(i); });
        std::sort(hit.begin(), hit.end());
        ASSERT_TRUE(std::adjacent_find(hit.begin(), hit.end()) == hit.end()) << "reported twice";
        for (uint32_t i = 0; i < boxes.size(); ++i) {
            if (nearBoundary(p, d, len, boxes[i])) continue;  // float and double may differ
            const bool meets = segmentMeetsBox(p, d, len, boxes[i]);
            const bool reported = std::binary_search(hit.begin(), hit.end(), i);
            if (leafSize == 1 || meets)
                ASSERT_EQ(meets, reported) << "segment query " << q << " box " << i;
        }
    }
}

}  // namespace

TEST(Bvh, WalksReportExactlyTheBoxesOfThinBeamParts) {
    Rng rng(11, 1);
    const std::vector<Bounds3> boxes = beamBoxes(rng, 3000);
    for (uint32_t leaf : {1u, 4u, 8u}) checkWalks(boxes, leaf, 100 + leaf);
}

TEST(Bvh, WalksReportExactlyTheBoxesOfSmallCubesAndDegenerateSets) {
    Rng rng(12, 1);
    std::vector<Bounds3> cubes;
    for (int i = 0; i < 2000; ++i) {
        const Vec3 c = randomIn(rng, 0.0f, 1.0f);
        Bounds3 b;
        b.extend(c - Vec3(0.03f, 0.03f, 0.03f));
        b.extend(c + Vec3(0.03f, 0.03f, 0.03f));
        cubes.push_back(b);
    }
    checkWalks(cubes, 1, 6);
    checkWalks(cubes, 4, 7);
    checkWalks({cubes[0]}, 1, 8);  // a leaf root: the only child of node 0
    // Coincident centres become one leaf whatever its size.
    checkWalks(std::vector<Bounds3>(50, cubes[1]), 4, 9);
    Bvh empty;
    empty.build({});
    int visits = 0;
    empty.querySegment(Vec3(0.0f), Vec3(1.0f, 0.0f, 0.0f), 1.0f, [&](uint32_t) { ++visits; });
    EXPECT_EQ(visits, 0);
}

// Built with groups (the medium of each photon or beam part), each group has a tree of its own:
// a walk from root(g) reports exactly the boxes of group g that a walk of the whole set
// reports, and nothing of another group; empty and unknown groups have no root; an
// ungrouped build and a build with one group make the same nodes (the splits round the
// absolute leaf-order position, which is the same on trees starting at 0).
TEST(Bvh, GroupedBuildWalksOneGroupsBoxesOnly) {
    Rng rng(21, 1);
    const std::vector<Bounds3> boxes = beamBoxes(rng, 2500);
    std::vector<uint32_t> groups(boxes.size());
    for (uint32_t& g : groups) g = rng.uniform() < 0.15f ? 0u : (rng.uniform() < 0.5f ? 1u : 3u);
    for (uint32_t leaf : {1u, 12u}) {
        Bvh grouped, whole;
        grouped.build(boxes, leaf, Bvh::kStackSize, &groups);
        whole.build(boxes, leaf);
        EXPECT_EQ(grouped.root(2), UB_BVH_NONE);
        EXPECT_EQ(grouped.root(9), UB_BVH_NONE);
        EXPECT_EQ(whole.root(9), 0u);
        EXPECT_NE(grouped.root(0), grouped.root(1));
        EXPECT_LE(grouped.stackNeed(), Bvh::kStackSize);
        // The leaf-order position of each box, for querySegmentLeaves.
        Bvh ordered;
        ordered.build(boxes, leaf, Bvh::kStackSize, &groups);
        std::vector<uint32_t> boxAt(boxes.size());
        for (uint32_t i = 0; i < boxAt.size(); ++i) boxAt[i] = i;
        ordered.permuteToLeafOrder(&boxAt);
        Rng q(22 + leaf, 3);
        for (int k = 0; k < 300; ++k) {
            const Vec3 p = randomIn(q, -0.1f, 1.1f);
            const Vec3 d = normalize(randomIn(q, -1.0f, 1.0f));
            const float len = 0.05f + 1.5f * q.uniform();
            std::vector<uint32_t> all;
            whole.queryPoint(p, [&](uint32_t i) { all.push_back(i); });
            std::vector<uint32_t> union_;
            for (uint32_t g : {0u, 1u, 2u, 3u}) {
                std::vector<uint32_t> found, seg;
                grouped.queryPoint(p, g, [&](uint32_t i) { found.push_back(i); });
                ordered.querySegmentLeaves(p, d, len, g, [&](uint32_t first, uint32_t end) {
                    for (uint32_t i = first; i < end; ++i) seg.push_back(boxAt[i]);
                });
                for (uint32_t i : found) ASSERT_EQ(groups[i], g) << "point query " << k;
                for (uint32_t i : seg) ASSERT_EQ(groups[i], g) << "segment query " << k;
                for (uint32_t i = 0; i < boxes.size(); ++i) {
                    if (groups[i] != g || nearBoundary(p, d, len, boxes[i])) continue;
                    if (segmentMeetsBox(p, d, len, boxes[i]))
                        ASSERT_NE(std::find(seg.begin(), seg.end(), i), seg.end())
                            << "segment query " << k << " box " << i;
                }
                union_.insert(union_.end(), found.begin(), found.end());
            }
            // Leaves of one box: the groups' walks together report what the whole walk does.
            if (leaf == 1) {
                std::sort(all.begin(), all.end());
                std::sort(union_.begin(), union_.end());
                ASSERT_EQ(union_, all) << "point query " << k;
            }
        }
        // One group: the same tree as without groups.
        Bvh one;
        const std::vector<uint32_t> zeros(boxes.size(), 0u);
        one.build(boxes, leaf, Bvh::kStackSize, &zeros);
        ASSERT_EQ(one.nodeCount(), whole.nodeCount());
        EXPECT_EQ(0, std::memcmp(one.nodes().data(), whole.nodes().data(),
                                 whole.nodeCount() * sizeof(BvhNode)));
    }
}

// The walks hold Bvh::kStackSize entries (and UB_BVH_STACK in kernels/beams.cl), with no
// check as they push. Boxes whose sizes fall geometrically along a line make the largest-box
// collapse leave inner children one binary level down at every four-wide level of the small
// boxes' path; the build must measure the stack the tree needs and keep it within the bound
// (it then opens the shallowest child first). Measured: 25 entries for the geometric set with
// leaves of 1, 16-20 for beam parts.
TEST(Bvh, StackNeedStaysWithinTheWalksStack) {
    std::vector<Bounds3> geometric;
    for (int i = 0; i < 4000; ++i) {
        const float x = std::pow(2.0f, -float(i) / 40.0f), h = 0.25f * x;
        Bounds3 b;
        b.extend(Vec3(x - h, -h, -h));
        b.extend(Vec3(x + h, h, h));
        geometric.push_back(b);
    }
    Rng rng(14, 1);
    const std::vector<Bounds3> beams = beamBoxes(rng, 20000);
    for (const std::vector<Bounds3>* set :
         std::vector<const std::vector<Bounds3>*>{&geometric, &beams})
        for (uint32_t leaf : {1u, 4u, 8u}) {
            Bvh bvh;
            bvh.build(*set, leaf);
            EXPECT_LE(bvh.stackNeed(), Bvh::kStackSize) << "leaf " << leaf;
            EXPECT_GE(bvh.stackNeed(), 4);
        }
    checkWalks(geometric, 1, 15);
    // The fallback collapse: 25 entries with the largest box opened first (above), at most
    // 3 ceil(12 / 2) + 1 = 19 with the shallowest first (12 binary levels over 4000 boxes).
    Bvh shallow;
    shallow.build(geometric, 1, 20);
    EXPECT_LE(shallow.stackNeed(), 19);
    // Still four-wide: about a third as many nodes as boxes, not a binary tree's one per box.
    EXPECT_LT(shallow.nodeCount(), geometric.size() / 2);
    size_t reported = 0;
    shallow.queryPoint(Vec3(0.5f, 0.0f, 0.0f), [&](uint32_t) { ++reported; });
    size_t expected = 0;
    for (const Bounds3& b : geometric) expected += (b.lo.x <= 0.5f && b.hi.x >= 0.5f) ? 1 : 0;
    EXPECT_EQ(reported, expected);
    EXPECT_GT(expected, 0u);
    EXPECT_THROW(shallow.build(geometric, 1, 10), std::logic_error);
    // The kernels' stack is the host's.
    std::ifstream cl(std::string(UNIBEAM_SOURCE_DIR) + "/kernels/beams.cl");
    std::stringstream text;
    text << cl.rdbuf();
    EXPECT_NE(text.str().find("#define UB_BVH_STACK " + std::to_string(Bvh::kStackSize) + "\n"),
              std::string::npos);
}

TEST(Bvh, SseNodeTestEqualsTheSharedOne) {
    Rng rng(13, 1);
    const float inf = std::numeric_limits<float>::infinity();
    int nanCases = 0;
    for (int k = 0; k < 200000; ++k) {
        BvhNode n{};
        for (int c = 0; c < 4; ++c) {
            const Vec3 a = randomIn(rng, -1.0f, 1.0f), b = a + randomIn(rng, 0.0f, 0.5f);
            n.loX[c] = a.x, n.loY[c] = a.y, n.loZ[c] = a.z;
            n.hiX[c] = b.x, n.hiY[c] = b.y, n.hiZ[c] = b.z;
            n.child[c] = uint32_t(c);
            n.count[c] = rng.uniform() < 0.15f ? UB_BVH_NONE : uint32_t(rng.nextU32() % 3);
        }
        Vec3 o = randomIn(rng, -1.5f, 1.5f), d = normalize(randomIn(rng, -1.0f, 1.0f));
        if (k % 3 == 0) d[k % 2] = 0.0f;
        if (k % 7 == 0) o.x = n.loX[k % 4];  // on a slab plane: 0 * inf = NaN with d.x = 0
        if (k % 11 == 0) o.y = n.hiY[k % 4];
        const ub_float3 oo = ub_make_float3(o.x, o.y, o.z);
        const ub_float3 invD = ub_make_float3(1.0f / d.x, 1.0f / d.y, 1.0f / d.z);
        const float len = k % 13 == 0 ? inf : 3.0f * rng.uniform();
        nanCases += (d.x == 0.0f && k % 7 == 0) ? 1 : 0;
        ASSERT_EQ(bvhMeets4(n, oo, invD, len), ub_bvh_meets(&n, oo, invD, len)) << "case " << k;
    }
    EXPECT_GT(nanCases, 1000);
}

// Ranges of 8192 boxes and more build their halves in parallel; the tree (every node's
// boxes, children and counts) and the leaf order are those of a build on one thread, and
// its walks report exactly the boxes they meet.
TEST(Bvh, ParallelBuildEqualsTheBuildOnOneThread) {
    Rng rng(21, 1);
    const std::vector<Bounds3> walked = beamBoxes(rng, 20000);
    for (uint32_t leaf : {1u, 8u}) checkWalks(walked, leaf, 300 + leaf);
    const std::vector<Bounds3> boxes = beamBoxes(rng, 60000);
    Bvh one, many;
    std::vector<uint32_t> orderOne(boxes.size()), orderMany(boxes.size());
    for (uint32_t i = 0; i < boxes.size(); ++i) orderOne[i] = orderMany[i] = i;
    {
        tbb::task_arena single(1);
        single.execute([&] { one.build(boxes, 8); });
    }
    many.build(boxes, 8);
    one.permuteToLeafOrder(&orderOne);
    many.permuteToLeafOrder(&orderMany);
    ASSERT_EQ(one.nodeCount(), many.nodeCount());
    ASSERT_GT(one.nodeCount(), 60000u / 8 / 4);
    EXPECT_EQ(
        0, std::memcmp(one.nodes().data(), many.nodes().data(), one.nodeCount() * sizeof(BvhNode)));
    EXPECT_EQ(orderOne, orderMany);
}

// With leaves of a multiple of four, every leaf but the one holding the last items starts on
// a block of four in leaf order and holds whole blocks (the walks test candidates four to a
// block), for any count of boxes; leaves of other sizes are plain median splits.
TEST(Bvh, LeavesOfAMultipleOfFourHoldWholeBlocks) {
    Rng rng(22, 1);
    for (int count : {12, 13, 1000, 20003}) {
        const std::vector<Bounds3> boxes = beamBoxes(rng, count);
        Bvh bvh;
        bvh.build(boxes, 12);
        size_t leaves = 0, items = 0;
        for (const BvhNode& n : bvh.nodes())
            for (int c = 0; c < 4; ++c) {
                if (n.count[c] == UB_BVH_NONE || n.count[c] == 0) continue;
                ++leaves;
                items += n.count[c];
                EXPECT_LE(n.count[c], 12u);
                EXPECT_EQ(n.child[c] % 4, 0u) << count << " boxes";
                if (n.child[c] + n.count[c] != uint32_t(count))
                    EXPECT_EQ(n.count[c] % 4, 0u) << count << " boxes";
            }
        EXPECT_EQ(items, size_t(count));
        EXPECT_GE(leaves, size_t(count + 11) / 12);
    }
}

/// A part of a beam of length 4 whose line passes near the segment o + t d, t in [0, 4] (its
/// origin 0-2 units back along it, so the closest point falls in 0-4), along d itself when
/// `parallel`; its range around the closest point, from 0 when k % 5 == 0 and to the beam's
/// end (a last part) when k % 7 == 0.
ub_beam_part randomPartNear(Rng& rng, const Vec3& o, const Vec3& d, int k, bool parallel) {
    Vec3 dj = sampleUniformSphere(rng.uniform2());
    if (parallel) dj = d;
    const Vec3 oj =
        o + d * (4.0f * rng.uniform()) + randomIn(rng, -0.3f, 0.3f) - dj * (2.0f * rng.uniform());
    ub_beam_part part{};
    for (int a = 0; a < 3; ++a) {
        part.origin[a] = oj[a];
        part.dir[a] = dj[a];
    }
    part.length = 4.0f;
    part.t0 = k % 5 == 0 ? 0.0f : 3.0f * rng.uniform();
    part.t1 = k % 7 == 0 ? 4.0f : std::min(4.0f, part.t0 + 1.5f * rng.uniform());
    return part;
}

// bb1d's first test of a leaf (kernels/shared/ub_bvh.h): the host's SSE form equals the shared
// one bit for bit, a part it rejects ub_bb1d_pair's geometry (ub_beam_beam_near, then
// ub_beam_part_holds) rejects too (the filter never drops a pair), and ub_block_lanes masks
// exactly the block's lanes inside a leaf's range. Lines at every angle (parallel ones
// included), separations around the radius, parts of beams of length 4 with ranges around the
// closest points, last parts among them, query beams of length 4 or ending around them (the
// filter tests the query's range too).
TEST(Bvh, BeamLineFilterEqualsTheSharedOneAndDropsNoPair) {
    Rng rng(31, 4);
    int near = 0, pairs = 0;
    for (int k = 0; k < 50000; ++k) {
        const Vec3 o = randomIn(rng, -2.0f, 2.0f);
        const Vec3 d = sampleUniformSphere(rng.uniform2());
        ub_beam_keys4 keys{};
        ub_beam_part parts[4];
        ub_float3 oB[4], dB[4];
        for (int j = 0; j < 4; ++j) {
            const ub_beam_part& part = parts[j] = randomPartNear(rng, o, d, k, k % 17 == j);
            ub_beam_keys4_set(&keys, j, part);
            oB[j] = ub_f3_from(part.origin);
            dB[j] = ub_f3_from(part.dir);
        }
        const ub_float3 oo = ub_make_float3(o.x, o.y, o.z), dd = ub_make_float3(d.x, d.y, d.z);
        const float r2 = 0.01f;
        // Query beams of length 4 (through the parts' region) or shorter, ending around it.
        const float qLen = k % 3 == 0 ? 4.0f : 0.5f + 3.5f * rng.uniform();
        const uint32_t mask = ub_beam_lines_near4(&keys, oo, dd, qLen, r2);
        ASSERT_EQ(beamLinesNear4(keys, oo, dd, qLen, r2), mask) << "case " << k;
        for (int j = 0; j < 4; ++j) {
            float tA = 0, tB = 0, sinTheta = 0;
            const bool pair =
                ub_beam_beam_near(oo, dd, qLen, oB[j], dB[j], 4.0f, r2, &tA, &tB, &sinTheta) &&
                ub_beam_part_holds(parts[j], tB, parts[j].length);
            pairs += pair;
            near += (mask >> j) & 1u;
            if (pair) ASSERT_TRUE((mask >> j) & 1u) << "case " << k << " lane " << j;
        }
    }
    std::printf("[ bvh      ] beam filter: %d pairs, %d passed the filter of 200000 parts\n", pairs,
                near);
    EXPECT_GT(pairs, 10000);
    EXPECT_GT(near, pairs);
    for (uint32_t first = 0; first < 12; ++first)
        for (uint32_t end = first + 1; end < 20; ++end)
            for (uint32_t b = first / 4; b * 4 < end; ++b)
                for (uint32_t j = 0; j < 4; ++j) {
                    const uint32_t i = 4 * b + j;
                    EXPECT_EQ((ub_block_lanes(b, first, end) >> j) & 1u,
                              uint32_t(i >= first && i < end));
                }
}

// bb1d's AVX walk tests two blocks of lines at once (src/estimators/bb1d_walk.inc): its mask is
// the two blocks' SSE masks side by side, bit for bit, on random lines (parallel ones among
// them), separations around the radius and ranges around the closest points, last parts (t1 =
// infinity) included. A CPU without AVX never runs that walk: there the test checks that it is
// never chosen and that asking for it is an error.
TEST(Bvh, BeamLineFilterEightWideEqualsTwoBlocks) {
    if (!bb1dWideWalkAvailable()) {
        EXPECT_FALSE(bb1dWideWalk());
        const ub_beam_keys4 keys[2] = {};
        const ub_float3 o = ub_make_float3(0.0f, 0.0f, 0.0f), d = ub_make_float3(1.0f, 0.0f, 0.0f);
        EXPECT_THROW(bb1dLinesNear8ForTests(keys, o, d, 4.0f, 0.01f), std::logic_error);
        return;
    }
    Rng rng(37, 5);
    int set = 0;
    for (int k = 0; k < 25000; ++k) {
        const Vec3 o = randomIn(rng, -2.0f, 2.0f);
        const Vec3 d = sampleUniformSphere(rng.uniform2());
        ub_beam_keys4 keys[2] = {};
        for (int j = 0; j < 8; ++j)
            ub_beam_keys4_set(&keys[j / 4], j % 4, randomPartNear(rng, o, d, k, k % 13 == j));
        const ub_float3 oo = ub_make_float3(o.x, o.y, o.z), dd = ub_make_float3(d.x, d.y, d.z);
        const float r2 = 0.01f, qLen = k % 3 == 0 ? 4.0f : 0.5f + 3.5f * rng.uniform();
        const uint32_t two = beamLinesNear4(keys[0], oo, dd, qLen, r2) |
                             beamLinesNear4(keys[1], oo, dd, qLen, r2) << 4;
        ASSERT_EQ(bb1dLinesNear8ForTests(keys, oo, dd, qLen, r2), two) << "case " << k;
        set += __builtin_popcount(two);
    }
    EXPECT_GT(set, 10000);  // lanes that passed: the comparison saw both answers
}

// pb2d's test of a leaf's photons four at a time: the host's SSE form (pb2dNear4ForTests) gives
// the shared ub_pb2d_near4's mask and beam parameters bit for bit, which are ub_pb2d_near's per
// photon; photons around the radius and the beam's ends, in two media, with padded lanes.
TEST(Bvh, PhotonKeyTestEqualsTheSharedOne) {
    Rng rng(37, 2);
    int near = 0;
    for (int k = 0; k < 50000; ++k) {
        const Vec3 o = randomIn(rng, -2.0f, 2.0f);
        const Vec3 d = sampleUniformSphere(rng.uniform2());
        const float len = 3.0f * rng.uniform();
        ub_photon_keys4 keys{};
        for (int j = 0; j < 4; ++j) {
            const Vec3 p = o + d * (-0.5f + 4.0f * rng.uniform()) + randomIn(rng, -0.15f, 0.15f);
            keys.px[j] = p.x, keys.py[j] = p.y, keys.pz[j] = p.z;
            keys.mediumId[j] = k % 5 == j ? UB_NO_MEDIUM : rng.nextU32() % 2;
        }
        const ub_float3 oo = ub_make_float3(o.x, o.y, o.z), dd = ub_make_float3(d.x, d.y, d.z);
        float tShared[4], tSse[4];
        const uint32_t mask = ub_pb2d_near4(&keys, oo, dd, len, 1u, 0.01f, tShared);
        ASSERT_EQ(pb2dNear4ForTests(keys, oo, dd, len, 1u, 0.01f, tSse), mask) << "case " << k;
        for (int j = 0; j < 4; ++j) {
            ub_photon_key key;
            key.pos[0] = keys.px[j], key.pos[1] = keys.py[j], key.pos[2] = keys.pz[j];
            key.mediumId = keys.mediumId[j];
            float t = 0.0f;
            ASSERT_EQ(ub_pb2d_near(key, oo, dd, len, 1u, 0.01f, &t), int((mask >> j) & 1u));
            if ((mask >> j) & 1u) {
                ASSERT_EQ(tSse[j], t);
                ASSERT_EQ(tShared[j], t);
                ++near;
            }
        }
    }
    EXPECT_GT(near, 10000);
}
