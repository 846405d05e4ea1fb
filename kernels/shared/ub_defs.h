/* Portability layer for code shared by host C++ and OpenCL C.
 *
 * Headers in kernels/shared/ are written in a C99 subset that compiles both
 * as OpenCL C 1.2 (on PoCL or any device) and as C++17 on the host, so host
 * tests exercise exactly the math the kernels run. Rules:
 *  - functions are UB_INLINE, take scalars or UB_* structs, never pointers to
 *    host memory unless marked UB_GLOBAL / UB_PRIVATE;
 *  - math through the ub_* wrappers below (OpenCL has overloaded sqrt etc.,
 *    C++ uses std::);
 *  - fixed-size scalars only (float, uint32_t via ub_uint), no double.
 */
#ifndef UB_DEFS_H
#define UB_DEFS_H

/* __OPENCL_C_VERSION__ is defined by every OpenCL C compiler (1.2 and later). Functions
 * are static inline so that each program or translation unit has its own copy. */
#ifdef __OPENCL_C_VERSION__
#define UB_INLINE static inline
#define UB_GLOBAL __global
#define UB_PRIVATE __private
typedef uint ub_uint;
#define ub_sqrt(x) sqrt(x)
#define ub_exp(x) exp(x)
#define ub_pow(x, y) pow(x, y)
#define ub_fabs(x) fabs(x)
#define ub_fmin(x, y) fmin(x, y)
#define ub_fmax(x, y) fmax(x, y)
#define ub_cos(x) cos(x)
#define ub_sin(x) sin(x)
#define ub_atan2(y, x) atan2(y, x)
#define ub_acos(x) acos(x)
#define ub_log(x) log(x)
#define ub_floor(x) floor(x)
#define ub_erf(x) erf(x)
#define ub_erfc(x) erfc(x)
#else
#include <cmath>
#include <cstdint>
#define UB_INLINE static inline
#define UB_GLOBAL
#define UB_PRIVATE
typedef uint32_t ub_uint;
#define ub_sqrt(x) std::sqrt(x)
#define ub_exp(x) std::exp(x)
#define ub_pow(x, y) std::pow(x, y)
#define ub_fabs(x) std::fabs(x)
#define ub_fmin(x, y) std::fmin(x, y)
#define ub_fmax(x, y) std::fmax(x, y)
#define ub_cos(x) std::cos(x)
#define ub_sin(x) std::sin(x)
#define ub_atan2(y, x) std::atan2(y, x)
#define ub_acos(x) std::acos(x)
#define ub_log(x) std::log(x)
#define ub_floor(x) std::floor(x)
#define ub_erf(x) std::erf(x)
#define ub_erfc(x) std::erfc(x)
#endif

/* A record aligned to a cache line (typedef struct UB_CACHE_ALIGNED {...} name;): a 128-byte
 * BVH node or block of keys then spans two 64-byte lines, not three when it starts mid-line
 * (malloc aligns to 16). Host vectors of such records allocate aligned (C++17); device buffers
 * are the runtime's (CL_MEM_USE_HOST_PTR: the host vector's). Sizes and offsets do not change. */
#ifdef __OPENCL_C_VERSION__
#define UB_CACHE_ALIGNED __attribute__((aligned(64)))
#else
#define UB_CACHE_ALIGNED alignas(64)
#endif

#define UB_PI 3.14159265358979323846f
#define UB_INV_PI 0.31830988618379067154f

UB_INLINE float ub_clampf(float x, float lo, float hi) {
    return ub_fmin(ub_fmax(x, lo), hi);
}
UB_INLINE float ub_sqr(float x) {
    return x * x;
}

#endif /* UB_DEFS_H */
