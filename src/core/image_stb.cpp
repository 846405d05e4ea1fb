// BMP, TGA, Radiance RGBE (.hdr) and PNM (.ppm/.pgm) images through stb_image (Debian's
// libstb-dev: the header carries the implementation, compiled here for these four formats
// only, so the sanitizer builds instrument it too). PNG, JPEG and EXR have their own
// readers (libpng, libjpeg, OpenEXR); these are the other formats Mitsuba 3's bitmap reads.
//
// stb_image does not report data missing at the end of a file: reading past the end of the
// buffer yields zeros. So the file is decoded twice, the second time followed by a block of
// 0xFF bytes; if the two images differ the decoder read past the end, and the file is
// reported as truncated instead of becoming a texture with black rows.
//
// stb_image allocates the image a header announces before reading its data, so the size is
// checked first (stbi_info) against the most pixels a byte of each format can hold in stb's
// decoders (maxPixelsPerByte): a header announcing more is an error rather than a large
// allocation and two long decodes of padding (a 4 KB TGA announcing 4 M pixels took 1.4 s
// under the fuzz build, and the fuzz run's 10 s limit was hit on such an input in CI).
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_STATIC
#define STBI_ONLY_BMP
#define STBI_ONLY_TGA
#define STBI_ONLY_HDR
#define STBI_ONLY_PNM
#define STBI_NO_STDIO
#define STBI_FAILURE_USERMSG
#define STBI_MAX_DIMENSIONS (1 << 16)
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#endif
#include <stb/stb_image.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/file_status.h"
#include "core/image.h"

namespace ub {

namespace {

constexpr size_t kPadding = 1 << 16;

/// The file name's extension in lower case (".bmp").
std::string extensionOf(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

struct Decoded {
    int w = 0, h = 0;
    std::vector<float> hdr;          // RGB floats (.hdr)
    std::vector<unsigned char> ldr;  // RGB bytes (the others)
    bool operator==(const Decoded& o) const {
        return w == o.w && h == o.h && hdr == o.hdr && ldr == o.ldr;
    }
};

/// Decodes the first `size` bytes of data (the rest is padding) to RGB. False with
/// stb's reason in *why on failure. stb is asked for the file's own channel count and the
/// channels are expanded here: its own conversion of 16-bit PNM data to a different channel
/// count reads past its buffer (found by fuzz_stb_image, libstb-dev 0.0~git20220908).
bool decode(const std::vector<unsigned char>& data, size_t size, bool isHdr, Decoded* out,
            std::string* why) {
    int n = 0;
    const int len = int(size);
    auto expand = [&](auto* p, auto* dst) {
        const size_t count = size_t(out->w) * size_t(out->h);
        dst->resize(count * 3);
        for (size_t i = 0; i < count; ++i)
            for (int c = 0; c < 3; ++c)  // grey (+ alpha): replicated; RGB(A): alpha dropped
                (*dst)[3 * i + size_t(c)] = p[size_t(n) * i + size_t(n < 3 ? 0 : c)];
    };
    if (isHdr) {
        std::unique_ptr<float, void (*)(void*)> p(
            stbi_loadf_from_memory(data.data(), len, &out->w, &out->h, &n, 0), stbi_image_free);
        if (!p) return *why = stbi_failure_reason(), false;
        expand(p.get(), &out->hdr);
    } else {
        std::unique_ptr<unsigned char, void (*)(void*)> p(
            stbi_load_from_memory(data.data(), len, &out->w, &out->h, &n, 0), stbi_image_free);
        if (!p) return *why = stbi_failure_reason(), false;
        expand(p.get(), &out->ldr);
    }
    return n >= 1 && n <= 4 ? true : (*why = "unexpected channel count", false);
}

/// The most pixels one byte of the file can hold in stb_image v2.27's decoders, by the
/// format stb will find in it (stb goes by the content, not the name: BMP's "BM", PNM's
/// "P5"/"P6", the RGBE signature, and TGA, which has none, last):
///   * BMP: 1 bit per pixel (stb rejects BMP's RLE compression): 8;
///   * PNM (P5/P6, 8 or 16 bits per sample): 1;
///   * Radiance RGBE: a run of 127 pixels takes 2 bytes in each of the 4 channel planes,
///     127 / 8 ≈ 16; 32 leaves room;
///   * TGA: an RLE packet of 128 8-bit pixels takes 2 bytes: 64.
double maxPixelsPerByte(const std::vector<unsigned char>& d, bool isHdr) {
    if (isHdr) return 32.0;
    if (d.size() >= 2 && d[0] == 'B' && d[1] == 'M') return 8.0;
    if (d.size() >= 2 && d[0] == 'P' && (d[1] == '5' || d[1] == '6')) return 1.0;
    return 64.0;
}

/// Radiance RGBE run-length data is walked here before stb decodes it: stb_image v2.27's RLE
/// decoder loops for ever on a packet of count 0 (a "dump" of no bytes makes no progress),
/// and it reads 0 past the end of the data, so every truncated run-length file hung the
/// reader (found by fuzz_stb_image in CI: a timeout). This follows stb's reading exactly
/// (header lines up to the first empty one, the resolution line, then per scanline the
/// 2, 2, length header or flat data, and per channel the run and dump packets) and stops
/// where stb would report an error or read flat pixels. True if stb will not meet a count
/// of 0; otherwise *why says where. w is the width stbi_info reported.
bool hdrRunLengthsEnd(const std::vector<unsigned char>& d, int w, int h, std::string* why) {
    size_t pos = 0;
    const size_t n = d.size();
    auto get8 = [&]() -> int { return pos < n ? d[pos++] : (++pos, 0); };
    // The data begin after the line that follows the first empty line.
    size_t p = 0;
    while (p + 1 < n && !(d[p] == '\n' && d[p + 1] == '\n')) ++p;
    if (p + 1 >= n) return true;  // stb reports the header
    p += 2;
    while (p < n && d[p] != '\n') ++p;
    pos = p + 1;
    if (w < 8 || w >= 32768) return true;  // stored flat: read linearly
    for (int j = 0; j < h; ++j) {
        const int c1 = get8(), c2 = get8();
        int len = get8();
        if (c1 != 2 || c2 != 2 || (len & 0x80)) return true;  // flat from here on
        len = (len << 8) | get8();
        if (len != w) return true;  // stb: "invalid decoded scanline length"
        for (int k = 0; k < 4; ++k) {
            for (int i = 0; i < w;) {
                const size_t at = pos;
                int count = get8();
                if (count > 128) {
                    get8();
                    count -= 128;
                } else if (count == 0) {
                    *why = at >= n ? "the image data ends before the image does (truncated "
                                     "file; in the run-length data of row " +
                                         std::to_string(j) + ")"
                                   : "corrupt run-length data: a packet of length 0 at byte " +
                                         std::to_string(at) + " (row " + std::to_string(j) +
                                         ", channel " + std::to_string(k) + ")";
                    return false;
                } else {
                    pos += size_t(count);
                }
                if (count > w - i) return true;  // stb: "bad RLE data in HDR"
                i += count;
            }
        }
    }
    return true;
}

/// PNM (P5/P6) headers are checked before stb parses them: stb reads each header number
/// into an int without an overflow check (signed overflow, undefined behaviour, found by
/// fuzz_stb_image), so a number of more than 9 digits is an error here. True if the data
/// is no PNM file or its header numbers are short enough; otherwise *why says which.
bool pnmHeaderNumbersFit(const std::vector<unsigned char>& d, std::string* why) {
    if (d.size() < 2 || d[0] != 'P' || (d[1] != '5' && d[1] != '6')) return true;
    size_t i = 2;
    for (int number = 0; number < 3; ++number) {
        // Whitespace and comments (stb's rules: '#' to the end of the line).
        while (i < d.size() && (std::isspace(d[i]) || d[i] == '#')) {
            if (d[i] == '#')
                while (i < d.size() && d[i] != '\n' && d[i] != '\r') ++i;
            else
                ++i;
        }
        size_t digits = 0;
        while (i < d.size() && d[i] >= '0' && d[i] <= '9') ++i, ++digits;
        if (digits > 9) {
            static const char* const kNames[3] = {"width", "height", "maximum value"};
            *why = std::string("PNM header ") + kNames[number] + " has " + std::to_string(digits) +
                   " digits (expected at most 9)";
            return false;
        }
        if (digits == 0) return true;  // stb reports the malformed header
    }
    return true;
}

}  // namespace

Image readStbImage(const std::string& path, bool linearize) {
    if (!isRegularFile(path)) throw InputError(path, "image file does not exist");
    std::ifstream f(path, std::ios::binary);
    std::vector<unsigned char> data((std::istreambuf_iterator<char>(f)),
                                    std::istreambuf_iterator<char>());
    if (!f.good() && !f.eof()) throw InputError(path, "cannot read the image file");
    if (data.size() > (size_t(1) << 30)) throw InputError(path, "image file larger than 1 GiB");
    const std::string ext = extensionOf(path);
    const bool isHdr = ext == ".hdr" || ext == ".rgbe";
    const size_t size = data.size();

    // The extension decides the format: RGBE data only in .hdr/.rgbe files, and no RGBE in
    // the others (stb would otherwise convert between the two on its own).
    if (isHdr != bool(stbi_is_hdr_from_memory(data.data(), int(size))))
        throw InputError(path, isHdr ? "not a Radiance RGBE file (no '#?RADIANCE' or '#?RGBE' "
                                       "signature)"
                                     : "a Radiance RGBE file under the name of a " +
                                           ext.substr(ext.empty() ? 0 : 1) + " image");
    std::string why;
    if (!pnmHeaderNumbersFit(data, &why)) throw InputError(path, why);
    int w = 0, h = 0, n = 0;
    if (!stbi_info_from_memory(data.data(), int(size), &w, &h, &n))
        throw InputError(path, "cannot decode the " + ext.substr(ext.empty() ? 0 : 1) +
                                   " image: " + stbi_failure_reason());
    // stbi_info gives a top-down BMP's height as stored, negative; stb's decoder takes its
    // absolute value (fuzz_stb_image: a 31-byte BMP announcing 8192 x -50527 pixels passed the
    // bound signed and made stb allocate 1.2 GB).
    if (std::fabs(double(w)) * std::fabs(double(h)) >
        maxPixelsPerByte(data, isHdr) * double(size) + 4096.0)
        throw InputError(path, "the header announces " + std::to_string(w) + " x " +
                                   std::to_string(std::llabs(h)) + " pixels, more than a " +
                                   std::to_string(size) + "-byte file can hold");
    if (isHdr && !hdrRunLengthsEnd(data, w, h, &why)) throw InputError(path, why);
    Decoded plain, padded;
    // The second decode sees the same bytes followed by 0xFF (stb reads 0 past the end).
    std::vector<unsigned char> withPad(data);
    withPad.resize(size + kPadding, 0xFF);
    if (!decode(data, size, isHdr, &plain, &why))
        throw InputError(path,
                         "cannot decode the " + ext.substr(ext.empty() ? 0 : 1) + " image: " + why);
    if (!decode(withPad, size + kPadding, isHdr, &padded, &why) || !(plain == padded))
        throw InputError(path, "the image data ends before the image does (truncated file)");
    if (plain.w <= 0 || plain.h <= 0) throw InputError(path, "image is empty");

    Image img(plain.w, plain.h);
    if (isHdr) {
        for (size_t i = 0; i < img.pixels.size(); ++i)
            img.pixels[i] = Rgb(plain.hdr[3 * i], plain.hdr[3 * i + 1], plain.hdr[3 * i + 2]);
    } else {
        float lut[256];
        for (int i = 0; i < 256; ++i)
            lut[i] = linearize ? srgbToLinear(float(i) / 255.0f) : float(i) / 255.0f;
        for (size_t i = 0; i < img.pixels.size(); ++i)
            img.pixels[i] =
                Rgb(lut[plain.ldr[3 * i]], lut[plain.ldr[3 * i + 1]], lut[plain.ldr[3 * i + 2]]);
    }
    return img;
}

bool isBitmapFile(const std::string& path) {
    const std::string ext = extensionOf(path);
    for (const char* e :
         {".png", ".jpg", ".jpeg", ".exr", ".bmp", ".tga", ".hdr", ".rgbe", ".ppm", ".pgm", ".pnm"})
        if (ext == e) return true;
    return false;
}

bool isFloatBitmapFile(const std::string& path) {
    const std::string ext = extensionOf(path);
    return ext == ".exr" || ext == ".hdr" || ext == ".rgbe";
}

Image readBitmapFile(const std::string& path, bool linearize) {
    const std::string ext = extensionOf(path);
    if (ext == ".png") return readPng(path, linearize);
    if (ext == ".jpg" || ext == ".jpeg") return readJpeg(path, linearize);
    if (ext == ".exr") return readExr(path);
    if (isBitmapFile(path)) return readStbImage(path, linearize);
    throw InputError(path, std::string("unsupported image format '") + ext + "' (expected " +
                               kBitmapFormats + ")");
}

}  // namespace ub
