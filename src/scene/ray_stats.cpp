// Ray query counters (see ray_stats.h).
#include "scene/ray_stats.h"

#include <chrono>
#include <deque>
#include <mutex>

#if defined(__x86_64__) || defined(__i386__)
#include <x86intrin.h>
#define UB_RAY_STATS_TSC 1
#else
#define UB_RAY_STATS_TSC 0
#endif

namespace ub::raystats {

namespace detail {
std::atomic<bool> on{false};
}  // namespace detail

namespace {

/// One thread's counters. Only its thread writes them (relaxed loads and stores, no locked
/// instruction); totals() reads every block.
struct Block {
    std::atomic<uint64_t> calls[kKinds];
    std::atomic<uint64_t> ticks;
    Block() : calls{}, ticks(0) {}
};

/// The blocks of every thread that has counted, never freed (a pool thread may end before
/// totals() reads it); a deque keeps their addresses.
struct Registry {
    std::mutex mutex;
    std::deque<Block> blocks;
    /// Where the clock was at enable(true) or reset(): ticks per second are measured over
    /// the interval up to totals().
    uint64_t startTicks = 0;
    std::chrono::steady_clock::time_point startTime;
};

Registry& registry() {
    static Registry r;
    return r;
}

Block& myBlock() {
    thread_local Block* block = nullptr;
    if (!block) {
        Registry& r = registry();
        std::lock_guard<std::mutex> lock(r.mutex);
        block = &r.blocks.emplace_back();
    }
    return *block;
}

void bump(std::atomic<uint64_t>& x, uint64_t by) {
    x.store(x.load(std::memory_order_relaxed) + by, std::memory_order_relaxed);
}

void zeroLocked(Registry& r) {
    for (Block& b : r.blocks) {
        for (auto& c : b.calls) c.store(0, std::memory_order_relaxed);
        b.ticks.store(0, std::memory_order_relaxed);
    }
    r.startTicks = detail::now();
    r.startTime = std::chrono::steady_clock::now();
}

}  // namespace

namespace detail {

uint64_t now() {
#if UB_RAY_STATS_TSC
    return __rdtsc();
#else
    return uint64_t(std::chrono::duration_cast<std::chrono::nanoseconds>(
                        std::chrono::steady_clock::now().time_since_epoch())
                        .count());
#endif
}

void add(Kind kind, uint64_t ticks) {
    Block& b = myBlock();
    bump(b.calls[kind], 1);
    bump(b.ticks, ticks);
}

}  // namespace detail

void enable(bool on) {
    if (on) {
        Registry& r = registry();
        std::lock_guard<std::mutex> lock(r.mutex);
        zeroLocked(r);
    }
    detail::on.store(on, std::memory_order_relaxed);
}

void reset() {
    Registry& r = registry();
    std::lock_guard<std::mutex> lock(r.mutex);
    zeroLocked(r);
}

Totals totals() {
    Registry& r = registry();
    std::lock_guard<std::mutex> lock(r.mutex);
    Totals t;
    uint64_t ticks = 0;
    for (const Block& b : r.blocks) {
        for (int k = 0; k < kKinds; ++k) t.calls[k] += b.calls[k].load(std::memory_order_relaxed);
        ticks += b.ticks.load(std::memory_order_relaxed);
    }
#if UB_RAY_STATS_TSC
    // The time-stamp counter's rate, measured against the steady clock since the start (it
    // is constant on every x86-64 CPU of the last fifteen years: constant_tsc).
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - r.startTime).count();
    const uint64_t elapsedTicks = detail::now() - r.startTicks;
    const double ticksPerSecond = elapsed > 0.0 ? double(elapsedTicks) / elapsed : 0.0;
    t.seconds = ticksPerSecond > 0.0 ? double(ticks) / ticksPerSecond : 0.0;
#else
    t.seconds = double(ticks) * 1e-9;
#endif
    return t;
}

}  // namespace ub::raystats
