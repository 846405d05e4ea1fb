// The `unibeam` subcommands. Each returns the process exit status:
//   0  success (also a render stopped by SIGINT/SIGTERM whose image was written)
//   1  unexpected failure (I/O error while writing an image, out of memory, ...)
//   2  bad input: command-line flags, scene file, or a missing/unwritable path
// Usage errors are reported by throwing UsageError (message printed, exit 2);
// ub::InputError is printed one diagnostic per line (exit 2).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "render/integrator.h"

namespace ub::app {

struct UsageError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

struct RenderArgs {
    std::string scene;
    std::string algorithm = "pt";
    /// -a was given; otherwise a scene's default algorithm (RenderSettings::defaultAlgorithm,
    /// e.g. lt for Mitsuba's ptracer) replaces pt, and on a scene with media pt and lt become
    /// vpt and vlt.
    bool algorithmGiven = false;
    double timeLimit = 0;    ///< -t, 0 if not given
    int iterations = 0;      ///< -i, 0 if not given
    std::string exrPath;     ///< -o
    std::string pngPath;     ///< --png
    bool pngLayers = false;  ///< --png-layers: also one PNG per technique layer
    float exposure = 0;
    int threads = 0;  ///< 0: all cores
    std::optional<uint64_t> seed;
    std::optional<int> maxLength;
    std::string resolution;  ///< "WxH" or empty
    std::string mis = "power";
    std::optional<float> radius;
    std::optional<float> alpha;
    /// UPBP (--radius-pp3d ... --alpha-bb1d, indexed by UB_TECH_*), --photon-beams,
    /// --query-beams, --beam-paths.
    std::optional<float> volumeRadius[4], volumeAlpha[4];
    std::string photonBeams, queryBeams;  ///< "short" / "long", empty: default
    std::optional<int> beamPaths;
    std::string backend = "auto";                ///< --backend host|opencl|auto
    std::string clDevice;                        ///< --cl-device PLATFORM:DEVICE
    std::string clCache;                         ///< --cl-cache DIR
    std::map<std::string, std::string> defines;  ///< -D name=value (Mitsuba XML parameters)
    std::string variancePath;                    ///< --variance: per-iteration variance EXR
    std::string checkpointPath;                  ///< --checkpoint FILE
    double checkpointEvery = 60;                 ///< --checkpoint-every SECONDS
    std::string resumePath;                      ///< --resume FILE
    std::string maxMemory;                       ///< --max-memory SIZE (empty: half the RAM)
};

struct CompareArgs {
    std::string image, reference;                  ///< IMAGE REF
    double threshold = -1;                         ///< --threshold (< 0: report only)
    std::string metric = "relmse";                 ///< --metric the threshold applies to
    std::string diffPng;                           ///< --diff OUT.png
    float diffMax = 0;                             ///< --diff-max (0: 99th percentile)
    std::string referenceVariance, imageVariance;  ///< --ztest VAR.exr, --image-var
    double samples = 0;                            ///< --spp: iterations averaged into IMAGE
    double referenceSamples = 0;                   ///< --ref-spp (0: exact reference)
    double alpha = 0.01;
    int varianceRadius = 0;  ///< --variance-radius: pool the image variance (needs --image-var)
};

/// Default number of iterations when neither -t nor -i is given.
constexpr int kDefaultIterations = 16;

int runRender(const RenderArgs& args);
/// The RenderOptions that args ask for on scene (scene settings where args are silent);
/// throws UsageError on a malformed --cl-device.
RenderOptions makeRenderOptions(const RenderArgs& args, const Scene& scene);
/// Parses "WxH" (positive integers up to 16384); throws UsageError naming --resolution.
void parseResolution(const std::string& s, int* w, int* h);

struct StudyArgs {
    std::string scene, outDir, reference;
    std::vector<std::string> techniques;
    double timeSeconds = 0;       ///< --time: per technique
    int iterations = 0;           ///< --iterations: per technique
    double referenceSeconds = 0;  ///< --reference-time (0: 4x the per-technique budget)
    RenderArgs render;            ///< resolution, seed, max length, backend, threads, -D
};
/// `unibeam study`: 0 done, 2 bad input.
int runStudy(const StudyArgs& args);
int runInfo(const std::string& scenePath, const std::map<std::string, std::string>& defines = {});
/// `unibeam devices`: the OpenCL platforms and devices; exit 2 if there is none.
int runDevices();
/// `unibeam compare`: 0 pass, 1 fail (threshold or z-test), 2 bad input (UsageError /
/// InputError).
int runCompare(const CompareArgs& args);
/// Parses the values of -D flags ("name=value"); throws UsageError on a malformed one.
std::map<std::string, std::string> parseDefines(const std::vector<std::string>& values);

}  // namespace ub::app
