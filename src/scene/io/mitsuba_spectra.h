// Values Mitsuba 3 scenes name rather than give: the refractive indices of its
// `int_ior` / `ext_ior` table, and spectra (wavelength:value lists) reduced to
// linear sRGB the way Mitsuba's `rgb` variants do at load time.
#pragma once

#include <string>
#include <vector>

#include "core/vec.h"

namespace ub {

/// Refractive index of a material Mitsuba names ("water", "air", "bk7", ...); false if the
/// name is not in the table.
bool namedIor(const std::string& name, float* ior);
/// The names namedIor() knows, for error messages.
std::vector<std::string> namedIorNames();

/// The complex IOR (eta + i k, linear sRGB) of one of Mitsuba 3's named conductor presets
/// ("Au", "Cu", "Al", "Ag", ..., the files of its ior/ data folder) as its rgb variants use it
/// (mitsuba_conductors.cpp); false if the name is unknown. "none" is not in the table.
bool namedConductor(const std::string& name, Rgb* eta, Rgb* k);
/// The names namedConductor() knows, for error messages.
std::vector<std::string> namedConductorNames();

/// Linear sRGB of a piecewise-linear spectrum (wavelengths in nm, increasing), integrated
/// against the CIE 1931 2-degree colour matching functions as Mitsuba's rgb variants do:
/// reflectance-like spectra (illuminant = false) are weighted by the D65 illuminant and
/// normalised so that a constant 1 gives Y = 1, then clamped to [0, 1]; emission spectra
/// (illuminant = true) are integrated without D65 (normalised by the integral of y-bar) and
/// clamped to >= 0.
/// Approximations (documented in docs/mitsuba.md): the CIE functions are the multi-lobe
/// Gaussian fit of Wyman, Sloan and Shirley 2013 ("Simple Analytic Approximations to the
/// CIE XYZ Color Matching Functions", JCGT 2(2)), and D65 is a 6504 K black body.
Rgb spectrumToLinearSrgb(const std::vector<double>& wavelengths, const std::vector<double>& values,
                         bool illuminant);

}  // namespace ub
