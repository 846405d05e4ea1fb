// OpenCL runtime of UPBP's estimate pass: device discovery, the program built from
// the embedded kernel sources (kernels/*.cl with kernels/shared/*.h, the same headers
// the host twins compile; cmake/EmbedKernels.cmake; $UNIBEAM_KERNEL_DIR makes it read them
// from a folder instead), the on-disk program cache, buffers and kernel launches.
//
// Queries go to the device in batches that fit its largest allocation and global memory;
// running out of resources halves the batch and retries (runEstimate).
//
// pp3d and surface merging run as kernels (kernels/pp3d.cl, kernels/surf.cl) in every scene; pb2d,
// bp2d and bb1d (kernels/beams.cl) in homogeneous media and in nearest-filtered NanoVDB grids
// without an albedo grid (regular tracking through the grid read with CNanoVDB.h,
// kernels/shared/ub_grid_medium.h); scenes with other grid media run them on the host.
// Results come back one per query and are added to pixels on the host in query order, so
// no float atomics are needed and images are deterministic.
#pragma once

#define CL_TARGET_OPENCL_VERSION 120
#include <CL/cl.h>

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/memory_budget.h"
#include "core/vec.h"
#include "estimators/grid_access.h"
#include "kernels/shared/ub_bvh.h"
#include "kernels/shared/ub_medium_homogeneous.h"
#include "kernels/shared/ub_surf.h"
#include "kernels/shared/ub_upbp_records.h"
#include "render/light_vertex.h"

namespace ub {

struct ScreenTiles;

class HashGrid;
class Bvh;

/// An OpenCL problem (no platform, bad device index, build failure, out of resources):
/// the message says what and, for build failures, includes the build log and options.
class ClError : public ResourceError {
  public:
    using ResourceError::ResourceError;
};

struct ClDeviceDescription {
    int platformIndex = 0, deviceIndex = 0;
    std::string platform, device, type, version, driver;
    unsigned computeUnits = 0;
    uint64_t globalMemBytes = 0, maxAllocBytes = 0;
};

/// Every device of every platform (empty, with *error set, if there is no platform).
std::vector<ClDeviceDescription> listClDevices(std::string* error);

/// The embedded sources of kernels/`files`, one after the other, with every #include "x.h"
/// replaced by the embedded kernels/shared/x.h, each header once. Throws ClError for an
/// unknown file.
std::string clProgramSource(const std::vector<std::string>& files);

class ClRuntime {
  public:
    /// Opens device `device` of platform `platform` (both -1: the first device found) and
    /// builds the estimate kernels, or loads them from the program cache in cacheDir (empty:
    /// $XDG_CACHE_HOME/unibeam/opencl, else ~/.cache/unibeam/opencl; "-": no cache). Cache
    /// entries are keyed by the source, the build options, the device and the driver
    /// version; a corrupt or stale entry is rebuilt and replaced, never fatal. extraOptions
    /// are appended to the build options: the scene's material types (clBsdfTypesOption),
    /// or a forced build failure in tests.
    /// Throws ClError.
    ClRuntime(int platform, int device, const std::string& cacheDir = "",
              const std::string& extraOptions = "");
    ~ClRuntime();
    ClRuntime(const ClRuntime&) = delete;
    ClRuntime& operator=(const ClRuntime&) = delete;

    const ClDeviceDescription& device() const { return desc_; }
    /// How the program was obtained: "built", "built, cached as FILE", "from cache FILE", or
    /// why the cache was not used.
    const std::string& programNote() const { return programNote_; }
    /// Resident kilobytes of the OpenCL compiler's text (LLVM, Clang) given back once the
    /// program was ready (cl/library_pages.h).
    size_t releasedLibraryKb() const { return releasedLibraryKb_; }

    /// The estimators as kernels (kernels/pp3d.cl, kernels/beams.cl; pb2d, bp2d and bb1d for
    /// homogeneous media only): (*out)[i] is query i's estimate, as the host twin computes it
    /// from the same records and lookups. media[m] describes medium m (ub_medium_info).
    struct EstimateArgs {
        const std::vector<ub_medium_info>* media = nullptr;
        /// Beam kernels: grids[m] describes medium m's NanoVDB grid inside gridData (grid
        /// media; unused entries for homogeneous ones). nullptr: no grid media.
        const std::vector<ub_grid_info>* grids = nullptr;
        const std::vector<uint8_t>* gridData = nullptr;
        ub_mis_constants mis{};
        float radius = 0, normalization = 0;
        uint32_t minLength = 0, maxLength = 0;
    };
    void estimatePP3D(const std::vector<ub_photon_point>& photons, const HashGrid& grid,
                      const std::vector<ub_query_point>& queries, const EstimateArgs& a,
                      std::vector<Rgb>* out);
    /// keys[i] = ub_photon_key_of(photons[i]) (kernels/shared/ub_pb2d.h).
    void estimatePB2D(const std::vector<ub_photon_point>& photons,
                      const std::vector<ub_photon_keys4>& keys, const Bvh& spheres,
                      const ScreenTiles& tiles, const std::vector<ub_beam>& queries,
                      const EstimateArgs& a, std::vector<Rgb>* out);
    /// bp2d and bb1d: pieces and ranges are the photon beams' medium tables
    /// (estimators/beam_medium.h flattenBeamTables; 2 ranges per beam, all 0 in homogeneous
    /// media).
    void estimateBP2D(const std::vector<ub_beam>& beams, const std::vector<ub_beam_part>& parts,
                      const std::vector<ub_beam_piece>& pieces, const std::vector<uint32_t>& ranges,
                      const Bvh& bvh, const std::vector<ub_query_point>& queries,
                      const EstimateArgs& a, std::vector<Rgb>* out);
    void estimateBB1D(const std::vector<ub_beam>& beams, const std::vector<ub_beam_part>& parts,
                      const std::vector<ub_beam_keys4>& lines,
                      const std::vector<ub_beam_piece>& pieces, const std::vector<uint32_t>& ranges,
                      const Bvh& bvh, const ScreenTiles& tiles, const std::vector<ub_beam>& queries,
                      const EstimateArgs& a, std::vector<Rgb>* out);
    /// Surface merging (kernels/surf.cl) over surface photons and surface queries; tables:
    /// the materials' rough-plastic coating tables (estimators/surface_merging.h).
    void estimateSurf(const std::vector<LightVertex>& photons, const HashGrid& grid,
                      const std::vector<float>& tables,
                      const std::vector<ub_surface_query>& queries, const EstimateArgs& a,
                      std::vector<Rgb>* out);

    /// Uploads the grid media for the beam kernels once per render (grids[m] describes
    /// medium m inside gridData); later estimates with EstimateArgs::grids == nullptr use
    /// these device buffers instead of uploading them each time. Throws ClError.
    void setGridMedia(const std::vector<ub_grid_info>& grids, const std::vector<uint8_t>& gridData);
    /// Bytes of the resident grid-media buffers.
    size_t gridMediaBytes() const { return gridMediaBytes_; }

    /// Queue profiling (CL_QUEUE_PROFILING_ENABLE; bench_upbp --cl-profile): the queue is
    /// created again with it, and each estimate records what the device reports of its
    /// launches. Throws ClError.
    void enableProfiling();
    /// The last estimate's kernel time on the device (CL_PROFILING_COMMAND_START to _END,
    /// summed over its batches) and its latency from submission to start (summed likewise),
    /// in seconds; both -1 without profiling or queries.
    struct KernelTiming {
        double kernelSeconds = -1.0, startLatencySeconds = -1.0;
    };
    const KernelTiming& lastKernelTiming() const { return lastTiming_; }
    void clearKernelTiming() { lastTiming_ = KernelTiming(); }

    /// Batches launched so far, and retries with a smaller batch after the device ran out of
    /// resources (runEstimate).
    size_t batches() const { return batches_; }
    size_t batchRetries() const { return batchRetries_; }
    /// Tests: at most n queries per batch (0: the device's limits only), and make the next
    /// k launches fail with CL_OUT_OF_RESOURCES.
    void setMaxBatchForTest(size_t n) { maxBatchForTest_ = n; }
    void failLaunchesForTest(int k) { failLaunchesForTest_ = k; }
    /// A kernel argument: host data uploaded as a buffer, a scalar/struct by value, or a
    /// buffer already on the device (mem).
    struct Arg {
        const void* data;
        size_t bytes;
        bool buffer;
        cl_mem mem = nullptr;
    };

  private:
    /// Runs the layout probe (kernels/pp3d.cl) and compares with the host; throws ClError.
    void checkLayout();

    ClDeviceDescription desc_;
    std::string programNote_;
    size_t releasedLibraryKb_ = 0;
    cl_context context_ = nullptr;
    cl_device_id deviceId_ = nullptr;
    cl_command_queue queue_ = nullptr;
    bool profiling_ = false;
    KernelTiming lastTiming_;
    cl_program program_ = nullptr;
    cl_kernel pp3d_ = nullptr, pb2d_ = nullptr, bp2d_ = nullptr, bb1d_ = nullptr, surf_ = nullptr;
    cl_mem gridInfoMem_ = nullptr, gridDataMem_ = nullptr;  ///< setGridMedia()
    size_t gridMediaBytes_ = 0;
    /// The grid-media arguments of a beam kernel: a's own vectors, else the resident buffers.
    std::vector<Arg> gridArgs(const EstimateArgs& a) const;
    size_t batches_ = 0, batchRetries_ = 0, maxBatchForTest_ = 0;
    int failLaunchesForTest_ = 0;
    /// Runs estimate kernel `kernel` over `count` queries: its arguments are `lookup`, then
    /// the queries (a buffer), their count and the EstimateArgs tail, then the results, read
    /// back as 3 floats per query.
    void runEstimate(cl_kernel kernel, const char* name, const std::vector<Arg>& lookup,
                     const Arg& queries, size_t count, const EstimateArgs& a,
                     std::vector<Rgb>* out);
};

}  // namespace ub
