// "materials" of the native JSON scene format (docs/scene-format.md):
// an object mapping names to materials with a "type" tag.
#include <algorithm>

#include "scene/io/json_scene_parts.h"

namespace ub {

namespace {

/// Optional "masking" of the rough GGX materials: "height_correlated" (default) or
/// "separable" (Mitsuba 3's G1(i) G1(o)); see Material::separableMasking.
bool readMasking(JsonReader& r, const Json& m, const std::string& ptr) {
    const std::string v = r.getString(m, ptr, "masking", Presence::Optional);
    if (v.empty() || v == "height_correlated") return false;
    if (v == "separable") return true;
    r.error(jsonPointerChild(ptr, "masking"),
            "unknown masking '" + v + "' (expected \"height_correlated\" or \"separable\")");
    return false;
}

/// Optional "distribution" of the rough materials: "ggx" (default) or "beckmann".
MicrofacetDistribution readDistribution(JsonReader& r, const Json& m, const std::string& ptr) {
    const std::string v = r.getString(m, ptr, "distribution", Presence::Optional);
    if (v.empty() || v == "ggx") return MicrofacetDistribution::kGgx;
    if (v == "beckmann") return MicrofacetDistribution::kBeckmann;
    r.error(jsonPointerChild(ptr, "distribution"),
            "unknown microfacet distribution '" + v + "' (expected \"ggx\" or \"beckmann\")");
    return MicrofacetDistribution::kGgx;
}

/// Named metals for rough_conductor "metal": complex IOR n + ik sampled at
/// 650 nm (R), 550 nm (G) and 450 nm (B) from measured tables (refractiveindex.info).
/// The same numbers are listed in docs/scene-format.md.
struct MetalPreset {
    const char* name;
    Rgb eta, k;
};
const MetalPreset kMetals[] = {
    {"gold", {0.1830f, 0.4211f, 1.3734f}, {3.4242f, 2.3459f, 1.7704f}},
    {"copper", {0.2711f, 0.6769f, 1.3164f}, {3.6092f, 2.6248f, 2.2921f}},
    {"silver", {0.1626f, 0.1451f, 0.1355f}, {4.0728f, 3.1900f, 2.1997f}},
    {"aluminium", {1.5196f, 0.9657f, 0.5312f}, {7.6635f, 6.4581f, 5.0699f}},
};

const std::vector<std::string> kMaterialTypes = {
    "diffuse",          "phong",          "mirror",        "dielectric",      "rough_conductor",
    "rough_dielectric", "plastic",        "rough_plastic", "thin_dielectric", "multi_lobe",
    "principled",       "principled_thin"};

/// Mitsuba 3's default IORs: polypropylene (plastics), BK7 glass (thin_dielectric), air.
constexpr float kPolypropyleneIor = 1.49f, kBk7Ior = 1.5046f, kAirIor = 1.000277f;

/// Per-channel maximum of a texture's values (for energy checks of sums of colours).
Rgb textureMax(const Texture& t) {
    switch (t.type) {
        case TextureType::Constant:
            return t.color0;
        case TextureType::Checkerboard:
            return vmax(t.color0, t.color1);
        case TextureType::Bitmap: {
            Rgb m(0.0f);
            if (t.image)
                for (const Rgb& p : t.image->pixels) m = vmax(m, p);
            return m;
        }
        case TextureType::MeshAttribute:  // not made by the JSON loader; no bound known
            return Rgb(kInf);
    }
    return Rgb(0.0f);
}

std::vector<std::string> metalNames() {
    std::vector<std::string> names;
    for (const auto& m : kMetals) names.push_back(m.name);
    return names;
}

/// The complex IOR of a conductor: "metal" (a preset of kMetals) or both "eta" and "k".
/// Without them: an error when `required`, else false (and mat is unchanged).
bool readConductorIor(JsonReader& r, const Json& m, const std::string& ptr, Material& mat,
                      bool required) {
    const Json* metal = r.member(m, ptr, "metal", Presence::Optional, "");
    bool hasEta = m.contains("eta"), hasK = m.contains("k");
    if (metal) {
        std::string metalPtr = jsonPointerChild(ptr, "metal");
        if (hasEta || hasK) {
            r.error(metalPtr, "give either \"metal\" or both \"eta\" and \"k\", not both");
        }
        std::string name = r.string(*metal, metalPtr);
        if (name == "aluminum") name = "aluminium";
        auto it = std::find_if(std::begin(kMetals), std::end(kMetals),
                               [&](const MetalPreset& p) { return name == p.name; });
        if (it != std::end(kMetals)) {
            mat.eta = it->eta;
            mat.k = it->k;
        } else if (!name.empty()) {
            r.error(metalPtr, "unknown metal '" + name + "'" + didYouMean(name, metalNames()) +
                                  "; valid metals: " + joinNames(metalNames()));
        }
    } else if (hasEta || hasK) {
        mat.eta = r.getRgb(m, ptr, "eta", Presence::Required, NumberRange::positive(), mat.eta);
        mat.k = r.getRgb(m, ptr, "k", Presence::Required, NumberRange::nonNegative(), mat.k);
    } else if (required) {
        r.error(ptr, "a rough_conductor needs \"metal\" (one of " + joinNames(metalNames()) +
                         ") or both \"eta\" and \"k\" (RGB)");
    }
    return metal || hasEta || hasK;
}

/// Reflectances are albedos: a component above 1 would create energy.
const NumberRange kReflectance = NumberRange::closed(0.0, 1.0);

const char* kChannel[3] = {"red", "green", "blue"};

void readMaterial(JsonReader& r, const Json& m, const std::string& ptr, Material& mat,
                  JsonSceneParts& parts) {
    // A colour that may be a texture: fills the constant and the texture index.
    auto colour = [&](const std::string& key, const Rgb& fallback, Rgb* value, int* texture) {
        *texture = readJsonTexturedRgb(r, m, ptr, key, kReflectance, fallback, parts, value);
    };
    // A microfacet roughness (rough_conductor, rough_dielectric): a number in (0, 1], or a
    // texture whose value at the hit's uv (the luminance of an RGB texture, each value in
    // [0, 1]) is the roughness there, clamped below at 1e-4 (scene/scene_textures.cpp).
    auto roughness = [&](const std::string& key, Presence presence, float fallback, float* value,
                         int* texture) {
        const Json* v = r.member(m, ptr, key, Presence::Optional, "");
        if (v && v->is_object()) {
            Rgb mean;
            *texture =
                readJsonTexturedRgb(r, m, ptr, key, kReflectance, Rgb(fallback), parts, &mean);
            *value = luminance(mean);
        } else {
            *value = r.getNumber(m, ptr, key, presence, NumberRange::leftOpen(0.0, 1.0), fallback);
        }
    };
    if (!r.isObject(m, ptr, "a material object with a \"type\" key")) return;
    const Json* typeJson = r.member(m, ptr, "type", Presence::Required,
                                    "a material type: one of " + joinNames(kMaterialTypes));
    if (!typeJson) return;
    std::string typePtr = jsonPointerChild(ptr, "type");
    std::string type = r.string(*typeJson, typePtr);
    if (type.empty()) return;

    std::vector<std::string> keys = {"type"};
    if (type == "diffuse") {
        mat.type = MaterialType::Diffuse;
        keys.insert(keys.end(), {"reflectance", "two_sided"});
        r.checkKeys(m, ptr, keys, "diffuse material");
        colour("reflectance", Rgb(0.5f), &mat.diffuse, &mat.textures.diffuse);
    } else if (type == "phong") {
        mat.type = MaterialType::Phong;
        keys.insert(keys.end(),
                    {"diffuse_reflectance", "glossy_reflectance", "exponent", "two_sided"});
        r.checkKeys(m, ptr, keys, "phong material");
        colour("diffuse_reflectance", Rgb(0.0f), &mat.diffuse, &mat.textures.diffuse);
        colour("glossy_reflectance", Rgb(0.0f), &mat.glossy, &mat.textures.glossy);
        // Textured colours are checked with their per-channel maxima.
        const Rgb maxDiffuse = mat.textures.diffuse >= 0
                                   ? textureMax(parts.textures[size_t(mat.textures.diffuse)])
                                   : mat.diffuse;
        const Rgb maxGlossy = mat.textures.glossy >= 0
                                  ? textureMax(parts.textures[size_t(mat.textures.glossy)])
                                  : mat.glossy;
        mat.exponent =
            r.getNumber(m, ptr, "exponent", Presence::Required, NumberRange::positive(), 1.0f);
        // The modified Phong lobe is normalized ((n+2)/(2 pi) cos^n, Lafortune & Willems
        // 1994), so its albedo is at most glossy_reflectance; the sum with the Lambertian
        // part must stay <= 1 per channel to conserve energy.
        for (int c = 0; c < 3; ++c) {
            float sum = maxDiffuse[c] + maxGlossy[c];
            if (sum > 1.0f) {
                r.error(ptr, "diffuse_reflectance + glossy_reflectance = " + formatNumber(sum) +
                                 " > 1 in the " + kChannel[c] +
                                 " channel: the material would create energy (expected a sum "
                                 "<= 1)");
                break;
            }
        }
    } else if (type == "multi_lobe") {
        // SmallUPBP's sum of lobes (scene/bsdf.cpp): Lambert + Phong + mirror (+ refraction).
        mat.type = MaterialType::MultiLobe;
        keys.insert(keys.end(), {"diffuse_reflectance", "glossy_reflectance", "exponent",
                                 "mirror_reflectance", "ior", "two_sided", "allow_energy_gain"});
        r.checkKeys(m, ptr, keys, "multi_lobe material");
        colour("diffuse_reflectance", Rgb(0.0f), &mat.diffuse, &mat.textures.diffuse);
        colour("glossy_reflectance", Rgb(0.0f), &mat.glossy, &mat.textures.glossy);
        colour("mirror_reflectance", Rgb(0.0f), &mat.specular, &mat.textures.specular);
        mat.exponent =
            r.getNumber(m, ptr, "exponent", Presence::Optional, NumberRange::positive(), 1.0f);
        mat.refract = m.contains("ior");
        if (mat.refract) {
            mat.ior = r.getNumber(m, ptr, "ior", Presence::Required, NumberRange::positive(), 1.5f);
            mat.twoSided = false;  // the normal tells inside from outside
        }
        // The lobes add: their albedos may sum above 1 (SmallUPBP allows it, e.g. its candle
        // wax: Kd 0.588 plus index-matched refraction). That is an error unless asked for.
        auto maxOf = [&](int texture, const Rgb& value) {
            return texture >= 0 ? textureMax(parts.textures[size_t(texture)]) : value;
        };
        const Rgb sum = maxOf(mat.textures.diffuse, mat.diffuse) +
                        maxOf(mat.textures.glossy, mat.glossy) +
                        (mat.refract ? Rgb(1.0f) : maxOf(mat.textures.specular, mat.specular));
        const bool allowGain = r.getBool(m, ptr, "allow_energy_gain", false);
        for (int c = 0; c < 3 && !allowGain; ++c)
            if (sum[c] > 1.0f + 1e-6f) {
                r.error(ptr, std::string("the lobes add up to an albedo of ") +
                                 formatNumber(sum[c]) + " in the " + kChannel[c] +
                                 " channel (diffuse + glossy + " +
                                 (mat.refract ? "refraction 1" : "mirror") +
                                 "): the material would create energy (expected <= 1, or "
                                 "\"allow_energy_gain\": true to keep SmallUPBP's model)");
                break;
            }
    } else if (type == "mirror") {
        // A perfect mirror, or with "metal" or "eta" and "k" a smooth conductor: reflectance
        // x F_conductor(cos theta_i) (Mitsuba's smooth `conductor`).
        mat.type = MaterialType::Mirror;
        keys.insert(keys.end(), {"reflectance", "metal", "eta", "k", "two_sided"});
        r.checkKeys(m, ptr, keys, "mirror material");
        colour("reflectance", Rgb(1.0f), &mat.specular, &mat.textures.specular);
        mat.conductorFresnel = readConductorIor(r, m, ptr, mat, false);
    } else if (type == "dielectric" || type == "rough_dielectric") {
        bool rough = type == "rough_dielectric";
        mat.type = rough ? MaterialType::RoughDielectric : MaterialType::Dielectric;
        keys.insert(keys.end(), {"ior", "tint"});
        if (rough) keys.insert(keys.end(), {"alpha", "alpha_v", "masking", "distribution"});
        r.checkKeys(m, ptr, keys, type + " material");
        mat.ior = r.getNumber(m, ptr, "ior", Presence::Required, NumberRange::positive(), 1.5f);
        if (rough) mat.separableMasking = readMasking(r, m, ptr);
        if (rough) mat.distribution = readDistribution(r, m, ptr);
        colour("tint", Rgb(1.0f), &mat.specular, &mat.textures.specular);
        if (rough) {
            roughness("alpha", Presence::Required, 0.1f, &mat.alpha, &mat.textures.alpha);
            roughness("alpha_v", Presence::Optional, -1.0f, &mat.alphaV, &mat.textures.alphaV);
        }
        mat.twoSided = false;  // the inside of a dielectric is defined by its normal
    } else if (type == "rough_conductor") {
        mat.type = MaterialType::RoughConductor;
        keys.insert(keys.end(), {"metal", "eta", "k", "alpha", "alpha_v", "masking", "distribution",
                                 "tint", "two_sided"});
        r.checkKeys(m, ptr, keys, "rough_conductor material");
        mat.separableMasking = readMasking(r, m, ptr);
        mat.distribution = readDistribution(r, m, ptr);
        readConductorIor(r, m, ptr, mat, true);
        roughness("alpha", Presence::Required, 0.1f, &mat.alpha, &mat.textures.alpha);
        roughness("alpha_v", Presence::Optional, -1.0f, &mat.alphaV, &mat.textures.alphaV);
        colour("tint", Rgb(1.0f), &mat.specular, &mat.textures.specular);
    } else if (type == "plastic" || type == "rough_plastic") {
        const bool rough = type == "rough_plastic";
        mat.type = rough ? MaterialType::RoughPlastic : MaterialType::Plastic;
        keys.insert(keys.end(), {"diffuse_reflectance", "specular_reflectance", "int_ior",
                                 "ext_ior", "nonlinear", "two_sided"});
        if (rough) keys.insert(keys.end(), {"alpha", "distribution"});
        r.checkKeys(m, ptr, keys, type + " material");
        if (rough) mat.distribution = readDistribution(r, m, ptr);
        colour("diffuse_reflectance", Rgb(0.5f), &mat.diffuse, &mat.textures.diffuse);
        colour("specular_reflectance", Rgb(1.0f), &mat.specular, &mat.textures.specular);
        const float intIor = r.getNumber(m, ptr, "int_ior", Presence::Optional,
                                         NumberRange::positive(), kPolypropyleneIor);
        const float extIor =
            r.getNumber(m, ptr, "ext_ior", Presence::Optional, NumberRange::positive(), kAirIor);
        mat.ior = intIor / extIor;
        if (rough && intIor == extIor)
            r.error(jsonPointerChild(ptr, "int_ior"),
                    "int_ior and ext_ior are equal (" + formatNumber(intIor) +
                        "): a rough_plastic needs a coating that differs from the outside");
        mat.nonlinear = r.getBool(m, ptr, "nonlinear", false);
        if (rough)
            mat.alpha = r.getNumber(m, ptr, "alpha", Presence::Optional,
                                    NumberRange::leftOpen(0.0, 1.0), 0.1f);
    } else if (type == "principled" || type == "principled_thin") {
        // Mitsuba 3's principled and principledthin (kernels/shared/ub_principled.h,
        // ub_principled_thin.h), their parameter names and defaults. principled is one-sided
        // unless "two_sided" (Mitsuba's twosided) and without spec_trans; principled_thin is a
        // sheet, the same from both sides.
        const bool thin = type == "principled_thin";
        mat.type = thin ? MaterialType::PrincipledThin : MaterialType::Principled;
        std::vector<std::string> weights = {"anisotropic", "spec_trans", "spec_tint",
                                            "sheen",       "sheen_tint", "flatness"};
        if (thin)
            weights.push_back("diff_trans");
        else
            weights.insert(weights.end(), {"metallic", "clearcoat", "clearcoat_gloss"});
        keys.insert(keys.end(),
                    {"base_color", "roughness", "eta", "diffuse_reflectance_sampling_rate"});
        if (thin)
            keys.insert(keys.end(), {"specular_reflectance_sampling_rate",
                                     "specular_transmittance_sampling_rate",
                                     "diffuse_transmittance_sampling_rate"});
        else
            keys.insert(keys.end(), {"specular", "two_sided", "main_specular_sampling_rate",
                                     "clearcoat_sampling_rate"});
        keys.insert(keys.end(), weights.begin(), weights.end());
        r.checkKeys(m, ptr, keys, type + " material");
        colour("base_color", Rgb(0.5f), &mat.diffuse, &mat.textures.diffuse);
        const Json* rough = r.member(m, ptr, "roughness", Presence::Optional, "");
        if (rough && rough->is_object()) {
            Rgb mean;
            mat.textures.alpha =
                readJsonTexturedRgb(r, m, ptr, "roughness", kReflectance, Rgb(0.5f), parts, &mean);
            mat.alpha = luminance(mean);
        } else {
            mat.alpha = r.getNumber(m, ptr, "roughness", Presence::Optional,
                                    NumberRange::closed(0.0, 1.0), 0.5f);
        }
        PrincipledParams& q = mat.principled;
        for (int i = 0; i < PrincipledParams::kWeights; ++i) {
            const std::string name = PrincipledParams::weightName(i);
            if (std::find(weights.begin(), weights.end(), name) == weights.end()) continue;
            q.weight(i) =
                r.getNumber(m, ptr, name, Presence::Optional,
                            NumberRange::closed(0.0, name == "diff_trans" ? 2.0 : 1.0), 0.0f);
        }
        auto rate = [&](const char* key) {
            return r.getNumber(m, ptr, key, Presence::Optional, NumberRange::nonNegative(), 1.0f);
        };
        q.rateDiffuse = rate("diffuse_reflectance_sampling_rate");
        if (thin) {
            q.rateSpecular = rate("specular_reflectance_sampling_rate");
            q.rateSpecTrans = rate("specular_transmittance_sampling_rate");
            q.rateDiffTrans = rate("diffuse_transmittance_sampling_rate");
            mat.ior = r.getNumber(m, ptr, "eta", Presence::Optional, NumberRange::positive(), 1.5f);
            mat.twoSided = true;
            if (q.rateDiffuse + q.rateSpecular + q.rateSpecTrans + q.rateDiffTrans <= 0.0f)
                r.error(ptr, "every sampling rate is zero (nothing can be sampled)");
            return;
        }
        q.rateSpecular = rate("main_specular_sampling_rate");
        q.rateClearcoat = rate("clearcoat_sampling_rate");
        if (m.contains("eta") && m.contains("specular")) {
            r.error(jsonPointerChild(ptr, "specular"),
                    "give either \"eta\" or \"specular\", not both");
        } else if (m.contains("eta")) {
            mat.ior = r.getNumber(m, ptr, "eta", Presence::Required, NumberRange::positive(), 1.5f);
            if (q.specTrans > 0.0f && mat.ior == 1.0f) mat.ior = 1.001f;  // Mitsuba's nudge
        } else {
            float specular = r.getNumber(m, ptr, "specular", Presence::Optional,
                                         NumberRange::closed(0.0, 1.0), 0.5f);
            if (q.specTrans > 0.0f && specular == 0.0f) specular = 1e-3f;  // Mitsuba's nudge
            mat.ior = 2.0f / (1.0f - std::sqrt(0.08f * specular)) - 1.0f;
        }
        if (q.rateDiffuse + q.rateSpecular + q.rateClearcoat <= 0.0f)
            r.error(ptr, "every sampling rate is zero (nothing can be sampled)");
        mat.twoSided = r.getBool(m, ptr, "two_sided", false);
        if (mat.twoSided && q.specTrans > 0.0f)
            r.error(jsonPointerChild(ptr, "two_sided"),
                    "a two-sided principled material cannot transmit (spec_trans > 0): its "
                    "back side is the inside of the transmission lobe");
        return;
    } else if (type == "thin_dielectric") {
        mat.type = MaterialType::ThinDielectric;
        keys.insert(keys.end(),
                    {"int_ior", "ext_ior", "specular_reflectance", "specular_transmittance"});
        r.checkKeys(m, ptr, keys, "thin_dielectric material");
        const float intIor =
            r.getNumber(m, ptr, "int_ior", Presence::Optional, NumberRange::positive(), kBk7Ior);
        const float extIor =
            r.getNumber(m, ptr, "ext_ior", Presence::Optional, NumberRange::positive(), kAirIor);
        mat.ior = intIor / extIor;
        colour("specular_reflectance", Rgb(1.0f), &mat.specular, &mat.textures.specular);
        colour("specular_transmittance", Rgb(1.0f), &mat.transmittance,
               &mat.textures.transmittance);
        mat.twoSided = false;  // a sheet: both sides alike whatever the flag
    } else {
        r.error(typePtr, "unknown material type '" + type + "'" + didYouMean(type, kMaterialTypes) +
                             "; valid types: " + joinNames(kMaterialTypes));
        return;
    }
    if (mat.type != MaterialType::Dielectric && mat.type != MaterialType::RoughDielectric &&
        mat.type != MaterialType::ThinDielectric)
        mat.twoSided = r.getBool(m, ptr, "two_sided", true);
}

}  // namespace

void readJsonMaterials(JsonReader& r, const Json& materials, JsonSceneParts& parts) {
    const std::string ptr = "/materials";
    if (!r.isObject(materials, ptr, "an object mapping material names to materials")) return;
    for (const auto& item : materials.items()) {
        std::string itemPtr = jsonPointerChild(ptr, item.key());
        if (item.key().empty()) {
            r.errorAtKey(itemPtr, "a material name must not be empty");
            continue;
        }
        Material mat;
        mat.name = item.key();
        readMaterial(r, item.value(), itemPtr, mat, parts);
        parts.materialIds[mat.name] = int(parts.materials.size());
        parts.materialNames.push_back(mat.name);
        parts.materials.push_back(mat);
    }
}

}  // namespace ub
