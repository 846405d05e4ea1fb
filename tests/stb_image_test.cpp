// BMP, PPM and Radiance RGBE images (core/image_stb.cpp, stb_image): small files written
// byte by byte here decode to the pixels they encode (row 0 at the top, 8-bit values
// sRGB-decoded unless raw, RGBE linear); truncated and corrupt files are errors naming the
// file; the Mitsuba `bitmap` texture reads a .bmp.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.h"
#include "core/image.h"
#include "scene/io/mitsuba_loader.h"
#include "scene/scene.h"
#include "tests/support/temp_file.h"

using namespace ub;
namespace fs = std::filesystem;

namespace {

std::string writeTemp(const std::string& name, const std::string& data) {
    return test::writeTempFile("unibeam_stb_image_test", name, data);
}

std::string errorOf(const std::string& path) {
    try {
        readBitmapFile(path);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

void put32(std::string* s, uint32_t v) {
    for (int i = 0; i < 4; ++i) s->push_back(char((v >> (8 * i)) & 0xFF));
}
void put16(std::string* s, uint16_t v) {
    s->push_back(char(v & 0xFF));
    s->push_back(char(v >> 8));
}

/// A 2x2 24-bit BMP: top row red, green; bottom row blue, grey 128. BMP rows are stored
/// bottom-up, each pixel as B, G, R, each row padded to 4 bytes.
std::string bmp2x2() {
    const uint8_t rows[2][2][3] = {{{0, 0, 255}, {128, 128, 128}},  // bottom row (stored first)
                                   {{255, 0, 0}, {0, 255, 0}}};     // top row
    std::string pixels;
    for (auto& row : rows) {
        for (auto& p : row)
            for (int c = 2; c >= 0; --c) pixels.push_back(char(p[c]));
        pixels.append(2, '\0');  // 6 bytes -> 8
    }
    std::string s = "BM";
    put32(&s, uint32_t(54 + pixels.size()));
    put32(&s, 0);
    put32(&s, 54);  // pixel data offset
    put32(&s, 40);  // BITMAPINFOHEADER
    put32(&s, 2);
    put32(&s, 2);
    put16(&s, 1);   // planes
    put16(&s, 24);  // bits per pixel
    put32(&s, 0);   // BI_RGB
    put32(&s, uint32_t(pixels.size()));
    put32(&s, 2835);
    put32(&s, 2835);
    put32(&s, 0);
    put32(&s, 0);
    return s + pixels;
}

void expectRgb(const Rgb& c, float r, float g, float b, float tol = 1e-6f) {
    EXPECT_NEAR(c.x, r, tol);
    EXPECT_NEAR(c.y, g, tol);
    EXPECT_NEAR(c.z, b, tol);
}

}  // namespace

TEST(StbImage, BmpDecodesTopRowFirstSrgbUnlessRaw) {
    const std::string path = writeTemp("quad.bmp", bmp2x2());
    Image img = readBitmapFile(path);
    ASSERT_EQ(img.width, 2);
    ASSERT_EQ(img.height, 2);
    expectRgb(img.at(0, 0), 1, 0, 0);
    expectRgb(img.at(1, 0), 0, 1, 0);
    expectRgb(img.at(0, 1), 0, 0, 1);
    const float grey = srgbToLinear(128.0f / 255.0f);
    EXPECT_NEAR(grey, 0.2158605f, 1e-5f);  // IEC 61966-2-1 at 128/255
    expectRgb(img.at(1, 1), grey, grey, grey);
    Image raw = readBitmapFile(path, /*linearize=*/false);
    expectRgb(raw.at(1, 1), 128.0f / 255.0f, 128.0f / 255.0f, 128.0f / 255.0f);
}

TEST(StbImage, PpmAndRgbeDecode) {
    std::string ppm = "P6\n2 1\n255\n";
    for (int v : {255, 0, 0, 0, 0, 255}) ppm.push_back(char(v));
    Image p = readBitmapFile(writeTemp("pair.ppm", ppm));
    ASSERT_EQ(p.width, 2);
    ASSERT_EQ(p.height, 1);
    expectRgb(p.at(0, 0), 1, 0, 0);
    expectRgb(p.at(1, 0), 0, 0, 1);
    // RGBE: value = mantissa * 2^(exponent - 136) (Ward's RGBE, as stb decodes it); rows of
    // fewer than 8 pixels are stored flat.
    std::string hdr = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 2\n";
    for (int v : {128, 64, 32, 129, 128, 128, 128, 137}) hdr.push_back(char(v));
    Image h = readBitmapFile(writeTemp("pair.hdr", hdr), /*linearize=*/true);
    ASSERT_EQ(h.width, 2);
    expectRgb(h.at(0, 0), 1.0f, 0.5f, 0.25f);
    expectRgb(h.at(1, 0), 256.0f, 256.0f, 256.0f);
}

TEST(StbImage, TruncatedCorruptAndUnknownFilesAreErrors) {
    std::string full = bmp2x2();
    std::string e = errorOf(writeTemp("short.bmp", full.substr(0, full.size() - 5)));
    EXPECT_NE(e.find("short.bmp"), std::string::npos) << e;
    EXPECT_NE(e.find("truncated file"), std::string::npos) << e;
    e = errorOf(writeTemp("junk.bmp", "this is not a bitmap at all"));
    EXPECT_NE(e.find("junk.bmp"), std::string::npos) << e;
    EXPECT_NE(e.find("cannot decode the bmp image"), std::string::npos) << e;
    e = errorOf(writeTemp("empty.tga", ""));
    EXPECT_NE(e.find("empty.tga"), std::string::npos) << e;
    e = errorOf(writeTemp("pic.gif", "GIF89a"));
    EXPECT_NE(e.find("unsupported image format '.gif'"), std::string::npos) << e;
    e = errorOf(
        (ub::test::processScratchDir() / "unibeam_stb_image_test" / "missing.bmp").string());
    EXPECT_NE(e.find("image file does not exist"), std::string::npos) << e;
}

/// An 8-bit grey RLE TGA (image type 11) of w x h pixels whose data is `packets` run packets
/// of 128 pixels of value 200 (a packet header byte 0xFF and one value byte).
std::string greyRleTga(uint16_t w, uint16_t h, int packets) {
    std::string s;
    s.push_back(0);     // no image ID
    s.push_back(0);     // no colour map
    s.push_back(11);    // RLE grey
    s.append(5, '\0');  // colour map specification
    put16(&s, 0);       // x origin
    put16(&s, 0);       // y origin
    put16(&s, w);
    put16(&s, h);
    s.push_back(8);  // bits per pixel
    s.push_back(0);  // descriptor
    for (int i = 0; i < packets; ++i) s += "\xFF\xC8";
    return s;
}

// The header's pixel count is checked against what the file can hold before stb allocates
// and decodes: 64 pixels per byte (TGA's densest run packets) plus 4096. A run-length TGA at
// that density reads; one announcing more pixels than its bytes can hold is an error, not
// two decodes of millions of pixels of padding.
TEST(StbImage, HeaderPixelCountIsBoundedByTheFileSize) {
    // 1024 x 128 pixels in 1024 packets: 2066 bytes, 63 pixels per byte.
    Image dense = readBitmapFile(writeTemp("dense.tga", greyRleTga(1024, 128, 1024)), false);
    ASSERT_EQ(dense.width, 1024);
    ASSERT_EQ(dense.height, 128);
    EXPECT_NEAR(dense.at(1023, 127).x, 200.0f / 255.0f, 1e-6f);
    // 1024 x 256 pixels announced by a 2066-byte file: at most 64 * 2066 + 4096 = 136320 can
    // be held.
    const std::string e = errorOf(writeTemp("sparse.tga", greyRleTga(1024, 256, 1024)));
    EXPECT_NE(e.find("sparse.tga"), std::string::npos) << e;
    EXPECT_NE(e.find("the header announces 1024 x 256 pixels, more than a 2066-byte file can "
                     "hold"),
              std::string::npos)
        << e;
}

/// A Radiance RGBE file of one row of 8 pixels, stored run-length encoded: each of the four
/// channel planes one run packet of 8 pixels (0x88, value), mantissas 128, 64, 32 and
/// exponent 129 (so RGB 1, 0.5, 0.25).
std::string rleRgbeRow8() {
    std::string s = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 8\n";
    for (int v : {2, 2, 0, 8}) s.push_back(char(v));  // a run-length row of width 8
    for (int v : {128, 64, 32, 129}) {
        s.push_back(char(0x88));
        s.push_back(char(v));
    }
    return s;
}

// stb_image v2.27 loops for ever on a run-length packet of count 0, and it reads zeros past
// the end of the data: a truncated run-length RGBE file hung the reader (fuzz_stb_image in
// CI). The run lengths are walked first; a run-length file that ends early or holds a zero
// packet is an error, and a whole one still reads.
TEST(StbImage, RunLengthRgbeThatEndsEarlyOrHasAZeroPacketIsAnError) {
    const std::string full = rleRgbeRow8();
    Image img = readBitmapFile(writeTemp("row.hdr", full), true);
    ASSERT_EQ(img.width, 8);
    expectRgb(img.at(7, 0), 1.0f, 0.5f, 0.25f);
    // Cut inside the third channel plane (its count byte is the last one left).
    std::string e = errorOf(writeTemp("cut.hdr", full.substr(0, full.size() - 3)));
    EXPECT_NE(e.find("cut.hdr"), std::string::npos) << e;
    EXPECT_NE(e.find("the image data ends before the image does (truncated file; in the "
                     "run-length data of row 0)"),
              std::string::npos)
        << e;
    // The second plane's packet replaced by a dump of 0 bytes.
    std::string zero = full;
    const size_t second = full.size() - 6;
    zero[second] = 0;
    e = errorOf(writeTemp("zero.hdr", zero));
    EXPECT_NE(e.find("zero.hdr"), std::string::npos) << e;
    EXPECT_NE(e.find("corrupt run-length data: a packet of length 0 at byte " +
                     std::to_string(second) + " (row 0, channel 1)"),
              std::string::npos)
        << e;
}

TEST(StbImage, MitsubaBitmapTextureReadsBmp) {
    const std::string path = writeTemp("tex.bmp", bmp2x2());
    const std::string dir = fs::path(path).parent_path().string();
    const std::string text = R"(<scene version="3.0.0">
<sensor type="perspective"><film type="hdrfilm"><integer name="width" value="8"/>
<integer name="height" value="8"/><rfilter type="box"/></film></sensor>
<emitter type="constant"/>
<shape type="sphere"><bsdf type="diffuse"><texture type="bitmap" name="reflectance">
<string name="filename" value="tex.bmp"/><string name="filter_type" value="nearest"/>
</texture></bsdf></shape>
</scene>
)";
    auto s = loadMitsubaSceneFromString(text, "scene.xml", dir, {});
    ASSERT_EQ(s->textures.size(), 1u);
    ASSERT_TRUE(s->textures[0].image);
    expectRgb(s->textures[0].image->at(0, 0), 1, 0, 0);
}
