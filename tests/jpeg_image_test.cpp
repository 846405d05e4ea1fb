// JPEG images (core/image_jpeg.cpp, libjpeg-turbo): the test texture
// tests/data/mitsuba/textures/stripes.jpg (16x16, written by Mitsuba 3's own JPEG writer,
// tools/make_mitsuba_refs.py make_jpeg) decodes to the image it was made from within the
// JPEG error, sRGB-decoded unless raw; truncated, corrupt and non-JPEG files are errors
// naming the file; the Mitsuba `bitmap` texture and the JSON bitmap read .jpg files.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "core/error.h"
#include "core/image.h"
#include "scene/io/mitsuba_loader.h"
#include "tests/support/temp_file.h"

using namespace ub;
namespace fs = std::filesystem;

namespace {

const std::string kJpeg =
    std::string(UNIBEAM_SOURCE_DIR) + "/tests/data/mitsuba/textures/stripes.jpg";

std::string readAll(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
}

std::string writeTemp(const std::string& name, const std::string& data) {
    return test::writeTempFile("unibeam_jpeg_test", name, data);
}

std::string errorOf(const std::string& path) {
    try {
        readJpeg(path);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

}  // namespace

TEST(JpegImage, DecodesTheTestTexture) {
    Image raw = readJpeg(kJpeg, /*linearize=*/false);
    ASSERT_EQ(raw.width, 16);
    ASSERT_EQ(raw.height, 16);
    // The source image (make_jpeg): r = 0.9 - 0.7 y, g = 0.2 + 0.7 x, b = 0.3 + 0.3 x y with
    // x, y = linspace(0, 1, 16), columns 0, 4, 8, 12 darkened to 1/4. Quality 95 with 4:2:0
    // chroma: compared on the luma-weighted mean of a smooth column, within 0.03.
    double err = 0;
    int n = 0;
    for (int yi = 2; yi < 14; ++yi)
        for (int xi : {2, 6, 10}) {
            const double x = xi / 15.0, y = yi / 15.0;
            const double r = 0.9 - 0.7 * y, g = 0.2 + 0.7 * x, b = 0.3 + 0.3 * x * y;
            const Rgb p = raw.at(xi, yi);
            err += std::fabs((0.299 * p.x + 0.587 * p.y + 0.114 * p.z) -
                             std::floor(255 * (0.299 * r + 0.587 * g + 0.114 * b)) / 255.0);
            ++n;
        }
    EXPECT_LT(err / n, 0.03);
    EXPECT_LT(raw.at(4, 8).y, 0.5f * raw.at(6, 8).y);  // a darkened column
    Image lin = readJpeg(kJpeg);
    EXPECT_NEAR(lin.at(6, 8).y, srgbToLinear(raw.at(6, 8).y), 1e-6f);
}

TEST(JpegImage, CorruptFilesAreErrorsNamingTheFile) {
    const std::string good = readAll(kJpeg);
    ASSERT_GT(good.size(), 600u);
    std::string e = errorOf(writeTemp("notjpeg.jpg", "GIF89a not a jpeg"));
    EXPECT_NE(e.find("notjpeg.jpg: error: not a JPEG file (missing the start-of-image marker"),
              std::string::npos)
        << e;
    e = errorOf(writeTemp("truncated.jpg", good.substr(0, 400)));
    EXPECT_NE(e.find("truncated.jpg: error: corrupt or unsupported JPEG image (libjpeg: "),
              std::string::npos)
        << e;
    std::string garbage = good;
    for (size_t i = 200; i < garbage.size() - 2; ++i) garbage[i] = char(0x5A ^ i);
    e = errorOf(writeTemp("garbage.jpg", garbage));
    EXPECT_NE(e.find("garbage.jpg: error: corrupt or unsupported JPEG image"), std::string::npos)
        << e;
    e = errorOf(writeTemp("header_only.jpg", good.substr(0, 20)));
    EXPECT_NE(e.find("header_only.jpg: error: corrupt or unsupported JPEG image"),
              std::string::npos)
        << e;
    EXPECT_NE(errorOf("/nonexistent/x.jpg").find("image file does not exist"), std::string::npos);
}

TEST(JpegImage, MitsubaBitmapReadsJpeg) {
    const std::string text = R"(<scene version="3.0.0">
<sensor type="perspective"><film type="hdrfilm"><integer name="width" value="8"/>
<integer name="height" value="8"/></film></sensor>
<shape type="rectangle"><bsdf type="diffuse"><texture type="bitmap" name="reflectance">
<string name="filename" value="textures/stripes.jpg"/></texture></bsdf></shape>
<emitter type="constant"/>
</scene>
)";
    auto scene = loadMitsubaSceneFromString(
        text, "scene.xml", std::string(UNIBEAM_SOURCE_DIR) + "/tests/data/mitsuba");
    ASSERT_EQ(scene->textures.size(), 1u);
    ASSERT_TRUE(scene->textures[0].image);
    EXPECT_EQ(scene->textures[0].image->width, 16);
}
