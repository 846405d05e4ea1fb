// Time per iteration of every surface algorithm (pt, lt, bpt, ppm, bpm, vcm) on a
// bundled Cornell box at 256x256 (one sample per pixel per iteration; the
// bidirectional ones also trace one light subpath per pixel). Each algorithm runs
// `runs` times; each run renders one warm-up iteration and then `iterations`
// timed ones; the table reports the median over runs of the mean time per
// iteration, and the fastest and slowest run. Not run by CTest.
//
// Usage: bench_bidir [scene.json] [iterations=4] [runs=5] [threads=0 (all)]
#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "core/error.h"
#include "render/integrator.h"
#include "scene/io/scene_loader.h"

using namespace ub;

int main(int argc, char** argv) {
    std::string scenePath =
        argc > 1 ? argv[1] : std::string(UNIBEAM_SOURCE_DIR) + "/scenes/cornell-small-light.json";
    const int iterations = argc > 2 ? std::atoi(argv[2]) : 4;
    const int runs = argc > 3 ? std::atoi(argv[3]) : 5;
    const int threads = argc > 4 ? std::atoi(argv[4]) : 0;
    if (iterations < 1 || runs < 1 || threads < 0) {
        std::fprintf(stderr, "usage: %s [scene.json] [iterations>=1] [runs>=1] [threads>=0]\n",
                     argv[0]);
        return 2;
    }
    std::unique_ptr<tbb::global_control> limit;
    if (threads > 0)
        limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                      size_t(threads));

    std::unique_ptr<Scene> scene;
    try {
        scene = loadScene(scenePath);
    } catch (const InputError& e) {
        std::fprintf(stderr, "%s\n", e.what());
        return 2;
    }
    Camera& cam = scene->camera;
    Camera c256;
    c256.setup(cam.position(), cam.position() + cam.forward(), cam.up(), cam.fovYDeg(), 256, 256,
               cam.lensRadius(), cam.focusDistance());
    cam = c256;

    std::printf("scene %s, 256x256, max path length %d, %d timed iterations x %d runs\n",
                scenePath.c_str(), scene->settings.maxPathLength, iterations, runs);
    std::printf("%-5s %14s %14s %14s\n", "algo", "median ms/it", "min ms/it", "max ms/it");
    for (const char* name : {"pt", "lt", "bpt", "ppm", "bpm", "vcm"}) {
        RenderOptions opt;
        opt.algorithm = name;
        opt.maxPathLength = scene->settings.maxPathLength;
        opt.seed = scene->settings.seed;
        std::vector<double> perIteration;
        for (int r = 0; r < runs; ++r) {
            auto integrator = makeIntegrator(*scene, opt);
            Image img;
            integrator->renderIteration(0, img);  // warm-up (allocations, caches)
            auto t0 = std::chrono::steady_clock::now();
            for (int it = 1; it <= iterations; ++it) integrator->renderIteration(it, img);
            auto t1 = std::chrono::steady_clock::now();
            perIteration.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count() /
                                   iterations);
        }
        std::sort(perIteration.begin(), perIteration.end());
        std::printf("%-5s %14.1f %14.1f %14.1f\n", name, perIteration[perIteration.size() / 2],
                    perIteration.front(), perIteration.back());
        std::fflush(stdout);
    }
    return 0;
}
