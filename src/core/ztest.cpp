#include "core/ztest.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>

#include "core/error.h"

namespace ub {

double zTestPValue(double z) {
    return std::erfc(std::fabs(z) / std::sqrt(2.0));
}

ZTestResult zTest(const Image& image, const Image* imageVariance, const Image& reference,
                  const Image& referenceVariance, const ZTestOptions& o) {
    auto fail = [](const std::string& msg) { throw InputError("", "z-test: " + msg); };
    if (!(o.alpha > 0.0 && o.alpha < 1.0)) fail("alpha must lie in (0, 1)");
    if (!(o.samples >= 1.0)) fail("the image must average at least 1 iteration");
    if (imageVariance && !(o.samples >= 2.0)) fail("an image variance needs at least 2 iterations");
    if (!(o.referenceSamples >= 0.0)) fail("reference sample count must be >= 0");
    if (!(o.varianceFloor >= 0.0)) fail("variance floor must be >= 0");
    if (o.varianceRadius < 0) fail("variance radius must be >= 0");
    if (o.varianceRadius > 0 && !imageVariance)
        fail("a pooled variance (radius > 0) needs the image variance");
    auto sameSize = [&](const Image& a, const char* what) {
        if (a.width != reference.width || a.height != reference.height)
            fail(std::string(what) + " is " + std::to_string(a.width) + "x" +
                 std::to_string(a.height) + ", the reference is " +
                 std::to_string(reference.width) + "x" + std::to_string(reference.height));
    };
    sameSize(image, "the image");
    sameSize(referenceVariance, "the reference variance");
    if (imageVariance) sameSize(*imageVariance, "the image variance");
    if (reference.width <= 0 || reference.height <= 0) fail("empty images");

    ZTestResult r;
    r.tests = size_t(reference.width) * reference.height * 3;
    // 1 - (1 - alpha)^(1/m) without cancellation: -expm1(log1p(-alpha) / m).
    r.perTestLevel = -std::expm1(std::log1p(-o.alpha) / double(r.tests));
    // Image variance of each (pixel, channel): its own, or the larger of its own and the
    // neighbourhood mean (see the header), each per-pixel value floored first.
    auto floored = [&](int x, int y, int c) {
        return std::max(double(imageVariance->at(x, y)[c]), o.varianceFloor);
    };
    auto pooledVariance = [&](int x, int y, int c) {
        const int rad = o.varianceRadius;
        double sum = 0;
        int count = 0;
        for (int yy = std::max(0, y - rad); yy <= std::min(reference.height - 1, y + rad); ++yy)
            for (int xx = std::max(0, x - rad); xx <= std::min(reference.width - 1, x + rad);
                 ++xx) {
                sum += floored(xx, yy, c);
                ++count;
            }
        return sum / count;
    };
    std::set<std::pair<int, int>> failing;
    for (int y = 0; y < reference.height; ++y)
        for (int x = 0; x < reference.width; ++x)
            for (int c = 0; c < 3; ++c) {
                const double v = image.at(x, y)[c], ref = reference.at(x, y)[c];
                double varRef = referenceVariance.at(x, y)[c];
                double varImg = imageVariance ? double(imageVariance->at(x, y)[c]) : varRef;
                const char* bad = !std::isfinite(v)        ? "image"
                                  : !std::isfinite(ref)    ? "reference"
                                  : !std::isfinite(varRef) ? "reference variance"
                                  : !std::isfinite(varImg) ? "image variance"
                                                           : nullptr;
                if (bad) {
                    std::ostringstream os;
                    os << "non-finite value in the " << bad << " at pixel (" << x << ", " << y
                       << "), channel " << c;
                    fail(os.str());
                }
                // A variance computed as m2 - m1^2 (Mitsuba's references) can round to a
                // slightly negative value; the floor below covers it.
                varRef = std::max(varRef, o.varianceFloor);
                varImg = std::max(varImg, o.varianceFloor);
                if (o.varianceRadius > 0) varImg = std::max(varImg, pooledVariance(x, y, c));
                double var = varImg / o.samples;
                if (o.referenceSamples > 0) var += varRef / o.referenceSamples;
                const double z = var > 0 ? (v - ref) / std::sqrt(var) : (v == ref ? 0.0 : INFINITY);
                const double p = zTestPValue(z);
                r.maxAbsZ = std::max(r.maxAbsZ, std::fabs(z));
                if (p < r.minPValue || (x == 0 && y == 0 && c == 0)) {
                    r.minPValue = p;
                    r.minX = x;
                    r.minY = y;
                    r.minChannel = c;
                }
                if (p < r.perTestLevel) {
                    r.failures.push_back({x, y, c, v, ref, z, p});
                    failing.insert({x, y});
                }
            }
    std::sort(r.failures.begin(), r.failures.end(),
              [](const ZTestFailure& a, const ZTestFailure& b) { return a.pValue < b.pValue; });
    r.failingPixels = failing.size();
    r.passed = r.failures.empty();
    return r;
}

std::string describeZTest(const ZTestResult& r, const ZTestOptions& o) {
    std::ostringstream os;
    os << (r.passed ? "PASS" : "FAIL") << ": per-pixel z-test, alpha " << o.alpha
       << " Sidak-corrected over " << r.tests << " pixel-channel tests (per-test level "
       << r.perTestLevel << "), " << o.samples << " image iterations";
    os << "\n  min p-value " << r.minPValue << " at pixel (" << r.minX << ", " << r.minY
       << ") channel "
       << "RGB"[r.minChannel] << ", max |z| " << r.maxAbsZ;
    os << "\n  failing pixels: " << r.failingPixels << " (" << r.failures.size()
       << " pixel-channels)";
    const size_t shown = std::min<size_t>(r.failures.size(), 10);
    for (size_t i = 0; i < shown; ++i) {
        const ZTestFailure& f = r.failures[i];
        os << "\n    (" << f.x << ", " << f.y << ") "
           << "RGB"[f.channel] << ": image " << f.value << ", reference " << f.reference << ", z "
           << f.z << ", p " << f.pValue;
    }
    return os.str();
}

}  // namespace ub
