// Mitsuba <bsdf> plugins -> unibeam materials (docs/mitsuba.md lists the mapping).
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "core/image.h"
#include "scene/io/mitsuba_build.h"
#include "scene/io/mitsuba_spectra.h"
#include "scene/texture.h"

namespace ub {

namespace {

const std::vector<std::string> kBsdfs = {
    "diffuse",        "conductor", "roughconductor", "dielectric", "roughdielectric",
    "thindielectric", "plastic",   "roughplastic",   "null",       "twosided",
    "normalmap",      "bumpmap",   "blendbsdf",      "mask",       "principled",
    "principledthin"};
const std::vector<std::string> kTextures = {"checkerboard", "bitmap", "mesh_attribute",
                                            "rawconstant"};

constexpr float kAirIor = 1.000277f;        // Mitsuba's default ext_ior ("air")
constexpr float kBk7Ior = 1.5046f;          // Mitsuba's default int_ior ("bk7")
constexpr float kPolypropyleneIor = 1.49f;  // Mitsuba's default int_ior of plastics

}  // namespace

int buildMitsubaTexture(MitsubaBuild& b, const XmlObject& t, ColorUse use) {
    const std::pair<const XmlObject*, ColorUse> key(&t, use);
    auto cached = b.textureIds.find(key);
    if (cached != b.textureIds.end()) return cached->second;
    XmlReader& r = b.r;
    const size_t before = r.errorCount();
    Texture tex;
    tex.name = t.id.empty() ? t.type : t.id;
    if (t.type == "checkerboard") {
        tex.type = TextureType::Checkerboard;
        tex.color0 = r.getColor(t, "color0", Rgb(0.4f), use);
        tex.color1 = r.getColor(t, "color1", Rgb(0.2f), use);
    } else if (t.type == "bitmap") {
        tex.type = TextureType::Bitmap;
        std::string filter = r.getString(t, "filter_type", "bilinear");
        if (filter == "nearest")
            tex.filter = TextureFilter::Nearest;
        else if (filter != "bilinear")
            r.error(t.find("filter_type")->pos,
                    t.label() + ": filter_type '" + filter + "' is not one of bilinear, nearest");
        std::string wrap = r.getString(t, "wrap_mode", "repeat");
        if (wrap == "mirror")
            tex.wrap = TextureWrap::Mirror;
        else if (wrap == "clamp")
            tex.wrap = TextureWrap::Clamp;
        else if (wrap != "repeat")
            r.error(t.find("wrap_mode")->pos,
                    t.label() + ": wrap_mode '" + wrap + "' is not one of repeat, mirror, clamp");
        const bool raw = r.getBool(t, "raw", false);
        // Mitsuba's storage precision of the texels (auto, variant, float16/fp16, uint8): the
        // values a 8- or 16-bit file holds are the same in every format; unibeam keeps floats.
        const std::string format = r.getString(t, "format", "auto");
        if (format != "auto" && format != "variant" && format != "float16" && format != "fp16" &&
            format != "uint8")
            r.error(t.find("format")->pos, t.label() + ": format '" + format +
                                               "' is not one of auto, variant, float16, uint8");
        std::string file = r.getString(t, "filename", "");
        if (file.empty()) {
            r.error(t.pos, t.label() + ": needs <string name=\"filename\">");
        } else if (std::string path = b.resolveFile(t, "filename", file); !path.empty()) {
            if (format == "uint8" && isFloatBitmapFile(path))
                r.error(t.find("format")->pos,
                        t.label() +
                            ": format 'uint8' on a floating-point image (Mitsuba would "
                            "quantise it to 8 bits; unibeam does not)");
            try {
                if (isBitmapFile(path))
                    tex.image = std::make_shared<Image>(readBitmapFile(path, !raw));
                else
                    r.error(t.find("filename")->pos, t.label() + ": '" + file +
                                                         "' is not an image unibeam reads (" +
                                                         kBitmapFormats + ")");
            } catch (const InputError& e) {
                for (const Diagnostic& d : e.diagnostics())
                    r.error(t.find("filename")->pos, t.label() + ": " + d.format());
            }
        }
    } else if (t.type == "rawconstant") {
        // Mitsuba 2's raw constant (not a Mitsuba 3 plugin; corpus scenes of format 2.x use
        // it, e.g. as a normal map): `value`, a float or a 3-vector, used as given, without
        // any colour conversion.
        tex.type = TextureType::Constant;
        const XmlProperty* v = t.find("value");
        if (!v) {
            r.error(t.pos, t.label() + ": needs a <float> or <vector> named \"value\"");
        } else if (v->kind == XmlValueKind::Vector) {
            tex.color0 = r.getVector(t, "value", Vec3(0.0f));
        } else {
            tex.color0 = Rgb(r.getFloat(t, "value", 0.0f));
        }
        if (!std::isfinite(tex.color0.x) || !std::isfinite(tex.color0.y) ||
            !std::isfinite(tex.color0.z))
            r.error(v ? v->pos : t.pos, t.label() + ": value is not finite");
    } else if (t.type == "mesh_attribute") {
        // The shape's attribute `name` (a "vertex_" or "face_" attribute of its PLY file),
        // times `scale`; the shape binds it (Builder::bindMeshAttribute).
        tex.type = TextureType::MeshAttribute;
        tex.attributeName = r.getString(t, "name", "");
        if (tex.attributeName.empty())
            r.error(t.pos, t.label() +
                               ": needs <string name=\"name\"> (the mesh attribute, "
                               "e.g. vertex_color or face_color)");
        else if (tex.attributeName.rfind("vertex_", 0) != 0 &&
                 tex.attributeName.rfind("face_", 0) != 0)
            r.error(t.find("name")->pos, t.label() + ": attribute name '" + tex.attributeName +
                                             "' does not start with vertex_ or face_");
        tex.color0 = Rgb(r.getFloatIn(t, "scale", 1.0f, 0.0f, 1e30f));
        tex.name = "mesh_attribute '" + tex.attributeName + "'";
    } else {
        r.unsupportedPlugin(t, kTextures);
        b.textureIds[key] = -1;
        return -1;
    }
    if (t.find("to_uv")) tex.toUv = UvTransform::fromMatrix4(r.getTransform(t, "to_uv"));
    r.checkUnused(t);
    int id = -1;
    if (r.errorCount() == before) {
        try {
            id = b.scene.addTexture(tex);
        } catch (const InputError& e) {
            for (const Diagnostic& d : e.diagnostics())
                r.error(t.pos, t.label() + ": " + d.message);
        }
    }
    b.textureIds[key] = id;
    return id;
}

namespace {

/// A reflectance given as a colour or as a nested/referenced texture.
void readReflectance(MitsubaBuild& b, const XmlObject& o, const std::string& name, Rgb def,
                     Rgb* value, int* texture) {
    if (const XmlObject* tex = b.r.child(o, "texture", name)) {
        *texture = buildMitsubaTexture(b, *tex);
        return;
    }
    *value = b.r.getColor(o, name, def, ColorUse::Reflectance);
}

/// Mitsuba's float textures through unibeam's RGB ones: the texture's luminance. Mitsuba 3's
/// checkerboard evaluates as a float texture with the opposite parity of its colour
/// evaluation (src/textures/checkerboard.cpp in 3.9.1: eval_1 takes color0 where exactly one
/// of frac(u), frac(v) exceeds 1/2, eval where both or neither do), so a float use sees the
/// colours swapped; measured against Mitsuba on tests/data/mitsuba/blend.xml.
int floatTexture(MitsubaBuild& b, const XmlObject& tex, ColorUse use = ColorUse::Reflectance) {
    int id = buildMitsubaTexture(b, tex, use);
    if (id >= 0 && b.scene.textures[size_t(id)].type == TextureType::Checkerboard) {
        Texture swapped = b.scene.textures[size_t(id)];
        std::swap(swapped.color0, swapped.color1);
        id = b.scene.addTexture(swapped);
    }
    return id;
}

/// A [0, 1] weight given as a float or as a nested/referenced texture (Mitsuba's float
/// textures: unibeam uses the texture's luminance).
void readWeight(MitsubaBuild& b, const XmlObject& o, const std::string& name, float def,
                float* value, int* texture) {
    if (const XmlObject* tex = b.r.child(o, "texture", name)) {
        *texture = floatTexture(b, *tex);
        return;
    }
    *value = b.r.getFloatIn(o, name, def, 0.0f, 1.0f);
}

/// A two-sided copy of material id (a Blend: a blend of two-sided copies of its parts, so
/// that `twosided` around `blendbsdf` or `mask` reaches the lobes); -2 on an error.
int twoSidedCopy(MitsubaBuild& b, int id) {
    Material m = b.scene.materials[size_t(id)];
    if (m.type == MaterialType::Blend)
        for (int& part : m.blendParts) part = twoSidedCopy(b, part);
    m.twoSided = true;
    return b.scene.addMaterial(m);
}

/// Reads a microfacet roughness into m: `alpha`, or `alpha_u` and `alpha_v` (both, as Mitsuba
/// requires), each a float or a texture where `full` (roughconductor, roughdielectric), a float
/// and isotropic otherwise (roughplastic); and the `distribution` (beckmann, Mitsuba's default,
/// or ggx).
void readMicrofacetRoughness(MitsubaBuild& b, const XmlObject& o, Material* m, bool full) {
    XmlReader& r = b.r;
    const XmlProperty* d = o.find("distribution");
    const std::string name = r.getString(o, "distribution", "beckmann");
    if (name == "beckmann") {
        m->distribution = MicrofacetDistribution::kBeckmann;
    } else if (name == "ggx") {
        m->distribution = MicrofacetDistribution::kGgx;
    } else {
        r.error(d ? d->pos : o.pos, o.label() + ": unknown microfacet distribution '" + name +
                                        "' (expected 'beckmann' or 'ggx')");
    }
    r.getBool(o, "sample_visible", true);  // sampling strategy only: same expectation
    // One roughness: a float property or a texture child (full only).
    auto has = [&](const char* n) {
        return o.find(n) != nullptr || r.child(o, "texture", n) != nullptr;
    };
    auto read = [&](const char* n, float* value, int* texture) {
        if (const XmlObject* tex = r.child(o, "texture", n)) {
            if (!full) {
                r.error(tex->pos, o.label() + ": a textured '" + n +
                                      "' is not supported here (Mitsuba's roughplastic takes a "
                                      "float)");
                return;
            }
            *texture = floatTexture(b, *tex);
            return;
        }
        *value = r.getFloatIn(o, n, 0.1f, 0.0f, 1.0f, true);
    };
    if (has("alpha_u") || has("alpha_v")) {
        if (has("alpha")) {
            const XmlProperty* a = o.find("alpha");
            r.error(a ? a->pos : o.pos, o.label() +
                                            ": give either 'alpha' or "
                                            "'alpha_u'/'alpha_v', not both");
        }
        if (!has("alpha_u") || !has("alpha_v")) {
            r.error(o.pos, o.label() + ": give both 'alpha_u' and 'alpha_v' (as Mitsuba requires)");
            return;
        }
        float av = 0.1f;
        read("alpha_u", &m->alpha, &m->textures.alpha);
        read("alpha_v", &av, &m->textures.alphaV);
        if (!full && av != m->alpha) {
            const XmlProperty* p = o.find("alpha_v");
            r.error(p ? p->pos : o.pos,
                    o.label() +
                        ": anisotropic roughness (alpha_u != alpha_v) is not supported "
                        "here (Mitsuba's roughplastic is isotropic)");
        }
        // Equal constants are isotropic; a texture on either side makes it anisotropic.
        if (full && (av != m->alpha || m->textures.alpha >= 0 || m->textures.alphaV >= 0))
            m->alphaV = av;
        return;
    }
    read("alpha", &m->alpha, &m->textures.alpha);
}

/// Mitsuba 3's `principled` (kernels/shared/ub_principled.h) and `principledthin`
/// (ub_principled_thin.h): base_color a colour or texture, roughness and the other weights
/// floats in [0, 1] (diff_trans [0, 2]) or float textures; principled's eta or specular (not
/// both, as Mitsuba), with Mitsuba's nudges of eta = 1 and specular = 0 when spec_trans is
/// given; principledthin's eta (a float, default 1.5); the sampling rates.
void readPrincipled(MitsubaBuild& b, const XmlObject& o, Material* m, bool thin) {
    XmlReader& r = b.r;
    m->type = thin ? MaterialType::PrincipledThin : MaterialType::Principled;
    readReflectance(b, o, "base_color", Rgb(0.5f), &m->diffuse, &m->textures.diffuse);
    if (const XmlObject* tex = r.child(o, "texture", "roughness"))
        m->textures.alpha = floatTexture(b, *tex);
    else
        m->alpha = r.getFloatIn(o, "roughness", 0.5f, 0.0f, 1.0f);
    PrincipledParams& q = m->principled;
    bool texturedSpecTrans = false;
    for (int i = 0; i < PrincipledParams::kWeights; ++i) {
        const std::string name = PrincipledParams::weightName(i);
        const bool thinOnly = name == "diff_trans";
        const bool fullOnly =
            name == "metallic" || name == "clearcoat" || name == "clearcoat_gloss";
        if ((thin && fullOnly) || (!thin && thinOnly)) continue;  // checkUnused reports them
        if (const XmlObject* tex = r.child(o, "texture", name)) {
            // diff_trans reaches 2: not a reflectance (its values are checked where used)
            m->textures.principled[size_t(i)] =
                floatTexture(b, *tex, thinOnly ? ColorUse::Unbounded : ColorUse::Reflectance);
            texturedSpecTrans |= name == "spec_trans";
        } else {
            q.weight(i) = r.getFloatIn(o, name, 0.0f, 0.0f, thinOnly ? 2.0f : 1.0f);
        }
    }
    const float inf = std::numeric_limits<float>::infinity();
    q.rateDiffuse = r.getFloatIn(o, "diffuse_reflectance_sampling_rate", 1.0f, 0.0f, inf);
    if (thin) {
        q.rateSpecular = r.getFloatIn(o, "specular_reflectance_sampling_rate", 1.0f, 0.0f, inf);
        q.rateSpecTrans = r.getFloatIn(o, "specular_transmittance_sampling_rate", 1.0f, 0.0f, inf);
        q.rateDiffTrans = r.getFloatIn(o, "diffuse_transmittance_sampling_rate", 1.0f, 0.0f, inf);
        if (const XmlObject* tex = r.child(o, "texture", "eta"))
            r.error(tex->pos, o.label() + ": a textured 'eta' is not supported (expected a float)");
        m->ior = r.getFloatIn(o, "eta", 1.5f, 0.0f, inf, /*loOpen=*/true);
        m->twoSided = true;  // a sheet, the same from both sides
        if (q.rateDiffuse + q.rateSpecular + q.rateSpecTrans + q.rateDiffTrans <= 0.0f)
            r.error(o.pos, o.label() + ": every sampling rate is zero (nothing can be sampled)");
        return;
    }
    q.rateSpecular = r.getFloatIn(o, "main_specular_sampling_rate", 1.0f, 0.0f, inf);
    q.rateClearcoat = r.getFloatIn(o, "clearcoat_sampling_rate", 1.0f, 0.0f, inf);
    const bool hasSpecTrans = texturedSpecTrans || (r.has(o, "spec_trans") && q.specTrans != 0.0f);
    if (r.has(o, "eta") && r.has(o, "specular")) {
        r.error(o.find("specular")->pos,
                o.label() + ": give either 'eta' or 'specular', not both (as Mitsuba requires)");
    } else if (r.has(o, "eta")) {
        m->ior = r.getFloatIn(o, "eta", 1.5f, 0.0f, inf, /*loOpen=*/true);
        if (hasSpecTrans && m->ior == 1.0f) m->ior = 1.001f;  // Mitsuba: eta 1 cannot refract
    } else {
        float specular = r.getFloatIn(o, "specular", 0.5f, 0.0f, 1.0f);
        if (hasSpecTrans && specular == 0.0f) specular = 1e-3f;  // Mitsuba's nudge
        // Burley 2015: specular 0.5 is eta 1.5 (Mitsuba's mapping)
        m->ior = 2.0f / (1.0f - std::sqrt(0.08f * specular)) - 1.0f;
    }
    if (q.rateDiffuse + q.rateSpecular + q.rateClearcoat <= 0.0f)
        r.error(o.pos, o.label() + ": every sampling rate is zero (nothing can be sampled)");
}

/// Dielectric tints: unibeam has one `specular` tint for reflection and transmission.
Rgb readDielectricTint(XmlReader& r, const XmlObject& o) {
    Rgb sr = r.getColor(o, "specular_reflectance", Rgb(1.0f), ColorUse::Reflectance);
    Rgb st = r.getColor(o, "specular_transmittance", Rgb(1.0f), ColorUse::Reflectance);
    if (sr.x != st.x || sr.y != st.y || sr.z != st.z) {
        const XmlProperty* p = o.find("specular_transmittance");
        r.error(p ? p->pos : o.pos, o.label() +
                                        ": different specular_reflectance and "
                                        "specular_transmittance are not supported "
                                        "(unibeam has one tint for both)");
    }
    return sr;
}

float readRelativeIor(XmlReader& r, const XmlObject& o) {
    float intIor = r.getIor(o, "int_ior", kBk7Ior);
    float extIor = r.getIor(o, "ext_ior", kAirIor);
    if (o.find("eta")) {
        if (o.find("int_ior") || o.find("ext_ior"))
            r.error(o.find("eta")->pos, o.label() + ": give either 'eta' or int_ior/ext_ior");
        return r.getFloatIn(o, "eta", 1.5f, 0.0f, 10.0f, true);
    }
    return intIor / extIor;
}

/// The complex IOR of a conductor: eta and k given, or Mitsuba's `material` preset (default
/// "none": eta 0, k 1, reflectance 1 at every angle, as Mitsuba's roughconductor has it).
/// Returns false for "none" without eta/k (a perfect mirror).
bool readConductorIor(MitsubaBuild& b, const XmlObject& o, Material& m) {
    XmlReader& r = b.r;
    std::string material = r.getString(o, "material", "none");
    if (o.find("eta") || o.find("k")) {
        if (o.find("material"))
            r.error(o.find("material")->pos, o.label() + ": give either 'material' or eta/k");
        m.eta = r.getColor(o, "eta", Rgb(0.0f), ColorUse::Unbounded);
        m.k = r.getColor(o, "k", Rgb(1.0f), ColorUse::Unbounded);
        return true;
    }
    m.eta = Rgb(0.0f);
    m.k = Rgb(1.0f);
    if (material == "none") return false;
    if (!namedConductor(material, &m.eta, &m.k)) {
        std::string names;
        for (const std::string& n : namedConductorNames()) names += (names.empty() ? "" : ", ") + n;
        r.error(o.find("material")->pos, o.label() + ": unknown conductor material '" + material +
                                             "' (expected none or one of " + names + ")");
    }
    return true;
}

/// `normalmap` / `bumpmap`: the nested BSDF's material with its shading normal perturbed by
/// a texture (scene/normal_perturbation.h). Returns false on an error (reported).
bool readPerturbation(MitsubaBuild& b, const XmlObject& o, Material* m) {
    XmlReader& r = b.r;
    const bool normalMap = o.type == "normalmap";
    // The texture: attached as "normalmap", or the only nested texture of a bumpmap.
    const XmlObject* texture = nullptr;
    if (normalMap) {
        texture = r.child(o, "texture", "normalmap");
        if (!texture) {
            r.error(o.pos, o.label() +
                               ": needs a <texture name=\"normalmap\"> (RGB texture of "
                               "tangent-space normals)");
        }
    } else {
        std::vector<const XmlObject*> textures = r.children(o, "texture");
        if (textures.size() != 1)
            r.error(o.pos, o.label() +
                               ": expected exactly one nested <texture> (the height "
                               "field), got " +
                               std::to_string(textures.size()));
        else
            texture = textures[0];
        if (texture && texture->type != "bitmap")
            r.error(texture->pos, o.label() +
                                      ": the height field must be a 'bitmap' texture "
                                      "(a '" +
                                      texture->type + "' has no uv gradient)");
    }
    const float scale = normalMap ? 1.0f : r.getFloat(o, "scale", 1.0f);
    if (!std::isfinite(scale)) r.error(o.find("scale")->pos, o.label() + ": scale is not finite");
    // Mitsuba flips the tangential part of a normal that faces away from the camera-side
    // direction; that rule depends on which direction is the camera's, so unibeam (one f for
    // all algorithms) reads the flag and does not apply it (docs/mitsuba.md).
    r.getBool(o, "flip_invalid_normals", true);
    const bool terminator = r.getBool(o, "use_shadowing_function", true);

    std::vector<const XmlObject*> inner = r.children(o, "bsdf");
    if (inner.size() != 1) {
        r.error(o.pos, o.label() + ": expected exactly one nested <bsdf>, got " +
                           std::to_string(inner.size()));
        return false;
    }
    if (inner[0]->type == "null" || inner[0]->type == "normalmap" || inner[0]->type == "bumpmap") {
        r.error(inner[0]->pos, o.label() + ": cannot wrap a '" + inner[0]->type + "' BSDF");
        return false;
    }
    if (inner[0]->type == "twosided") {
        // twosided(X) is X with twoSided set: look through it for a second perturbation.
        for (const XmlChild& c : inner[0]->children)
            if (c.object && (c.object->type == "normalmap" || c.object->type == "bumpmap")) {
                r.error(c.pos, o.label() + ": cannot wrap a second '" + c.object->type + "'");
                return false;
            }
    }
    const int textureId = texture ? buildMitsubaTexture(b, *texture) : -1;
    const int innerId = buildMitsubaBsdf(b, *inner[0]);
    if (innerId < 0 || textureId < 0) return false;
    if (b.scene.textures[size_t(textureId)].type == TextureType::MeshAttribute) {
        r.error(texture->pos, o.label() + ": a mesh_attribute cannot be its " +
                                  (normalMap ? "normal map" : "height map") +
                                  " (not supported; use a bitmap)");
        return false;
    }
    *m = b.scene.materials[size_t(innerId)];
    m->perturbation = normalMap ? NormalPerturbation::kNormalMap : NormalPerturbation::kBumpMap;
    m->perturbationTexture = textureId;
    m->bumpScale = scale;
    m->shadowTerminator = terminator;
    if (!o.id.empty()) m->name = o.id;
    return true;
}

}  // namespace

int nullPassMaterial(MitsubaBuild& b) {
    if (b.nullPassId >= 0) return b.nullPassId;
    // Mitsuba's null BSDF as a surface: straight transmission of weight 1, no reflection.
    // ThinDielectric with ior 1 is exactly that (reflectance 2r / (1 + r) = 0); its
    // transmission is a null lobe (Bsdf::hasNullLobe), not counted as a vertex by max_depth.
    Material m;
    m.name = "null";
    m.type = MaterialType::ThinDielectric;
    m.ior = 1.0f;
    m.specular = Rgb(0.0f);
    m.transmittance = Rgb(1.0f);
    b.nullPassId = b.scene.addMaterial(m);
    return b.nullPassId;
}

int buildMitsubaBsdf(MitsubaBuild& b, const XmlObject& o) {
    auto cached = b.materialIds.find(&o);
    if (cached != b.materialIds.end()) return cached->second;
    XmlReader& r = b.r;
    const size_t errorsBefore = r.errorCount();
    Material m;
    m.name = o.id.empty() ? o.type : o.id;
    m.twoSided = false;  // Mitsuba's opaque BSDFs are one-sided unless wrapped in `twosided`
    int id = -2;
    if (o.type == "null") {
        r.checkUnused(o);
        b.materialIds[&o] = -1;
        return -1;
    } else if (o.type == "twosided") {
        std::vector<const XmlObject*> inner = r.children(o, "bsdf");
        if (inner.size() != 1) {
            r.error(o.pos, o.label() +
                               ": expected exactly one nested <bsdf> (two different "
                               "sides are not supported), got " +
                               std::to_string(inner.size()));
        } else if (inner[0]->type == "dielectric" || inner[0]->type == "roughdielectric" ||
                   inner[0]->type == "thindielectric" || inner[0]->type == "null" ||
                   inner[0]->type == "twosided" || inner[0]->type == "principledthin") {
            r.error(inner[0]->pos, o.label() + ": cannot wrap a '" + inner[0]->type + "' BSDF");
        } else if (inner[0]->type == "principled" &&
                   (r.child(*inner[0], "texture", "spec_trans") ||
                    (r.has(*inner[0], "spec_trans") &&
                     r.getFloat(*inner[0], "spec_trans", 0.0f) != 0.0f))) {
            r.error(inner[0]->pos, o.label() +
                                       ": cannot wrap a 'principled' BSDF with spec_trans (a "
                                       "transmitting BSDF; Mitsuba refuses it too)");
        } else {
            int innerId = buildMitsubaBsdf(b, *inner[0]);
            if (innerId >= 0) {
                m = b.scene.materials[size_t(innerId)];
                if (m.type == MaterialType::Blend)
                    for (int& part : m.blendParts) part = twoSidedCopy(b, part);
                m.twoSided = true;
                if (!o.id.empty()) m.name = o.id;
            }
        }
    } else if (o.type == "normalmap" || o.type == "bumpmap") {
        readPerturbation(b, o, &m);
    } else if (o.type == "blendbsdf" || o.type == "mask") {
        // Mitsuba 3's blendbsdf: (1 - weight) f_0 + weight f_1 of its two nested BSDFs in
        // document order, weight a float or texture in [0, 1] (default 0.5). Its mask: a
        // blend of a null interface (straight pass-through) and the nested BSDF with weight
        // `opacity` (default 0.5). Both: scene/bsdf.cpp, "Blend".
        const bool mask = o.type == "mask";
        const char* weightName = mask ? "opacity" : "weight";
        m.type = MaterialType::Blend;
        readWeight(b, o, weightName, 0.5f, &m.blendWeight, &m.textures.weight);
        std::vector<const XmlObject*> inner = r.children(o, "bsdf");
        const size_t expected = mask ? 1 : 2;
        if (inner.size() != expected) {
            r.error(o.pos, o.label() + ": expected exactly " + std::to_string(expected) +
                               " nested <bsdf>" + (mask ? "" : "s") + ", got " +
                               std::to_string(inner.size()));
        } else {
            std::vector<int> ids;
            if (mask) ids.push_back(nullPassMaterial(b));
            for (const XmlObject* part : inner) {
                if (part->type == "dielectric" || part->type == "roughdielectric")
                    r.error(part->pos, o.label() + ": cannot hold a '" + part->type +
                                           "' BSDF (a blend of a medium interface; not "
                                           "supported)");
                const int id = buildMitsubaBsdf(b, *part);
                ids.push_back(id == -1 ? nullPassMaterial(b) : id);
            }
            m.blendParts[0] = ids[0];
            m.blendParts[1] = ids[1];
        }
    } else if (o.type == "diffuse") {
        m.type = MaterialType::Diffuse;
        readReflectance(b, o, "reflectance", Rgb(0.5f), &m.diffuse, &m.textures.diffuse);
    } else if (o.type == "conductor") {
        // Mitsuba's smooth conductor: specular_reflectance x F_conductor(cos theta_i, eta + i k);
        // material "none" (the default, no eta/k) is a perfect mirror (F = 1).
        m.type = MaterialType::Mirror;
        m.conductorFresnel = readConductorIor(b, o, m);
        m.specular = r.getColor(o, "specular_reflectance", Rgb(1.0f), ColorUse::Reflectance);
    } else if (o.type == "roughconductor") {
        m.type = MaterialType::RoughConductor;
        readMicrofacetRoughness(b, o, &m, /*full=*/true);
        m.separableMasking = true;  // Mitsuba's MicrofacetDistribution::G = G1(i) G1(o)
        readConductorIor(b, o, m);  // "none" (the default): eta 0, k 1
        m.specular = r.getColor(o, "specular_reflectance", Rgb(1.0f), ColorUse::Reflectance);
    } else if (o.type == "dielectric") {
        m.type = MaterialType::Dielectric;
        m.ior = readRelativeIor(r, o);
        m.specular = readDielectricTint(r, o);
    } else if (o.type == "thindielectric") {
        m.type = MaterialType::ThinDielectric;
        m.ior = readRelativeIor(r, o);
        readReflectance(b, o, "specular_reflectance", Rgb(1.0f), &m.specular, &m.textures.specular);
        readReflectance(b, o, "specular_transmittance", Rgb(1.0f), &m.transmittance,
                        &m.textures.transmittance);
    } else if (o.type == "plastic" || o.type == "roughplastic") {
        const bool rough = o.type == "roughplastic";
        m.type = rough ? MaterialType::RoughPlastic : MaterialType::Plastic;
        float intIor = r.getIor(o, "int_ior", kPolypropyleneIor);
        float extIor = r.getIor(o, "ext_ior", kAirIor);
        m.ior = intIor / extIor;
        if (rough && intIor == extIor)
            r.error(o.pos, o.label() +
                               ": int_ior equals ext_ior (a rough coating needs an "
                               "index mismatch)");
        readReflectance(b, o, "diffuse_reflectance", Rgb(0.5f), &m.diffuse, &m.textures.diffuse);
        readReflectance(b, o, "specular_reflectance", Rgb(1.0f), &m.specular, &m.textures.specular);
        m.nonlinear = r.getBool(o, "nonlinear", false);
        if (rough) readMicrofacetRoughness(b, o, &m, /*full=*/false);
    } else if (o.type == "principled" || o.type == "principledthin") {
        readPrincipled(b, o, &m, o.type == "principledthin");
    } else if (o.type == "roughdielectric") {
        m.type = MaterialType::RoughDielectric;
        m.ior = readRelativeIor(r, o);
        readMicrofacetRoughness(b, o, &m, /*full=*/true);
        m.separableMasking = true;  // Mitsuba's MicrofacetDistribution::G = G1(i) G1(o)
        m.specular = readDielectricTint(r, o);
    } else {
        r.unsupportedPlugin(o, kBsdfs);
        b.materialIds[&o] = -2;
        return -2;
    }
    r.checkUnused(o);
    if (r.errorCount() == errorsBefore) id = b.scene.addMaterial(m);
    b.materialIds[&o] = id;
    return id;
}

}  // namespace ub
