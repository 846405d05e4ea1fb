// "media" and medium references of the native JSON scene format
// (docs/scene-format.md, section media): homogeneous media with RGB
// coefficients and heterogeneous media whose density comes from a .vdb file,
// with a constant albedo or an albedo grid (a float or vec3 grid of a .vdb).
#include <filesystem>
#include <limits>
#include <map>

#include "core/file_status.h"
#include "scene/albedo_grid.h"
#include "scene/io/json_scene_parts.h"
#include "scene/vdb_grid.h"

namespace ub {

namespace fs = std::filesystem;

namespace {

const std::vector<std::string> kMediumTypes = {"homogeneous", "heterogeneous"};

/// |g| < 1: at |g| = 1 the Henyey-Greenstein lobe is a delta and its pdf is not defined.
const NumberRange kG = NumberRange::open(-1.0, 1.0);

void readHomogeneous(JsonReader& r, const Json& v, const std::string& ptr, Medium& med) {
    r.checkKeys(v, ptr,
                {"type", "sigma_a", "sigma_s", "sigma_t", "albedo", "scale", "emission", "g"},
                "homogeneous medium");
    const NumberRange nonNeg = NumberRange::nonNegative();
    const bool absorbScatter = v.contains("sigma_a") || v.contains("sigma_s");
    const bool extinctionAlbedo = v.contains("sigma_t") || v.contains("albedo");
    Rgb sigmaA(0.0f), sigmaS(0.0f);
    if (absorbScatter && extinctionAlbedo) {
        r.error(ptr,
                "give either \"sigma_a\"/\"sigma_s\" or \"sigma_t\"/\"albedo\", not both "
                "forms");
    } else if (extinctionAlbedo) {
        Rgb sigmaT = r.getRgb(v, ptr, "sigma_t", Presence::Required, nonNeg, Rgb(0.0f));
        Rgb albedo = r.getRgb(v, ptr, "albedo", Presence::Required, NumberRange::closed(0.0, 1.0),
                              Rgb(0.0f));
        sigmaS = sigmaT * albedo;
        sigmaA = sigmaT - sigmaS;
        sigmaA = vmax(sigmaA, Rgb(0.0f));
    } else if (absorbScatter) {
        sigmaA = r.getRgb(v, ptr, "sigma_a", Presence::Optional, nonNeg, Rgb(0.0f));
        sigmaS = r.getRgb(v, ptr, "sigma_s", Presence::Optional, nonNeg, Rgb(0.0f));
    } else {
        r.error(ptr,
                "a homogeneous medium needs its coefficients: \"sigma_a\" and/or "
                "\"sigma_s\", or \"sigma_t\" and \"albedo\" (per unit length, RGB)");
    }
    float scale = r.getNumber(v, ptr, "scale", Presence::Optional, nonNeg, 1.0f);
    Rgb emission = r.getRgb(v, ptr, "emission", Presence::Optional, nonNeg, Rgb(0.0f));
    float g = r.getNumber(v, ptr, "g", Presence::Optional, kG, 0.0f);
    med = Medium();
    med.type = MediumType::kHomogeneous;
    med.sigmaA = sigmaA * scale;
    med.sigmaS = sigmaS * scale;
    med.Le = emission;
    med.g = g;
    if (!isBlack(emission) && isBlack(med.sigmaA))
        r.warning(jsonPointerChild(ptr, "emission"),
                  "the medium emits nothing: emission is scaled by sigma_a, which is 0");
}

/// Loads `gridName` of the VDB `file` (relative to the scene); errors go to filePtr for file
/// problems and gridPtr for grid problems. load() returns the grids or throws InputError.
template <typename Load>
bool loadVdbFile(JsonReader& r, const JsonSceneParts& parts, const std::string& file,
                 const std::string& filePtr, const std::string& gridPtr, Load&& load) {
    std::string path = resolveScenePath(parts.baseDir, file);
    if (fs::path(file).extension() != ".vdb") {
        r.error(filePtr, "a heterogeneous medium needs a .vdb file, got '" + file + "'");
    } else if (!isRegularFile(path)) {
        r.error(filePtr, "VDB file '" + file + "' not found (looked for '" + path +
                             "'; paths are relative to the scene file)");
    } else {
        try {
            load(path);
            return true;
        } catch (const InputError& e) {
            for (const Diagnostic& d : e.diagnostics()) {
                const bool gridProblem =
                    d.message.find("no grid of that name") != std::string::npos ||
                    d.message.find("grid holds values of type") != std::string::npos;
                r.error(gridProblem ? gridPtr : filePtr,
                        "cannot use VDB file '" + file + "': " + d.message);
            }
        }
    }
    return false;
}

const std::vector<std::string> kAlbedoFilters = {"nearest", "trilinear"};

void readHeterogeneous(JsonReader& r, const Json& v, const std::string& ptr, JsonSceneParts& parts,
                       Medium& med) {
    r.checkKeys(v, ptr,
                {"type", "file", "grid", "density_scale", "albedo", "albedo_grid", "albedo_file",
                 "albedo_filter", "g", "transform"},
                "heterogeneous medium");
    size_t before = r.errorCount();
    float densityScale =
        r.getNumber(v, ptr, "density_scale", Presence::Optional, NumberRange::nonNegative(), 1.0f);
    const bool albedoGrid = v.contains("albedo_grid") || v.contains("albedo_file");
    if (albedoGrid && v.contains("albedo"))
        r.error(ptr,
                "give either a constant \"albedo\" or an albedo grid (\"albedo_grid\", "
                "\"albedo_file\"), not both");
    Rgb albedo =
        r.getRgb(v, ptr, "albedo", Presence::Optional, NumberRange::closed(0.0, 1.0), Rgb(1.0f));
    GridFilter albedoFilter = GridFilter::kNearest;
    if (v.contains("albedo_filter")) {
        const std::string fPtr = jsonPointerChild(ptr, "albedo_filter");
        std::string f = r.getString(v, ptr, "albedo_filter", Presence::Optional);
        if (!albedoGrid)
            r.error(fPtr, "\"albedo_filter\" needs an albedo grid (\"albedo_grid\")");
        else if (f == "trilinear")
            albedoFilter = GridFilter::kTrilinear;
        else if (f != "nearest" && !f.empty())
            r.error(fPtr, "unknown albedo filter '" + f + "'" + didYouMean(f, kAlbedoFilters) +
                              "; valid filters: " + joinNames(kAlbedoFilters));
    }
    float g = r.getNumber(v, ptr, "g", Presence::Optional, kG, 0.0f);
    Transform toWorld;
    if (const Json* tj = r.member(v, ptr, "transform", Presence::Optional, ""))
        toWorld = readJsonTransform(r, *tj, jsonPointerChild(ptr, "transform"));
    std::string gridName = "density";
    if (v.contains("grid")) gridName = r.getString(v, ptr, "grid", Presence::Optional);
    std::string file = r.getString(v, ptr, "file", Presence::Required);
    const std::string filePtr = jsonPointerChild(ptr, "file");
    // A float grid (grey extinction) or a vec3 grid (chromatic: one density per channel).
    std::vector<std::shared_ptr<const VdbGrid>> channels;
    if (!file.empty() && !gridName.empty())
        loadVdbFile(r, parts, file, filePtr,
                    v.contains("grid") ? jsonPointerChild(ptr, "grid") : filePtr,
                    [&](const std::string& path) {
                        channels = VdbGrid::loadChannels(path, gridName, "density",
                                                         std::numeric_limits<float>::infinity());
                    });

    // Albedo grid: "albedo_grid" (default "albedo") in "albedo_file" (default: "file").
    std::vector<std::shared_ptr<const VdbGrid>> albedoChannels;
    std::string albedoFile = file, albedoFilePtr = filePtr, albedoGridName = "albedo";
    const std::string gridPtr =
        jsonPointerChild(ptr, v.contains("albedo_grid") ? "albedo_grid" : "albedo_file");
    if (albedoGrid) {
        if (v.contains("albedo_grid"))
            albedoGridName = r.getString(v, ptr, "albedo_grid", Presence::Optional);
        if (v.contains("albedo_file")) {
            albedoFile = r.getString(v, ptr, "albedo_file", Presence::Optional);
            albedoFilePtr = jsonPointerChild(ptr, "albedo_file");
        }
        if (!albedoFile.empty() && !albedoGridName.empty())
            loadVdbFile(r, parts, albedoFile, albedoFilePtr, gridPtr, [&](const std::string& path) {
                albedoChannels = loadVdbAlbedoChannels(path, albedoGridName);
            });
    }
    if (r.errorCount() != before || channels.empty()) return;
    try {
        if (channels.size() == 3)
            med = Medium::heterogeneousRgb(channels.data(), densityScale, albedo, g, toWorld);
        else
            med = Medium::heterogeneous(channels[0], densityScale, albedo, g, toWorld);
        if (albedoGrid)
            med.albedoGrid =
                AlbedoGrid::make(albedoChannels, albedoFilter, toWorld, nullptr, nullptr,
                                 "'" + albedoFile + "' grid '" + albedoGridName + "'");
    } catch (const std::invalid_argument& e) {
        r.error(ptr, e.what());
    } catch (const InputError& e) {
        for (const Diagnostic& d : e.diagnostics()) r.error(gridPtr, d.message);
    }
}

void readMedium(JsonReader& r, const Json& v, const std::string& ptr, JsonSceneParts& parts,
                Medium& med) {
    if (!r.isObject(v, ptr, "a medium object with a \"type\" key")) return;
    const Json* typeJson = r.member(v, ptr, "type", Presence::Required,
                                    "a medium type: one of " + joinNames(kMediumTypes));
    if (!typeJson) return;
    const std::string typePtr = jsonPointerChild(ptr, "type");
    std::string type = r.string(*typeJson, typePtr);
    if (type.empty()) return;
    if (type == "homogeneous") {
        readHomogeneous(r, v, ptr, med);
    } else if (type == "heterogeneous") {
        readHeterogeneous(r, v, ptr, parts, med);
    } else {
        r.error(typePtr, "unknown medium type '" + type + "'" + didYouMean(type, kMediumTypes) +
                             "; valid types: " + joinNames(kMediumTypes));
    }
}

}  // namespace

void readJsonMedia(JsonReader& r, const Json& media, JsonSceneParts& parts) {
    const std::string ptr = "/media";
    if (!r.isObject(media, ptr, "an object mapping medium names to media")) return;
    for (auto it = media.begin(); it != media.end(); ++it) {
        const std::string mPtr = jsonPointerChild(ptr, it.key());
        if (it.key().empty()) {
            r.errorAtKey(mPtr, "a medium name must not be empty");
            continue;
        }
        Medium med;
        size_t before = r.errorCount();
        readMedium(r, it.value(), mPtr, parts, med);
        if (r.errorCount() != before) med = Medium();  // placeholder keeps the name known
        parts.mediumIds[it.key()] = int(parts.media.size());
        parts.media.push_back(med);
        parts.mediumNames.push_back(it.key());
        parts.mediumPtrs.push_back(mPtr);
    }
}

bool readJsonMediumRef(JsonReader& r, const Json& v, const std::string& ptr,
                       const JsonSceneParts& parts, int* id) {
    *id = -1;
    if (v.is_null()) return true;
    if (!v.is_string()) {
        r.error(ptr,
                "expected the name of a medium defined in \"media\", or null for vacuum, "
                "got " +
                    JsonReader::describeValue(v));
        return false;
    }
    std::string name = r.string(v, ptr);
    if (name.empty()) return false;
    auto it = parts.mediumIds.find(name);
    if (it == parts.mediumIds.end()) {
        r.error(ptr,
                "unknown medium '" + name + "'" + didYouMean(name, parts.mediumNames) +
                    (parts.mediumNames.empty()
                         ? std::string(" (no media are defined in \"media\")")
                         : " (defined: " + joinNames(parts.mediumNames) + "; null means vacuum)"));
        return false;
    }
    *id = it->second;
    return true;
}

}  // namespace ub
