#include "scene/io/mitsuba_spectra.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace ub {

namespace {

/// Refractive indices at 589 nm (sodium D line) of the materials Mitsuba 3 names in its
/// dielectric documentation (values from standard optics tables).
const std::pair<const char*, float> kIors[] = {
    {"vacuum", 1.0f},      {"helium", 1.00004f},         {"hydrogen", 1.00013f},
    {"air", 1.00028f},     {"carbon dioxide", 1.00045f}, {"water", 1.3330f},
    {"acetone", 1.36f},    {"ethanol", 1.361f},          {"carbon tetrachloride", 1.461f},
    {"glycerol", 1.4729f}, {"benzene", 1.501f},          {"silicone oil", 1.52045f},
    {"bromine", 1.661f},   {"water ice", 1.31f},         {"fused quartz", 1.458f},
    {"pyrex", 1.470f},     {"acrylic glass", 1.49f},     {"polypropylene", 1.49f},
    {"bk7", 1.5046f},      {"sodium chloride", 1.544f},  {"amber", 1.55f},
    {"pet", 1.5750f},      {"diamond", 2.419f},
};

/// Piecewise Gaussian of Wyman et al. 2013, Eq. (1).
double g(double x, double mu, double s1, double s2) {
    double t = (x - mu) / (x < mu ? s1 : s2);
    return std::exp(-0.5 * t * t);
}

/// CIE 1931 x-bar, y-bar, z-bar: multi-lobe fit of Wyman et al. 2013, Eq. (2)-(4).
void cmf(double l, double* x, double* y, double* z) {
    *x = 1.056 * g(l, 599.8, 37.9, 31.0) + 0.362 * g(l, 442.0, 16.0, 26.7) -
         0.065 * g(l, 501.1, 20.4, 26.2);
    *y = 0.821 * g(l, 568.8, 46.9, 40.5) + 0.286 * g(l, 530.9, 16.3, 31.1);
    *z = 1.217 * g(l, 437.0, 11.8, 36.0) + 0.681 * g(l, 459.0, 26.0, 13.8);
}

/// Relative spectral power of a black body at temperature T (Planck's law, unnormalised).
double planck(double lambdaNm, double T) {
    const double c = 299792458.0, h = 6.62607015e-34, kB = 1.380649e-23;
    double l = lambdaNm * 1e-9;
    return 2.0 * h * c * c / (std::pow(l, 5) * (std::exp(h * c / (l * kB * T)) - 1.0));
}

}  // namespace

bool namedIor(const std::string& nameIn, float* ior) {
    std::string name = nameIn;
    std::transform(name.begin(), name.end(), name.begin(), ::tolower);
    for (const auto& e : kIors)
        if (name == e.first) {
            *ior = e.second;
            return true;
        }
    return false;
}

std::vector<std::string> namedIorNames() {
    std::vector<std::string> v;
    for (const auto& e : kIors) v.push_back(e.first);
    return v;
}

Rgb spectrumToLinearSrgb(const std::vector<double>& wl, const std::vector<double>& val,
                         bool illuminant) {
    // Riemann sum over Mitsuba's CIE range [360, 830] nm; the spectrum is linear between
    // its samples and zero outside them.
    const double lo = 360.0, hi = 830.0;
    const int steps = 4700;
    double X = 0, Y = 0, Z = 0, norm = 0;
    for (int i = 0; i < steps; ++i) {
        double l = lo + (i + 0.5) * (hi - lo) / steps;
        double x, y, z;
        cmf(l, &x, &y, &z);
        double w = illuminant ? 1.0 : planck(l, 6504.0);
        norm += y * w;
        if (l < wl.front() || l > wl.back()) continue;
        size_t k = size_t(std::upper_bound(wl.begin(), wl.end(), l) - wl.begin());
        k = std::min(std::max<size_t>(k, 1), wl.size() - 1);
        double t = (l - wl[k - 1]) / (wl[k] - wl[k - 1]);
        double v = (1.0 - t) * val[k - 1] + t * val[k];
        X += v * x * w;
        Y += v * y * w;
        Z += v * z * w;
    }
    X /= norm;
    Y /= norm;
    Z /= norm;
    // XYZ -> linear sRGB (IEC 61966-2-1, D65 white).
    Rgb rgb(float(3.2404542 * X - 1.5371385 * Y - 0.4985314 * Z),
            float(-0.9692660 * X + 1.8760108 * Y + 0.0415560 * Z),
            float(0.0556434 * X - 0.2040259 * Y + 1.0572252 * Z));
    for (int c = 0; c < 3; ++c) {
        rgb[c] = std::max(rgb[c], 0.0f);
        if (!illuminant) rgb[c] = std::min(rgb[c], 1.0f);
    }
    return rgb;
}

}  // namespace ub
