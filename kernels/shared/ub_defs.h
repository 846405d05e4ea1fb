/* Portability layer for code shared by host C++ and OpenCL C.
 *
 * Headers in kernels/shared/ are written in a C99 subset that compiles both
 * as OpenCL C 1.2 (on PoCL or any device) and as C++17 on the host, so host
 * tests exercise exactly the math the kernels run. Rules:
 *  - functions are UB_INLINE (UB_INLINE_HOT: forced inline on the host), take
 *    scalars or UB_* structs, never pointers to host memory unless marked
 *    UB_GLOBAL / UB_PRIVATE;
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
#define UB_INLINE_HOT static inline /* see the host's definition below */
#define UB_GLOBAL __global
#define UB_PRIVATE __private
typedef uint ub_uint;
#define ub_sqrt(x) sqrt(x)
/* PoCL's exp() is a slow routine on its CPU devices (about 40% of the bb1d kernel's pair
 * evaluation, perf with -g; docs/performance.md, session 38): there the kernels take
 * ub_exp_poly (below, within one ulp), and other device compilers (a GPU's) their own exp. */
#if defined(__clang__) && defined(__x86_64__) && !defined(UB_LIBRARY_EXP)
#define ub_exp(x) ub_exp_poly(x)
#else
#define ub_exp(x) exp(x)
#endif
#define ub_pow(x, y) pow(x, y)
#define ub_fabs(x) fabs(x)
#define ub_fmin(x, y) fmin(x, y)
#define ub_fmax(x, y) fmax(x, y)
#define ub_cos(x) cos(x)
#define ub_sin(x) sin(x)
#define ub_atan2(y, x) atan2(y, x)
#define ub_acos(x) acos(x)
#define ub_log(x) log(x)
/* PoCL's floor() is a software routine with three branches; clang's builtin is one roundss.
 * Only for clang's x86-64 targets (PoCL's CPU devices): a GPU's floor() is its own instruction
 * already, and its driver's compiler need not know the builtin. */
#if defined(__clang__) && defined(__x86_64__)
#define ub_floor(x) __builtin_floorf(x)
#else
#define ub_floor(x) floor(x)
#endif
#define ub_rint(x) rint(x)
#define ub_erf(x) erf(x)
#define ub_erfc(x) erfc(x)
/* Before a loop of a fixed small count (colour channels, a BVH node's four children, a
 * query's eight hash cells): unroll it. PoCL 3.1 left such loops rolled, with their arrays
 * on the stack: the pb2d kernel's MIS sum over four techniques and its homogeneous segment's
 * three channels ran as loops through memory (perf annotate). Unrolled, the pp3d kernels took
 * 0.69-0.93 of their time and several bp2d kernels 0.81-0.90; the candle's pb2d replay went
 * from 0.94 to 0.93-1.01 of its host twin (docs/performance.md, session 47). Host compilers
 * unroll these already (UB_UNROLL is empty there). */
#define UB_UNROLL _Pragma("unroll")
#else
#include <cmath>
#include <cstdint>
#include <cstring>
#define UB_INLINE static inline
/* A function of a twin's inner loop that GCC keeps out of line for its size. It then copied
 * its by-value records (two 96-byte beams, the MIS constants) for each call: bb1d's pair
 * contribution was 5.8% of the bunny's `upbp:bb1d` samples on its own. Inlined, the host
 * twin's pass took 0.95-0.96 of its time, against the kernel's pass in the same processes
 * (bunny, mirrorballs; docs/performance.md, session 48). OpenCL compilers inline these
 * already. */
#define UB_INLINE_HOT static inline __attribute__((always_inline))
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
#define ub_rint(x) std::rint(x)
#define ub_erf(x) std::erf(x)
#define ub_erfc(x) std::erfc(x)
#define UB_UNROLL /* host compilers unroll these loops themselves */
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

/* A hint to start loading the cache line of address p. The host twins use the compiler's
 * builtin. In OpenCL C, `prefetch()` does nothing on PoCL, so on a clang-built x86-64 or
 * AArch64 device compiler (PoCL's CPU devices) the kernels take the clang builtin, which
 * becomes the CPU's prefetch instruction; other device compilers get no hint. */
#if !defined(__OPENCL_C_VERSION__) || \
    (defined(__clang__) && (defined(__x86_64__) || defined(__aarch64__)))
#define UB_PREFETCH(p) __builtin_prefetch(p)
#else
#define UB_PREFETCH(p) ((void)0)
#endif

#ifdef __OPENCL_C_VERSION__
/* Bit j set where lane j of a vector comparison (-1 true, 0 false) is true. On clang's x86
 * targets (PoCL's CPU devices) one movmskps: LLVM 15 compiles the portable form, four ands and
 * three ors of the lanes, to nine extracts and ors, about 5% of the bb1d kernel's samples
 * (perf; docs/performance.md, session 34). The result is the same either way (UB_PORTABLE_LANE_MASK
 * forces the portable form; tests/opencl_headers_test.cpp runs both). */
#if defined(__clang__) && defined(__SSE__) && !defined(UB_PORTABLE_LANE_MASK)
typedef float ub_v4sf __attribute__((vector_size(16)));
UB_INLINE ub_uint ub_lane_mask4(int4 v) {
    return (ub_uint)__builtin_ia32_movmskps((ub_v4sf)as_float4(v));
}
#else
UB_INLINE ub_uint ub_lane_mask4(int4 v) {
    return (ub_uint)((v.x & 1) | (v.y & 2) | (v.z & 4) | (v.w & 8));
}
#endif
#if defined(__clang__) && defined(__AVX__) && !defined(UB_PORTABLE_LANE_MASK)
typedef float ub_v8sf __attribute__((vector_size(32)));
UB_INLINE ub_uint ub_lane_mask8(int8 v) {
    return (ub_uint)__builtin_ia32_movmskps256((ub_v8sf)as_float8(v));
}
#else
UB_INLINE ub_uint ub_lane_mask8(int8 v) {
    return ub_lane_mask4(v.lo) | ub_lane_mask4(v.hi) << 4;
}
#endif
#endif

#define UB_PI 3.14159265358979323846f
#define UB_INV_PI 0.31830988618379067154f

UB_INLINE float ub_clampf(float x, float lo, float hi) {
    return ub_fmin(ub_fmax(x, lo), hi);
}
UB_INLINE float ub_sqr(float x) {
    return x * x;
}

/* The float whose bits are u. */
UB_INLINE float ub_float_from_bits(ub_uint u) {
#ifdef __OPENCL_C_VERSION__
    return as_float(u);
#else
    float f;
    std::memcpy(&f, &u, sizeof f);
    return f;
#endif
}

/* exp(x) in float arithmetic, within one ulp of the exact value where exp is a normal float
 * (0.99 ulp at most, on every seventh float of that range when it was written;
 * tests/opencl_headers_test.cpp checks every 61st, and that a PoCL kernel gives the same bits),
 * for the kernels on PoCL's CPU devices (ub_exp).
 * Cody and Waite's reduction: k = round(x / ln 2), r = x - k ln 2 with ln 2 in two parts, the
 * first with nine trailing zero bits so that k * ln2Hi is exact (|k| <= 150); then
 * exp(r) = 1 + r + r^2 P(r) on |r| <= ln 2 / 2, P the degree-5 minimax polynomial of the Cephes
 * library's expf (S. L. Moshier); 2^k as two powers of two, so that k = 128 overflows to inf
 * and k down to -150 gives denormals, as exp() does. Below -104 the result is 0, above 89 inf;
 * NaN stays NaN. (In PoCL's bb1d kernel this form is as fast as one without those ends; rounding
 * by adding and subtracting 1.5 * 2^23, or k / 2 for k >> 1, lost most of the gain.) */
UB_INLINE float ub_exp_poly(float x) {
    float xc = x > -104.0f ? x : -104.0f; /* NaN: -104, then returned as x below */
    xc = xc < 89.0f ? xc : 89.0f;
    const float kf = ub_rint(xc * 1.44269504088896341f);
    const float r = (xc - kf * 0.693145751953125f) - kf * 1.428606765330187045e-06f;
    float p = 1.9875691500e-4f;
    p = p * r + 1.3981999507e-3f;
    p = p * r + 8.3334519073e-3f;
    p = p * r + 4.1665795894e-2f;
    p = p * r + 1.6666665459e-1f;
    p = p * r + 5.0000001201e-1f;
    p = p * r * r + r + 1.0f;
    const int k = (int)kf, k1 = k >> 1, k2 = k - k1;
    const float e = (p * ub_float_from_bits((ub_uint)(k1 + 127) << 23)) *
                    ub_float_from_bits((ub_uint)(k2 + 127) << 23);
    return x == x ? e : x;
}

#endif /* UB_DEFS_H */
