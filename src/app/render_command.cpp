// `unibeam render`: load a scene, run the progressive loop, write EXR/PNG.
#include <tbb/global_control.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>

#include "app/commands.h"
#include "app/progress_bar.h"
#include "app/scene_access.h"
#include "core/error.h"
#include "core/file_status.h"
#include "core/image.h"
#include "core/memory_budget.h"
#include "render/aov.h"
#include "render/checkpoint.h"
#include "render/integrator.h"
#include "render/progressive.h"
#include "render/upbp_techniques.h"

namespace ub::app {

namespace fs = std::filesystem;

namespace {

std::string lower(std::string s) {
    for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

/// Throws UsageError unless `path` has extension `ext` and can be created or overwritten.
void checkOutputPath(const std::string& path, const std::string& ext, const std::string& flag) {
    fs::path p(path);
    if (!ext.empty() && lower(p.extension().string()) != ext)
        throw UsageError(flag + ": output file '" + path + "' must end in " + ext);
    fs::path dir = p.parent_path();
    if (dir.empty()) dir = ".";
    if (!isDirectory(dir))
        throw UsageError(flag + ": cannot write '" + path + "': directory '" + dir.string() +
                         "' does not exist");
    if (isDirectory(p)) throw UsageError(flag + ": cannot write '" + path + "': it is a directory");
    if (::access(dir.c_str(), W_OK) != 0)
        throw UsageError(flag + ": cannot write '" + path + "': directory '" + dir.string() +
                         "' is not writable");
    if (pathExists(p) && ::access(p.c_str(), W_OK) != 0)
        throw UsageError(flag + ": cannot write '" + path + "': file is not writable");
}

/// The options that affect the image, one "key=value" line each (checkpoint.h): a resumed
/// render must have the same. Iteration counts, time limits, threads, outputs and the
/// backend (host and OpenCL agree to float rounding only) are left out, except the backend,
/// which is kept because the two differ in the last bits.
std::string imageOptionsText(const RenderOptions& o, const RenderArgs& args, const Scene& scene) {
    std::ostringstream t;
    t.precision(9);
    t << "algorithm=" << o.algorithm << "\nresolution=" << scene.camera.width() << "x"
      << scene.camera.height() << "\nmaxPathLength=" << o.maxPathLength
      << "\nminPathLength=" << o.minPathLength << "\nseed=" << o.seed
      << "\nmis=" << (o.heuristic == MisHeuristic::Balance ? "balance" : "power")
      << "\nradius=" << o.radius << "\nalpha=" << o.alpha << "\nradiusPP3D=" << o.radiusPP3D
      << "\nradiusPB2D=" << o.radiusPB2D << "\nradiusBP2D=" << o.radiusBP2D
      << "\nradiusBB1D=" << o.radiusBB1D << "\nalphaPP3D=" << o.alphaPP3D
      << "\nalphaPB2D=" << o.alphaPB2D << "\nalphaBP2D=" << o.alphaBP2D
      << "\nalphaBB1D=" << o.alphaBB1D
      << "\nphotonBeams=" << (o.shortPhotonBeams ? "short" : "long")
      << "\nqueryBeams=" << (o.shortQueryBeams ? "short" : "long") << "\nbeamPaths=" << o.beamPaths
      << "\nbackend=" << o.backend << "\nvariance=" << (args.variancePath.empty() ? "no" : "yes")
      << "\n";
    for (const auto& [k, v] : args.defines) t << "define." << k << "=" << v << "\n";
    return t.str();
}

}  // namespace

void parseResolution(const std::string& s, int* w, int* h) {
    auto bad = [&] {
        return UsageError(
            "--resolution: expected WIDTHxHEIGHT with positive integers up to "
            "16384 (e.g. 640x480), got '" +
            s + "'");
    };
    size_t x = s.find_first_of("xX");
    if (x == std::string::npos || x == 0 || x + 1 >= s.size()) throw bad();
    auto parse = [&](const std::string& part) {
        if (part.size() > 5 || !std::all_of(part.begin(), part.end(), ::isdigit)) throw bad();
        int v = std::stoi(part);
        if (v < 1 || v > 16384) throw bad();
        return v;
    };
    *w = parse(s.substr(0, x));
    *h = parse(s.substr(x + 1));
}

namespace {

std::string join(const std::vector<std::string>& v) {
    std::string s;
    for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
    return s;
}

}  // namespace

RenderOptions makeRenderOptions(const RenderArgs& args, const Scene& scene) {
    RenderOptions options;
    options.algorithm = args.algorithm;
    // A scene may name its algorithm (Mitsuba's ptracer: lt); -a overrides it. Without -a, a
    // scene with media gets the volumetric twin (pt -> vpt, lt -> vlt), as Mitsuba's volpath
    // renders what its path does and the media too.
    if (!args.algorithmGiven) {
        if (!scene.settings.defaultAlgorithm.empty())
            options.algorithm = scene.settings.defaultAlgorithm;
        if (scene.hasMedia() && (options.algorithm == "pt" || options.algorithm == "lt"))
            options.algorithm = options.algorithm == "pt" ? "vpt" : "vlt";
    }
    options.maxPathLength = args.maxLength ? *args.maxLength : scene.settings.maxPathLength;
    options.minPathLength = scene.settings.minPathLength;
    options.seed = args.seed ? *args.seed : scene.settings.seed;
    options.heuristic = args.mis == "balance" ? MisHeuristic::Balance : MisHeuristic::Power;
    if (args.radius) options.radius = *args.radius;
    if (args.alpha) options.alpha = *args.alpha;
    float* radii[4] = {&options.radiusPP3D, &options.radiusPB2D, &options.radiusBP2D,
                       &options.radiusBB1D};
    float* alphas[4] = {&options.alphaPP3D, &options.alphaPB2D, &options.alphaBP2D,
                        &options.alphaBB1D};
    for (int t = 0; t < 4; ++t) {
        if (args.volumeRadius[t]) *radii[t] = *args.volumeRadius[t];
        if (args.volumeAlpha[t]) *alphas[t] = *args.volumeAlpha[t];
    }
    if (!args.photonBeams.empty()) options.shortPhotonBeams = args.photonBeams == "short";
    if (!args.queryBeams.empty()) options.shortQueryBeams = args.queryBeams == "short";
    if (args.beamPaths) options.beamPaths = *args.beamPaths;
    options.backend = args.backend;
    if (args.maxMemory.empty()) {
        options.maxMemoryBytes = defaultMemoryBudget();
    } else {
        try {
            options.maxMemoryBytes = parseMemorySize(args.maxMemory);
        } catch (const std::invalid_argument& e) {
            throw UsageError(std::string("--max-memory: ") + e.what());
        }
    }
    options.clCache = args.clCache;
    if (!args.clDevice.empty()) {
        int p = -1, d = -1;
        char tail = 0;
        if (std::sscanf(args.clDevice.c_str(), "%d:%d%c", &p, &d, &tail) != 2 || p < 0 || d < 0)
            throw UsageError(
                "--cl-device: expected PLATFORM:DEVICE (two indices >= 0, as "
                "'unibeam devices' lists them), got '" +
                args.clDevice + "'");
        options.clPlatform = p;
        options.clDevice = d;
    }
    return options;
}

int runRender(const RenderArgs& args) {
    // ---- validate everything that does not need the scene ----
    const auto names = integratorNames();
    if (isUpbpAlgorithm(args.algorithm)) {
        try {
            parseUpbpTechniques(args.algorithm);
        } catch (const InputError& e) {
            throw UsageError("-a/--algorithm: " + e.diagnostics()[0].message);
        }
    } else if (std::find(names.begin(), names.end(), args.algorithm) == names.end()) {
        throw UsageError("-a/--algorithm: unknown algorithm '" + args.algorithm +
                         "' (valid: " + join(names) + ", upbp:T1+T2+...)");
    }
    int width = 0, height = 0;
    if (!args.resolution.empty()) parseResolution(args.resolution, &width, &height);
    std::string exrPath = args.exrPath;
    if (exrPath.empty() && args.pngPath.empty())
        exrPath = fs::path(args.scene).stem().string() + ".exr";
    if (!exrPath.empty()) checkOutputPath(exrPath, ".exr", "-o/--output");
    if (!args.pngPath.empty()) checkOutputPath(args.pngPath, ".png", "--png");
    if (args.pngLayers && args.pngPath.empty())
        throw UsageError("--png-layers: needs --png FILE.png (the layers go beside it)");
    if (!args.variancePath.empty()) checkOutputPath(args.variancePath, ".exr", "--variance");
    if (!pathExists(args.scene)) throw UsageError("scene file '" + args.scene + "' does not exist");

    std::unique_ptr<tbb::global_control> threadLimit;
    if (args.threads > 0)
        threadLimit = std::make_unique<tbb::global_control>(
            tbb::global_control::max_allowed_parallelism, size_t(args.threads));

    // ---- scene and options ----
    std::unique_ptr<Scene> scene = loadSceneFile(args.scene, args.defines);
    if (width > 0)
        scene->camera = scene->camera.resized(width, height, scene->settings.keepHorizontalFov);
    RenderOptions options = makeRenderOptions(args, *scene);
    if (options.algorithm != args.algorithm)
        std::fprintf(
            stderr, "unibeam: %s renders with %s (-a chooses another)\n",
            scene->hasMedia() ? "the scene has participating media:" : "the scene's integrator",
            options.algorithm.c_str());
    std::unique_ptr<Integrator> integrator = makeIntegrator(*scene, options);
    if (!integrator->setupNote().empty())
        std::fprintf(stderr, "unibeam: %s\n", integrator->setupNote().c_str());

    // ---- checkpoints ----
    const std::string checkpointPath =
        !args.checkpointPath.empty() ? args.checkpointPath : args.resumePath;
    CheckpointHeader header;
    std::unique_ptr<ProgressiveState> resumed;
    if (!checkpointPath.empty() || !args.resumePath.empty()) {
        header.version = UNIBEAM_VERSION;
        header.sceneDigest = digestFile(args.scene);
        header.options = imageOptionsText(options, args, *scene);
        header.width = uint32_t(scene->camera.width());
        header.height = uint32_t(scene->camera.height());
    }
    if (!checkpointPath.empty()) checkOutputPath(checkpointPath, "", "--checkpoint");
    if (!args.resumePath.empty()) {
        if (!isRegularFile(args.resumePath))
            throw UsageError("--resume: checkpoint '" + args.resumePath + "' does not exist");
        resumed = std::make_unique<ProgressiveState>(readCheckpoint(args.resumePath, header));
        std::fprintf(stderr, "unibeam: resuming %s: %d iterations, %.1f s done\n",
                     args.resumePath.c_str(), resumed->iterations, resumed->seconds);
    }
    ProgressiveOptions prog;
    prog.iterations = args.iterations;
    prog.timeLimitSeconds = args.timeLimit;
    prog.computeVariance = !args.variancePath.empty();
    prog.resume = resumed.get();
    if (!checkpointPath.empty()) {
        prog.checkpointEverySeconds = args.checkpointEvery;
        prog.checkpoint = [&](const ProgressiveState& state) {
            writeCheckpoint(checkpointPath, header, state);
        };
    }
    if (prog.iterations <= 0 && prog.timeLimitSeconds <= 0) prog.iterations = kDefaultIterations;
    ProgressBar bar(stderr, ::isatty(::fileno(stderr)) != 0);
    prog.progress = [&](const ProgressInfo& info) { bar.update(info); };
    const int w = scene->camera.width(), h = scene->camera.height();
    installStopSignalHandlers();
    std::fprintf(stderr, "unibeam: rendering %s with %s at %dx%d, max path length %d, seed %llu\n",
                 args.scene.c_str(), options.algorithm.c_str(), w, h, options.maxPathLength,
                 static_cast<unsigned long long>(options.seed));

    ProgressiveResult result = renderProgressive(*integrator, w, h, prog);
    bar.finish();
    if (!result.stopError.empty())
        std::fprintf(stderr, "unibeam: stopped after %d iterations: %s; writing the image\n",
                     result.iterations, result.stopError.c_str());
    else if (result.interrupted)
        std::fprintf(stderr, "unibeam: stopped by %s after %d iterations; writing the image\n",
                     lastStopSignal() == SIGTERM ? "SIGTERM" : "SIGINT", result.iterations);

    // ---- output ----
    ImageMetadata meta;
    meta["software"] = std::string("unibeam ") + UNIBEAM_VERSION;
    meta["scene"] = args.scene;
    meta["technique"] = options.algorithm;
    meta["iterations"] = std::to_string(result.iterations);
    char seconds[32];
    std::snprintf(seconds, sizeof(seconds), "%.3f", result.seconds);
    meta["renderTimeSeconds"] = seconds;
    meta["seed"] = std::to_string(options.seed);
    meta["resolution"] = std::to_string(w) + "x" + std::to_string(h);
    meta["maxPathLength"] = std::to_string(options.maxPathLength);
    meta["mis"] = args.mis;
    meta["interrupted"] = result.interrupted ? "true" : "false";
    if (!result.layers.empty()) {
        std::string names;
        for (const auto& l : result.layers) names += (names.empty() ? "" : ",") + l.first;
        meta["layers"] = names;
    }
    for (const auto& [key, value] : rejectionAttributes(result.rejected)) meta[key] = value;
    // Mitsuba's aov integrator: its variables as extra layers (render/aov.h), from as many
    // camera samples per pixel as the image had iterations, at most 64.
    std::vector<std::pair<std::string, Image>> exrLayers = result.layers;
    if (!scene->settings.aovs.empty()) {
        const int samples = std::clamp(result.iterations, 1, 64);
        for (auto& l : renderAovs(*scene, samples, options.seed)) exrLayers.push_back(std::move(l));
        std::string names;
        for (const auto& a : scene->settings.aovs)
            names += (names.empty() ? "" : ",") + a.name + ":" + a.type;
        meta["aovs"] = names;
        std::fprintf(stderr, "unibeam: AOV layers %s (%d camera samples per pixel)\n",
                     names.c_str(), samples);
    }
    if (!exrPath.empty()) {
        writeExr(exrPath, result.image, meta, exrLayers);
        std::fprintf(stderr, "unibeam: wrote %s\n", exrPath.c_str());
    }
    if (!args.variancePath.empty()) {
        if (result.iterations < 2)
            throw UsageError("--variance: needs at least 2 iterations, rendered " +
                             std::to_string(result.iterations));
        ImageMetadata vmeta = meta;
        vmeta["content"] =
            "per-pixel sample variance of one iteration (divide by iterations "
            "for the variance of the mean image)";
        writeExr(args.variancePath, result.variance, vmeta);
        std::fprintf(stderr, "unibeam: wrote %s\n", args.variancePath.c_str());
    }
    if (!args.pngPath.empty()) {
        writePng(args.pngPath, result.image, args.exposure);
        std::fprintf(stderr, "unibeam: wrote %s\n", args.pngPath.c_str());
        if (args.pngLayers)
            for (const auto& l : result.layers) {
                const fs::path p(args.pngPath);
                const std::string path =
                    (p.parent_path() / (p.stem().string() + "." + l.first + ".png")).string();
                writePng(path, l.second, args.exposure);
                std::fprintf(stderr, "unibeam: wrote %s\n", path.c_str());
            }
    }
    if (!result.layers.empty()) {
        // Each technique's share of the image (layer mean over image mean, channel average).
        const double total = average(result.image.mean());
        std::string shares;
        for (const auto& l : result.layers) {
            char buf[64];
            std::snprintf(buf, sizeof(buf), "%s%s %.1f%%", shares.empty() ? "" : ", ",
                          l.first.c_str(),
                          total > 0.0 ? 100.0 * double(average(l.second.mean())) / total : 0.0);
            shares += buf;
        }
        std::fprintf(stderr, "unibeam: technique shares of the image: %s\n", shares.c_str());
    }
    // Always printed, zeros included (docs/cli.md, "Rejected contributions").
    std::fprintf(stderr, "unibeam: rejected contributions (NaN, Inf or negative): %s\n",
                 formatRejections(result.rejected).c_str());
    if (!result.stopError.empty()) {
        std::fprintf(stderr, "unibeam: error: %s\n", result.stopError.c_str());
        return 2;
    }
    const std::string summary = integrator->iterationSummary();
    if (!summary.empty()) std::fprintf(stderr, "unibeam: %s\n", summary.c_str());
    std::fprintf(stderr, "unibeam: %d iterations in %s (%.3f s/iteration)\n", result.iterations,
                 formatSeconds(result.seconds).c_str(),
                 result.iterations > 0 ? result.seconds / result.iterations : 0.0);
    return 0;
}

}  // namespace ub::app
