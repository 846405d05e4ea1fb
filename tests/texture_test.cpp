// Tests of scene/texture.h (checkerboard and bitmap lookups with Mitsuba 3's
// conventions), the PNG reader in core/image.h, and Scene::setupBsdf resolving textures.
#include "scene/texture.h"

#include <gtest/gtest.h>
#include <png.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/image.h"
#include "scene/bsdf.h"
#include "scene/scene.h"
#include "scene/shapes.h"
#include "tests/support/temp_file.h"

using namespace ub;

namespace {

const Rgb kC0(0.9f, 0.1f, 0.2f), kC1(0.05f, 0.6f, 0.3f);

Texture checkerboard() {
    Texture t;
    t.type = TextureType::Checkerboard;
    t.name = "checks";
    t.color0 = kC0;
    t.color1 = kC1;
    return t;
}

bool sameRgb(const Rgb& a, const Rgb& b, float tol = 1e-6f) {
    return std::fabs(a.x - b.x) <= tol && std::fabs(a.y - b.y) <= tol &&
           std::fabs(a.z - b.z) <= tol;
}

std::string tempPath(const std::string& name) {
    return (ub::test::processScratchDir() / ("texture_test_" + name)).string();
}

/// Writes a 16-bit grey + alpha PNG with libpng directly (writePng only writes 8-bit RGB).
void writeGrey16Png(const std::string& path, int w, int h, const std::vector<uint16_t>& grey) {
    FILE* fp = std::fopen(path.c_str(), "wb");
    ASSERT_NE(fp, nullptr);
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png_create_info_struct(png);
    png_init_io(png, fp);
    png_set_IHDR(png, info, w, h, 16, PNG_COLOR_TYPE_GRAY_ALPHA, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    std::vector<unsigned char> row(size_t(w) * 4);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            uint16_t g = grey[size_t(y) * w + x];
            row[4 * x] = (unsigned char)(g >> 8);  // PNG is big-endian
            row[4 * x + 1] = (unsigned char)(g & 0xff);
            row[4 * x + 2] = 0x12;  // alpha: ignored by the reader
            row[4 * x + 3] = 0x34;
        }
        png_write_row(png, row.data());
    }
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
    std::fclose(fp);
}

}  // namespace

// Mitsuba 3's checkerboard: colour0 where frac(u) > 1/2 equals frac(v) > 1/2, so uv (0, 0)
// is colour0, period 1, and negative uv wraps (frac(-0.25) = 0.75).
TEST(Texture, CheckerboardMatchesMitsubaPattern) {
    const Texture t = checkerboard();
    EXPECT_TRUE(sameRgb(t.eval({0.0f, 0.0f}), kC0));
    EXPECT_TRUE(sameRgb(t.eval({0.25f, 0.25f}), kC0));
    EXPECT_TRUE(sameRgb(t.eval({0.75f, 0.75f}), kC0));
    EXPECT_TRUE(sameRgb(t.eval({0.75f, 0.25f}), kC1));
    EXPECT_TRUE(sameRgb(t.eval({0.25f, 0.75f}), kC1));
    EXPECT_TRUE(sameRgb(t.eval({0.5f, 0.0f}), kC0));    // 0.5 is not > 0.5
    EXPECT_TRUE(sameRgb(t.eval({1.25f, 3.25f}), kC0));  // period 1
    EXPECT_TRUE(sameRgb(t.eval({-0.25f, 0.25f}), kC1));
    EXPECT_TRUE(sameRgb(t.eval({-0.25f, -0.25f}), kC0));
    EXPECT_TRUE(sameRgb(t.mean(), (kC0 + kC1) * 0.5f));
    // Mitsuba's default colours.
    Texture d;
    d.type = TextureType::Checkerboard;
    EXPECT_TRUE(sameRgb(d.eval({0.1f, 0.1f}), Rgb(0.4f)));
    EXPECT_TRUE(sameRgb(d.eval({0.6f, 0.1f}), Rgb(0.2f)));
    // Non-finite uv: black, no crash.
    EXPECT_TRUE(isBlack(t.eval({NAN, 0.0f})));
}

// to_uv is applied before the pattern: scale 4 in u gives four squares per unit in u.
// From a 4x4 matrix Mitsuba keeps rows/columns 0, 1 and the translation column.
TEST(Texture, UvTransform) {
    Texture t = checkerboard();
    t.toUv = UvTransform::scale(4.0f, 1.0f);
    EXPECT_TRUE(sameRgb(t.eval({0.1f, 0.1f}), kC0));   // u' = 0.4
    EXPECT_TRUE(sameRgb(t.eval({0.15f, 0.1f}), kC1));  // u' = 0.6
    Transform m = Transform::translate({0.5f, 0.25f, 7.0f}) * Transform::scale({2.0f, 3.0f, 5.0f});
    UvTransform r = UvTransform::fromMatrix4(m);
    Vec2 uv = r.apply({0.1f, 0.2f});
    EXPECT_NEAR(uv.x, 0.5f + 2.0f * 0.1f, 1e-6f);
    EXPECT_NEAR(uv.y, 0.25f + 3.0f * 0.2f, 1e-6f);
}

// Bilinear lookup between pixel centres ((x + 1/2) / W, (y + 1/2) / H), row 0 at v = 0,
// with repeat wrapping at the borders.
TEST(Texture, BitmapBilinearRepeat) {
    auto img = std::make_shared<Image>(2, 2);
    img->at(0, 0) = Rgb(1, 0, 0);
    img->at(1, 0) = Rgb(0, 1, 0);
    img->at(0, 1) = Rgb(0, 0, 1);
    img->at(1, 1) = Rgb(1, 1, 1);
    Texture t;
    t.type = TextureType::Bitmap;
    t.image = img;
    EXPECT_TRUE(sameRgb(t.eval({0.25f, 0.25f}), Rgb(1, 0, 0)));
    EXPECT_TRUE(sameRgb(t.eval({0.75f, 0.25f}), Rgb(0, 1, 0)));
    EXPECT_TRUE(sameRgb(t.eval({0.25f, 0.75f}), Rgb(0, 0, 1)));
    EXPECT_TRUE(sameRgb(t.eval({0.5f, 0.25f}), Rgb(0.5f, 0.5f, 0)));
    EXPECT_TRUE(sameRgb(t.eval({0.5f, 0.5f}), Rgb(0.5f, 0.5f, 0.5f)));
    // u = 0 lies halfway between the centres of column 1 (wrapped) and column 0.
    EXPECT_TRUE(sameRgb(t.eval({0.0f, 0.25f}), Rgb(0.5f, 0.5f, 0)));
    EXPECT_TRUE(sameRgb(t.eval({1.25f, -0.75f}), Rgb(1, 0, 0)));  // repeat
    // A quarter of the way from column 0's centre to column 1's.
    EXPECT_TRUE(sameRgb(t.eval({0.375f, 0.25f}), Rgb(0.75f, 0.25f, 0)));
    EXPECT_TRUE(sameRgb(t.mean(), Rgb(0.5f, 0.5f, 0.5f)));
}

// 8-bit RGB PNG round trip: writePng encodes linear values to sRGB bytes; readPng decodes
// them (IEC 61966-2-1) to within half a quantisation step (the sRGB curve's slope is at
// most 12.92, so |error| <= 12.92 * 0.5 / 255 in linear units); without linearize the raw
// encoded values k / 255 come back.
TEST(Texture, PngReadDecodesSrgb) {
    Image img(3, 2);
    const float values[6] = {0.0f, 0.002f, 0.18f, 0.5f, 0.8f, 1.0f};
    for (int i = 0; i < 6; ++i) img.at(i % 3, i / 3) = Rgb(values[i], values[5 - i], 0.25f);
    const std::string path = tempPath("rgb8.png");
    writePng(path, img);
    const Image lin = readPng(path);
    ASSERT_EQ(lin.width, 3);
    ASSERT_EQ(lin.height, 2);
    for (int i = 0; i < 6; ++i) {
        EXPECT_NEAR(lin.at(i % 3, i / 3).x, values[i], 12.92f * 0.5f / 255) << i;
        EXPECT_NEAR(lin.at(i % 3, i / 3).y, values[5 - i], 12.92f * 0.5f / 255) << i;
    }
    const Image raw = readPng(path, false);
    for (const Rgb& p : raw.pixels)
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(p[c] * 255.0f, std::round(p[c] * 255.0f), 1e-3f);
    EXPECT_NEAR(raw.at(2, 0).x, 0.4613f, 0.5f / 255);  // 0.18 linear -> sRGB 0.4613
    EXPECT_NEAR(srgbToLinear(0.5f), 0.21404f, 1e-5f);
    EXPECT_NEAR(srgbToLinear(0.04f), 0.04f / 12.92f, 1e-7f);
    std::filesystem::remove(path);
}

// 16-bit grey + alpha: grey replicated to RGB, alpha dropped, 65535 = 1.
TEST(Texture, PngReadGrey16WithAlpha) {
    const std::string path = tempPath("grey16.png");
    writeGrey16Png(path, 2, 1, {0, 65535});
    Image raw = readPng(path, false);
    ASSERT_EQ(raw.width, 2);
    EXPECT_TRUE(sameRgb(raw.at(0, 0), Rgb(0.0f)));
    EXPECT_TRUE(sameRgb(raw.at(1, 0), Rgb(1.0f)));
    writeGrey16Png(path, 1, 1, {32768});
    Image lin = readPng(path);
    EXPECT_NEAR(lin.at(0, 0).y, srgbToLinear(32768.0f / 65535.0f), 1e-6f);
    std::filesystem::remove(path);
}

TEST(Texture, PngReadErrors) {
    EXPECT_THROW(readPng(tempPath("does_not_exist.png")), InputError);
    const std::string path = tempPath("garbage.png");
    FILE* fp = std::fopen(path.c_str(), "wb");
    std::fputs("this is not a png file at all", fp);
    std::fclose(fp);
    try {
        readPng(path);
        FAIL() << "expected InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("not a PNG"), std::string::npos) << e.what();
    }
    // A valid signature followed by garbage: the chunk walk finds a chunk longer than the file.
    fp = std::fopen(path.c_str(), "wb");
    const unsigned char sig[8] = {137, 80, 78, 71, 13, 10, 26, 10};
    std::fwrite(sig, 1, 8, fp);
    std::fputs("garbage after the signature", fp);
    std::fclose(fp);
    try {
        readPng(path);
        FAIL() << "expected InputError";
    } catch (const InputError& e) {
        EXPECT_NE(
            std::string(e.what()).find("corrupt PNG image: chunk 'age ' at byte 8 announces "),
            std::string::npos)
            << e.what();
    }
    // Chunks that fit the file but an IHDR with garbage and a wrong CRC: libpng's error path,
    // not a crash.
    fp = std::fopen(path.c_str(), "wb");
    std::fwrite(sig, 1, 8, fp);
    const unsigned char ihdr[25] = {0, 0, 0, 13, 'I', 'H', 'D', 'R', 9, 9, 9, 9, 9,
                                    9, 9, 9, 9,  9,   9,   9,   9,   1, 2, 3, 4};
    std::fwrite(ihdr, 1, sizeof(ihdr), fp);
    const unsigned char iend[12] = {0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xae, 0x42, 0x60, 0x82};
    std::fwrite(iend, 1, sizeof(iend), fp);
    std::fclose(fp);
    try {
        readPng(path);
        FAIL() << "expected InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("corrupt or unsupported PNG image (libpng: "),
                  std::string::npos)
            << e.what();
    }
    std::filesystem::remove(path);
}

TEST(Texture, ValidateRejectsBadData) {
    Texture t;
    t.type = TextureType::Bitmap;
    t.name = "empty";
    EXPECT_THROW(t.validate(), InputError);
    Texture c = checkerboard();
    c.color1 = Rgb(-1.0f);
    EXPECT_THROW(c.validate(), InputError);
    Texture u = checkerboard();
    u.toUv.m[0][2] = INFINITY;
    EXPECT_THROW(u.validate(), InputError);
    EXPECT_NO_THROW(checkerboard().validate());
}

// Scene::setupBsdf looks the material's textures up at hit.uv: a Lambertian floor with a
// checkerboard reflectance (4 squares per unit of uv) evaluates to colour / pi on the
// squares the pattern predicts, for both integrator entry points.
TEST(Texture, SceneSetupBsdfResolvesTexturesAtHitUv) {
    Scene scene;
    Texture t = checkerboard();
    t.toUv = UvTransform::scale(2.0f, 2.0f);
    const int tex = scene.addTexture(t);
    Material m;
    m.diffuse = Rgb(0.5f);  // replaced by the texture
    m.textures.diffuse = tex;
    const int mat = scene.addMaterial(m);
    scene.addMesh(makeRectangle(), mat, -1, "floor");  // [-1,1]^2, uv = ((x+1)/2, (y+1)/2)
    scene.commit();
    struct Probe {
        Vec3 at;
        Rgb expected;
    };
    // uv' = 2 uv = (x + 1, y + 1).
    const Probe probes[] = {{{-0.75f, -0.75f, 0}, kC0},
                            {{-0.25f, -0.75f, 0}, kC1},
                            {{0.25f, -0.75f, 0}, kC0},
                            {{-0.75f, -0.25f, 0}, kC1},
                            {{0.75f, 0.75f, 0}, kC0}};
    for (const Probe& p : probes) {
        Ray ray;
        ray.org = p.at + Vec3(0, 0, 2);
        ray.dir = Vec3(0, 0, -1);
        Hit hit;
        ASSERT_TRUE(scene.intersect(ray, &hit));
        Bsdf bsdf;
        ASSERT_TRUE(scene.setupBsdf(&bsdf, hit, -ray.dir, false));
        const Vec3 gen = normalize(Vec3(0.3f, 0.1f, 1.0f));
        EXPECT_TRUE(sameRgb(bsdf.evaluate(gen, nullptr, nullptr, nullptr), p.expected * kInvPi))
            << p.at.x << " " << p.at.y;
        Bsdf stored;
        ASSERT_TRUE(scene.setupBsdf(&stored, hit.materialId, hit.uv, hit.attribute, -ray.dir,
                                    hit.geoNormal, hit.shadingNormal, hit.tangent, true));
        EXPECT_TRUE(sameRgb(stored.evaluate(gen, nullptr, nullptr, nullptr), p.expected * kInvPi));
    }
    Hit none;
    Bsdf b;
    EXPECT_FALSE(scene.setupBsdf(&b, none, Vec3(0, 0, 1), false));
    EXPECT_FALSE(b.isValid());
}

// A material that refers to a texture the scene does not have is a programming error.
TEST(Texture, MaterialWithUnknownTextureThrows) {
    Scene scene;
    Material m;
    m.textures.specular = 0;
    EXPECT_THROW(scene.addMaterial(m), std::logic_error);
}
