// Counters of the Scene's Embree queries: how many of each kind a render made and how long
// they took, summed over threads. For benchmarks (bench_upbp --ray-stats): the tracing rows
// of the performance work are bound by Embree, and sessions 37, 41 and 46 counted its calls
// and timed them with temporary builds (docs/performance.md).
//
// Off by default. Off, a query pays one relaxed atomic load and a predictable branch. On, it
// reads the time-stamp counter twice (about 20 cycles against the 400-900 of a query on the
// SmallUPBP scenes) and adds to counters of its own thread, which no other thread writes.
#pragma once

#include <atomic>
#include <cstdint>

namespace ub::raystats {

/// The kinds of query: Scene::intersectNearest (and intersect), any-hit (occluded,
/// occludedToInfinity, anyHitWithin) and the shadow walks' crossing collection
/// (shadowCrossings).
enum Kind : int { kNearest = 0, kAnyHit = 1, kCrossings = 2, kKinds = 3 };

struct Totals {
    uint64_t calls[kKinds] = {0, 0, 0};
    double seconds = 0.0;  ///< inside Embree, summed over threads
    uint64_t allCalls() const { return calls[0] + calls[1] + calls[2]; }
};

/// Starts counting from zero (on) or stops (off; the totals stay readable).
void enable(bool on);
/// Zeroes the counters; counting goes on if it was on.
void reset();
/// The counts and time since enable(true) or reset(). Read after the queries have finished
/// (a parallel loop's end orders them before): a query still running may be missed.
Totals totals();

namespace detail {
extern std::atomic<bool> on;
uint64_t now();
void add(Kind kind, uint64_t ticks);
}  // namespace detail

inline bool enabled() {
    return detail::on.load(std::memory_order_relaxed);
}

/// Runs `query` (an Embree call), counted as `kind` when counting is on.
template <class F>
inline void timed(Kind kind, F&& query) {
    if (!enabled()) {
        query();
        return;
    }
    const uint64_t t0 = detail::now();
    query();
    detail::add(kind, detail::now() - t0);
}

}  // namespace ub::raystats
