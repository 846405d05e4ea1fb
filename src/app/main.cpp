// `unibeam`: the command-line program (CLI11). Commands:
//   unibeam render SCENE [options]   render a scene progressively, write EXR / PNG
//   unibeam info SCENE               print what a scene contains
//   unibeam compare IMAGE REF [--threshold T] [--diff OUT.png] [--ztest REF_VAR --spp N]
//   unibeam --version | --help, and --help on every command.
// Exit status: 0 success, 1 unexpected failure, 2 bad input (flags, scene, paths).
// docs/cli.md documents every option.
#include <CLI/CLI.hpp>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <new>
#include <sstream>
#include <string>

#include "app/commands.h"
#include "core/error.h"
#include "core/memory_budget.h"
#include "render/integrator.h"

namespace {

constexpr int kExitFailure = 1;
constexpr int kExitBadInput = 2;

/// Parses a non-negative decimal 64-bit integer, or throws UsageError.
uint64_t parseSeed(const std::string& s) {
    bool digits = !s.empty() && s.size() <= 20;
    for (char c : s) digits = digits && c >= '0' && c <= '9';
    if (digits) {
        errno = 0;
        char* end = nullptr;
        unsigned long long v = std::strtoull(s.c_str(), &end, 10);
        if (errno == 0 && *end == '\0') return uint64_t(v);
    }
    throw ub::app::UsageError("--seed: expected a non-negative integer below 2^64, got '" + s +
                              "'");
}

/// CLI11 validator: a decimal integer > 0.
CLI::Validator positiveInteger() {
    return CLI::Validator(
        [](std::string& s) -> std::string {
            bool ok = !s.empty() && s.size() <= 9 &&
                      s.find_first_not_of("0123456789") == std::string::npos;
            if (ok && std::stol(s) > 0) return {};
            return "expected an integer > 0, got '" + s + "'";
        },
        "");
}

/// CLI11 validator: a finite real number in (0, max].
CLI::Validator positiveReal(double max = 1e30) {
    return CLI::Validator(
        [max](std::string& s) -> std::string {
            char* end = nullptr;
            double v = std::strtod(s.c_str(), &end);
            if (!s.empty() && end && *end == '\0' && std::isfinite(v) && v > 0 && v <= max)
                return {};
            char range[64];
            std::snprintf(range, sizeof(range), max < 1e30 ? "in (0, %g]" : "> 0", max);
            return std::string("expected a number ") + range + ", got '" + s + "'";
        },
        "");
}

/// CLI11 validator: a decimal integer in [1, max].
CLI::Validator integerUpTo(long max) {
    return CLI::Validator(
        [max](std::string& s) -> std::string {
            bool ok = !s.empty() && s.size() <= 9 &&
                      s.find_first_not_of("0123456789") == std::string::npos;
            if (ok && std::stol(s) > 0 && std::stol(s) <= max) return {};
            return "expected an integer in [1, " + std::to_string(max) + "], got '" + s + "'";
        },
        "");
}

/// CLI11 validator: a finite real number in [-limit, limit].
CLI::Validator finiteReal(double limit) {
    return CLI::Validator(
        [limit](std::string& s) -> std::string {
            char* end = nullptr;
            double v = std::strtod(s.c_str(), &end);
            if (!s.empty() && end && *end == '\0' && std::isfinite(v) && std::fabs(v) <= limit)
                return {};
            char range[64];
            std::snprintf(range, sizeof(range), "in [%g, %g]", -limit, limit);
            return std::string("expected a number ") + range + ", got '" + s + "'";
        },
        "");
}

std::string algorithmList() {
    std::string s;
    for (const auto& n : ub::integratorNames()) s += (s.empty() ? "" : ", ") + n;
    return s;
}

int run(int argc, char** argv) {
    CLI::App app{"unibeam: a physically based renderer (path tracing, VCM, UPBP)", "unibeam"};
    app.set_version_flag("--version", std::string("unibeam ") + UNIBEAM_VERSION);
    app.require_subcommand(1);
    app.fallthrough(false);

    // ---- render ----
    ub::app::RenderArgs ra;
    std::string seedText, maxLengthText;
    float radius = 0, alpha = 0;
    CLI::App* render = app.add_subcommand("render", "Render a scene progressively");
    render
        ->add_option(
            "scene", ra.scene,
            "Scene file: unibeam .json, Mitsuba 3 .xml, or SmallUPBP .obj (with its .obj.aux)")
        ->required()
        ->type_name("SCENE");
    CLI::Option* algorithmOpt =
        render
            ->add_option("-a,--algorithm", ra.algorithm,
                         "Rendering algorithm: one of " + algorithmList() +
                             " (default pt, or lt for a Mitsuba scene whose integrator is "
                             "ptracer; on a scene with media vpt, or vlt). UPBP: 'upbp' runs all "
                             "six techniques, "
                             "'upbp:T1+T2+...' any subset of bpt (connections, NEE, light "
                             "tracing), surf (surface merging), pp3d, pb2d, bp2d, bb1d (volumetric "
                             "points and beams), with MIS over exactly those; without bpt only "
                             "paths the chosen estimators can merge are rendered (docs/"
                             "algorithms.md). 'vcm' on a scene with media is upbp:bpt+surf")
            ->type_name("ALGO");
    CLI::Option* timeOpt =
        render
            ->add_option("-t,--time", ra.timeLimit,
                         "Time limit in seconds (> 0); the iteration running at the limit "
                         "is finished")
            ->check(positiveReal())
            ->type_name("SECONDS");
    CLI::Option* iterOpt =
        render
            ->add_option("-i,--iterations", ra.iterations,
                         "Number of iterations, one sample per pixel each (> 0; default " +
                             std::to_string(ub::app::kDefaultIterations) +
                             " when neither -t nor -i is given)")
            ->check(positiveInteger())
            ->type_name("N");
    timeOpt->excludes(iterOpt);
    render
        ->add_option("-o,--output", ra.exrPath,
                     "OpenEXR output (32-bit float RGB); default SCENE_STEM.exr in the "
                     "current directory unless only --png is given")
        ->type_name("FILE.exr");
    render->add_option("--png", ra.pngPath, "Also write an 8-bit sRGB PNG")->type_name("FILE.png");
    render->add_flag("--png-layers", ra.pngLayers,
                     "With --png and upbp: also write each technique's layer as "
                     "FILE.TECHNIQUE.png, with the exposure of the image");
    render
        ->add_option("--exposure", ra.exposure,
                     "PNG exposure in stops, in [-64, 64] (PNG = 2^EV x image)")
        ->check(finiteReal(64.0))
        ->type_name("EV");
    // Bounded: TBB stalls when told to allow a billion threads.
    render
        ->add_option("--threads", ra.threads,
                     "Number of threads, in [1, 4096] (default: all cores)")
        ->check(integerUpTo(4096))
        ->type_name("N");
    render->add_option("--seed", seedText, "Random seed (non-negative integer; default: scene)")
        ->type_name("S");
    render
        ->add_option("--max-length", maxLengthText,
                     "Maximum path length in segments (>= 1; a directly visible light is "
                     "length 1; default: scene)")
        ->type_name("L");
    render->add_option("--resolution", ra.resolution, "Image size WIDTHxHEIGHT (default: scene)")
        ->type_name("WxH");
    render->add_option("--mis", ra.mis, "MIS heuristic: power or balance (default power)")
        ->check(CLI::IsMember({"power", "balance"}).description(""))
        ->type_name("power|balance");
    CLI::Option* radiusOpt =
        render
            ->add_option("--radius", radius,
                         "Merging radius (ppm/bpm/vcm) as a fraction of the scene bounding "
                         "sphere radius (> 0)")
            ->check(positiveReal())
            ->type_name("R");
    CLI::Option* alphaOpt =
        render
            ->add_option("--alpha", alpha,
                         "Radius reduction exponent of progressive merging, in (0, 1]")
            ->check(positiveReal(1.0))
            ->type_name("A");

    // UPBP's volumetric estimators.
    const char* kTech[4] = {"pp3d", "pb2d", "bp2d", "bb1d"};
    const char* kDim[4] = {"3", "2", "2", "1"};
    const float kDefaultRadius[4] = {ub::RenderOptions().radiusPP3D, ub::RenderOptions().radiusPB2D,
                                     ub::RenderOptions().radiusBP2D,
                                     ub::RenderOptions().radiusBB1D};
    float volumeRadius[4] = {0, 0, 0, 0}, volumeAlpha[4] = {0, 0, 0, 0};
    CLI::Option* volumeRadiusOpt[4];
    CLI::Option* volumeAlphaOpt[4];
    for (int t = 0; t < 4; ++t) {
        char def[32];
        std::snprintf(def, sizeof(def), "%g", double(kDefaultRadius[t]));
        volumeRadiusOpt[t] =
            render
                ->add_option(
                    std::string("--radius-") + kTech[t], volumeRadius[t],
                    std::string("upbp: initial ") + kTech[t] +
                        " radius as a fraction of the media's radius (docs/algorithms.md; > "
                        "0; default " +
                        def + ")")
                ->check(positiveReal())
                ->type_name("R");
        volumeAlphaOpt[t] = render
                                ->add_option(std::string("--alpha-") + kTech[t], volumeAlpha[t],
                                             std::string("upbp: ") + kTech[t] +
                                                 " radius reduction, r_i = r_1 i^((alpha-1)/" +
                                                 kDim[t] + "), in (0, 1] (default 0.75)")
                                ->check(positiveReal(1.0))
                                ->type_name("A");
    }
    render
        ->add_option("--photon-beams", ra.photonBeams,
                     "upbp: photon beams end at the sampled scattering distance (short, "
                     "default) or run to the next surface (long)")
        ->check(CLI::IsMember({"short", "long"}).description(""))
        ->type_name("short|long");
    render
        ->add_option("--query-beams", ra.queryBeams,
                     "upbp: query (camera) beams short or long (default long)")
        ->check(CLI::IsMember({"short", "long"}).description(""))
        ->type_name("short|long");
    int beamPaths = 0;
    CLI::Option* beamPathsOpt =
        render
            ->add_option("--beam-paths", beamPaths,
                         "upbp: the first N light subpaths of an iteration emit photon beams "
                         "(>= 1; default 1/16 of the light subpaths)")
            ->check(positiveInteger())
            ->type_name("N");

    render
        ->add_option("--backend", ra.backend,
                     "upbp: where the estimate pass runs: opencl (kernels; error without a "
                     "working device), host (C++), auto (OpenCL if a device works, else the "
                     "host; default). Every estimator has a kernel (pp3d, pb2d, bp2d, bb1d, "
                     "surf); in grid media with an albedo grid or trilinear filtering pb2d, "
                     "bp2d and bb1d run on the host (docs/opencl.md)")
        ->check(CLI::IsMember({"host", "opencl", "auto"}).description(""))
        ->type_name("opencl|host|auto");
    render
        ->add_option("--cl-device", ra.clDevice,
                     "upbp: OpenCL device PLATFORM:DEVICE as 'unibeam devices' lists them "
                     "(default: the first)")
        ->type_name("P:D");
    render
        ->add_option("--cl-cache", ra.clCache,
                     "upbp: folder of the OpenCL program cache (default "
                     "$XDG_CACHE_HOME/unibeam/opencl or ~/.cache/unibeam/opencl; '-': none)")
        ->type_name("DIR");
    std::vector<std::string> renderDefines, infoDefines;
    render
        ->add_option("-D,--define", renderDefines,
                     "Scene parameter NAME=VALUE: overrides a Mitsuba XML <default> (repeatable)")
        ->type_name("NAME=VALUE")
        ->take_all()
        ->allow_extra_args(false);
    render
        ->add_option("--variance", ra.variancePath,
                     "Also write the per-pixel sample variance of one iteration (OpenEXR; needs "
                     ">= 2 iterations; divide by the iteration count for the mean's variance)")
        ->type_name("FILE.exr");
    render
        ->add_option("--checkpoint", ra.checkpointPath,
                     "Write the render's state to FILE every --checkpoint-every seconds and at "
                     "the end (atomically), so --resume FILE can continue it")
        ->type_name("FILE");
    render
        ->add_option("--checkpoint-every", ra.checkpointEvery,
                     "Seconds between checkpoints (default 60)")
        ->check(positiveReal())
        ->type_name("SECONDS");
    render
        ->add_option("--max-memory", ra.maxMemory,
                     "Bound on the per-iteration records (light vertices, photons, beams, "
                     "queries) and lookups, e.g. 512M or 8G; checked before they grow (default: "
                     "half of the machine's memory)")
        ->type_name("SIZE");
    render
        ->add_option("--resume", ra.resumePath,
                     "Continue the render saved in FILE (same scene and options; -i / -t count "
                     "the iterations and seconds already done); checkpoints go on into FILE "
                     "unless --checkpoint names another")
        ->type_name("FILE");

    // ---- info ----
    std::string infoScene;
    CLI::App* info = app.add_subcommand("info", "Print what a scene file contains");
    info->add_option("scene", infoScene, "Scene file")->required()->type_name("SCENE");
    info->add_option("-D,--define", infoDefines,
                     "Scene parameter NAME=VALUE: overrides a Mitsuba XML <default> (repeatable)")
        ->type_name("NAME=VALUE")
        ->allow_extra_args(false);

    // ---- devices ----
    CLI::App* devices = app.add_subcommand("devices", "List the OpenCL platforms and devices");

    // ---- compare ----
    ub::app::CompareArgs ca;
    CLI::App* compare = app.add_subcommand(
        "compare",
        "Compare a rendered image with a reference: RMSE, relative MSE and mean absolute error "
        "per channel and overall (exit 0 pass, 1 fail, 2 bad input)");
    compare->add_option("IMAGE", ca.image, "Rendered image (OpenEXR)")
        ->required()
        ->type_name("IMAGE.exr");
    compare->add_option("REF", ca.reference, "Reference image (OpenEXR, same size)")
        ->required()
        ->type_name("REF.exr");
    compare
        ->add_option("--threshold", ca.threshold,
                     "Fail (exit 1) when the overall --metric exceeds T; default: report only")
        ->check(CLI::NonNegativeNumber)
        ->type_name("T");
    compare
        ->add_option("--metric", ca.metric,
                     "Metric that --threshold applies to: relmse (default), rmse or mae")
        ->check(CLI::IsMember({"relmse", "rmse", "mae"}))
        ->type_name("M");
    compare
        ->add_option("--diff", ca.diffPng,
                     "Write a false-colour PNG of the per-pixel relative error with a colour bar")
        ->type_name("OUT.png");
    compare
        ->add_option("--diff-max", ca.diffMax,
                     "Top of the --diff colour scale (default: the 99th percentile)")
        ->check(positiveReal())
        ->type_name("E");
    compare
        ->add_option("--ztest", ca.referenceVariance,
                     "Also run a per-pixel z-test with this per-sample variance of the reference "
                     "(e.g. Mitsuba's *_ref_rgb_var.exr); needs --spp")
        ->type_name("VAR.exr");
    compare
        ->add_option("--image-var", ca.imageVariance,
                     "z-test: per-sample variance of the image (unibeam render --variance); "
                     "default: the reference variance stands for it")
        ->type_name("VAR.exr");
    compare->add_option("--spp", ca.samples, "z-test: iterations averaged into IMAGE")
        ->check(positiveReal())
        ->type_name("N");
    compare
        ->add_option("--ref-spp", ca.referenceSamples,
                     "z-test: samples per pixel of the reference (adds its own error); default: "
                     "the reference is treated as exact")
        ->check(positiveReal())
        ->type_name("M");
    compare
        ->add_option("--alpha", ca.alpha,
                     "z-test: family-wise significance level, Sidak-corrected over all "
                     "pixel-channels (default 0.01)")
        ->check(positiveReal(0.999))
        ->type_name("A");
    compare
        ->add_option("--variance-radius", ca.varianceRadius,
                     "z-test: image variance of a pixel is the larger of its own and the mean "
                     "over its (2R+1)^2 neighbourhood (needs --image-var; guards against "
                     "heavy-tailed estimators; default 0: its own)")
        ->check(CLI::Range(0, 8))
        ->type_name("R");

    // ---- study ----
    ub::app::StudyArgs sa;
    std::string studyTechniques;
    uint64_t studySeed = 0;
    int studyMaxLength = 0;
    CLI::App* study = app.add_subcommand(
        "study",
        "Equal-time (or equal-iteration) comparison of techniques against a reference: "
        "convergence.csv, summary.csv, convergence.png and index.html in --out DIR");
    study->add_option("SCENE", sa.scene, "Scene file (.json, .xml, .obj)")->required();
    study
        ->add_option("--techniques", studyTechniques,
                     "Comma-separated techniques, any -a value (e.g. upbp,upbp:bpt+bb1d,vpt)")
        ->required()
        ->type_name("T1,T2,...");
    auto* studyTime = study->add_option("--time", sa.timeSeconds, "Seconds per technique")
                          ->check(positiveReal())
                          ->type_name("S");
    study->add_option("--iterations", sa.iterations, "Iterations per technique")
        ->check(CLI::PositiveNumber)
        ->excludes(studyTime)
        ->type_name("N");
    study
        ->add_option("--reference", sa.reference,
                     "Reference image (OpenEXR, the study's resolution); default: rendered "
                     "first with upbp for 4x the per-technique budget")
        ->type_name("REF.exr");
    study
        ->add_option("--reference-time", sa.referenceSeconds,
                     "Seconds for the reference render when no --reference is given")
        ->check(positiveReal())
        ->type_name("S");
    study->add_option("--resolution", sa.render.resolution, "Image size WIDTHxHEIGHT")
        ->type_name("WxH");
    study->add_option("--out", sa.outDir, "Output folder (created)")->required()->type_name("DIR");
    auto* studySeedOpt =
        study->add_option("--seed", studySeed, "Random seed (default: scene)")->type_name("N");
    auto* studyLengthOpt =
        study->add_option("--max-length", studyMaxLength, "Maximum path length (default: scene)")
            ->check(CLI::PositiveNumber)
            ->type_name("N");
    study->add_option("--backend", sa.render.backend, "upbp estimate pass: opencl, host, auto")
        ->check(CLI::IsMember({"opencl", "host", "auto"}));
    study->add_option("--threads", sa.render.threads, "Worker threads (default: all cores)")
        ->check(CLI::PositiveNumber);
    float studyRadius[4] = {0, 0, 0, 0}, studySurfRadius = 0;
    CLI::Option* studyRadiusOpt[4];
    for (int t = 0; t < 4; ++t)
        studyRadiusOpt[t] =
            study
                ->add_option(std::string("--radius-") + kTech[t], studyRadius[t],
                             std::string("upbp: initial ") + kTech[t] + " radius, as for render")
                ->check(positiveReal())
                ->type_name("R");
    auto* studySurfRadiusOpt =
        study->add_option("--radius", studySurfRadius, "Surface merging radius, as for render")
            ->check(positiveReal())
            ->type_name("R");

    if (argc >= 2 && argv[1][0] != '-' && std::string(argv[1]) != "render" &&
        std::string(argv[1]) != "info" && std::string(argv[1]) != "compare" &&
        std::string(argv[1]) != "devices" && std::string(argv[1]) != "study") {
        std::fprintf(
            stderr,
            "unibeam: error: unknown command '%s' (valid: render, info, compare, devices, study)\n"
            "Run 'unibeam --help' for usage.\n",
            argv[1]);
        return kExitBadInput;
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::Success& e) {
        return app.exit(e);  // --help / --version
    } catch (const CLI::ParseError& e) {
        std::fprintf(stderr,
                     "unibeam: error: %s\nRun 'unibeam --help' or 'unibeam COMMAND --help' "
                     "for usage.\n",
                     e.what());
        return kExitBadInput;
    }

    try {
        if (*render) {
            if (!seedText.empty()) ra.seed = parseSeed(seedText);
            if (!maxLengthText.empty()) {
                bool ok = maxLengthText.size() <= 6 &&
                          maxLengthText.find_first_not_of("0123456789") == std::string::npos;
                int v = ok ? std::stoi(maxLengthText) : 0;
                if (!ok || v < 1)
                    throw ub::app::UsageError("--max-length: expected an integer >= 1, got '" +
                                              maxLengthText + "'");
                ra.maxLength = v;
            }
            ra.algorithmGiven = algorithmOpt->count() > 0;
            if (radiusOpt->count() > 0) ra.radius = radius;
            if (alphaOpt->count() > 0) ra.alpha = alpha;
            for (int t = 0; t < 4; ++t) {
                if (volumeRadiusOpt[t]->count() > 0) ra.volumeRadius[t] = volumeRadius[t];
                if (volumeAlphaOpt[t]->count() > 0) ra.volumeAlpha[t] = volumeAlpha[t];
            }
            if (beamPathsOpt->count() > 0) ra.beamPaths = beamPaths;
            ra.defines = ub::app::parseDefines(renderDefines);
            return ub::app::runRender(ra);
        }
        if (*info) return ub::app::runInfo(infoScene, ub::app::parseDefines(infoDefines));
        if (*devices) return ub::app::runDevices();
        if (*compare) return ub::app::runCompare(ca);
        if (*study) {
            std::stringstream list(studyTechniques);
            for (std::string t; std::getline(list, t, ',');)
                if (!t.empty()) sa.techniques.push_back(t);
            if (studySeedOpt->count() > 0) sa.render.seed = studySeed;
            if (studyLengthOpt->count() > 0) sa.render.maxLength = studyMaxLength;
            for (int t = 0; t < 4; ++t)
                if (studyRadiusOpt[t]->count() > 0) sa.render.volumeRadius[t] = studyRadius[t];
            if (studySurfRadiusOpt->count() > 0) sa.render.radius = studySurfRadius;
            return ub::app::runStudy(sa);
        }
    } catch (const ub::ResourceError& e) {
        std::fprintf(stderr, "unibeam: error: %s\n", e.what());
        return kExitBadInput;
    } catch (const ub::app::UsageError& e) {
        std::fprintf(stderr, "unibeam: error: %s\n", e.what());
        return kExitBadInput;
    } catch (const ub::InputError& e) {
        for (const auto& d : e.diagnostics()) std::fprintf(stderr, "%s\n", d.format().c_str());
        return kExitBadInput;
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr,
                     "unibeam: error: out of memory (a smaller --resolution, a smaller "
                     "scene or fewer --threads need less)\n");
        return kExitFailure;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "unibeam: error: %s\n", e.what());
        return kExitFailure;
    }
    return kExitBadInput;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        return run(argc, argv);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "unibeam: error: %s\n", e.what());
        return kExitFailure;
    } catch (...) {
        std::fprintf(stderr, "unibeam: error: unknown exception\n");
        return kExitFailure;
    }
}
