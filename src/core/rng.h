// Random numbers: PCG32 (O'Neill 2014, "PCG: A Family of Simple Fast
// Space-Efficient Statistically Good Algorithms"), one independent stream per
// (seed, iteration, pixel/path index) so that images are bit-identical for a
// given seed regardless of thread count and scheduling.
#pragma once

#include <cstdint>

#include "core/vec.h"

namespace ub {

/// 64-bit mix (splitmix64 finaliser) used to derive stream ids.
inline uint64_t mix64(uint64_t x) {
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

class Rng {
  public:
    Rng() { seed(0, 0); }
    Rng(uint64_t seedValue, uint64_t stream) { seed(seedValue, stream); }
    /// Stream for path `index` of iteration `iteration` of a render seeded by `seed`.
    static Rng forPath(uint64_t seed, uint64_t iteration, uint64_t index, uint64_t salt = 0) {
        uint64_t s = mix64(seed ^ mix64(iteration * 0x1000193ull + salt));
        return Rng(s, mix64(index + 0x632BE59BD9B4E019ull * (salt + 1)));
    }
    void seed(uint64_t initState, uint64_t stream) {
        state_ = 0;
        inc_ = (stream << 1u) | 1u;
        nextU32();
        state_ += initState;
        nextU32();
    }
    uint32_t nextU32() {
        uint64_t old = state_;
        state_ = old * 6364136223846793005ull + inc_;
        uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
        uint32_t rot = uint32_t(old >> 59u);
        return (xorshifted >> rot) | (xorshifted << ((-rot) & 31));
    }
    /// Uniform float in [0, 1).
    float uniform() { return float(nextU32() >> 8) * 0x1p-24f; }
    Vec2 uniform2() {
        float a = uniform();
        return {a, uniform()};
    }
    Vec3 uniform3() {
        float a = uniform();
        float b = uniform();
        return {a, b, uniform()};
    }

  private:
    uint64_t state_, inc_;
};

}  // namespace ub
