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
    e = errorOf((fs::temp_directory_path() / "unibeam_stb_image_test" / "missing.bmp").string());
    EXPECT_NE(e.find("image file does not exist"), std::string::npos) << e;
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
