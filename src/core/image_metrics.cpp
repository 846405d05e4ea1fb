// Image error metrics and the false-colour error picture (see image_metrics.h).
#include "core/image_metrics.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

namespace ub {

double ImageError::overall(const std::string& metric) const {
    if (metric == "rmse") return rmseAll;
    if (metric == "relmse") return relMseAll;
    if (metric == "mae") return maeAll;
    throw std::invalid_argument("unknown metric '" + metric + "' (valid: rmse, relmse, mae)");
}

ImageError imageError(const Image& image, const Image& reference) {
    if (image.width != reference.width || image.height != reference.height)
        throw std::invalid_argument("images differ in size: " + std::to_string(image.width) + "x" +
                                    std::to_string(image.height) + " against " +
                                    std::to_string(reference.width) + "x" +
                                    std::to_string(reference.height));
    ImageError e;
    double se[3] = {0, 0, 0}, rel[3] = {0, 0, 0}, ae[3] = {0, 0, 0};
    for (size_t i = 0; i < image.pixels.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            const double a = image.pixels[i][c], r = reference.pixels[i][c];
            const double d = std::isfinite(a) ? a - r : HUGE_VAL;
            se[c] += d * d;
            rel[c] += d * d / (r * r + kRelMseEpsilon);
            ae[c] += std::fabs(d);
        }
    const double n = std::max<double>(1.0, double(image.pixels.size()));
    for (int c = 0; c < 3; ++c) {
        e.rmse[c] = std::sqrt(se[c] / n);
        e.relMse[c] = rel[c] / n;
        e.mae[c] = ae[c] / n;
    }
    e.rmseAll = std::sqrt((se[0] + se[1] + se[2]) / (3 * n));
    e.relMseAll = (rel[0] + rel[1] + rel[2]) / (3 * n);
    e.maeAll = (ae[0] + ae[1] + ae[2]) / (3 * n);
    return e;
}

std::string describeImageError(const ImageError& e) {
    std::string out;
    char line[200];
    const char* names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c) {
        std::snprintf(line, sizeof(line), "%-7s RMSE %.6g  relMSE %.6g  MAE %.6g\n", names[c],
                      e.rmse[c], e.relMse[c], e.mae[c]);
        out += line;
    }
    std::snprintf(line, sizeof(line), "%-7s RMSE %.6g  relMSE %.6g  MAE %.6g", "overall", e.rmseAll,
                  e.relMseAll, e.maeAll);
    return out + line;
}

namespace {

/// The colour scale: sRGB stops at 0, 0.25, 0.5, 0.75, 1 (black, purple, red, yellow,
/// white), linear between them; returned linear so that writePng shows these sRGB values.
Rgb scaleColour(float t) {
    static const float stops[5][3] = {{0.0f, 0.0f, 0.0f},
                                      {0.35f, 0.05f, 0.55f},
                                      {0.85f, 0.15f, 0.2f},
                                      {1.0f, 0.8f, 0.1f},
                                      {1.0f, 1.0f, 1.0f}};
    t = std::min(1.0f, std::max(0.0f, std::isfinite(t) ? t : 1.0f)) * 4.0f;
    const int k = std::min(3, int(t));
    const float f = t - float(k);
    Rgb out;
    for (int c = 0; c < 3; ++c)
        out[c] = srgbToLinear(stops[k][c] * (1.0f - f) + stops[k + 1][c] * f);
    return out;
}

/// 3x5 glyphs of the characters a scale label needs (bit 2 = left column).
const char* glyph(char ch) {
    switch (ch) {
        case '0':
            return "\7\5\5\5\7";
        case '1':
            return "\2\6\2\2\7";
        case '2':
            return "\7\1\7\4\7";
        case '3':
            return "\7\1\7\1\7";
        case '4':
            return "\5\5\7\1\1";
        case '5':
            return "\7\4\7\1\7";
        case '6':
            return "\7\4\7\5\7";
        case '7':
            return "\7\1\1\1\1";
        case '8':
            return "\7\5\7\5\7";
        case '9':
            return "\7\5\7\1\7";
        case '.':
            return "\0\0\0\0\2";
        case '-':
            return "\0\0\7\0\0";
        case '+':
            return "\0\2\7\2\0";
        case 'e':
            return "\0\7\7\4\7";
        default:
            return "\0\0\0\0\0";
    }
}

/// Draws text with its top-left corner at (x, y), each glyph pixel a scale x scale square.
void drawText(Image& img, int x, int y, const std::string& text, int scale, const Rgb& colour) {
    for (char ch : text) {
        const char* g = glyph(ch);
        for (int row = 0; row < 5; ++row)
            for (int col = 0; col < 3; ++col) {
                if (!((g[row] >> (2 - col)) & 1)) continue;
                for (int dy = 0; dy < scale; ++dy)
                    for (int dx = 0; dx < scale; ++dx) {
                        const int px = x + col * scale + dx, py = y + row * scale + dy;
                        if (px >= 0 && py >= 0 && px < img.width && py < img.height)
                            img.at(px, py) = colour;
                    }
            }
        x += 4 * scale;
    }
}

}  // namespace

Image falseColourError(const Image& image, const Image& reference, float maxError, float* usedMax) {
    if (image.width != reference.width || image.height != reference.height)
        throw std::invalid_argument("images differ in size");
    const int w = image.width, h = image.height;
    std::vector<float> err(image.pixels.size());
    for (size_t i = 0; i < err.size(); ++i) {
        float sum = 0;
        for (int c = 0; c < 3; ++c)
            sum += std::fabs(image.pixels[i][c] - reference.pixels[i][c]) /
                   (reference.pixels[i][c] + 0.01f);
        err[i] = std::isfinite(sum) ? sum / 3.0f : HUGE_VALF;
    }
    if (!(maxError > 0.0f)) {
        std::vector<float> sorted = err;
        const size_t k = sorted.empty() ? 0 : std::min(sorted.size() - 1, sorted.size() * 99 / 100);
        if (!sorted.empty()) std::nth_element(sorted.begin(), sorted.begin() + k, sorted.end());
        maxError = sorted.empty() ? 1.0f : sorted[k];
        if (!(maxError >= 1e-6f) || !std::isfinite(maxError)) maxError = 1e-6f;
    }
    if (usedMax) *usedMax = maxError;
    // The bar: a strip of the scale, then the end values in glyphs scaled to the width.
    const int scale = std::max(1, std::min(4, w / 64));
    const int barH = 6 * scale, textH = 7 * scale;
    Image out(w, h + barH + textH + 2 * scale);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) out.at(x, y) = scaleColour(err[size_t(y) * w + x] / maxError);
    for (int y = h + scale; y < h + scale + barH; ++y)
        for (int x = 0; x < w; ++x) out.at(x, y) = scaleColour((x + 0.5f) / float(w));
    char hi[32];
    std::snprintf(hi, sizeof(hi), "%.2g", double(maxError));
    const Rgb white(1.0f);
    const int ty = h + 2 * scale + barH;
    drawText(out, scale, ty, "0", scale, white);
    drawText(out, w - int(std::string(hi).size()) * 4 * scale, ty, hi, scale, white);
    return out;
}

}  // namespace ub
