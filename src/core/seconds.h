// secondsSince: wall-clock seconds from a steady_clock time point to now (the passes'
// timings of an iteration).
#pragma once

#include <chrono>

namespace ub {

inline double secondsSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace ub
