// OpenCL runtime (see cl_runtime.h).
#include "cl/cl_runtime.h"

#include <unistd.h>

#include <algorithm>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>

#include "cl/embedded_kernels.h"
#include "cl/library_pages.h"
#include "core/file_status.h"
#include "estimators/bvh.h"
#include "estimators/hash_grid.h"
#include "estimators/screen_tiles.h"

namespace ub {

namespace {

std::string clString(cl_device_id d, cl_device_info what) {
    size_t n = 0;
    if (clGetDeviceInfo(d, what, 0, nullptr, &n) != CL_SUCCESS || n == 0) return "";
    std::string s(n, '\0');
    clGetDeviceInfo(d, what, n, &s[0], nullptr);
    while (!s.empty() && s.back() == '\0') s.pop_back();
    return s;
}

std::string platformString(cl_platform_id p, cl_platform_info what) {
    size_t n = 0;
    if (clGetPlatformInfo(p, what, 0, nullptr, &n) != CL_SUCCESS || n == 0) return "";
    std::string s(n, '\0');
    clGetPlatformInfo(p, what, n, &s[0], nullptr);
    while (!s.empty() && s.back() == '\0') s.pop_back();
    return s;
}

void check(cl_int err, const char* what) {
    if (err == CL_SUCCESS) return;
    std::string msg =
        std::string("OpenCL: ") + what + " failed (error " + std::to_string(err) + ")";
    if (err == CL_OUT_OF_RESOURCES || err == CL_MEM_OBJECT_ALLOCATION_FAILURE ||
        err == CL_OUT_OF_HOST_MEMORY)
        msg += ": the device is out of resources (a smaller --resolution needs less)";
    throw ClError(msg);
}

/// The text of kernel file `name`: embedded, or read from $UNIBEAM_KERNEL_DIR (and its
/// shared/ folder) when that developer option is set, so kernels can be edited without a
/// rebuild. False if there is no such file.
bool kernelText(const std::string& name, std::string* text) {
    if (const char* dir = std::getenv("UNIBEAM_KERNEL_DIR")) {
        for (const std::string& path :
             {std::string(dir) + "/" + name, std::string(dir) + "/shared/" + name}) {
            std::ifstream in(path, std::ios::binary);
            if (in) {
                std::ostringstream ss;
                ss << in.rdbuf();
                *text = ss.str();
                return true;
            }
        }
        return false;
    }
    for (size_t i = 0; i < kEmbeddedKernelFileCount; ++i)
        if (name == kEmbeddedKernelFiles[i].name) {
            *text = kEmbeddedKernelFiles[i].text;
            return true;
        }
    return false;
}

/// FNV-1a, 64 bits: a stable key for cache file names (std::hash is not stable).
uint64_t fnv1a(const std::string& s, uint64_t h = 1469598103934665603ull) {
    for (unsigned char c : s) {
        h ^= c;
        h *= 1099511628211ull;
    }
    return h;
}

std::string defaultCacheDir() {
    if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x)
        return std::string(x) + "/unibeam/opencl";
    if (const char* home = std::getenv("HOME"); home && *home)
        return std::string(home) + "/.cache/unibeam/opencl";
    return "";
}

/// Cache file layout: magic, the key, the binary's size, the binary, an FNV-1a checksum of
/// the binary. Anything else is "corrupt".
constexpr char kCacheMagic[8] = {'U', 'B', 'C', 'L', 'B', 'I', 'N', '1'};

bool readCache(const std::string& path, uint64_t key, std::vector<unsigned char>* binary) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return false;
    char magic[8];
    uint64_t k = 0, size = 0, sum = 0;
    if (!in.read(magic, 8) || std::memcmp(magic, kCacheMagic, 8) != 0) return false;
    if (!in.read(reinterpret_cast<char*>(&k), 8) || k != key) return false;
    if (!in.read(reinterpret_cast<char*>(&size), 8) || size == 0 || size > (1ull << 30))
        return false;
    binary->resize(size_t(size));
    if (!in.read(reinterpret_cast<char*>(binary->data()), std::streamsize(size))) return false;
    if (!in.read(reinterpret_cast<char*>(&sum), 8)) return false;
    return sum == fnv1a(std::string(binary->begin(), binary->end()));
}

/// Writes atomically (temporary file, then rename); false on any failure.
bool writeCache(const std::string& path, uint64_t key, const std::vector<unsigned char>& binary) {
    const std::string tmp = path + ".tmp" + std::to_string(uint64_t(::getpid()));
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out) return false;
        const uint64_t size = binary.size();
        const uint64_t sum = fnv1a(std::string(binary.begin(), binary.end()));
        out.write(kCacheMagic, 8);
        out.write(reinterpret_cast<const char*>(&key), 8);
        out.write(reinterpret_cast<const char*>(&size), 8);
        out.write(reinterpret_cast<const char*>(binary.data()), std::streamsize(size));
        out.write(reinterpret_cast<const char*>(&sum), 8);
        if (!out.flush()) {
            std::remove(tmp.c_str());
            return false;
        }
    }
    if (std::rename(tmp.c_str(), path.c_str()) != 0) {
        std::remove(tmp.c_str());
        return false;
    }
    return true;
}

void expandIncludes(const std::string& name, std::set<std::string>& done, std::string& out) {
    if (!done.insert(name).second) return;
    std::string text;
    if (!kernelText(name, &text))
        throw ClError(std::string("OpenCL: no kernel source '") + name + "'" +
                      (std::getenv("UNIBEAM_KERNEL_DIR") ? " in $UNIBEAM_KERNEL_DIR"
                                                         : " among the embedded ones"));
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line)) {
        const size_t p = line.find("#include \"");
        if (p != std::string::npos && line.find_first_not_of(" \t") == p) {
            const size_t q = line.find('"', p + 10);
            expandIncludes(line.substr(p + 10, q - p - 10), done, out);
            continue;
        }
        out += line;
        out += '\n';
    }
}

/// A device buffer copied from host data (at least one element, so empty inputs work).
/// A read-only buffer with a copy of data, or (useHost: a CPU device, data alive until the
/// kernel has run) over the host memory itself, which saves the copy on a CPU device.
cl_mem upload(cl_context ctx, const void* data, size_t bytes, bool useHost = false) {
    cl_int err = CL_SUCCESS;
    static const uint32_t dummy = 0;
    const cl_mem_flags flags =
        CL_MEM_READ_ONLY | (useHost && bytes > 0 ? CL_MEM_USE_HOST_PTR : CL_MEM_COPY_HOST_PTR);
    cl_mem m = clCreateBuffer(ctx, flags, bytes > 0 ? bytes : sizeof(dummy),
                              const_cast<void*>(bytes > 0 ? data : &dummy), &err);
    check(err, "clCreateBuffer");
    return m;
}

}  // namespace

std::vector<ClDeviceDescription> listClDevices(std::string* error) {
    std::vector<ClDeviceDescription> out;
    cl_uint np = 0;
    if (clGetPlatformIDs(0, nullptr, &np) != CL_SUCCESS || np == 0) {
        if (error)
            *error =
                "no OpenCL platform found (scripts/setup.sh installs PoCL, pocl-opencl-icd; "
                "check /etc/OpenCL/vendors)";
        return out;
    }
    std::vector<cl_platform_id> platforms(np);
    clGetPlatformIDs(np, platforms.data(), nullptr);
    // The first call loaded the driver: LLVM's text read at load time goes back at once, so
    // that it does not stay resident beside the scene (cl/library_pages.h).
    releaseLibraryText(openClCompilerLibraries());
    for (cl_uint p = 0; p < np; ++p) {
        cl_uint nd = 0;
        if (clGetDeviceIDs(platforms[p], CL_DEVICE_TYPE_ALL, 0, nullptr, &nd) != CL_SUCCESS)
            continue;
        std::vector<cl_device_id> devices(nd);
        clGetDeviceIDs(platforms[p], CL_DEVICE_TYPE_ALL, nd, devices.data(), nullptr);
        for (cl_uint d = 0; d < nd; ++d) {
            ClDeviceDescription desc;
            desc.platformIndex = int(p);
            desc.deviceIndex = int(d);
            desc.platform = platformString(platforms[p], CL_PLATFORM_NAME);
            desc.device = clString(devices[d], CL_DEVICE_NAME);
            desc.version = clString(devices[d], CL_DEVICE_VERSION);
            desc.driver = clString(devices[d], CL_DRIVER_VERSION);
            cl_device_type type = 0;
            clGetDeviceInfo(devices[d], CL_DEVICE_TYPE, sizeof(type), &type, nullptr);
            desc.type = (type & CL_DEVICE_TYPE_GPU)   ? "GPU"
                        : (type & CL_DEVICE_TYPE_CPU) ? "CPU"
                                                      : "other";
            cl_uint cu = 0;
            clGetDeviceInfo(devices[d], CL_DEVICE_MAX_COMPUTE_UNITS, sizeof(cu), &cu, nullptr);
            desc.computeUnits = cu;
            cl_ulong mem = 0, alloc = 0;
            clGetDeviceInfo(devices[d], CL_DEVICE_GLOBAL_MEM_SIZE, sizeof(mem), &mem, nullptr);
            clGetDeviceInfo(devices[d], CL_DEVICE_MAX_MEM_ALLOC_SIZE, sizeof(alloc), &alloc,
                            nullptr);
            desc.globalMemBytes = mem;
            desc.maxAllocBytes = alloc;
            out.push_back(desc);
        }
    }
    if (out.empty() && error) *error = "OpenCL platforms found, but no device";
    return out;
}

std::string clProgramSource(const std::vector<std::string>& files) {
    std::set<std::string> done;
    std::string out;
    for (const std::string& f : files) expandIncludes(f, done, out);
    return out;
}

ClRuntime::ClRuntime(int platform, int device, const std::string& cacheDir,
                     const std::string& extraOptions) {
    std::string why;
    std::vector<ClDeviceDescription> all = listClDevices(&why);
    if (all.empty()) throw ClError("OpenCL: " + why);
    const ClDeviceDescription* pick = nullptr;
    for (const auto& d : all)
        if ((platform < 0 && device < 0) ||
            (d.platformIndex == platform && d.deviceIndex == device)) {
            pick = &d;
            break;
        }
    if (!pick) {
        std::string list;
        for (const auto& d : all)
            list += " " + std::to_string(d.platformIndex) + ":" + std::to_string(d.deviceIndex);
        throw ClError("OpenCL: no device " + std::to_string(platform) + ":" +
                      std::to_string(device) + " (devices:" + list + ")");
    }
    desc_ = *pick;
    cl_uint np = 0;
    clGetPlatformIDs(0, nullptr, &np);
    std::vector<cl_platform_id> platforms(np);
    clGetPlatformIDs(np, platforms.data(), nullptr);
    cl_uint nd = 0;
    clGetDeviceIDs(platforms[size_t(desc_.platformIndex)], CL_DEVICE_TYPE_ALL, 0, nullptr, &nd);
    std::vector<cl_device_id> devices(nd);
    clGetDeviceIDs(platforms[size_t(desc_.platformIndex)], CL_DEVICE_TYPE_ALL, nd, devices.data(),
                   nullptr);
    cl_device_id dev = devices[size_t(desc_.deviceIndex)];
    cl_int err = CL_SUCCESS;
    context_ = clCreateContext(nullptr, 1, &dev, nullptr, nullptr, &err);
    check(err, "clCreateContext");
    deviceId_ = dev;
    queue_ = clCreateCommandQueue(context_, dev, 0, &err);
    check(err, "clCreateCommandQueue");
    // One program of the three files. No contraction of a * b + c into fma anywhere in it: the
    // host twins compute without (x86-64 baseline), and the candidate filters (ub_bvh.h,
    // ub_pb2d.h) must give the pair tests' answers at the radius. The pragma is the program's
    // first line because a shared header's functions take the state where they are first
    // defined: beams.cl's own pragma came after pp3d.cl had defined ub_bvh.h's filters and
    // ub_vec3.h's dot products contracted (PoCL's code had 99 fused multiply-adds in the bb1d
    // kernel, its line filter's among them).
    const std::string src =
        "#pragma OPENCL FP_CONTRACT OFF\n" + clProgramSource({"pp3d.cl", "beams.cl", "surf.cl"});
    const std::string options =
        std::string("-cl-std=CL1.2") + (extraOptions.empty() ? "" : " " + extraOptions);
    // Program cache: key = source, options, device, driver.
    const std::string dir =
        cacheDir.empty() ? defaultCacheDir() : (cacheDir == "-" ? "" : cacheDir);
    const uint64_t key =
        fnv1a(desc_.driver, fnv1a(desc_.device + "|" + desc_.platform, fnv1a(options, fnv1a(src))));
    std::string cachePath;
    if (!dir.empty()) {
        std::error_code ec;
        std::filesystem::create_directories(dir, ec);
        char name[40];
        std::snprintf(name, sizeof(name), "%016llx.bin", static_cast<unsigned long long>(key));
        if (!ec)
            cachePath = dir + "/" + name;
        else
            programNote_ = "program cache unusable (" + dir + ": " + ec.message() + ")";
    }
    std::vector<unsigned char> binary;
    if (!cachePath.empty() && readCache(cachePath, key, &binary)) {
        const unsigned char* bin = binary.data();
        const size_t binLen = binary.size();
        cl_int status = CL_SUCCESS;
        program_ = clCreateProgramWithBinary(context_, 1, &dev, &binLen, &bin, &status, &err);
        if (err == CL_SUCCESS && status == CL_SUCCESS &&
            clBuildProgram(program_, 1, &dev, options.c_str(), nullptr, nullptr) == CL_SUCCESS) {
            programNote_ = "program from cache " + cachePath;
        } else {
            if (program_) clReleaseProgram(program_);
            program_ = nullptr;  // a stale or corrupt entry: rebuilt and replaced below
        }
    } else if (!cachePath.empty() && pathExists(cachePath)) {
        programNote_ = "corrupt program cache entry " + cachePath + " rebuilt";
    }
    if (!program_) {
        const char* text = src.c_str();
        const size_t len = src.size();
        program_ = clCreateProgramWithSource(context_, 1, &text, &len, &err);
        check(err, "clCreateProgramWithSource");
        if (clBuildProgram(program_, 1, &dev, options.c_str(), nullptr, nullptr) != CL_SUCCESS) {
            size_t n = 0;
            clGetProgramBuildInfo(program_, dev, CL_PROGRAM_BUILD_LOG, 0, nullptr, &n);
            std::string log(n, '\0');
            clGetProgramBuildInfo(program_, dev, CL_PROGRAM_BUILD_LOG, n, &log[0], nullptr);
            throw ClError("OpenCL: building kernels/pp3d.cl, beams.cl and surf.cl for " +
                          desc_.device + " with options '" + options + "' failed:\n" + log);
        }
        if (!cachePath.empty()) {
            size_t binSize = 0;
            clGetProgramInfo(program_, CL_PROGRAM_BINARY_SIZES, sizeof(binSize), &binSize, nullptr);
            std::vector<unsigned char> out(binSize);
            unsigned char* ptr = out.data();
            const bool got =
                binSize > 0 && clGetProgramInfo(program_, CL_PROGRAM_BINARIES, sizeof(ptr), &ptr,
                                                nullptr) == CL_SUCCESS;
            const bool saved = got && writeCache(cachePath, key, out);
            programNote_ = (programNote_.empty() ? std::string("built") : programNote_) +
                           (saved ? ", cached as " + cachePath : ", not cached");
        } else if (programNote_.empty()) {
            programNote_ = "built (no program cache)";
        }
    }
    pp3d_ = clCreateKernel(program_, "ub_pp3d_estimate", &err);
    check(err, "clCreateKernel(ub_pp3d_estimate)");
    pb2d_ = clCreateKernel(program_, "ub_pb2d_estimate", &err);
    check(err, "clCreateKernel(ub_pb2d_estimate)");
    bp2d_ = clCreateKernel(program_, "ub_bp2d_estimate", &err);
    check(err, "clCreateKernel(ub_bp2d_estimate)");
    bb1d_ = clCreateKernel(program_, "ub_bb1d_estimate", &err);
    check(err, "clCreateKernel(ub_bb1d_estimate)");
    surf_ = clCreateKernel(program_, "ub_surf_estimate", &err);
    check(err, "clCreateKernel(ub_surf_estimate)");
    checkLayout();
    // The program is built and its kernels have run (the probe): what building touched of
    // LLVM's text goes back too (cl/library_pages.h).
    releasedLibraryKb_ = releaseLibraryText(openClCompilerLibraries());
}

namespace {
constexpr int kProbeEntries = 20;  // what kernels/pp3d.cl's ub_layout_probe writes
}  // namespace

void ClRuntime::checkLayout() {
    cl_int err = CL_SUCCESS;
    cl_kernel probe = clCreateKernel(program_, "ub_layout_probe", &err);
    check(err, "clCreateKernel(ub_layout_probe)");
    cl_mem out =
        clCreateBuffer(context_, CL_MEM_WRITE_ONLY, kProbeEntries * sizeof(cl_uint), nullptr, &err);
    if (err != CL_SUCCESS) clReleaseKernel(probe);
    check(err, "clCreateBuffer(layout probe)");
    cl_uint device[kProbeEntries] = {};
    const size_t one = 1;
    err = clSetKernelArg(probe, 0, sizeof(cl_mem), &out);
    if (err == CL_SUCCESS)
        err = clEnqueueNDRangeKernel(queue_, probe, 1, nullptr, &one, &one, 0, nullptr, nullptr);
    if (err == CL_SUCCESS)
        err = clEnqueueReadBuffer(queue_, out, CL_TRUE, 0, sizeof(device), device, 0, nullptr,
                                  nullptr);
    clReleaseMemObject(out);
    clReleaseKernel(probe);
    check(err, "running the layout probe");
    const cl_uint host[kProbeEntries] = {cl_uint(sizeof(ub_photon_point)),
                                         cl_uint(sizeof(ub_query_point)),
                                         cl_uint(sizeof(ub_beam)),
                                         cl_uint(sizeof(ub_hash_grid)),
                                         cl_uint(sizeof(ub_mis_constants)),
                                         cl_uint(offsetof(ub_photon_point, dVCM)),
                                         cl_uint(offsetof(ub_query_point, pixel)),
                                         cl_uint(offsetof(ub_beam, fwdPassBefore)),
                                         cl_uint(sizeof(ub_light_vertex)),
                                         cl_uint(sizeof(ub_surface_query)),
                                         cl_uint(offsetof(ub_surface_query, bsdf.tableIndex)),
                                         cl_uint(offsetof(ub_surface_query, pixel)),
                                         cl_uint(sizeof(ub_beam_part)),
                                         cl_uint(offsetof(ub_beam_part, pathLength)),
                                         cl_uint(sizeof(ub_bvh_node)),
                                         cl_uint(offsetof(ub_bvh_node, child)),
                                         cl_uint(sizeof(ub_photon_keys4)),
                                         cl_uint(offsetof(ub_photon_keys4, mediumId)),
                                         cl_uint(sizeof(ub_beam_keys4)),
                                         cl_uint(offsetof(ub_beam_keys4, dx))};
    const char* what[kProbeEntries] = {"sizeof(ub_photon_point)",
                                       "sizeof(ub_query_point)",
                                       "sizeof(ub_beam)",
                                       "sizeof(ub_hash_grid)",
                                       "sizeof(ub_mis_constants)",
                                       "offsetof(ub_photon_point, dVCM)",
                                       "offsetof(ub_query_point, pixel)",
                                       "offsetof(ub_beam, fwdPassBefore)",
                                       "sizeof(ub_light_vertex)",
                                       "sizeof(ub_surface_query)",
                                       "offsetof(ub_surface_query, bsdf.tableIndex)",
                                       "offsetof(ub_surface_query, pixel)",
                                       "sizeof(ub_beam_part)",
                                       "offsetof(ub_beam_part, pathLength)",
                                       "sizeof(ub_bvh_node)",
                                       "offsetof(ub_bvh_node, child)",
                                       "sizeof(ub_photon_keys4)",
                                       "offsetof(ub_photon_keys4, mediumId)",
                                       "sizeof(ub_beam_keys4)",
                                       "offsetof(ub_beam_keys4, dx)"};
    for (int i = 0; i < kProbeEntries; ++i)
        if (device[i] != host[i])
            throw ClError("OpenCL: device '" + desc_.device +
                          "' lays out the shared records "
                          "differently from the host: " +
                          what[i] + " is " + std::to_string(device[i]) + " on the device, " +
                          std::to_string(host[i]) + " on the host");
}

void ClRuntime::enableProfiling() {
    if (profiling_) return;
    cl_int err = CL_SUCCESS;
    cl_command_queue q = clCreateCommandQueue(context_, deviceId_, CL_QUEUE_PROFILING_ENABLE, &err);
    check(err, "clCreateCommandQueue(CL_QUEUE_PROFILING_ENABLE)");
    clReleaseCommandQueue(queue_);
    queue_ = q;
    profiling_ = true;
}

ClRuntime::~ClRuntime() {
    for (cl_kernel k : {pp3d_, pb2d_, bp2d_, bb1d_, surf_})
        if (k) clReleaseKernel(k);
    for (cl_mem m : {gridInfoMem_, gridDataMem_})
        if (m) clReleaseMemObject(m);
    if (program_) clReleaseProgram(program_);
    if (queue_) clReleaseCommandQueue(queue_);
    if (context_) clReleaseContext(context_);
}

namespace {
template <class T>
ClRuntime::Arg bufferArg(const std::vector<T>& v) {
    return {v.data(), v.size() * sizeof(T), true};
}
template <class T>
ClRuntime::Arg scalarArg(const T& v) {
    return {&v, sizeof(T), false};
}
}  // namespace

namespace {

bool outOfResources(cl_int err) {
    return err == CL_OUT_OF_RESOURCES || err == CL_MEM_OBJECT_ALLOCATION_FAILURE ||
           err == CL_OUT_OF_HOST_MEMORY;
}

struct MemList {
    std::vector<cl_mem> mems;
    ~MemList() { clear(); }
    void clear() {
        for (cl_mem m : mems) clReleaseMemObject(m);
        mems.clear();
    }
};

}  // namespace

void ClRuntime::runEstimate(cl_kernel kernel, const char* name, const std::vector<Arg>& lookup,
                            const Arg& queries, size_t count, const EstimateArgs& a,
                            std::vector<Rgb>* out) {
    // Every query's work-item writes its result, so `out` is sized, not filled: the callers
    // (estimators/volume_estimate.cpp) hand it over zeroed and sized already, and a second
    // fill was a few percent of the millisecond passes (docs/performance.md, session 36).
    out->resize(count);
    lastTiming_ = KernelTiming();
    if (count == 0) return;
    // The lookups (and the media) are uploaded once; the queries go in batches that fit the
    // device's largest allocation and what its global memory leaves after the lookups. A
    // launch, allocation or read-back that runs out of resources is retried with half the
    // batch (down to 64 queries). Each query's result depends on that query alone, so the
    // results do not depend on the batch size.
    std::vector<Arg> fixed = lookup;
    size_t lookupBytes = 0;
    for (const Arg& x : lookup) {
        if (!x.buffer || x.mem) continue;
        lookupBytes += x.bytes;
        if (desc_.maxAllocBytes > 0 && x.bytes > desc_.maxAllocBytes)
            throw ClError(std::string("OpenCL: ") + name + ": a lookup buffer needs " +
                          std::to_string(x.bytes >> 20) +
                          " MB, more than the device's largest "
                          "allocation (" +
                          std::to_string(desc_.maxAllocBytes >> 20) +
                          " MB): a smaller --resolution or fewer --beam-paths need less");
    }
    if (desc_.globalMemBytes > 0 && lookupBytes > desc_.globalMemBytes)
        throw ClError(std::string("OpenCL: ") + name + ": the lookups need " +
                      std::to_string(lookupBytes >> 20) + " MB, more than the device's " +
                      std::to_string(desc_.globalMemBytes >> 20) +
                      " MB: a smaller --resolution or fewer --beam-paths need less");
    MemList fixedMems;
    cl_uint index = 0;
    for (const Arg& x : fixed) {
        if (x.mem) {
            check(clSetKernelArg(kernel, index++, sizeof(cl_mem), &x.mem), "clSetKernelArg");
        } else if (x.buffer) {
            // On a CPU device the kernel reads the lookups in place (they outlive this call).
            cl_mem m = upload(context_, x.data, x.bytes, desc_.type == "CPU");
            fixedMems.mems.push_back(m);
            check(clSetKernelArg(kernel, index++, sizeof(cl_mem), &m), "clSetKernelArg");
        } else {
            check(clSetKernelArg(kernel, index++, x.bytes, x.data), "clSetKernelArg");
        }
    }
    const cl_uint queryIndex = index++, countIndex = index++;
    cl_mem media = upload(context_, a.media->data(), a.media->size() * sizeof(ub_medium_info));
    fixedMems.mems.push_back(media);
    check(clSetKernelArg(kernel, index++, sizeof(cl_mem), &media), "clSetKernelArg");
    for (const Arg& x : {scalarArg(a.mis), scalarArg(a.radius), scalarArg(a.normalization),
                         scalarArg(a.minLength), scalarArg(a.maxLength)})
        check(clSetKernelArg(kernel, index++, x.bytes, x.data), "clSetKernelArg");
    const cl_uint resultIndex = index++;

    const size_t querySize = queries.bytes / count, perQuery = querySize + 3 * sizeof(float);
    size_t batch = count;
    if (maxBatchForTest_ > 0) batch = std::min(batch, maxBatchForTest_);
    if (desc_.maxAllocBytes > 0) batch = std::min(batch, size_t(desc_.maxAllocBytes / perQuery));
    if (desc_.globalMemBytes > lookupBytes)
        batch = std::min(batch, size_t((desc_.globalMemBytes - lookupBytes) / 2 / perQuery));
    batch = std::max<size_t>(batch, 1);
    const size_t local = 64;
    std::vector<float> host;
    const bool inPlace = desc_.type == "CPU";
    const char* base = static_cast<const char*>(queries.data);
    for (size_t begin = 0; begin < count;) {
        const size_t n = std::min(batch, count - begin);
        MemList batchMems;
        cl_int err = CL_SUCCESS;
        const char* step = "clCreateBuffer(queries)";
        cl_event launch = nullptr;  // with profiling only
        const cl_mem_flags queryFlags =
            CL_MEM_READ_ONLY | (desc_.type == "CPU" ? CL_MEM_USE_HOST_PTR : CL_MEM_COPY_HOST_PTR);
        cl_mem q = clCreateBuffer(context_, queryFlags, n * querySize,
                                  const_cast<char*>(base + begin * querySize), &err);
        if (err == CL_SUCCESS) {
            batchMems.mems.push_back(q);
            step = "clCreateBuffer(results)";
            // On a CPU device the kernel writes into `out` itself (3 floats per query, Rgb's
            // layout), and mapping the buffer afterwards copies nothing: for the millisecond
            // passes the read-back and its conversion loop were a tenth of the pass.
            static_assert(sizeof(Rgb) == 3 * sizeof(float), "Rgb is three packed floats");
            cl_mem res =
                clCreateBuffer(context_, CL_MEM_WRITE_ONLY | (inPlace ? CL_MEM_USE_HOST_PTR : 0),
                               n * 3 * sizeof(float), inPlace ? &(*out)[begin] : nullptr, &err);
            if (err == CL_SUCCESS) {
                batchMems.mems.push_back(res);
                const cl_uint nq = cl_uint(n);
                check(clSetKernelArg(kernel, queryIndex, sizeof(cl_mem), &q), "clSetKernelArg");
                check(clSetKernelArg(kernel, countIndex, sizeof(nq), &nq), "clSetKernelArg");
                check(clSetKernelArg(kernel, resultIndex, sizeof(cl_mem), &res), "clSetKernelArg");
                const size_t global = (n + local - 1) / local * local;
                step = name;
                err = failLaunchesForTest_ > 0
                          ? (--failLaunchesForTest_, CL_OUT_OF_RESOURCES)
                          : clEnqueueNDRangeKernel(queue_, kernel, 1, nullptr, &global, &local, 0,
                                                   nullptr, profiling_ ? &launch : nullptr);
                if (err == CL_SUCCESS && inPlace) {
                    // The map is enqueued without waiting: where the device maps the results in
                    // place (PoCL), map, unmap and kernel are waited for once, by clFinish. A
                    // blocking map and then clFinish waited twice on the device's threads, a
                    // few percent of the millisecond passes (docs/performance.md, session 34).
                    step = "clEnqueueMapBuffer(results)";
                    void* p = clEnqueueMapBuffer(queue_, res, CL_FALSE, CL_MAP_READ, 0,
                                                 n * 3 * sizeof(float), 0, nullptr, nullptr, &err);
                    if (err == CL_SUCCESS && p != &(*out)[begin]) {
                        // A device that could not use the pointer in place maps a copy, which
                        // may be read once the map is done.
                        err = clFinish(queue_);
                        if (err == CL_SUCCESS)
                            std::memcpy(&(*out)[begin], p, n * 3 * sizeof(float));
                    }
                    if (err == CL_SUCCESS) {
                        step = "clEnqueueUnmapMemObject(results)";
                        err = clEnqueueUnmapMemObject(queue_, res, p, 0, nullptr, nullptr);
                        if (err == CL_SUCCESS) err = clFinish(queue_);
                    }
                } else if (err == CL_SUCCESS) {
                    host.resize(n * 3);
                    step = "clEnqueueReadBuffer(results)";
                    err = clEnqueueReadBuffer(queue_, res, CL_TRUE, 0, host.size() * sizeof(float),
                                              host.data(), 0, nullptr, nullptr);
                }
            }
        }
        if (launch) {
            // The event's times, once the batch is done (the map or read above waited for it).
            cl_ulong submit = 0, start = 0, end = 0;
            if (err == CL_SUCCESS &&
                clGetEventProfilingInfo(launch, CL_PROFILING_COMMAND_SUBMIT, sizeof(submit),
                                        &submit, nullptr) == CL_SUCCESS &&
                clGetEventProfilingInfo(launch, CL_PROFILING_COMMAND_START, sizeof(start), &start,
                                        nullptr) == CL_SUCCESS &&
                clGetEventProfilingInfo(launch, CL_PROFILING_COMMAND_END, sizeof(end), &end,
                                        nullptr) == CL_SUCCESS) {
                lastTiming_.kernelSeconds =
                    std::max(0.0, lastTiming_.kernelSeconds) + double(end - start) * 1e-9;
                lastTiming_.startLatencySeconds =
                    std::max(0.0, lastTiming_.startLatencySeconds) + double(start - submit) * 1e-9;
            }
            clReleaseEvent(launch);
        }
        if (outOfResources(err) && batch > 64) {
            batch = std::max<size_t>(64, batch / 2);  // retry this range in smaller batches
            ++batchRetries_;
            continue;
        }
        check(err, step);
        if (!inPlace)
            for (size_t i = 0; i < n; ++i)
                (*out)[begin + i] = Rgb(host[3 * i], host[3 * i + 1], host[3 * i + 2]);
        begin += n;
        ++batches_;
    }
}

namespace {
const std::vector<ub_grid_info> kNoGrids;
const std::vector<uint8_t> kNoGridData;

std::vector<ClRuntime::Arg> withGrids(std::vector<ClRuntime::Arg> lookup,
                                      const std::vector<ClRuntime::Arg>& grids) {
    lookup.insert(lookup.end(), grids.begin(), grids.end());
    return lookup;
}
}  // namespace

std::vector<ClRuntime::Arg> ClRuntime::gridArgs(const EstimateArgs& a) const {
    if (a.grids || !gridInfoMem_)
        return {bufferArg(a.grids ? *a.grids : kNoGrids),
                bufferArg(a.gridData ? *a.gridData : kNoGridData)};
    Arg info{nullptr, 0, true, gridInfoMem_}, data{nullptr, 0, true, gridDataMem_};
    return {info, data};
}

void ClRuntime::setGridMedia(const std::vector<ub_grid_info>& grids,
                             const std::vector<uint8_t>& gridData) {
    for (cl_mem* m : {&gridInfoMem_, &gridDataMem_})
        if (*m) {
            clReleaseMemObject(*m);
            *m = nullptr;
        }
    const size_t bytes = grids.size() * sizeof(ub_grid_info) + gridData.size();
    if (desc_.maxAllocBytes > 0 && gridData.size() > desc_.maxAllocBytes)
        throw ClError("OpenCL: the grid media need " + std::to_string(gridData.size() >> 20) +
                      " MB, more than the device's largest allocation (" +
                      std::to_string(desc_.maxAllocBytes >> 20) +
                      " MB): use --backend host for this scene");
    const Arg info = bufferArg(grids.empty() ? kNoGrids : grids);
    const Arg data = bufferArg(gridData.empty() ? kNoGridData : gridData);
    gridInfoMem_ = upload(context_, info.data, info.bytes);
    gridDataMem_ = upload(context_, data.data, data.bytes);
    gridMediaBytes_ = bytes;
}

void ClRuntime::estimateSurf(const std::vector<LightVertex>& photons, const HashGrid& grid,
                             const std::vector<float>& tables,
                             const std::vector<ub_surface_query>& queries, const EstimateArgs& a,
                             std::vector<Rgb>* out) {
    if (photons.empty()) return out->assign(queries.size(), Rgb(0.0f));
    runEstimate(surf_, "clEnqueueNDRangeKernel(ub_surf_estimate)",
                {bufferArg(photons), bufferArg(grid.cellEnds()), bufferArg(grid.indices()),
                 bufferArg(grid.keys()), scalarArg(grid.params()), bufferArg(tables)},
                bufferArg(queries), queries.size(), a, out);
}

namespace {
/// The beam kernels read a leaf's entry k as item k (kernels/beams.cl): the items must be in
/// the BVH's leaf order (Bvh::permuteToLeafOrder).
void requireLeafOrder(const Bvh& bvh, const char* estimator) {
    if (!bvh.leafOrdered())
        throw std::logic_error(std::string(estimator) +
                               " kernel given a BVH whose items are not in leaf order");
}
}  // namespace

void ClRuntime::estimatePP3D(const std::vector<ub_photon_point>& photons, const HashGrid& grid,
                             const std::vector<ub_query_point>& queries, const EstimateArgs& a,
                             std::vector<Rgb>* out) {
    if (photons.empty()) return out->assign(queries.size(), Rgb(0.0f));
    runEstimate(pp3d_, "clEnqueueNDRangeKernel(ub_pp3d_estimate)",
                {bufferArg(photons), bufferArg(grid.cellEnds()), bufferArg(grid.indices()),
                 bufferArg(grid.keys()), scalarArg(grid.params())},
                bufferArg(queries), queries.size(), a, out);
}

void ClRuntime::estimatePB2D(const std::vector<ub_photon_point>& photons,
                             const std::vector<ub_photon_keys4>& keys, const Bvh& spheres,
                             const ScreenTiles& tiles, const std::vector<ub_beam>& queries,
                             const EstimateArgs& a, std::vector<Rgb>* out) {
    if (photons.empty() || spheres.empty()) return out->assign(queries.size(), Rgb(0.0f));
    requireLeafOrder(spheres, "pb2d");
    const std::vector<uint32_t> roots = spheres.roots(uint32_t(a.media->size()));
    if (tiles.start.empty() || tiles.photonKeys.empty() || tiles.items.empty())
        throw std::logic_error("pb2d kernel given screen tiles that were not built");
    runEstimate(pb2d_, "clEnqueueNDRangeKernel(ub_pb2d_estimate)",
                withGrids({bufferArg(photons), bufferArg(keys), bufferArg(spheres.nodes()),
                           bufferArg(roots), bufferArg(tiles.start), bufferArg(tiles.photonKeys),
                           bufferArg(tiles.items), scalarArg(tiles.params)},
                          gridArgs(a)),
                bufferArg(queries), queries.size(), a, out);
}

void ClRuntime::estimateBP2D(const std::vector<ub_beam>& beams,
                             const std::vector<ub_beam_part>& parts,
                             const std::vector<ub_beam_piece>& pieces,
                             const std::vector<uint32_t>& ranges, const Bvh& bvh,
                             const std::vector<ub_query_point>& queries, const EstimateArgs& a,
                             std::vector<Rgb>* out) {
    if (beams.empty() || bvh.empty()) return out->assign(queries.size(), Rgb(0.0f));
    requireLeafOrder(bvh, "bp2d");
    const std::vector<uint32_t> roots = bvh.roots(uint32_t(a.media->size()));
    runEstimate(bp2d_, "clEnqueueNDRangeKernel(ub_bp2d_estimate)",
                withGrids({bufferArg(beams), bufferArg(parts), bufferArg(pieces), bufferArg(ranges),
                           bufferArg(bvh.nodes()), bufferArg(roots)},
                          gridArgs(a)),
                bufferArg(queries), queries.size(), a, out);
}

void ClRuntime::estimateBB1D(const std::vector<ub_beam>& beams,
                             const std::vector<ub_beam_part>& parts,
                             const std::vector<ub_beam_keys4>& lines,
                             const std::vector<ub_beam_piece>& pieces,
                             const std::vector<uint32_t>& ranges, const Bvh& bvh,
                             const ScreenTiles& tiles, const std::vector<ub_beam>& queries,
                             const EstimateArgs& a, std::vector<Rgb>* out) {
    if (beams.empty() || bvh.empty()) return out->assign(queries.size(), Rgb(0.0f));
    requireLeafOrder(bvh, "bb1d");
    const std::vector<uint32_t> roots = bvh.roots(uint32_t(a.media->size()));
    if (tiles.start.empty() || tiles.lines.empty() || tiles.items.empty() ||
        tiles.itemParts.empty())
        throw std::logic_error("bb1d kernel given screen tiles that were not built");
    runEstimate(bb1d_, "clEnqueueNDRangeKernel(ub_bb1d_estimate)",
                withGrids({bufferArg(beams), bufferArg(parts), bufferArg(lines), bufferArg(pieces),
                           bufferArg(ranges), bufferArg(bvh.nodes()), bufferArg(roots),
                           bufferArg(tiles.start), bufferArg(tiles.lines), bufferArg(tiles.items),
                           bufferArg(tiles.itemParts), scalarArg(tiles.params)},
                          gridArgs(a)),
                bufferArg(queries), queries.size(), a, out);
}

}  // namespace ub
