// Benchmark: time per iteration of `vpt` (one sample per pixel) on each bundled media scene
// at its own resolution (256x256), median of `runs` runs after one warm-up iteration.
// Wall time and process CPU time (all threads) are reported: on a shared, loaded machine
// the CPU time is the comparable number. Also reports the image mean of the last run
// (a sanity check that the scene renders something). Not run by ctest.
//
// Usage: bench_vpt [--runs N] [SCENE ...]   (default: the five media scenes in scenes/)
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
    std::vector<std::string> scenes;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        if (a == "--runs" && i + 1 < argc)
            runs = std::max(1, std::atoi(argv[++i]));
        else
            scenes.push_back(a);
    }
    if (scenes.empty())
        for (const char* s : {"cornell-fog", "cornell-smoke", "glass-medium-caustics",
                              "forward-scattering", "medium-specular-light"})
            scenes.push_back(std::string(UNIBEAM_SOURCE_DIR) + "/scenes/" + s + ".json");

    std::printf("vpt, median of %d runs, %d threads\n", runs, tbb::info::default_concurrency());
    std::printf("%-28s %9s %12s %12s %12s\n", "scene", "size", "wall s/it", "cpu s/it",
                "image mean");
    for (const std::string& path : scenes) {
        try {
            auto scene = loadScene(path);
            RenderOptions opt;
            opt.algorithm = "vpt";
            opt.maxPathLength = scene->settings.maxPathLength;
            opt.minPathLength = scene->settings.minPathLength;
            opt.seed = scene->settings.seed;
            auto vpt = makeIntegrator(*scene, opt);
            Image img;
            vpt->renderIteration(0, img);  // warm-up (page faults, TBB threads)
            std::vector<double> wall, cpu;
            for (int r = 0; r < runs; ++r) {
                auto t0 = std::chrono::steady_clock::now();
                double c0 = processCpuSeconds();
                vpt->renderIteration(r + 1, img);
                cpu.push_back(processCpuSeconds() - c0);
                wall.push_back(
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
            }
            std::sort(wall.begin(), wall.end());
            std::sort(cpu.begin(), cpu.end());
            double mean = 0;
            for (const Rgb& p : img.pixels) mean += (p.x + p.y + p.z) / 3.0;
            mean /= double(img.pixels.size());
            std::string name = path.substr(path.find_last_of('/') + 1);
            std::printf("%-28s %4dx%-4d %12.4f %12.4f %12.5f\n", name.c_str(), img.width,
                        img.height, wall[wall.size() / 2], cpu[cpu.size() / 2], mean);
        } catch (const InputError& e) {
            std::fprintf(stderr, "%s\n", e.what());
            return 2;
        }
    }
    return 0;
}
