// Image error metrics (core/image_metrics.h): values computed by hand on small images,
// non-finite pixels, size mismatch, and the false-colour picture's size, scale and bar.
#include "core/image_metrics.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace ub;

TEST(ImageMetrics, ValuesByHand) {
    Image ref(2, 1), img(2, 1);
    ref.pixels[0] = Rgb(1.0f, 0.0f, 2.0f);
    ref.pixels[1] = Rgb(0.5f, 0.0f, 2.0f);
    img.pixels[0] = Rgb(2.0f, 0.1f, 2.0f);   // errors 1, 0.1, 0
    img.pixels[1] = Rgb(0.5f, -0.1f, 1.0f);  // errors 0, -0.1, -1
    const ImageError e = imageError(img, ref);
    EXPECT_NEAR(e.rmse[0], std::sqrt(0.5), 1e-12);
    EXPECT_NEAR(e.rmse[1], 0.1, 1e-7);
    EXPECT_NEAR(e.rmse[2], std::sqrt(0.5), 1e-12);
    EXPECT_NEAR(e.mae[0], 0.5, 1e-12);
    EXPECT_NEAR(e.mae[1], 0.1, 1e-7);
    EXPECT_NEAR(e.relMse[0], 0.5 * (1.0 / (1.0 + 1e-2)), 1e-9);
    EXPECT_NEAR(e.relMse[1], 0.01 / 1e-2, 1e-5);  // black reference: eps keeps it finite
    EXPECT_NEAR(e.relMse[2], 0.5 * (1.0 / (4.0 + 1e-2)), 1e-9);
    EXPECT_NEAR(e.rmseAll, std::sqrt((1.0 + 0.02 + 1.0) / 6.0), 1e-7);
    EXPECT_NEAR(e.maeAll, 2.2 / 6.0, 1e-7);
    EXPECT_DOUBLE_EQ(e.overall("relmse"), e.relMseAll);
    EXPECT_THROW(e.overall("psnr"), std::invalid_argument);
    // Identical images: zero.
    const ImageError z = imageError(ref, ref);
    EXPECT_EQ(z.rmseAll, 0.0);
    EXPECT_EQ(z.relMseAll, 0.0);
}

TEST(ImageMetrics, NonFiniteIsInfiniteErrorAndSizesMustMatch) {
    Image ref(1, 1), img(1, 1);
    img.pixels[0] = Rgb(NAN, 0.0f, 0.0f);
    EXPECT_TRUE(std::isinf(imageError(img, ref).rmseAll));
    EXPECT_THROW(imageError(Image(2, 2), Image(2, 3)), std::invalid_argument);
}

TEST(ImageMetrics, FalseColourHasBarAndScale) {
    Image ref(64, 32), img(64, 32);
    for (Rgb& p : ref.pixels) p = Rgb(1.0f);
    img = ref;
    img.at(10, 10) = Rgb(2.0f);  // relative error 1 / 1.01
    float used = 0;
    const Image fc = falseColourError(img, ref, 0.0f, &used);
    EXPECT_EQ(fc.width, 64);
    EXPECT_GT(fc.height, 32);  // the bar and its labels below
    // The 99th percentile of the errors is 0 here: the floor 1e-6 is the scale's top.
    EXPECT_FLOAT_EQ(used, 1e-6f);
    EXPECT_EQ(fc.at(0, 0)[0], 0.0f);    // no error: black
    EXPECT_GT(fc.at(10, 10)[0], 0.9f);  // saturated: white
    const Image fixed = falseColourError(img, ref, 2.0f / 1.01f, &used);
    EXPECT_FLOAT_EQ(used, 2.0f / 1.01f);
    // Halfway up the scale: the red stop (sRGB 0.85, 0.15, 0.2).
    EXPECT_NEAR(fixed.at(10, 10)[0], srgbToLinear(0.85f), 1e-3f);
    // The bar runs from black at the left to white at the right.
    const int barY = 32 + 2;
    EXPECT_LT(fc.at(0, barY)[0] + fc.at(0, barY)[1], 0.05f);
    EXPECT_GT(fc.at(63, barY)[1], 0.9f);
}
