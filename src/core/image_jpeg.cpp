// JPEG images through libjpeg(-turbo) (Debian's libjpeg62-turbo-dev). libjpeg reports
// fatal errors through error_exit (here a longjmp back to readJpeg) and corrupt or missing
// data as warnings (it would fill the rest of the image with grey); both are errors here,
// with libjpeg's message, so a truncated or corrupt file never becomes a texture.
// clang-format off
#include <cstdio>  // before jpeglib.h, which uses FILE and size_t
#include <jpeglib.h>
// clang-format on

#include <csetjmp>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/file_status.h"
#include "core/image.h"

namespace ub {

namespace {

struct JpegError {
    jpeg_error_mgr mgr;
    std::jmp_buf jump;
    std::string message;
};

void jpegErrorExit(j_common_ptr cinfo) {
    auto* e = reinterpret_cast<JpegError*>(cinfo->err);
    char buf[JMSG_LENGTH_MAX];
    (*cinfo->err->format_message)(cinfo, buf);
    e->message = buf;
    std::longjmp(e->jump, 1);
}

/// Warnings (level -1: corrupt data, premature end of file) abort the read; trace messages
/// (level >= 0) are ignored.
void jpegEmitMessage(j_common_ptr cinfo, int level) {
    if (level >= 0) return;
    jpegErrorExit(cinfo);
}

}  // namespace

Image readJpeg(const std::string& path, bool linearize) {
    if (!isRegularFile(path)) throw InputError(path, "image file does not exist");
    std::ifstream f(path, std::ios::binary);
    if (!f) throw InputError(path, "cannot open the JPEG image");
    const std::vector<unsigned char> file((std::istreambuf_iterator<char>(f)),
                                          std::istreambuf_iterator<char>());
    if (file.size() < 3 || file[0] != 0xFF || file[1] != 0xD8 || file[2] != 0xFF)
        throw InputError(path, "not a JPEG file (missing the start-of-image marker FF D8 FF)");

    jpeg_decompress_struct cinfo;
    JpegError err;
    cinfo.err = jpeg_std_error(&err.mgr);
    err.mgr.error_exit = jpegErrorExit;
    err.mgr.emit_message = jpegEmitMessage;
    // Declared before setjmp: the decoded rows (8-bit RGB), grown row by row so that a header
    // announcing a huge image without the data to fill it fails before much is allocated.
    std::vector<unsigned char> rgb;
    int width = 0, height = 0;
    if (setjmp(err.jump)) {
        jpeg_destroy_decompress(&cinfo);
        throw InputError(path, "corrupt or unsupported JPEG image (libjpeg: " + err.message + ")");
    }
    jpeg_create_decompress(&cinfo);
    // libjpeg allocates the whole coefficient buffer of a progressive image up front: cap its
    // memory (beyond it, an error, since no backing store is compiled in) so that a header
    // announcing a huge image is an error rather than gigabytes.
    cinfo.mem->max_memory_to_use = long(1) << 30;
    jpeg_mem_src(&cinfo, file.data(), static_cast<unsigned long>(file.size()));
    jpeg_read_header(&cinfo, TRUE);
    if (cinfo.jpeg_color_space == JCS_CMYK || cinfo.jpeg_color_space == JCS_YCCK) {
        jpeg_destroy_decompress(&cinfo);
        throw InputError(path, "CMYK JPEG images are not supported (expected grey or RGB)");
    }
    cinfo.out_color_space = JCS_RGB;  // grey is replicated, YCbCr converted
    jpeg_start_decompress(&cinfo);
    width = int(cinfo.output_width);
    height = int(cinfo.output_height);
    if (int64_t(width) > 65536 || int64_t(height) > 65536 ||
        int64_t(width) * int64_t(height) > (int64_t(1) << 28) || cinfo.output_components != 3) {
        jpeg_destroy_decompress(&cinfo);
        throw InputError(path, "JPEG image of " + std::to_string(width) + " x " +
                                   std::to_string(height) +
                                   " pixels is too large (at most 65536 on a side and 2^28 "
                                   "pixels)");
    }
    const size_t rowBytes = size_t(width) * 3;
    while (cinfo.output_scanline < cinfo.output_height) {
        rgb.resize(rgb.size() + rowBytes);
        JSAMPROW row = rgb.data() + rgb.size() - rowBytes;
        jpeg_read_scanlines(&cinfo, &row, 1);
    }
    jpeg_finish_decompress(&cinfo);
    jpeg_destroy_decompress(&cinfo);
    if (width <= 0 || height <= 0) throw InputError(path, "JPEG image is empty");

    float lut[256];
    for (int i = 0; i < 256; ++i)
        lut[i] = linearize ? srgbToLinear(float(i) / 255.0f) : float(i) / 255.0f;
    Image img(width, height);
    for (size_t i = 0; i < img.pixels.size(); ++i)
        img.pixels[i] = Rgb(lut[rgb[3 * i]], lut[rgb[3 * i + 1]], lut[rgb[3 * i + 2]]);
    return img;
}

}  // namespace ub
