// `unibeam compare`: error metrics of a rendered image against a reference
// (core/image_metrics.h), an optional false-colour error PNG and per-pixel z-test
// (core/ztest.h), and the -D flag parser.
#include <cctype>
#include <cstdio>
#include <filesystem>

#include "app/commands.h"
#include "core/file_status.h"
#include "core/image.h"
#include "core/image_metrics.h"
#include "core/ztest.h"

namespace ub::app {

std::map<std::string, std::string> parseDefines(const std::vector<std::string>& values) {
    std::map<std::string, std::string> out;
    for (const std::string& v : values) {
        size_t eq = v.find('=');
        std::string name = eq == std::string::npos ? v : v.substr(0, eq);
        bool ok = eq != std::string::npos && !name.empty();
        for (char c : name) ok = ok && (std::isalnum(static_cast<unsigned char>(c)) || c == '_');
        if (!ok)
            throw UsageError(
                "-D: expected NAME=VALUE with a name of letters, digits and '_', "
                "got '" +
                v + "'");
        if (out.count(name)) throw UsageError("-D: parameter '" + name + "' is given twice");
        out[name] = v.substr(eq + 1);
    }
    return out;
}

int runCompare(const CompareArgs& args) {
    for (const std::string* f :
         {&args.image, &args.reference, &args.referenceVariance, &args.imageVariance}) {
        if (!f->empty() && !isRegularFile(*f))
            throw UsageError("compare: file '" + *f + "' does not exist");
    }
    if (args.referenceVariance.empty() &&
        (args.samples > 0 || !args.imageVariance.empty() || args.referenceSamples > 0))
        throw UsageError("compare: --spp, --image-var and --ref-spp belong to --ztest VAR.exr");
    if (!args.referenceVariance.empty() && !(args.samples > 0))
        throw UsageError("compare: --ztest needs --spp N (iterations averaged into IMAGE)");
    const Image img = readExr(args.image);
    const Image ref = readExr(args.reference);
    if (img.width != ref.width || img.height != ref.height)
        throw UsageError("compare: '" + args.image + "' is " + std::to_string(img.width) + "x" +
                         std::to_string(img.height) + " but the reference '" + args.reference +
                         "' is " + std::to_string(ref.width) + "x" + std::to_string(ref.height));
    const ImageError e = imageError(img, ref);
    std::printf("%s\n", describeImageError(e).c_str());
    bool passed = true;
    if (args.threshold >= 0) {
        const double v = e.overall(args.metric);
        passed = v <= args.threshold;
        std::printf("%s %.6g %s threshold %.6g: %s\n", args.metric.c_str(), v, passed ? "<=" : ">",
                    args.threshold, passed ? "pass" : "FAIL");
    }
    if (!args.diffPng.empty()) {
        float used = 0;
        writePng(args.diffPng, falseColourError(img, ref, args.diffMax, &used));
        std::printf("wrote %s (relative error |a - r| / (r + 0.01), scale 0 .. %.3g)\n",
                    args.diffPng.c_str(), double(used));
    }
    if (!args.referenceVariance.empty()) {
        const Image refVar = readExr(args.referenceVariance);
        Image imgVar;
        if (!args.imageVariance.empty()) imgVar = readExr(args.imageVariance);
        ZTestOptions o;
        o.alpha = args.alpha;
        o.samples = args.samples;
        o.referenceSamples = args.referenceSamples;
        o.varianceRadius = args.varianceRadius;
        if (o.varianceRadius > 0 && args.imageVariance.empty())
            throw UsageError("compare: --variance-radius needs --image-var");
        ZTestResult r = zTest(img, args.imageVariance.empty() ? nullptr : &imgVar, ref, refVar, o);
        std::printf("%s\n", describeZTest(r, o).c_str());
        passed = passed && r.passed;
    }
    return passed ? 0 : 1;
}

}  // namespace ub::app
