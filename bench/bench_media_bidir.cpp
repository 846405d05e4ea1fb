// Benchmark: time per iteration of the volumetric integrators `vpt`, `vlt` and `vbpt` on each
// bundled media scene at its own resolution (256x256): one sample per pixel, and for vlt and
// vbpt one light subpath per pixel; median of `runs` iterations after one warm-up iteration
// (each timed iteration is a fresh, independent one).
// Wall time and process CPU time (all threads) are reported: on a shared, loaded machine
// the CPU time is the comparable number. Also reports the image mean of the last run
// (a sanity check that the scene renders something). Not run by ctest.
//
// Usage: bench_media_bidir [--runs N] [--algorithms a,b,...] [SCENE ...]
//   (default: vpt,vlt,vbpt on the five media scenes in scenes/)
#include <tbb/info.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>
#include <vector>

#include "core/error.h"
#include "render/integrator.h"
#include "scene/io/scene_loader.h"

using namespace ub;

namespace {

double processCpuSeconds() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

}  // namespace

int main(int argc, char** argv) {
    int runs = 5;
    std::vector<std::string> scenes, algorithms;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        if (a == "--runs" && i + 1 < argc) {
            runs = std::max(1, std::atoi(argv[++i]));
        } else if (a == "--algorithms" && i + 1 < argc) {
            std::string list = argv[++i];
            for (size_t p = 0; p <= list.size();) {
                size_t q = list.find(',', p);
                if (q == std::string::npos) q = list.size();
                if (q > p) algorithms.push_back(list.substr(p, q - p));
                p = q + 1;
            }
        } else
            scenes.push_back(a);
    }
    if (scenes.empty())
        for (const char* s : {"cornell-fog", "cornell-smoke", "glass-medium-caustics",
                              "forward-scattering", "medium-specular-light"})
            scenes.push_back(std::string(UNIBEAM_SOURCE_DIR) + "/scenes/" + s + ".json");

    if (algorithms.empty()) algorithms = {"vpt", "vlt", "vbpt"};

    std::printf("median of %d iterations, %d threads\n", runs, tbb::info::default_concurrency());
    std::printf("%-28s %-5s %9s %12s %12s %12s\n", "scene", "algo", "size", "wall s/it", "cpu s/it",
                "image mean");
    for (const std::string& path : scenes)
        for (const std::string& algorithm : algorithms) {
            try {
                auto scene = loadScene(path);
                RenderOptions opt;
                opt.algorithm = algorithm;
                opt.maxPathLength = scene->settings.maxPathLength;
                opt.minPathLength = scene->settings.minPathLength;
                opt.seed = scene->settings.seed;
                auto integrator = makeIntegrator(*scene, opt);
                Image img;
                integrator->renderIteration(0, img);  // warm-up (page faults, TBB threads)
                std::vector<double> wall, cpu;
                for (int r = 0; r < runs; ++r) {
                    auto t0 = std::chrono::steady_clock::now();
                    double c0 = processCpuSeconds();
                    integrator->renderIteration(r + 1, img);
                    cpu.push_back(processCpuSeconds() - c0);
                    wall.push_back(
                        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0)
                            .count());
                }
                std::sort(wall.begin(), wall.end());
                std::sort(cpu.begin(), cpu.end());
                double mean = 0;
                for (const Rgb& p : img.pixels) mean += (p.x + p.y + p.z) / 3.0;
                mean /= double(img.pixels.size());
                std::string name = path.substr(path.find_last_of('/') + 1);
                std::printf("%-28s %-5s %4dx%-4d %12.4f %12.4f %12.5f\n", name.c_str(),
                            algorithm.c_str(), img.width, img.height, wall[wall.size() / 2],
                            cpu[cpu.size() / 2], mean);
                std::fflush(stdout);
            } catch (const InputError& e) {
                std::fprintf(stderr, "%s\n", e.what());
                return 2;
            }
        }
    return 0;
}
