#include "core/image.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStandardAttributes.h>
#include <ImfStringAttribute.h>
#include <png.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <vector>

#include "core/error.h"
#include "core/file_status.h"

namespace ub {

Rgb Image::mean() const {
    double s[3] = {0, 0, 0};
    for (const auto& p : pixels)
        for (int c = 0; c < 3; ++c) s[c] += p[c];
    double n = std::max<size_t>(1, pixels.size());
    return {float(s[0] / n), float(s[1] / n), float(s[2] / n)};
}

namespace {

// Largest image the readers accept: 65536 pixels on a side and 2^28 pixels in all (a 16k x 16k
// environment map; 3 GiB as float RGB). A corrupt or hostile header announcing more would
// otherwise make the reader allocate whatever it claims before a single pixel is read.
constexpr int64_t kMaxImageSide = 65536;
constexpr int64_t kMaxImagePixels = int64_t(1) << 28;

void checkImageSize(const std::string& path, const char* format, int64_t w, int64_t h) {
    if (w > kMaxImageSide || h > kMaxImageSide || w * h > kMaxImagePixels)
        throw InputError(path, std::string(format) + " image of " + std::to_string(w) + " x " +
                                   std::to_string(h) + " pixels is too large (expected at most " +
                                   std::to_string(kMaxImageSide) + " pixels on a side and " +
                                   std::to_string(kMaxImagePixels) + " pixels in all)");
}

}  // namespace

namespace {

/// A name read from a file, as an error message shows it: its first 32 characters, each
/// unprintable one as '?', and "..." when it is longer.
std::string shownName(const std::string& name) {
    std::string shown;
    for (char c : name.substr(0, 32))
        shown += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
    if (name.size() > 32) shown += "...";
    return shown;
}

/// Throws the InputError of a header attribute that does not hold what it should.
[[noreturn]] void throwCorruptExrAttribute(const std::string& path, const std::string& name,
                                           const std::string& type, const std::string& what) {
    throw InputError(path, "corrupt OpenEXR image: header attribute '" + shownName(name) + "' (" +
                               type + ") " + what + " (truncated or corrupt file?)");
}

/// An OpenEXR chlist attribute: per channel a name (NUL-terminated), int32 pixel type, uint8
/// pLinear, 3 reserved bytes, int32 xSampling and ySampling; an empty name ends it. Throws
/// InputError for a type other than uint, half, float, or a sampling other than 1 x 1.
void checkExrChannels(const std::string& path, const std::string& list) {
    size_t at = 0;
    auto int32At = [&](size_t i) {
        return int32_t(uint32_t(uint8_t(list[i])) | (uint32_t(uint8_t(list[i + 1])) << 8) |
                       (uint32_t(uint8_t(list[i + 2])) << 16) |
                       (uint32_t(uint8_t(list[i + 3])) << 24));
    };
    while (at < list.size()) {
        const size_t end = list.find('\0', at);
        if (end == at) {  // the empty name that ends the list
            // OpenEXR reads a channel list up to that name, whatever the attribute's size: a
            // list that ends before the attribute does would have it read the rest of the
            // attribute as the next attributes (found by fuzz_exr_image, docs/fuzzing.md).
            if (at + 1 != list.size())
                throw InputError(path, "corrupt OpenEXR image: the channel list attribute ends " +
                                           std::to_string(list.size() - at - 1) +
                                           " bytes before its size says (truncated or corrupt "
                                           "file?)");
            return;
        }
        // A name or entry running past the attribute: OpenEXR would read on into the next
        // attributes as channel data.
        if (end == std::string::npos || end + 1 + 16 > list.size())
            throw InputError(path,
                             "corrupt OpenEXR image: the channel list attribute ends "
                             "inside a channel entry (truncated or corrupt file?)");
        const std::string name = list.substr(at, end - at);
        const int32_t type = int32At(end + 1);
        const int32_t xs = int32At(end + 9), ys = int32At(end + 13);
        if (type < 0 || type > 2 || xs != 1 || ys != 1) {
            const std::string shown = shownName(name);
            throw InputError(path, "OpenEXR channel '" + shown + "' has pixel type " +
                                       std::to_string(type) + " and sampling " +
                                       std::to_string(xs) + " x " + std::to_string(ys) +
                                       " (expected uint, half or float, sampled 1 x 1)");
        }
        at = end + 1 + 16;
    }
    // No empty name inside the attribute: OpenEXR would read on past it for one.
    throw InputError(path,
                     "corrupt OpenEXR image: the channel list attribute does not end with an "
                     "empty channel name within its size (truncated or corrupt file?)");
}

/// A preview or string vector attribute must hold what it announces (see checkExrHeader).
void checkExrAttribute(const std::string& path, const std::string& name, const std::string& type,
                       const std::string& value) {
    if (type == "chlist") return checkExrChannels(path, value);
    auto u32At = [&](size_t i) {
        return uint32_t(uint8_t(value[i])) | (uint32_t(uint8_t(value[i + 1])) << 8) |
               (uint32_t(uint8_t(value[i + 2])) << 16) | (uint32_t(uint8_t(value[i + 3])) << 24);
    };
    auto corrupt = [&](const std::string& what) {
        throwCorruptExrAttribute(path, name, type, what);
    };
    if (type == "preview") {
        if (value.size() < 8) corrupt("is shorter than its size fields");
        const uint64_t need = 8u + uint64_t(u32At(0)) * uint64_t(u32At(4)) * 4u;
        if (need != value.size())
            corrupt("announces a " + std::to_string(u32At(0)) + " x " + std::to_string(u32At(4)) +
                    " preview (" + std::to_string(need) + " bytes) in " +
                    std::to_string(value.size()) + " bytes");
        return;
    }
    // stringvector: (int32 length, characters) until the attribute ends
    size_t at = 0;
    while (at < value.size()) {
        if (at + 4 > value.size()) corrupt("ends inside a string's length");
        const uint64_t len = u32At(at);
        at += 4;
        if (len > value.size() - at)
            corrupt("announces a string of " + std::to_string(len) + " bytes, more than the " +
                    std::to_string(value.size() - at) + " left in it");
        at += size_t(len);
    }
}

/// Bytes that OpenEXR (3.1) reads for an attribute of a fixed-size type, whatever the size
/// the file announces (OpenEXR's Xdr layout of each type); 0 for other types.
int exrFixedAttributeSize(const std::string& type) {
    static const std::pair<const char*, int> kSizes[] = {{"box2i", 16},
                                                         {"box2f", 16},
                                                         {"chromaticities", 32},
                                                         {"compression", 1},
                                                         {"deepImageState", 1},
                                                         {"double", 8},
                                                         {"envmap", 1},
                                                         {"float", 4},
                                                         {"int", 4},
                                                         {"keycode", 28},
                                                         {"lineOrder", 1},
                                                         {"m33f", 36},
                                                         {"m33d", 72},
                                                         {"m44f", 64},
                                                         {"m44d", 128},
                                                         {"rational", 8},
                                                         {"tiledesc", 9},
                                                         {"timecode", 8},
                                                         {"v2i", 8},
                                                         {"v2f", 8},
                                                         {"v2d", 16},
                                                         {"v3i", 12},
                                                         {"v3f", 12},
                                                         {"v3d", 24}};
    for (const auto& [name, bytes] : kSizes)
        if (type == name) return bytes;
    return 0;
}

/// Walks the attributes of the OpenEXR header(s) (OpenEXR file layout: magic, version, then
/// per header name\0 type\0 int32 size, value; an empty name ends a header, an empty header
/// the headers of a multi-part file): each attribute's announced size must fit in the rest of
/// the file. OpenEXR allocates what an attribute announces before reading it (found by
/// fuzz_exr_image: a 647-byte file announcing a 1.6 GB attribute), and each must announce what
/// OpenEXR will read for it (see below). Throws InputError.
void checkExrHeader(const std::string& path) {
    std::error_code ec;
    const uint64_t fileBytes = std::filesystem::file_size(path, ec);
    std::ifstream in(path, std::ios::binary);
    if (ec || !in) return;  // OpenEXR reports what it cannot read
    unsigned char head[8];
    if (!in.read(reinterpret_cast<char*>(head), 8)) return;
    const bool multipart = (head[5] & 0x10) != 0;  // version flag bit 12
    auto readString = [&](std::string* out) {
        out->clear();
        for (int i = 0; i < 256; ++i) {
            const int c = in.get();
            if (c == EOF) return false;
            if (c == 0) return true;
            out->push_back(char(c));
        }
        return false;  // too long: OpenEXR rejects it
    };
    for (int header = 0;; ++header) {
        for (int attr = 0;; ++attr) {
            std::string name, type;
            if (!readString(&name)) return;
            if (name.empty()) break;  // end of this header
            if (!readString(&type)) return;
            unsigned char sz[4];
            if (!in.read(reinterpret_cast<char*>(sz), 4)) return;
            const int64_t size = int32_t(uint32_t(sz[0]) | (uint32_t(sz[1]) << 8) |
                                         (uint32_t(sz[2]) << 16) | (uint32_t(sz[3]) << 24));
            const uint64_t at = uint64_t(in.tellg());
            if (size < 0 || at + uint64_t(size) > fileBytes) {
                const std::string shown = shownName(name);
                throw InputError(path, "corrupt OpenEXR image: header attribute '" + shown +
                                           "' announces " + std::to_string(size) +
                                           " bytes, more than the " +
                                           std::to_string(fileBytes - at) +
                                           " bytes left in the file (truncated or corrupt file?)");
            }
            // OpenEXR reads an attribute of a known type by its type, not by its announced
            // size, and goes on from where that read stops: a size other than what the type
            // reads makes it parse the rest as other attributes, one of which may then announce
            // gigabytes (found by fuzz_exr_image: 1.6-1.9 GB from 3 KB files, docs/fuzzing.md).
            if (const int expected = exrFixedAttributeSize(type); expected != 0) {
                if (size != expected)
                    throwCorruptExrAttribute(path, name, type,
                                             "has " + std::to_string(size) + " bytes, expected " +
                                                 std::to_string(expected));
            } else if (type == "idmanifest") {
                // Its reader's layout differs between OpenEXR releases (a 4- or 8-byte
                // uncompressed size before size - 4 bytes), so its extent is not known here.
                throw InputError(path,
                                 "OpenEXR header attribute of type idmanifest is not "
                                 "supported in images read as textures or environment "
                                 "maps");
            } else if (type == "floatvector" && size % 4 != 0) {
                throwCorruptExrAttribute(
                    path, name, type,
                    "has " + std::to_string(size) + " bytes, not a whole number of floats");
            }
            if (type == "chlist" || type == "preview" || type == "stringvector") {
                // Attributes whose contents OpenEXR sizes allocations from when the file is
                // opened: a channel list (line buffers from each channel's type and sampling;
                // by type, whatever the attribute's name), a preview image (width x height x 4
                // bytes) and a string vector (each string's length) must fit in the attribute
                // (found by fuzz_exr_image: 2 GB from 4.5 KB and 2.6 KB files).
                std::string value(size_t(size), '\0');
                if (!in.read(value.data(), size)) return;
                checkExrAttribute(path, name, type, value);
                continue;
            }
            in.seekg(std::streamoff(size), std::ios::cur);
        }
        if (!multipart) return;
        if (in.peek() == 0 || in.peek() == EOF) return;  // an empty header ends the list
    }
}

}  // namespace

Image readExr(const std::string& path, ImageMetadata* metadata) {
    if (!pathExists(path)) throw InputError(path, "image file does not exist");
    checkExrHeader(path);
    // OpenEXR sizes its line-offset table and buffers from the header's windows when the file
    // is opened, before our check below: bound them there too (found by fuzz_exr_image: a
    // 647-byte file made the reader take 270 MB).
    static const bool limited = [] {
        Imf::Header::setMaxImageSize(int(kMaxImageSide), int(kMaxImageSide));
        Imf::Header::setMaxTileSize(int(kMaxImageSide), int(kMaxImageSide));
        return true;
    }();
    (void)limited;
    try {
        Imf::InputFile file(path.c_str());
        const Imf::Header& h = file.header();
        Imath::Box2i dw = h.dataWindow();
        // In 64 bits: a corrupt window (min -2^31, max 2^31-1) overflows int.
        const int64_t w64 = int64_t(dw.max.x) - dw.min.x + 1,
                      h64 = int64_t(dw.max.y) - dw.min.y + 1;
        if (w64 <= 0 || h64 <= 0) throw InputError(path, "OpenEXR image has an empty data window");
        checkImageSize(path, "OpenEXR", w64, h64);
        const int w = int(w64), ht = int(h64);
        const Imf::ChannelList& ch = h.channels();
        bool hasRgb = ch.findChannel("R") && ch.findChannel("G") && ch.findChannel("B");
        bool hasY = ch.findChannel("Y");
        if (!hasRgb && !hasY)
            throw InputError(path, "OpenEXR image has neither R,G,B nor Y channels");
        // Each pixel stores at least one half-float channel, and no OpenEXR compression shrinks
        // data more than deflate's 1032:1: a window whose pixels cannot fit in the file is
        // rejected before the image is allocated (found by fuzz_exr_image: a 20 KB file
        // announcing 145 million pixels made readExr allocate 1.7 GB).
        {
            std::error_code ec;
            const uintmax_t fileBytes = std::filesystem::file_size(path, ec);
            const uint64_t minBytes = uint64_t(w64) * uint64_t(h64) * 2u;
            if (!ec && minBytes > uint64_t(fileBytes) * 1032 + 65536)
                throw InputError(path, "corrupt OpenEXR image: " + std::to_string(w64) + " x " +
                                           std::to_string(h64) + " pixels need at least " +
                                           std::to_string(minBytes / 1032) +
                                           " bytes of compressed pixel data, more than the " +
                                           std::to_string(fileBytes) +
                                           " bytes of the file (truncated or corrupt file?)");
        }
        Image img(w, ht);
        Imf::FrameBuffer fb;
        // OpenEXR addresses pixel (x, y) of the data window as base + x * xs + y * ys.
        char* base = reinterpret_cast<char*>(img.pixels.data()) -
                     (int64_t(dw.min.x) + int64_t(dw.min.y) * w) * int64_t(sizeof(Rgb));
        size_t xs = sizeof(Rgb), ys = sizeof(Rgb) * w;
        if (hasRgb) {
            fb.insert("R", Imf::Slice(Imf::FLOAT, base, xs, ys));
            fb.insert("G", Imf::Slice(Imf::FLOAT, base + sizeof(float), xs, ys));
            fb.insert("B", Imf::Slice(Imf::FLOAT, base + 2 * sizeof(float), xs, ys));
        } else {
            fb.insert("Y", Imf::Slice(Imf::FLOAT, base, xs, ys));
        }
        file.setFrameBuffer(fb);
        file.readPixels(dw.min.y, dw.max.y);
        if (!hasRgb)
            for (auto& p : img.pixels) p = Rgb(p.x);
        if (metadata) {
            for (auto it = h.begin(); it != h.end(); ++it) {
                if (auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute()))
                    (*metadata)[it.name()] = s->value();
            }
        }
        for (const auto& p : img.pixels)
            if (!isFinite(p))
                throw InputError(path, "OpenEXR image contains non-finite pixel values");
        return img;
    } catch (const InputError&) {
        throw;
    } catch (const std::exception& e) {
        throw InputError(path, std::string("cannot read OpenEXR image: ") + e.what());
    }
}

void writeExr(const std::string& path, const Image& img, const ImageMetadata& metadata) {
    writeExr(path, img, metadata, {});
}

void writeExr(const std::string& path, const Image& img, const ImageMetadata& metadata,
              const std::vector<std::pair<std::string, Image>>& layers) {
    Imf::Header h(img.width, img.height);
    std::vector<std::pair<std::string, const Image*>> all = {{"", &img}};
    for (const auto& l : layers) {
        if (l.second.width != img.width || l.second.height != img.height)
            throw std::invalid_argument("writeExr: layer '" + l.first + "' has another size");
        all.emplace_back(l.first + ".", &l.second);
    }
    for (const auto& [prefix, im] : all)
        for (const char* c : {"R", "G", "B"})
            h.channels().insert(prefix + c, Imf::Channel(Imf::FLOAT));
    for (const auto& [k, v] : metadata) h.insert(k, Imf::StringAttribute(v));
    try {
        Imf::OutputFile file(path.c_str(), h);
        Imf::FrameBuffer fb;
        size_t xs = sizeof(Rgb), ys = sizeof(Rgb) * img.width;
        for (const auto& [prefix, im] : all) {
            char* base = const_cast<char*>(reinterpret_cast<const char*>(im->pixels.data()));
            fb.insert(prefix + "R", Imf::Slice(Imf::FLOAT, base, xs, ys));
            fb.insert(prefix + "G", Imf::Slice(Imf::FLOAT, base + sizeof(float), xs, ys));
            fb.insert(prefix + "B", Imf::Slice(Imf::FLOAT, base + 2 * sizeof(float), xs, ys));
        }
        file.setFrameBuffer(fb);
        file.writePixels(img.height);
    } catch (const std::exception& e) {
        throw std::runtime_error("cannot write OpenEXR image '" + path + "': " + e.what());
    }
}

float srgbToLinear(float c) {
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

namespace {

/// libpng error handler: keeps the message for the InputError and returns to setjmp
/// (libpng's default handler would also print to stderr).
void pngError(png_structp png, png_const_charp message) {
    if (auto* m = static_cast<std::string*>(png_get_error_ptr(png))) *m = message;
    png_longjmp(png, 1);
}
void pngWarning(png_structp, png_const_charp) {}

}  // namespace

namespace {

/// Walks the chunks of the PNG file fp (positioned after the signature, and left there): each
/// chunk's announced length must fit in the rest of the file. libpng allocates what an
/// ancillary chunk (tEXt, iCCP, ...) announces before reading it, whatever its user limits say
/// (found by fuzz_png_image: a 239-byte file announcing a 973 MB tEXt chunk took 1.1 GB, the
/// "memory growth" of earlier fuzzing runs). Throws InputError naming the chunk.
void checkPngChunks(const std::string& path, FILE* fp) {
    std::error_code ec;
    const uint64_t fileBytes = std::filesystem::file_size(path, ec);
    if (ec) return;  // libpng reports what it cannot read
    uint64_t offset = 8;
    while (offset + 8 <= fileBytes) {
        unsigned char h[8];
        if (std::fseek(fp, long(offset), SEEK_SET) != 0 || std::fread(h, 1, 8, fp) != 8) break;
        const uint64_t length =
            (uint64_t(h[0]) << 24) | (uint64_t(h[1]) << 16) | (uint64_t(h[2]) << 8) | h[3];
        const std::string type(reinterpret_cast<const char*>(h + 4), 4);
        if (offset + 12 + length > fileBytes) {
            std::fclose(fp);
            std::string name;
            for (char c : type) name += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
            throw InputError(path, "corrupt PNG image: chunk '" + name + "' at byte " +
                                       std::to_string(offset) + " announces " +
                                       std::to_string(length) + " bytes, more than the " +
                                       std::to_string(fileBytes - offset - 12) +
                                       " bytes left in the file (truncated or corrupt file?)");
        }
        if (type == "IEND") break;
        offset += 12 + length;
    }
    std::fseek(fp, 8, SEEK_SET);
}

}  // namespace

Image readPng(const std::string& path, bool linearize) {
    if (!isRegularFile(path)) throw InputError(path, "image file does not exist");
    FILE* fp = std::fopen(path.c_str(), "rb");
    if (!fp) throw InputError(path, "cannot open the PNG image");
    unsigned char sig[8] = {};
    if (std::fread(sig, 1, 8, fp) != 8 || png_sig_cmp(sig, 0, 8) != 0) {
        std::fclose(fp);
        throw InputError(path, "not a PNG file (bad signature)");
    }
    checkPngChunks(path, fp);
    std::string pngMessage;
    png_structp png =
        png_create_read_struct(PNG_LIBPNG_VER_STRING, &pngMessage, pngError, pngWarning);
    png_infop info = png ? png_create_info_struct(png) : nullptr;
    // Declared before setjmp: libpng longjmps here on a corrupt file.
    std::vector<unsigned char> data;
    std::vector<png_bytep> rows;
    int width = 0, height = 0, bitDepth = 8;
    if (!png || !info || setjmp(png_jmpbuf(png))) {
        png_destroy_read_struct(&png, &info, nullptr);
        std::fclose(fp);
        throw InputError(path, "corrupt or unsupported PNG image" +
                                   (pngMessage.empty() ? "" : " (libpng: " + pngMessage + ")"));
    }
    png_init_io(png, fp);
    png_set_sig_bytes(png, 8);
    png_read_info(png, info);
    const int64_t w64 = png_get_image_width(png, info), h64 = png_get_image_height(png, info);
    if (w64 > kMaxImageSide || h64 > kMaxImageSide || w64 * h64 > kMaxImagePixels) {
        png_destroy_read_struct(&png, &info, nullptr);
        std::fclose(fp);
        checkImageSize(path, "PNG", w64, h64);  // throws
    }
    width = int(w64);
    height = int(h64);
    bitDepth = png_get_bit_depth(png, info);
    const int colorType = png_get_color_type(png, info);
    // The pixels are deflate-compressed, which shrinks data at most 1032:1: a header whose
    // pixels cannot fit in the rest of the file is rejected before the image is allocated
    // (found by fuzz_png_image: a few hundred bytes made readPng allocate gigabytes).
    {
        std::error_code ec;
        const uintmax_t fileBytes = std::filesystem::file_size(path, ec);
        const int channels = png_get_channels(png, info);
        const uint64_t rawBytes =
            (uint64_t(w64) * uint64_t(channels) * uint64_t(bitDepth) + 7) / 8 * uint64_t(h64) +
            uint64_t(h64);  // one filter byte per row
        if (!ec && rawBytes > uint64_t(fileBytes) * 1032 + 4096) {
            png_destroy_read_struct(&png, &info, nullptr);
            std::fclose(fp);
            throw InputError(
                path, "corrupt PNG image: " + std::to_string(w64) + " x " + std::to_string(h64) +
                          " pixels need " + std::to_string(rawBytes) +
                          " bytes of image data, more than the " + std::to_string(fileBytes) +
                          " bytes of the file can hold (expected the image data "
                          "of every pixel the header announces)");
        }
    }
    // Normalise to 8/16-bit RGB without alpha.
    if (colorType == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
    if (colorType == PNG_COLOR_TYPE_GRAY && bitDepth < 8) png_set_expand_gray_1_2_4_to_8(png);
    if (png_get_valid(png, info, PNG_INFO_tRNS)) png_set_tRNS_to_alpha(png);
    if (colorType == PNG_COLOR_TYPE_GRAY || colorType == PNG_COLOR_TYPE_GRAY_ALPHA)
        png_set_gray_to_rgb(png);
    png_set_strip_alpha(png);
    if (bitDepth == 16) png_set_swap(png);  // little-endian byte order in the rows
    png_read_update_info(png, info);
    bitDepth = png_get_bit_depth(png, info);
    const size_t rowBytes = png_get_rowbytes(png, info);
    data.resize(rowBytes * size_t(height));
    rows.resize(size_t(height));
    for (int y = 0; y < height; ++y) rows[size_t(y)] = data.data() + size_t(y) * rowBytes;
    png_read_image(png, rows.data());
    png_read_end(png, nullptr);
    png_destroy_read_struct(&png, &info, nullptr);
    std::fclose(fp);
    if (width <= 0 || height <= 0) throw InputError(path, "PNG image is empty");

    Image img(width, height);
    const float maxValue = bitDepth == 16 ? 65535.0f : 255.0f;
    // Decode through a lookup table (at most 65536 entries).
    std::vector<float> lut(size_t(maxValue) + 1);
    for (size_t i = 0; i < lut.size(); ++i) {
        float v = float(i) / maxValue;
        lut[i] = linearize ? srgbToLinear(v) : v;
    }
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            for (int c = 0; c < 3; ++c) {
                size_t i = size_t(y) * rowBytes + (size_t(x) * 3 + size_t(c)) * (bitDepth / 8);
                unsigned v = bitDepth == 16 ? unsigned(data[i]) | (unsigned(data[i + 1]) << 8)
                                            : unsigned(data[i]);
                img.at(x, y)[c] = lut[v];
            }
    return img;
}

static unsigned char toSrgb8(float v) {
    v = std::clamp(v, 0.0f, 1.0f);
    float s = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
    return (unsigned char)std::clamp(int(s * 255.0f + 0.5f), 0, 255);
}

void writePng(const std::string& path, const Image& img, float exposure) {
    FILE* fp = std::fopen(path.c_str(), "wb");
    if (!fp) throw std::runtime_error("cannot open '" + path + "' for writing");
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png ? png_create_info_struct(png) : nullptr;
    if (!png || !info || setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        std::fclose(fp);
        throw std::runtime_error("cannot write PNG image '" + path + "'");
    }
    png_init_io(png, fp);
    png_set_IHDR(png, info, img.width, img.height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    float scale = std::exp2(exposure);
    std::vector<unsigned char> row(size_t(img.width) * 3);
    for (int y = 0; y < img.height; ++y) {
        for (int x = 0; x < img.width; ++x) {
            Rgb c = img.at(x, y) * scale;
            for (int k = 0; k < 3; ++k) row[size_t(x) * 3 + k] = toSrgb8(c[k]);
        }
        png_write_row(png, row.data());
    }
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
    if (std::fclose(fp) != 0) throw std::runtime_error("cannot write PNG image '" + path + "'");
}

}  // namespace ub
