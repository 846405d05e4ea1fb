// Textured colours of the native JSON format (docs/scene-format.md, "Textures"): a
// material colour is an RGB value or a texture object {"type": "checkerboard" | "bitmap",
// ...} whose conventions are those of scene/texture.h (Mitsuba 3's).
#include <filesystem>
#include <memory>

#include "core/file_status.h"
#include "core/image.h"
#include "scene/io/json_scene_parts.h"

namespace ub {

namespace fs = std::filesystem;

namespace {

const std::vector<std::string> kTextureTypes = {"checkerboard", "bitmap"};

/// "to_uv": {"scale": s | [su, sv], "translate": [tu, tv]} (uv' = scale * uv + translate)
/// or {"matrix": 3 rows of 3 numbers (last row [0, 0, 1]) | 4 rows of 4 numbers}.
UvTransform readUvTransform(JsonReader& r, const Json& v, const std::string& ptr) {
    UvTransform t;
    if (!r.isObject(v, ptr, "a uv transform object with \"scale\"/\"translate\" or \"matrix\""))
        return t;
    r.checkKeys(v, ptr, {"scale", "translate", "matrix"}, "uv transform");
    if (const Json* m = r.member(v, ptr, "matrix", Presence::Optional, "")) {
        const std::string mPtr = jsonPointerChild(ptr, "matrix");
        if (v.size() > 1) {
            r.error(mPtr, "\"matrix\" cannot be combined with \"scale\" or \"translate\"");
            return t;
        }
        const size_t n = m->is_array() ? m->size() : 0;
        bool shapeOk = n == 3 || n == 4;
        for (size_t i = 0; shapeOk && i < n; ++i)
            shapeOk = (*m)[i].is_array() && (*m)[i].size() == n;
        if (!shapeOk) {
            r.error(mPtr,
                    "expected a row-major 3x3 matrix (3 rows of 3 numbers) or 4x4 matrix (4 "
                    "rows of 4 numbers), got " +
                        JsonReader::describeValue(*m));
            return t;
        }
        float a[4][4];
        size_t before = r.errorCount();
        for (size_t i = 0; i < n; ++i)
            for (size_t j = 0; j < n; ++j)
                a[i][j] = r.number((*m)[i][j], jsonPointerChild(jsonPointerChild(mPtr, i), j),
                                   NumberRange::any(), 0.0f);
        if (r.errorCount() != before) return t;
        if (n == 3) {
            if (a[2][0] != 0.0f || a[2][1] != 0.0f || a[2][2] != 1.0f) {
                r.error(mPtr, "the last row of a 3x3 uv matrix must be [0, 0, 1] (affine)");
                return t;
            }
            for (int i = 0; i < 2; ++i)
                for (int j = 0; j < 3; ++j) t.m[i][j] = a[i][j];
        } else {
            // Mitsuba keeps rows/columns 0, 1 and the translation column 3.
            Transform full;
            for (int i = 0; i < 4; ++i)
                for (int j = 0; j < 4; ++j) full.m[i][j] = a[i][j];
            t = UvTransform::fromMatrix4(full);
        }
        return t;
    }
    float su = 1.0f, sv = 1.0f;
    if (const Json* s = r.member(v, ptr, "scale", Presence::Optional, "")) {
        const std::string sPtr = jsonPointerChild(ptr, "scale");
        if (s->is_number()) {
            su = sv = r.number(*s, sPtr, NumberRange::any(), 1.0f);
        } else if (s->is_array() && s->size() == 2) {
            su = r.number((*s)[0], jsonPointerChild(sPtr, 0), NumberRange::any(), 1.0f);
            sv = r.number((*s)[1], jsonPointerChild(sPtr, 1), NumberRange::any(), 1.0f);
        } else {
            r.error(sPtr, "expected a scale factor (one number or [su, sv]), got " +
                              JsonReader::describeValue(*s));
        }
    }
    t = UvTransform::scale(su, sv);
    if (const Json* tr = r.member(v, ptr, "translate", Presence::Optional, "")) {
        const std::string tPtr = jsonPointerChild(ptr, "translate");
        if (tr->is_array() && tr->size() == 2) {
            t.m[0][2] = r.number((*tr)[0], jsonPointerChild(tPtr, 0), NumberRange::any(), 0.0f);
            t.m[1][2] = r.number((*tr)[1], jsonPointerChild(tPtr, 1), NumberRange::any(), 0.0f);
        } else {
            r.error(tPtr,
                    "expected a uv translation [tu, tv], got " + JsonReader::describeValue(*tr));
        }
    }
    return t;
}

/// Loads the image of a bitmap texture (cached per resolved path and `raw`).
std::shared_ptr<const Image> loadBitmap(JsonReader& r, const std::string& file, bool raw,
                                        const std::string& filePtr, JsonSceneParts& parts) {
    const std::string path = resolveScenePath(parts.baseDir, file);
    if (!isBitmapFile(file)) {
        r.error(filePtr, "unsupported bitmap file '" + file + "' (expected " + kBitmapFormats +
                             "; EXR and RGBE are linear, the others sRGB unless raw)");
        return nullptr;
    }
    if (!isRegularFile(path)) {
        r.error(filePtr, "bitmap '" + file + "' not found (looked for '" + path +
                             "'; paths are relative to the scene file)");
        return nullptr;
    }
    const std::string key = path + (raw ? "|raw" : "");
    auto it = parts.bitmapCache.find(key);
    if (it != parts.bitmapCache.end()) return it->second;
    try {
        auto img = std::make_shared<const Image>(readBitmapFile(path, !raw));
        parts.bitmapCache[key] = img;
        return img;
    } catch (const InputError& e) {
        for (const Diagnostic& d : e.diagnostics())
            r.error(filePtr, "cannot read bitmap '" + file + "': " + d.message);
    }
    return nullptr;
}

/// Reads a texture object; returns false after reporting errors.
bool readTexture(JsonReader& r, const Json& v, const std::string& ptr, const NumberRange& range,
                 JsonSceneParts& parts, Texture* tex) {
    const Json* typeJson = r.member(v, ptr, "type", Presence::Required,
                                    "a texture type: one of " + joinNames(kTextureTypes));
    if (!typeJson) return false;
    const std::string typePtr = jsonPointerChild(ptr, "type");
    const std::string type = r.string(*typeJson, typePtr);
    if (type.empty()) return false;
    const size_t before = r.errorCount();
    tex->name = type + " at " + ptr;
    if (type == "checkerboard") {
        tex->type = TextureType::Checkerboard;
        r.checkKeys(v, ptr, {"type", "color0", "color1", "to_uv"}, "checkerboard texture");
        tex->color0 = r.getRgb(v, ptr, "color0", Presence::Optional, range, Rgb(0.4f));
        tex->color1 = r.getRgb(v, ptr, "color1", Presence::Optional, range, Rgb(0.2f));
    } else if (type == "bitmap") {
        tex->type = TextureType::Bitmap;
        r.checkKeys(v, ptr, {"type", "file", "raw", "to_uv"}, "bitmap texture");
        const bool raw = r.getBool(v, ptr, "raw", false);
        const std::string file = r.getString(v, ptr, "file", Presence::Required);
        const std::string filePtr = jsonPointerChild(ptr, "file");
        if (!file.empty()) {
            tex->name = file;
            tex->image = loadBitmap(r, file, raw, filePtr, parts);
            if (tex->image) {
                // Every pixel must lie in the parameter's range (e.g. an albedo <= 1).
                for (int y = 0; y < tex->image->height; ++y)
                    for (int x = 0; x < tex->image->width; ++x) {
                        const Rgb& p = tex->image->at(x, y);
                        if (!range.contains(minComponent(p)) || !range.contains(maxComponent(p))) {
                            r.error(filePtr, "bitmap '" + file + "' pixel (" + std::to_string(x) +
                                                 ", " + std::to_string(y) + ") = [" +
                                                 formatNumber(p.x) + ", " + formatNumber(p.y) +
                                                 ", " + formatNumber(p.z) + "] is not " +
                                                 range.describe());
                            x = tex->image->width;
                            y = tex->image->height;
                        }
                    }
            }
        }
    } else {
        r.error(typePtr, "unknown texture type '" + type + "'" + didYouMean(type, kTextureTypes) +
                             "; valid types: " + joinNames(kTextureTypes) +
                             " (or give an RGB colour)");
        return false;
    }
    if (const Json* uv = r.member(v, ptr, "to_uv", Presence::Optional, ""))
        tex->toUv = readUvTransform(r, *uv, jsonPointerChild(ptr, "to_uv"));
    return r.errorCount() == before;
}

}  // namespace

int readJsonTexturedRgb(JsonReader& r, const Json& obj, const std::string& objPtr,
                        const std::string& key, const NumberRange& range, const Rgb& fallback,
                        JsonSceneParts& parts, Rgb* value) {
    *value = fallback;
    const Json* v = r.member(obj, objPtr, key, Presence::Optional, "");
    if (!v) return -1;
    const std::string ptr = jsonPointerChild(objPtr, key);
    if (v->is_number() || v->is_array()) {
        *value = r.rgb(*v, ptr, range, fallback);
        return -1;
    }
    if (!v->is_object()) {
        r.error(ptr, "expected an RGB colour (one number or [r, g, b], each " + range.describe() +
                         ") or a texture object {\"type\": \"checkerboard\" or \"bitmap\", "
                         "...}, got " +
                         JsonReader::describeValue(*v));
        return -1;
    }
    Texture tex;
    if (!readTexture(r, *v, ptr, range, parts, &tex)) return -1;
    *value = tex.mean();  // the constant stays meaningful (e.g. for summaries)
    parts.textures.push_back(std::move(tex));
    return int(parts.textures.size()) - 1;
}

}  // namespace ub
