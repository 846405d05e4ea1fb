// Benchmark: time per iteration and peak memory of `upbp` and of each of its estimators
// alone (upbp:bpt, upbp:pp3d, upbp:pb2d, upbp:bp2d, upbp:bb1d, upbp:surf...), with SmallUPBP's
// settings by default: 256x256 (65,536 light subpaths per iteration), 4,000 of them emitting
// photon beams, radius 0.001 of the scene radius for pp3d/pb2d/bp2d/bb1d (constant), 0.0015
// with alpha 0.75 for surf, short photon beams, long query beams, maximum path length 12
// (candle 4), as issue #10 lists them.
//
// Each (scene, technique set) runs in a child process (fork), so that its peak resident
// memory (getrusage of the child) is its own: one warm-up iteration, then the median of
// `runs` timed iterations (each a fresh, independent one). Also prints the photon, beam and
// query counts of the last iteration and the image mean (a sanity check). Not run by ctest.
//
// Usage: bench_upbp [--runs N] [--sets s1,s2,...] [--backends host,opencl] [--resolution WxH]
//                   [--radius-of media|scene] [--rays cut,whole] [--replay K] [--cl-profile]
//                   [--ray-stats] [SCENE ...]
//   --replay K: after the timed iterations of an OpenCL run, the last iteration's estimate pass
//   of each estimator of the set (surf, pp3d, pb2d, bp2d, bb1d) runs K more times on the host
//   twin and K times as the kernel, alternately, on the same photons, beams and queries
//   (VertexCM::replayEstimate); prints the median estimate times, queries per second, the
//   ratio host / OpenCL and how far the two estimates' image sums differ. Ratios from one
//   process and alternating runs are what docs/performance.md quotes for issue #11. Last, the
//   run's median iteration with the replayed host passes in place of the kernels' (the other
//   passes are the same code on both backends): the whole iteration's host / OpenCL ratio
//   without the noise between separate processes.
//   --cl-profile: the OpenCL queue profiles its commands (RenderOptions::clProfile), and the
//   replay also prints the median of each kernel's time on the device and of its latency from
//   submission to start, which separate the kernel from its launch.
//   --ray-stats: counts the Embree queries of the timed iterations and their time
//   (scene/ray_stats.h): queries per iteration by kind, the mean time of one, and Embree's share
//   of the iterations' thread time. Adds two time-stamp reads to each query.
//   --rays: with "whole" the bidirectional engine traces every ray through media to the next
//   surface instead of cutting it where free-flight sampling stops (RenderOptions::
//   cutRaysAtFlight; same image); both listed: an A/B in one run. Default: cut.
//   --radius-of scene: the volumetric radii are 0.001 of the scene's bounding sphere (half the
//   diagonal of the geometry's bounding box), SmallUPBP's convention, so that both renderers
//   use the same absolute radius; media (default): 0.001 of the media's radius, unibeam's.
//   default scenes: cornell-fog, cornell-smoke, forward-scattering (scenes/) and the SmallUPBP
//   candle, mirrorballs, bunny (scenes/smallupbp/)
#include <sys/resource.h>
#include <sys/wait.h>
#include <tbb/task_arena.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "core/error.h"
#include "render/integrator.h"
#include "render/vcm.h"
#include "scene/io/scene_loader.h"
#include "scene/ray_stats.h"

using namespace ub;

namespace {

std::vector<std::string> splitList(const std::string& list) {
    std::vector<std::string> out;
    for (size_t p = 0; p <= list.size();) {
        size_t q = list.find(',', p);
        if (q == std::string::npos) q = list.size();
        if (q > p) out.push_back(list.substr(p, q - p));
        p = q + 1;
    }
    return out;
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

/// --replay: the estimators' host twins against their kernels on the last iteration's records.
/// Adds each estimator's median host and OpenCL pass times to *hostSum and *deviceSum.
void replayEstimates(VertexCM& vcm, const std::string& set, int replays, int width, int height,
                     bool clProfile, double* hostSum, double* deviceSum) {
    const UpbpTechniques& t = vcm.upbpTechniques();
    const std::pair<const char*, bool> techniques[] = {
        {"surf", t.surf}, {"pp3d", t.pp3d}, {"pb2d", t.pb2d}, {"bp2d", t.bp2d}, {"bb1d", t.bb1d}};
    for (const auto& [name, on] : techniques) {
        if (!on) continue;
        std::vector<double> host, device, kernel, latency;
        size_t queries = 0;
        Rgb sumHost(0.0f), sumDevice(0.0f);
        for (int k = 0; k < replays; ++k)
            for (bool onDevice : {false, true}) {
                Image img(width, height);
                const VertexCM::EstimateTiming timing = vcm.replayEstimate(name, onDevice, &img);
                (onDevice ? device : host).push_back(timing.estimates);
                if (onDevice && timing.deviceKernel >= 0.0) {
                    kernel.push_back(timing.deviceKernel);
                    latency.push_back(timing.deviceStartLatency);
                }
                queries = timing.queries;
                (onDevice ? sumDevice : sumHost) = img.mean();
            }
        const double h = median(host), d = median(device);
        if (queries == 0) {
            std::printf("    replay %-5s %-16s no queries\n", name, set.c_str());
            continue;
        }
        *hostSum += h;
        *deviceSum += d;
        const double scale = std::max({double(sumHost.x), double(sumHost.y), double(sumHost.z)});
        const double diff = std::max({std::abs(double(sumHost.x - sumDevice.x)),
                                      std::abs(double(sumHost.y - sumDevice.y)),
                                      std::abs(double(sumHost.z - sumDevice.z))});
        std::printf(
            "    replay %-5s %-16s %zu queries: host %.4f s (%.3g/s), OpenCL %.4f s (%.3g/s), "
            "host/OpenCL %.3f (median of %d each, alternating); image means differ by %.2g "
            "relative\n",
            name, set.c_str(), queries, h, double(queries) / h, d, double(queries) / d, h / d,
            replays, scale > 0.0 ? diff / scale : diff);
        if (clProfile && !kernel.empty())
            std::printf(
                "    replay %-5s %-16s OpenCL kernel %.3f ms on the device, %.1f us from "
                "submission to start (medians, queue profiling)\n",
                name, set.c_str(), median(kernel) * 1e3, median(latency) * 1e6);
    }
}

int runOne(const std::string& path, const std::string& set, int runs, int width, int height,
           const std::string& backend, bool sceneRadius, bool cutRays, int replays, bool clProfile,
           bool rayStats) {
    std::vector<Diagnostic> warnings;
    std::unique_ptr<Scene> scene = loadScene(path, &warnings);
    scene->camera = scene->camera.resized(width, height, scene->settings.keepHorizontalFov);
    RenderOptions opt;
    opt.algorithm = set;
    const bool candle = path.find("candle") != std::string::npos;
    opt.maxPathLength = candle ? 4 : 12;
    opt.seed = 1234;
    opt.radius = 0.0015f;
    opt.alpha = 0.75f;
    opt.radiusPP3D = opt.radiusPB2D = opt.radiusBP2D = opt.radiusBB1D = 0.001f;
    if (sceneRadius) {
        opt.radiusIsRelative = false;  // every radius absolute, surf's too
        opt.radius = 0.0015f * scene->sceneSphere.radius;
        opt.radiusPP3D = opt.radiusPB2D = opt.radiusBP2D = opt.radiusBB1D =
            0.001f * scene->sceneSphere.radius;
        std::printf("    volumetric radius %.5g (0.001 of the scene radius %.5g)\n",
                    double(opt.radiusPP3D), double(scene->sceneSphere.radius));
    }
    opt.alphaPP3D = opt.alphaPB2D = opt.alphaBP2D = opt.alphaBB1D = 1.0f;
    opt.shortPhotonBeams = true;
    opt.shortQueryBeams = false;
    opt.beamPaths = 4000;
    opt.backend = backend;
    opt.cutRaysAtFlight = cutRays;
    opt.clProfile = clProfile;
    std::unique_ptr<Integrator> integrator = makeIntegrator(*scene, opt);
    Image img;
    integrator->renderIteration(0, img);
    std::vector<double> times;
    if (rayStats) raystats::enable(true);
    for (int r = 0; r < runs; ++r) {
        const auto t0 = std::chrono::steady_clock::now();
        integrator->renderIteration(r + 1, img);
        times.push_back(
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    raystats::Totals rays;
    if (rayStats) {
        rays = raystats::totals();
        raystats::enable(false);
    }
    double timedSeconds = 0.0;
    for (double t : times) timedSeconds += t;
    std::sort(times.begin(), times.end());
    const Rgb mean = img.mean();
    std::printf("%-14s %-16s %-6s %9.3f s/it  mean %.4g %.4g %.4g\n",
                std::filesystem::path(path).stem().string().c_str(), set.c_str(),
                (backend + (cutRays ? "" : "/whole")).c_str(), times[times.size() / 2], mean.x,
                mean.y, mean.z);
    const std::string summary = integrator->iterationSummary();
    if (!summary.empty()) std::printf("    %s\n", summary.c_str());
    if (rayStats) {
        const int threads = tbb::this_task_arena::max_concurrency();
        const double perIteration = 1.0 / double(runs);
        std::printf(
            "    Embree queries per iteration: %.0f nearest, %.0f any-hit, %.0f crossing "
            "collections; %.0f ns each on average; %.4f s of thread time per iteration, %.0f%% "
            "of the iterations' time on %d threads\n",
            double(rays.calls[raystats::kNearest]) * perIteration,
            double(rays.calls[raystats::kAnyHit]) * perIteration,
            double(rays.calls[raystats::kCrossings]) * perIteration,
            rays.allCalls() > 0 ? rays.seconds / double(rays.allCalls()) * 1e9 : 0.0,
            rays.seconds * perIteration,
            timedSeconds > 0.0 ? 100.0 * rays.seconds / (double(threads) * timedSeconds) : 0.0,
            threads);
    }
    if (replays > 0 && backend == "opencl") {
        auto* vcm = dynamic_cast<VertexCM*>(integrator.get());
        if (!vcm || !vcm->hasDeviceEstimates())
            std::printf("    replay: this run has no OpenCL estimate pass\n");
        else {
            double hostSum = 0.0, deviceSum = 0.0;
            replayEstimates(*vcm, set, replays, width, height, clProfile, &hostSum, &deviceSum);
            // The whole iteration with the host twins' passes in place of the kernels', from
            // this process's alternating replays: the other passes are the same code on either
            // backend, so this ratio is free of the noise between separate runs.
            const double it = times[times.size() / 2], withHost = it - deviceSum + hostSum;
            std::printf(
                "    replay: estimate passes %.4f s on the host twins, %.4f s as kernels (medians "
                "summed); this run's iteration of %.4f s would take %.4f s with the twins: "
                "iteration host/OpenCL %.3f\n",
                hostSum, deviceSum, it, withHost, it > 0.0 ? withHost / it : 0.0);
        }
    }
    std::fflush(stdout);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    int runs = 3, width = 256, height = 256, replays = 0;
    bool sceneRadius = false, clProfile = false, rayStats = false;
    std::vector<std::string> backends = {"host"}, rays = {"cut"};
    std::vector<std::string> scenes,
        sets = {"upbp:bpt", "upbp:pp3d", "upbp:pb2d", "upbp:bp2d", "upbp:bb1d", "upbp"};
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        if (a == "--runs" && i + 1 < argc) {
            runs = std::max(1, std::atoi(argv[++i]));
        } else if (a == "--replay" && i + 1 < argc) {
            replays = std::max(1, std::atoi(argv[++i]));
        } else if (a == "--cl-profile") {
            clProfile = true;
        } else if (a == "--ray-stats") {
            rayStats = true;
        } else if (a == "--sets" && i + 1 < argc) {
            sets = splitList(argv[++i]);
        } else if (a == "--backends" && i + 1 < argc) {
            backends = splitList(argv[++i]);
        } else if (a == "--rays" && i + 1 < argc) {
            rays = splitList(argv[++i]);
            for (const std::string& r : rays)
                if (r != "cut" && r != "whole") {
                    std::fprintf(stderr, "bench_upbp: --rays expects cut, whole or cut,whole\n");
                    return 2;
                }
        } else if (a == "--radius-of" && i + 1 < argc) {
            const std::string of = argv[++i];
            if (of != "scene" && of != "media") {
                std::fprintf(stderr, "bench_upbp: --radius-of expects media or scene\n");
                return 2;
            }
            sceneRadius = of == "scene";
        } else if (a == "--resolution" && i + 1 < argc) {
            if (std::sscanf(argv[++i], "%dx%d", &width, &height) != 2 || width < 1 || height < 1) {
                std::fprintf(stderr, "bench_upbp: --resolution expects WxH\n");
                return 2;
            }
        } else if (a == "--help" || a == "-h") {
            std::printf(
                "usage: bench_upbp [--runs N] [--sets s1,s2,...] [--backends host,opencl] "
                "[--resolution WxH] [--radius-of media|scene] [--rays cut,whole] [--replay K] "
                "[--cl-profile] [--ray-stats] [SCENE ...]\n");
            return 0;
        } else if (!a.empty() && a[0] == '-') {
            std::fprintf(stderr, "bench_upbp: unknown option '%s' (or missing value; --help)\n",
                         a.c_str());
            return 2;
        } else {
            scenes.push_back(a);
        }
    }
    const std::string dir = std::string(UNIBEAM_SOURCE_DIR) + "/scenes/";
    if (scenes.empty()) {
        for (const char* s : {"cornell-fog", "cornell-smoke", "forward-scattering"})
            scenes.push_back(dir + s + ".json");
        for (const char* s : {"candle", "mirrorballs", "bunny"})
            scenes.push_back(dir + "smallupbp/" + s + "/" + s + ".obj");
    }
    std::printf("bench_upbp: %dx%d, median of %d iterations, peak resident memory per run\n", width,
                height, runs);
    for (const std::string& scene : scenes)
        for (const std::string& set : sets)
            for (const std::string& backend : backends)
                for (const std::string& ray : rays) {
                    std::fflush(stdout);
                    const pid_t pid = fork();
                    if (pid < 0) {
                        std::perror("fork");
                        return 1;
                    }
                    if (pid == 0) {
                        try {
                            std::_Exit(runOne(scene, set, runs, width, height, backend, sceneRadius,
                                              ray == "cut", replays, clProfile, rayStats));
                        } catch (const std::exception& e) {
                            std::fprintf(stderr, "bench_upbp: %s %s: %s\n", scene.c_str(),
                                         set.c_str(), e.what());
                            std::_Exit(1);
                        }
                    }
                    int status = 0;
                    rusage ru{};
                    wait4(pid, &status, 0, &ru);
                    std::printf("    peak memory %.0f MB%s\n", double(ru.ru_maxrss) / 1024.0,
                                WIFEXITED(status) && WEXITSTATUS(status) == 0 ? "" : " (failed)");
                }
    return 0;
}
