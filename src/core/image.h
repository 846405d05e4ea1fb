// RGB float images and their files: OpenEXR (32-bit float RGB, with string
// metadata) and sRGB tone-mapped PNG. Reading errors throw InputError naming
// the file and what was expected.
#pragma once

#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/vec.h"

namespace ub {

struct Image {
    int width = 0, height = 0;
    std::vector<Rgb> pixels;  ///< row-major, row 0 at the top

    Image() = default;
    Image(int w, int h) : width(w), height(h), pixels(size_t(w) * h) {}
    Rgb& at(int x, int y) { return pixels[size_t(y) * width + x]; }
    const Rgb& at(int x, int y) const { return pixels[size_t(y) * width + x]; }
    Rgb mean() const;
};

using ImageMetadata = std::map<std::string, std::string>;

/// Reads the R, G, B channels of an OpenEXR file (Y only is replicated to RGB).
/// Throws InputError if the file is missing, not an EXR, or has no colour channels.
Image readExr(const std::string& path, ImageMetadata* metadata = nullptr);
/// Reads an 8- or 16-bit PNG (grey, grey+alpha, RGB, RGBA or palette; alpha is dropped,
/// grey is replicated to RGB). PNG values are sRGB-encoded, as Mitsuba 3 assumes for every
/// PNG (gAMA/iCCP chunks are ignored): with linearize = true each value is decoded with the
/// sRGB transfer function (IEC 61966-2-1), otherwise it is returned as value / max.
/// Throws InputError if the file is missing or not a readable PNG.
Image readPng(const std::string& path, bool linearize = true);
/// Reads a baseline or progressive JPEG (grey or YCbCr; CMYK is an error), 8-bit values
/// decoded like readPng (sRGB unless linearize = false). Corrupt or truncated data is an
/// error (libjpeg's warnings are not ignored). Throws InputError naming the file.
Image readJpeg(const std::string& path, bool linearize = true);
/// Reads a BMP, TGA, PNM (.ppm/.pgm/.pnm) or Radiance RGBE (.hdr/.rgbe) image through
/// stb_image (core/image_stb.cpp). 8-bit formats are decoded like readPng (sRGB unless
/// linearize = false); RGBE is linear. Alpha is dropped, grey replicated. Unreadable,
/// corrupt or truncated data throws InputError naming the file.
Image readStbImage(const std::string& path, bool linearize = true);
/// The image formats of the bitmap textures (Mitsuba 3's bitmap reads the same set but PFM).
inline constexpr const char* kBitmapFormats =
    ".png, .jpg/.jpeg, .exr, .bmp, .tga, .hdr/.rgbe or .ppm/.pgm/.pnm";
/// Whether the file name's extension (any case) names one of kBitmapFormats.
bool isBitmapFile(const std::string& path);
/// Whether it names one of the floating-point formats among them (EXR, Radiance RGBE).
bool isFloatBitmapFile(const std::string& path);
/// Reads any of kBitmapFormats by its extension (EXR and RGBE linear, the others sRGB unless
/// linearize = false). An unknown extension throws InputError.
Image readBitmapFile(const std::string& path, bool linearize = true);
/// The sRGB transfer function (IEC 61966-2-1): encoded value in [0,1] -> linear.
float srgbToLinear(float encoded);
/// Writes 32-bit float RGB with the given string attributes. Throws std::runtime_error on I/O
/// failure.
void writeExr(const std::string& path, const Image& img, const ImageMetadata& metadata = {});
/// The same with extra layers, written as channels NAME.R, NAME.G, NAME.B (each layer the size
/// of img).
void writeExr(const std::string& path, const Image& img, const ImageMetadata& metadata,
              const std::vector<std::pair<std::string, Image>>& layers);
/// Writes an 8-bit sRGB PNG of img * 2^exposure (clamped). Throws std::runtime_error on failure.
void writePng(const std::string& path, const Image& img, float exposure = 0.0f);

}  // namespace ub
