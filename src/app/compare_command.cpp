// `unibeam compare --ztest`: per-pixel z-test of a rendered image against a
// reference mean and variance (core/ztest.h), and the -D flag parser.
#include <cctype>
#include <cstdio>
#include <filesystem>

#include "app/commands.h"
#include "core/image.h"
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

int runCompareZTest(const CompareArgs& args) {
    for (const std::string* f :
         {&args.reference, &args.referenceVariance, &args.image, &args.imageVariance}) {
        if (!f->empty() && !std::filesystem::is_regular_file(*f))
            throw UsageError("compare: file '" + *f + "' does not exist");
    }
    Image ref = readExr(args.reference);
    Image refVar = readExr(args.referenceVariance);
    Image img = readExr(args.image);
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
    return r.passed ? 0 : 1;
}

}  // namespace ub::app
