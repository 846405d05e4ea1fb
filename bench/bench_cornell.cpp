// Benchmark: `pt` on the Cornell box (scenes/cornell-large-light.json) at 256x256, next to
// Embree's raw closest-hit throughput on exactly the rays pt traces.
//
//  1. One iteration (iteration index 0, seed 1) is rendered with a PtRayLog: every
//     closest-hit ray pt traces is recorded, and shadow rays are counted.
//  2. The same iteration is rendered again `runs` times without the log (it traces the
//     same rays: the random streams depend only on seed, iteration and pixel); the
//     median wall time gives time per iteration and pt rays/s = (closest + shadow) / time.
//  3. The recorded closest-hit rays are traced again with Scene::intersect alone
//     (tbb::parallel_for over the rays, same threads), median of `runs`: Embree's raw
//     closest-hit rays/s on the same scene and rays.
// Both are also measured on one thread. Wall time and process CPU time (all threads) are
// reported: on a shared, loaded machine the CPU-time rates are the comparable ones.
// Not run by ctest.
//
// Usage: bench_cornell [SCENE] [--runs N] [--resolution N]
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <functional>
#include <string>
#include <vector>

#include "core/error.h"
#include "render/pt.h"
#include "scene/io/scene_loader.h"

using namespace ub;

namespace {

double processCpuSeconds() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

struct Timing {
    double wall = 0;  ///< median wall-clock seconds
    double cpu = 0;   ///< median process CPU seconds (all threads), robust to a loaded machine
};

Timing medianTiming(int runs, const std::function<void()>& f) {
    std::vector<double> wall, cpu;
    for (int i = 0; i < runs; ++i) {
        auto start = std::chrono::steady_clock::now();
        double cpuStart = processCpuSeconds();
        f();
        cpu.push_back(processCpuSeconds() - cpuStart);
        wall.push_back(
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    std::sort(wall.begin(), wall.end());
    std::sort(cpu.begin(), cpu.end());
    return {wall[wall.size() / 2], cpu[cpu.size() / 2]};
}

struct Row {
    std::string what;
    int threads;
    Timing t;
    uint64_t rays;
};

}  // namespace

int main(int argc, char** argv) {
    std::string scenePath = std::string(UNIBEAM_SOURCE_DIR) + "/scenes/cornell-large-light.json";
    int runs = 7, res = 256;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        if (a == "--runs" && i + 1 < argc)
            runs = std::max(1, std::atoi(argv[++i]));
        else if (a == "--resolution" && i + 1 < argc)
            res = std::max(1, std::atoi(argv[++i]));
        else
            scenePath = a;
    }
    std::unique_ptr<Scene> scene;
    try {
        scene = loadScene(scenePath);
    } catch (const InputError& e) {
        std::fprintf(stderr, "%s\n", e.what());
        return 2;
    }
    {
        const Camera& c = scene->camera;
        Camera cam;
        cam.setup(c.position(), c.position() + c.forward(), c.up(), c.fovYDeg(), res, res,
                  c.lensRadius(), c.focusDistance());
        scene->camera = cam;
    }
    RenderOptions opt;
    opt.maxPathLength = scene->settings.maxPathLength;
    opt.seed = 1;
    PathTracer pt(*scene, opt);
    Image img;

    PtRayLog log;
    pt.setRayLog(&log);
    pt.renderIteration(0, img);
    pt.setRayLog(nullptr);
    std::vector<Ray> rays;
    rays.reserve(log.closestCount());
    for (const auto& row : log.closestRays) rays.insert(rays.end(), row.begin(), row.end());
    const uint64_t closest = log.closestCount(), shadow = log.shadowCount();

    const int allThreads = tbb::info::default_concurrency();
    std::vector<Row> rows;
    for (int threads : {allThreads, 1}) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
        pt.renderIteration(0, img);  // warm-up
        Timing tPt = medianTiming(runs, [&] { pt.renderIteration(0, img); });
        std::vector<uint8_t> hitFlags(rays.size());
        Timing tRaw = medianTiming(runs, [&] {
            tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), 1024),
                              [&](const tbb::blocked_range<size_t>& r) {
                                  for (size_t i = r.begin(); i != r.end(); ++i) {
                                      Hit hit;
                                      hitFlags[i] = scene->intersect(rays[i], &hit);
                                  }
                              });
        });
        rows.push_back({"pt iteration (closest + shadow rays)", threads, tPt, closest + shadow});
        rows.push_back({"Embree closest hit, same rays", threads, tRaw, closest});
    }

    std::printf("scene %s, %dx%d, 1 sample/pixel, max path length %d, median of %d runs\n",
                scenePath.c_str(), res, res, opt.maxPathLength, runs);
    std::printf(
        "rays of one pt iteration: %llu closest-hit + %llu shadow = %llu "
        "(%.2f closest-hit rays per pixel)\n",
        (unsigned long long)closest, (unsigned long long)shadow,
        (unsigned long long)(closest + shadow), double(closest) / (double(res) * res));
    std::printf("| %-38s | %7s | %9s | %9s | %8s | %8s | %10s |\n", "measurement", "threads",
                "wall [ms]", "CPU [ms]", "rays", "Mrays/s", "Mrays/CPU-s");
    std::printf("|%s|%s|%s|%s|%s|%s|%s|\n", std::string(40, '-').c_str(),
                std::string(9, '-').c_str(), std::string(11, '-').c_str(),
                std::string(11, '-').c_str(), std::string(10, '-').c_str(),
                std::string(10, '-').c_str(), std::string(13, '-').c_str());
    for (const Row& r : rows)
        std::printf("| %-38s | %7d | %9.2f | %9.2f | %8llu | %8.2f | %11.2f |\n", r.what.c_str(),
                    r.threads, r.t.wall * 1e3, r.t.cpu * 1e3, (unsigned long long)r.rays,
                    r.rays / r.t.wall * 1e-6, r.rays / r.t.cpu * 1e-6);
    std::printf("time per pt iteration (%d threads, median wall): %.2f ms\n", allThreads,
                rows[0].t.wall * 1e3);
    return 0;
}
