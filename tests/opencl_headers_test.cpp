// Every header in kernels/shared/ must compile as OpenCL C (DESIGN.md: the math
// shared by host and kernels is written once). Each header is built as its own
// OpenCL C 1.2 program on the first available OpenCL device (PoCL on the CPU by
// default, installed by scripts/setup.sh), with a probe kernel so the program is
// not empty. A missing OpenCL platform is a failure with a clear message, never a skip.
#include <gtest/gtest.h>

#define CL_TARGET_OPENCL_VERSION 120
#include <CL/cl.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include "kernels/shared/ub_defs.h"
#include "kernels/shared/ub_medium_homogeneous.h"

namespace {

struct ClDevice {
    cl_platform_id platform = nullptr;
    cl_device_id device = nullptr;
    std::string description;
    std::string error;
};

// First platform with any device; prefers a CPU device (PoCL) so results do not
// depend on which GPU driver happens to be installed.
ClDevice findDevice() {
    ClDevice out;
    cl_uint np = 0;
    if (clGetPlatformIDs(0, nullptr, &np) != CL_SUCCESS || np == 0) {
        out.error =
            "no OpenCL platform found (install PoCL: scripts/setup.sh installs "
            "pocl-opencl-icd; check /etc/OpenCL/vendors)";
        return out;
    }
    std::vector<cl_platform_id> platforms(np);
    clGetPlatformIDs(np, platforms.data(), nullptr);
    for (cl_device_type type :
         {cl_device_type(CL_DEVICE_TYPE_CPU), cl_device_type(CL_DEVICE_TYPE_ALL)}) {
        for (cl_platform_id p : platforms) {
            cl_device_id d = nullptr;
            cl_uint nd = 0;
            if (clGetDeviceIDs(p, type, 1, &d, &nd) == CL_SUCCESS && nd > 0) {
                char name[256] = {0}, pname[256] = {0};
                clGetDeviceInfo(d, CL_DEVICE_NAME, sizeof(name) - 1, name, nullptr);
                clGetPlatformInfo(p, CL_PLATFORM_NAME, sizeof(pname) - 1, pname, nullptr);
                out.platform = p;
                out.device = d;
                out.description = std::string(pname) + " / " + name;
                return out;
            }
        }
    }
    out.error = "OpenCL platforms exist but none has a device";
    return out;
}

std::vector<std::string> sharedHeaders() {
    namespace fs = std::filesystem;
    std::vector<std::string> out;
    fs::path dir = fs::path(UNIBEAM_SOURCE_DIR) / "kernels" / "shared";
    for (const auto& e : fs::directory_iterator(dir))
        if (e.path().extension() == ".h") out.push_back(e.path().filename().string());
    std::sort(out.begin(), out.end());
    return out;
}

}  // namespace

TEST(OpenClHeaders, EverySharedHeaderBuildsAsOpenClC) {
    ClDevice dev = findDevice();
    ASSERT_TRUE(dev.error.empty()) << dev.error;
    cl_int err = CL_SUCCESS;
    cl_context ctx = clCreateContext(nullptr, 1, &dev.device, nullptr, nullptr, &err);
    ASSERT_EQ(err, CL_SUCCESS) << "clCreateContext failed on " << dev.description;

    const std::string includeDir = std::string(UNIBEAM_SOURCE_DIR) + "/kernels/shared";
    ASSERT_EQ(includeDir.find(' '), std::string::npos)
        << "the OpenCL include path must not contain spaces: " << includeDir;
    const std::vector<std::string> headers = sharedHeaders();
    ASSERT_FALSE(headers.empty()) << "no headers found in " << includeDir;
    for (const std::string& h : headers) {
        SCOPED_TRACE(h);
        std::string src = "#include \"" + h +
                          "\"\n__kernel void ub_header_probe(__global int* o) { o[0] = 1; }\n";
        const char* s = src.c_str();
        size_t len = src.size();
        cl_program prog = clCreateProgramWithSource(ctx, 1, &s, &len, &err);
        ASSERT_EQ(err, CL_SUCCESS);
        // PoCL does not strip quotes from -I; the source path must not contain spaces.
        // NanoVDB's C header (ub_grid_medium.h includes it) from libnanovdb-dev.
        std::string options =
            "-cl-std=CL1.2 -I" + includeDir + " -I" + std::string(UNIBEAM_CNANOVDB_DIR);
        cl_int buildErr = clBuildProgram(prog, 1, &dev.device, options.c_str(), nullptr, nullptr);
        size_t logSize = 0;
        clGetProgramBuildInfo(prog, dev.device, CL_PROGRAM_BUILD_LOG, 0, nullptr, &logSize);
        std::string log(logSize, '\0');
        if (logSize > 0)
            clGetProgramBuildInfo(prog, dev.device, CL_PROGRAM_BUILD_LOG, logSize, log.data(),
                                  nullptr);
        while (!log.empty() && log.back() == '\0') log.pop_back();
        EXPECT_EQ(buildErr, CL_SUCCESS)
            << "kernels/shared/" << h << " does not build as OpenCL C on " << dev.description
            << ":\n"
            << log;
        clReleaseProgram(prog);
    }
    clReleaseContext(ctx);
}

// OpenCL C 1.2 has no variadic macros. PoCL's clang accepts them silently, NVIDIA's
// compiler rejects the program ("variadic macros not supported in OpenCL", seen on an
// H200 with driver 580.159.04, docs/opencl.md), so the sources are checked here, where
// CI has no GPU driver.
TEST(OpenClHeaders, KernelSourcesUseNoVariadicMacros) {
    namespace fs = std::filesystem;
    const std::regex variadic(R"(#\s*define\s+\w+\([^)]*\.\.\.\s*\)|__VA_ARGS__)");
    int files = 0;
    for (const char* sub : {"kernels", "kernels/shared"}) {
        for (const auto& e : fs::directory_iterator(fs::path(UNIBEAM_SOURCE_DIR) / sub)) {
            const std::string ext = e.path().extension().string();
            if (ext != ".cl" && ext != ".h") continue;
            ++files;
            std::ifstream in(e.path());
            std::string line;
            for (int n = 1; std::getline(in, line); ++n)
                EXPECT_FALSE(std::regex_search(line, variadic))
                    << e.path().string() << ":" << n << ": a variadic macro: " << line;
        }
    }
    EXPECT_GE(files, 20);
}

// Builds `src` as OpenCL C 1.2 on findDevice()'s device, with kernels/shared on the include path
// and `options` added, runs kernel `name` over `global` work-items with one argument, a buffer of
// out->size() uints, and reads the buffer back into *out. Any OpenCL error fails the test.
static void runUintKernel(const std::string& src, const char* name, const std::string& options,
                          size_t global, std::vector<cl_uint>* out) {
    ClDevice dev = findDevice();
    ASSERT_TRUE(dev.error.empty()) << dev.error;
    cl_int err = CL_SUCCESS;
    cl_context ctx = clCreateContext(nullptr, 1, &dev.device, nullptr, nullptr, &err);
    ASSERT_EQ(err, CL_SUCCESS) << "clCreateContext failed on " << dev.description;
    cl_command_queue queue = clCreateCommandQueue(ctx, dev.device, 0, &err);
    ASSERT_EQ(err, CL_SUCCESS);
    const char* s = src.c_str();
    size_t len = src.size();
    cl_program prog = clCreateProgramWithSource(ctx, 1, &s, &len, &err);
    ASSERT_EQ(err, CL_SUCCESS);
    const std::string all =
        "-cl-std=CL1.2 -I" + std::string(UNIBEAM_SOURCE_DIR) + "/kernels/shared" + options;
    if (clBuildProgram(prog, 1, &dev.device, all.c_str(), nullptr, nullptr) != CL_SUCCESS) {
        size_t logSize = 0;
        clGetProgramBuildInfo(prog, dev.device, CL_PROGRAM_BUILD_LOG, 0, nullptr, &logSize);
        std::string log(logSize, '\0');
        clGetProgramBuildInfo(prog, dev.device, CL_PROGRAM_BUILD_LOG, logSize, log.data(), nullptr);
        FAIL() << "build failed, options: " << all << "\n" << log;
    }
    cl_kernel kernel = clCreateKernel(prog, name, &err);
    ASSERT_EQ(err, CL_SUCCESS);
    cl_mem buf =
        clCreateBuffer(ctx, CL_MEM_WRITE_ONLY, out->size() * sizeof(cl_uint), nullptr, &err);
    ASSERT_EQ(err, CL_SUCCESS);
    ASSERT_EQ(clSetKernelArg(kernel, 0, sizeof(buf), &buf), CL_SUCCESS);
    ASSERT_EQ(
        clEnqueueNDRangeKernel(queue, kernel, 1, nullptr, &global, nullptr, 0, nullptr, nullptr),
        CL_SUCCESS);
    ASSERT_EQ(clEnqueueReadBuffer(queue, buf, CL_TRUE, 0, out->size() * sizeof(cl_uint),
                                  out->data(), 0, nullptr, nullptr),
              CL_SUCCESS);
    clReleaseMemObject(buf);
    clReleaseKernel(kernel);
    clReleaseProgram(prog);
    clReleaseCommandQueue(queue);
    clReleaseContext(ctx);
}

// ub_lane_mask4 / ub_lane_mask8 (kernels/shared/ub_defs.h) give bit j for a true lane j: every
// pattern of four and of eight lanes, in the movmskps form PoCL's x86 devices take and in the
// portable form (UB_PORTABLE_LANE_MASK) other devices take.
TEST(OpenClHeaders, LaneMasksGiveOneBitPerTrueLane) {
    const std::string src = R"(#include "ub_defs.h"
__kernel void ub_lane_masks(__global uint* out) {
    uint i = get_global_id(0);
    int8 v = (int8)(0) - (int8)((int)(i & 1u), (int)(i >> 1 & 1u), (int)(i >> 2 & 1u),
                                (int)(i >> 3 & 1u), (int)(i >> 4 & 1u), (int)(i >> 5 & 1u),
                                (int)(i >> 6 & 1u), (int)(i >> 7 & 1u));
    out[2u * i] = ub_lane_mask8(v);
    out[2u * i + 1u] = ub_lane_mask4(v.lo);
})";
    for (const char* variant : {"", " -DUB_PORTABLE_LANE_MASK"}) {
        SCOPED_TRACE(std::string("options:") + variant);
        std::vector<cl_uint> out(512, 0xdeadbeefu);
        ASSERT_NO_FATAL_FAILURE(runUintKernel(src, "ub_lane_masks", variant, 256, &out));
        for (cl_uint i = 0; i < 256; ++i) {
            EXPECT_EQ(out[2 * i], i) << "eight lanes, pattern " << i;
            EXPECT_EQ(out[2 * i + 1], i & 15u) << "four lanes, pattern " << i;
        }
    }
}

// ub_hash_buckets8, the kernels' form of ub_hash_buckets (kernels/shared/ub_hash_grid.h), gives
// the same buckets in the same order. Bucket counts of 1 to 64 make two cells of a block share a
// bucket often, so the duplicate test is exercised, and 2^20 rarely.
TEST(OpenClHeaders, HashBuckets8EqualsHashBuckets) {
    // Work-item i: a point on a lattice of 1/7 cells around the origin, buckets 2^(i % 7),
    // or 2^20 for i % 7 == 6. out[18 i ...]: both counts, then both bucket lists.
    const std::string src = R"(#include "ub_hash_grid.h"
__kernel void ub_hash_pair(__global uint* out) {
    uint i = get_global_id(0);
    ub_hash_grid g;
    g.lo[0] = -1.0f; g.lo[1] = -2.0f; g.lo[2] = -3.0f;
    g.invCellSize = 0.5f;
    g.radiusSqr = 1.0f;
    g.cellCount = i % 7u == 6u ? (1u << 20) : (1u << (i % 7u));
    g.pad0 = g.pad1 = 0u;
    ub_float3 q = ub_make_float3((float)(i % 23u) / 7.0f - 1.5f, (float)(i / 23u % 19u) / 7.0f,
                                 (float)(i / 437u) / 7.0f - 3.0f);
    uint a[8], b[8];
    for (int k = 0; k < 8; ++k) a[k] = b[k] = 0xffffffffu;
    int na = ub_hash_buckets(g, q, a), nb = ub_hash_buckets8(g, q, b);
    out[18u * i] = (uint)na;
    out[18u * i + 1u] = (uint)nb;
    for (int k = 0; k < 8; ++k) {
        out[18u * i + 2u + k] = k < na ? a[k] : 0xffffffffu;
        out[18u * i + 10u + k] = k < nb ? b[k] : 0xffffffffu;
    }
})";
    const size_t n = 23 * 19 * 12;
    std::vector<cl_uint> out(18 * n, 0);
    ASSERT_NO_FATAL_FAILURE(runUintKernel(src, "ub_hash_pair", "", n, &out));
    int withDuplicates = 0;
    for (size_t i = 0; i < n; ++i) {
        const cl_uint* r = &out[18 * i];
        ASSERT_EQ(r[0], r[1]) << "point " << i;
        for (int k = 0; k < 8; ++k)
            ASSERT_EQ(r[2 + k], r[10 + k]) << "point " << i << " bucket " << k;
        withDuplicates += r[0] < 8 ? 1 : 0;
    }
    EXPECT_GT(withDuplicates, int(n / 2));  // the duplicate test ran
    EXPECT_LT(withDuplicates, int(n));      // and so did the case without duplicates
}

// ub_pb2d_near8_global (kernels/shared/ub_pb2d.h), the pb2d kernel's test of two blocks of
// photon keys at once, gives block k[0]'s mask in bits 0-3 and block k[1]'s in bits 4-7, and the
// same beam parameters, bit for bit, as ub_pb2d_near4_global on each block. The photons lie
// around a beam at distances on both sides of the radius, some before its origin or past its
// end, some in another medium.
TEST(OpenClHeaders, Pb2dNear8EqualsTwoBlocksOfFour) {
    // Work-item i writes its two blocks into out[64 i ...] (32 words), then the masks (3 words)
    // and both sets of parameters (16 words) after them.
    const std::string src = R"(#include "ub_pb2d.h"
__kernel void ub_pb2d_pair8(__global uint* out) {
    uint i = get_global_id(0);
    __global uint* o = out + 64u * i;
    __global ub_photon_keys4* k = (__global ub_photon_keys4*)o;
    uint s = i * 2654435761u + 12345u;
    ub_float3 origin = ub_make_float3(0.1f * (float)(i % 7u), -0.2f, 0.3f);
    ub_float3 dir = ub_f3_normalize(ub_make_float3(1.0f, 0.5f * (float)(i % 3u) - 0.5f, 0.25f));
    for (int j = 0; j < 8; ++j) {
        s = s * 1664525u + 1013904223u;
        float along = (float)(s >> 8) * (1.0f / 16777216.0f) * 1.4f - 0.2f; /* -0.2 .. 1.2 */
        s = s * 1664525u + 1013904223u;
        float off = (float)(s >> 8) * (1.0f / 16777216.0f) * 0.2f;         /* 0 .. 0.2 */
        ub_float3 side = ub_f3_normalize(ub_f3_cross(dir, ub_make_float3(0.0f, 0.0f, 1.0f)));
        ub_float3 p = ub_f3_add(ub_f3_add(origin, ub_f3_scale(dir, along)), ub_f3_scale(side, off));
        k[j / 4].px[j % 4] = p.x;
        k[j / 4].py[j % 4] = p.y;
        k[j / 4].pz[j % 4] = p.z;
        k[j / 4].mediumId[j % 4] = (s >> 28) == 0u ? 2u : 1u;
    }
    float t8[8], t4[8];
    uint m8 = ub_pb2d_near8_global(k, origin, dir, 1.0f, 1u, 0.01f, t8);
    uint a = ub_pb2d_near4_global(k, origin, dir, 1.0f, 1u, 0.01f, t4);
    uint b = ub_pb2d_near4_global(k + 1, origin, dir, 1.0f, 1u, 0.01f, t4 + 4);
    o[32] = m8;
    o[33] = a;
    o[34] = b;
    for (int j = 0; j < 8; ++j) {
        o[35 + j] = as_uint(t8[j]);
        o[43 + j] = as_uint(t4[j]);
    }
})";
    const size_t n = 4096;
    std::vector<cl_uint> out(64 * n, 0);
    ASSERT_NO_FATAL_FAILURE(runUintKernel(src, "ub_pb2d_pair8", "", n, &out));
    int near = 0, far = 0;
    for (size_t i = 0; i < n; ++i) {
        const cl_uint* r = &out[64 * i + 32];
        ASSERT_EQ(r[0], r[1] | r[2] << 4) << "work-item " << i;
        for (int j = 0; j < 8; ++j) ASSERT_EQ(r[3 + j], r[11 + j]) << "work-item " << i;
        near += __builtin_popcount(r[0]);
        far += 8 - __builtin_popcount(r[0]);
    }
    EXPECT_GT(near, int(n));  // both outcomes occur often
    EXPECT_GT(far, int(n));
}

namespace {

// Bits of the float x_i of ub_exp_poly's test points: i < n/2 from -0 down to -104, the rest from
// +0 up to 89, evenly spaced in their bit patterns (so in ulps), the same integer arithmetic on
// the host and in the kernel below.
constexpr cl_uint kExpNeg = 0x80000000u, kExpNegEnd = 0xc2d00000u;  // -0, -104
constexpr cl_uint kExpPosEnd = 0x42b20000u;                         // 89
cl_uint expTestBits(cl_uint i, cl_uint n) {
    const cl_uint half = n / 2u;
    return i < half ? kExpNeg + i * ((kExpNegEnd - kExpNeg) / half)
                    : (i - half) * (kExpPosEnd / half);
}

// |got - exact| in ulps of the float nearest the exact value (for denormal results, the
// denormal spacing).
double ulpError(float got, double exact) {
    const float nearest = float(exact);
    double ulp = double(std::nextafter(nearest, INFINITY)) - double(nearest);
    if (!(ulp > 0.0)) ulp = double(std::nextafter(nearest, -INFINITY)) - double(nearest);
    return std::fabs(double(got) - exact) / std::fabs(ulp);
}

}  // namespace

// ub_exp_poly (kernels/shared/ub_defs.h), the kernels' exp on PoCL's CPU devices, is within one
// ulp of exp over the range where exp is neither 0 nor inf, gives exp's values at the ends and
// for the special inputs, and a kernel computes the same bits as the host.
TEST(OpenClHeaders, ExpPolyIsWithinOneUlpAndTheSameOnTheDevice) {
    // Host: one float in 61 where exp is a normal float, -87.34 to 88.72 (about 34 million),
    // against exp in double. (unibeam flushes denormals to zero, src/scene/scene.cpp, so below
    // -87.34 both exp and ub_exp_poly give 0 in this process.)
    double worst = 0.0;
    float worstAt = 0.0f;
    auto check = [&](cl_uint u) {
        float x;
        std::memcpy(&x, &u, sizeof x);
        const double e = ulpError(ub_exp_poly(x), std::exp(double(x)));
        if (e > worst) {
            worst = e;
            worstAt = x;
        }
    };
    for (cl_uint u = kExpNeg; u <= 0xc2aeac4fu; u += 61u) check(u);  // down to -87.34
    for (cl_uint u = 0u; u <= 0x42b17217u; u += 61u) check(u);       // up to 88.72: below FLT_MAX
    EXPECT_LE(worst, 1.0) << "at x = " << worstAt;
    EXPECT_GT(worst, 0.5) << "the sweep did not reach a rounding error";  // it ran
    EXPECT_EQ(ub_exp_poly(0.0f), 1.0f);
    EXPECT_EQ(ub_exp_poly(-0.0f), 1.0f);
    EXPECT_EQ(ub_exp_poly(-INFINITY), 0.0f);
    EXPECT_EQ(ub_exp_poly(-110.0f), 0.0f);
    EXPECT_EQ(ub_exp_poly(89.0f), INFINITY);
    EXPECT_EQ(ub_exp_poly(INFINITY), INFINITY);
    EXPECT_TRUE(std::isnan(ub_exp_poly(NAN)));

    // Device: the same source, the program's floating-point mode (no contraction).
    const std::string src = R"(#pragma OPENCL FP_CONTRACT OFF
#include "ub_defs.h"
__kernel void ub_exp_bits(__global uint* out) {
    uint i = get_global_id(0), n = get_global_size(0), h = n / 2u;
    uint u = i < h ? 0x80000000u + i * ((0xc2d00000u - 0x80000000u) / h) : (i - h) * (0x42b20000u / h);
    out[i] = as_uint(ub_exp_poly(as_float(u)));
})";
    const cl_uint n = 1u << 20;
    std::vector<cl_uint> out(n, 0u);
    ASSERT_NO_FATAL_FAILURE(runUintKernel(src, "ub_exp_bits", "", n, &out));
    // Compared where exp is a normal float: below, this process flushes denormal results to
    // zero and PoCL's kernels (which set their own floating-point mode) need not.
    int differ = 0, compared = 0;
    for (cl_uint i = 0; i < n; ++i) {
        const cl_uint u = expTestBits(i, n);
        float x;
        std::memcpy(&x, &u, sizeof x);
        if (x < -87.33654f) continue;
        ++compared;
        const float host = ub_exp_poly(x);
        cl_uint hostBits;
        std::memcpy(&hostBits, &host, sizeof hostBits);
        if (out[i] != hostBits && ++differ <= 5)
            ADD_FAILURE() << "x = " << x << ": device bits " << out[i] << ", host " << hostBits;
    }
    EXPECT_EQ(differ, 0);
    EXPECT_GT(compared, int(n / 2) + int(n / 3));
}

namespace {
// Code compiled here and, as the text of the same tokens, in a kernel.
#define UB_HOST_AND_DEVICE(text, ...) \
    __VA_ARGS__                       \
    const char* const text = #__VA_ARGS__;

// Pair j of case i: distances from i and j, up to about 40 mean free paths; odd i: a grey medium.
// Counts the transmittances where ub_homogeneous_transmittances and ub_homogeneous_segment_cp
// differ (no NaN or -0 among them: != compares their bits).
UB_HOST_AND_DEVICE(
    kPairsSource, UB_INLINE ub_uint ub_pairs_mismatches(ub_uint i) {
        ub_medium_info m;
        m.sigmaT[0] = 0.7f;
        m.sigmaT[1] = (i & 1u) ? 0.7f : 1.3f;
        m.sigmaT[2] = (i & 1u) ? 0.7f : 0.05f;
        m.sigmaS[0] = m.sigmaS[1] = m.sigmaS[2] = 0.5f;
        m.g = 0.0f;
        m.homogeneous = 1u;
        int n = (int)(i % 32u) + 1;
        float t0[32], t1[32], T[3 * 32];
        for (int j = 0; j < n; ++j) {
            t0[j] = (float)((i * 37u + (ub_uint)j * 11u) % 1000u) * 0.0571f;
            t1[j] = (float)((i * 13u + (ub_uint)j * 29u) % 1000u) * 0.0313f;
        }
        ub_uint bad = 0u;
        ub_homogeneous_transmittances(m, t0, n, T);
        for (int j = 0; j < n; ++j) {
            ub_segment_eval e0 = ub_homogeneous_segment_cp(m, t0[j], 1.0f);
            for (int a = 0; a < 3; ++a) bad += T[3 * j + a] != e0.transmittance[a] ? 1u : 0u;
        }
        ub_homogeneous_transmittances(m, t1, n, T);
        for (int j = 0; j < n; ++j) {
            ub_segment_eval e1 = ub_homogeneous_segment_cp(m, t1[j], 1.0f);
            for (int a = 0; a < 3; ++a) bad += T[3 * j + a] != e1.transmittance[a] ? 1u : 0u;
        }
        return bad;
    })
}  // namespace

// ub_homogeneous_transmittances (bb1d's and pb2d's kernels: the exponentials of a flush's pairs in
// one loop) gives the transmittances of ub_homogeneous_segment_cp at each distance, bit for bit,
// for 1 to 32 distances (both beams' of bb1d's pairs) in a grey and a coloured medium, on the host
// and on the device.
TEST(OpenClHeaders, TransmittancePairsEqualTheSegmentsOneByOne) {
    const cl_uint n = 4096;
    cl_uint hostBad = 0;
    for (cl_uint i = 0; i < n; ++i) hostBad += ub_pairs_mismatches(i);
    EXPECT_EQ(hostBad, 0u);
    const std::string src = std::string(
                                "#pragma OPENCL FP_CONTRACT OFF\n"
                                "#include \"ub_medium_homogeneous.h\"\n") +
                            kPairsSource + R"(
__kernel void ub_pairs(__global uint* out) {
    uint i = get_global_id(0);
    out[i] = ub_pairs_mismatches(i);
})";
    std::vector<cl_uint> out(n, 1u);
    ASSERT_NO_FATAL_FAILURE(runUintKernel(src, "ub_pairs", "", n, &out));
    cl_uint deviceBad = 0;
    for (cl_uint v : out) deviceBad += v;
    EXPECT_EQ(deviceBad, 0u);
}
