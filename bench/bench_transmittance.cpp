// Cost of medium queries: transmittance (regular tracking through the voxels of
// media/smoke.vdb, 64^3) against the closed form of a homogeneous medium, plus
// free-flight sampling in the smoke. Each query is one segment: a fixed-seed
// random chord of the grid's bounding cube [-0.5, 0.5]^3 (mean ~0.6 units,
// ~40 voxels). Reported: time per query (ns) and queries/s (items_per_second),
// median over 7 repetitions:
//   bench_transmittance --benchmark_repetitions=7 --benchmark_report_aggregates_only=true
// (those are also the defaults set below).
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "core/rng.h"
#include "core/sampling.h"
#include "scene/medium.h"

namespace {

struct Segment {
    ub::Vec3 o, d;
    float len;
};

// Chords: a uniform point in the cube and a uniform direction, extended both ways to the
// cube's faces.
std::vector<Segment> makeChords(int n) {
    std::vector<Segment> out;
    ub::Rng rng(2024, 0);
    while (int(out.size()) < n) {
        ub::Vec3 p = rng.uniform3() - ub::Vec3(0.5f);
        ub::Vec3 d = ub::sampleUniformSphere(rng.uniform2());
        float tLo = -1e30f, tHi = 1e30f;
        for (int a = 0; a < 3; ++a) {
            if (d[a] == 0) continue;
            float t0 = (-0.5f - p[a]) / d[a], t1 = (0.5f - p[a]) / d[a];
            if (t0 > t1) std::swap(t0, t1);
            tLo = std::max(tLo, t0);
            tHi = std::min(tHi, t1);
        }
        if (tHi - tLo < 1e-3f) continue;
        out.push_back({p + d * tLo, d, tHi - tLo});
    }
    return out;
}

const std::vector<Segment>& chords() {
    static const std::vector<Segment> c = makeChords(4096);
    return c;
}

const ub::Medium& smoke() {
    static const ub::Medium m = ub::Medium::heterogeneous(
        ub::VdbGrid::load(std::string(UNIBEAM_SOURCE_DIR) + "/media/smoke.vdb", "density"), 20.0f,
        ub::Rgb(0.9f), 0.3f);
    return m;
}

const ub::Medium& homogeneous() {
    static const ub::Medium m =
        ub::Medium::homogeneous(ub::Rgb(0.5f, 1.0f, 2.0f), ub::Rgb(2.0f, 1.5f, 1.0f), 0.3f);
    return m;
}

void transmittanceLoop(benchmark::State& state, const ub::Medium& m) {
    const auto& segs = chords();
    size_t i = 0;
    for (auto _ : state) {
        const Segment& s = segs[i++ & (segs.size() - 1)];
        benchmark::DoNotOptimize(ub::transmittance(m, s.o, s.d, s.len));
    }
    state.SetItemsProcessed(state.iterations());
}

void BM_TransmittanceSmokeVdb(benchmark::State& state) {
    transmittanceLoop(state, smoke());
}
void BM_TransmittanceHomogeneous(benchmark::State& state) {
    transmittanceLoop(state, homogeneous());
}

void BM_FreeFlightSmokeVdb(benchmark::State& state) {
    const auto& segs = chords();
    ub::Rng rng(7, 0);
    size_t i = 0;
    for (auto _ : state) {
        const Segment& s = segs[i++ & (segs.size() - 1)];
        benchmark::DoNotOptimize(
            ub::sampleFreeFlight(smoke(), s.o, s.d, s.len, rng.uniform(), rng.uniform()));
    }
    state.SetItemsProcessed(state.iterations());
}

void BM_FreeFlightHomogeneous(benchmark::State& state) {
    const auto& segs = chords();
    ub::Rng rng(7, 0);
    size_t i = 0;
    for (auto _ : state) {
        const Segment& s = segs[i++ & (segs.size() - 1)];
        benchmark::DoNotOptimize(
            ub::sampleFreeFlight(homogeneous(), s.o, s.d, s.len, rng.uniform(), rng.uniform()));
    }
    state.SetItemsProcessed(state.iterations());
}

#define UB_MEDIAN_OF_7 Repetitions(7)->ReportAggregatesOnly(true)
BENCHMARK(BM_TransmittanceSmokeVdb)->UB_MEDIAN_OF_7;
BENCHMARK(BM_TransmittanceHomogeneous)->UB_MEDIAN_OF_7;
BENCHMARK(BM_FreeFlightSmokeVdb)->UB_MEDIAN_OF_7;
BENCHMARK(BM_FreeFlightHomogeneous)->UB_MEDIAN_OF_7;

}  // namespace

BENCHMARK_MAIN();
