// RGB textures as flat data with a type tag, looked up at a hit's uv (Scene::setupBsdf).
// They follow Mitsuba 3's `checkerboard` and `bitmap` plugins so that scenes render the
// same in both:
//
//  * uv transform (`to_uv`): uv' = A (u, v, 1), a 2D affine map stored as the top two
//    rows of a 3x3 matrix. From a 4x4 matrix Mitsuba keeps rows/columns 0, 1 and the
//    translation column 3 (UvTransform::fromMatrix4).
//  * Checkerboard: f = frac(uv'); colour0 where (f.u > 1/2) == (f.v > 1/2), else
//    colour1, so uv' = (0, 0) is colour0 and the pattern has period 1 in u and v
//    (two squares per unit). Mitsuba's defaults: colour0 = 0.4, colour1 = 0.2.
//  * Bitmap: linear RGB pixels, row 0 (the top of the image file) at v' = 0, column 0 at
//    u' = 0; pixel (x, y) is centred at ((x + 1/2) / W, (y + 1/2) / H). Bilinear
//    interpolation between the four nearest pixel centres (or the nearest pixel), wrap mode
//    "repeat" (uv' taken modulo 1 first), "mirror" or "clamp" (on pixel indices, as
//    Mitsuba 3's bitmap does). PNG files are sRGB-decoded at load (each texel, before
//    interpolation, as Mitsuba does for `raw = false`); EXR files are used as stored.
//    Scene loaders follow Mitsuba's convention for mesh texture coordinates: OBJ files get
//    v = 1 - t (the file's t = 0 is the bottom row of the image; Mitsuba's
//    `flip_tex_coords`, default true for OBJ), PLY files are used as stored (default false).
//    mesh_io itself returns the file's values.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "core/image.h"
#include "core/vec.h"

namespace ub {

/// Bitmap lookups (Mitsuba's `filter_type`): bilinear between the four nearest pixel centres,
/// or the pixel containing uv'.
enum class TextureFilter : uint8_t { Bilinear, Nearest };
/// Bitmap wrap modes (Mitsuba's `wrap_mode`), applied to pixel indices: repeat (index modulo
/// the size), mirror (period twice the size, the second copy reversed), clamp (to the edge).
enum class TextureWrap : uint8_t { Repeat, Mirror, Clamp };

enum class TextureType : uint32_t {
    Constant = 0,      ///< color0 everywhere
    Checkerboard = 1,  ///< color0 / color1 squares
    Bitmap = 2,        ///< image, bilinear, repeat
    /// Mitsuba 3's `mesh_attribute`: the hit's mesh attribute value (Hit::attribute) times
    /// color0 (Mitsuba's `scale`); the attribute is attributeName. No uv lookup.
    MeshAttribute = 3,
};

/// uv' = (m[0][0] u + m[0][1] v + m[0][2], m[1][0] u + m[1][1] v + m[1][2]).
struct UvTransform {
    float m[2][3] = {{1, 0, 0}, {0, 1, 0}};
    Vec2 apply(const Vec2& uv) const {
        return {m[0][0] * uv.x + m[0][1] * uv.y + m[0][2],
                m[1][0] * uv.x + m[1][1] * uv.y + m[1][2]};
    }
    /// Mitsuba's reduction of a 4x4 transform to a 2D one: rows and columns 0 and 1 and
    /// the translation column 3 (the z row and column are dropped).
    static UvTransform fromMatrix4(const Transform& t);
    static UvTransform scale(float su, float sv) {
        UvTransform r;
        r.m[0][0] = su;
        r.m[1][1] = sv;
        return r;
    }
};

struct Texture {
    TextureType type = TextureType::Constant;
    std::string name;                    ///< for messages (e.g. the file of a bitmap)
    Rgb color0{0.4f, 0.4f, 0.4f};        ///< Constant value; Checkerboard colour at uv' = (0, 0)
    Rgb color1{0.2f, 0.2f, 0.2f};        ///< Checkerboard's other colour
    UvTransform toUv;                    ///< Checkerboard, Bitmap
    std::shared_ptr<const Image> image;  ///< Bitmap: linear RGB, row 0 at v' = 0
    TextureFilter filter = TextureFilter::Bilinear;  ///< Bitmap
    TextureWrap wrap = TextureWrap::Repeat;          ///< Bitmap
    std::string attributeName;  ///< MeshAttribute: "vertex_color", "face_weight", ...

    /// Value at the surface uv (before toUv). Non-finite uv gives black.
    Rgb eval(const Vec2& uv) const;
    /// Value at a surface point with uv and mesh attribute value `attribute`: a
    /// MeshAttribute texture gives color0 * attribute, the others eval(uv).
    Rgb eval(const Vec2& uv, const Rgb& attribute) const {
        return type == TextureType::MeshAttribute ? color0 * attribute : eval(uv);
    }
    /// Gradient d/d(u, v) of the luminance of eval() (Rec. 709 weights, luminance()) at the
    /// surface uv, as Mitsuba 3's `eval_1_grad`: a bilinear bitmap differentiates its
    /// interpolation in the cell of uv' (pixel-space slopes, times the transpose of toUv's
    /// linear part, then per component times the resolution W, H); nearest lookups and
    /// constants give 0. Checkerboards have no gradient (the loader refuses them; 0 here).
    Vec2 luminanceGradient(const Vec2& uv) const;
    /// Average over the texture's domain (Checkerboard: (color0 + color1) / 2; Bitmap:
    /// the pixel mean).
    Rgb mean() const;
    /// Throws InputError (file "", where "texture '<name>'") for a bitmap without pixels,
    /// non-finite or negative colours/pixels, or a non-finite uv transform.
    void validate() const;
};

}  // namespace ub
