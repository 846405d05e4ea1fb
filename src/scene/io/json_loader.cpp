// Native JSON scene loader: parsing, the top level, camera, settings and
// lights; materials and shapes are in json_materials.cpp and json_shapes.cpp.
// Reading fills a JsonSceneParts and the diagnostics; a Scene is built only
// from a file without errors.
#include "scene/io/json_loader.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "core/file_status.h"
#include "core/image.h"
#include "scene/io/json_scene_parts.h"

namespace ub {

namespace fs = std::filesystem;

namespace {

const std::vector<std::string> kLightTypes = {"point", "spot", "directional", "constant", "envmap"};

/// nlohmann messages start with "[json.exception.parse_error.101] parse error at line 3,
/// column 14: "; we print our own position, so keep only what follows.
std::string stripNlohmannPrefix(const std::string& what) {
    std::string s = what;
    size_t bracket = s.find("] ");
    if (s.rfind("[json.exception", 0) == 0 && bracket != std::string::npos)
        s = s.substr(bracket + 2);
    size_t colon = s.find(": ");
    if (s.rfind("parse error", 0) == 0 && colon != std::string::npos) s = s.substr(colon + 2);
    return s;
}

bool parseText(const std::string& text, const std::string& file, Diagnostics& diags, Json* out) {
    auto add = [&](SourcePos p, const std::string& msg) {
        Diagnostic d;
        d.file = file;
        d.line = p.line;
        d.column = p.column;
        d.message = msg;
        diags.error(d);
    };
    try {
        *out = Json::parse(text, nullptr, /*allow_exceptions=*/true, /*ignore_comments=*/true);
        return true;
    } catch (const Json::parse_error& e) {
        // e.byte is the 1-based index of the last character nlohmann read, which can be
        // the whitespace after the offending token: step back to the token.
        size_t offset = std::min(e.byte > 0 ? size_t(e.byte - 1) : 0, text.size());
        while (offset > 0 && (offset >= text.size() || std::isspace(uint8_t(text[offset]))))
            --offset;
        add(sourcePosOfOffset(text, offset), "invalid JSON: " + stripNlohmannPrefix(e.what()));
    } catch (const Json::exception& e) {
        // Number overflow (e.g. 1e999) carries no position: find the literal in the text.
        std::string msg = stripNlohmannPrefix(e.what());
        SourcePos pos;
        size_t q0 = msg.find('\''), q1 = msg.rfind('\'');
        if (q0 != std::string::npos && q1 > q0) {
            size_t at = text.find(msg.substr(q0 + 1, q1 - q0 - 1));
            if (at != std::string::npos) pos = sourcePosOfOffset(text, at);
        }
        add(pos, "invalid number: " + msg + " (expected a finite number)");
    }
    return false;
}

void readCamera(JsonReader& r, const Json& c, JsonSceneParts& parts) {
    const std::string ptr = "/camera";
    if (!r.isObject(c, ptr, "a camera object")) return;
    r.checkKeys(c, ptr,
                {"position", "target", "up", "fov", "resolution", "lens_radius", "focus_distance"},
                "camera");
    size_t before = r.errorCount();
    JsonCameraDesc& cam = parts.camera;
    cam.position = r.getVec3(c, ptr, "position", Presence::Required, cam.position);
    cam.target = r.getVec3(c, ptr, "target", Presence::Required, cam.target);
    cam.up = r.getDirection(c, ptr, "up", Presence::Optional, Vec3(0, 1, 0));
    cam.fovYDeg =
        r.getNumber(c, ptr, "fov", Presence::Optional, NumberRange::open(0.0, 180.0), 45.0f);
    if (const Json* res = r.member(c, ptr, "resolution", Presence::Optional, "")) {
        std::string resPtr = jsonPointerChild(ptr, "resolution");
        // 16384 per side: larger images are almost surely a typo (and 4 GiB of film).
        const int64_t kMaxSide = 16384;
        if (!res->is_array() || res->size() != 2) {
            r.error(resPtr, "expected [width, height] (two integers in [1, 16384]), got " +
                                JsonReader::describeValue(*res));
        } else {
            cam.width = int(r.integer((*res)[0], jsonPointerChild(resPtr, 0), 1, kMaxSide, 256));
            cam.height = int(r.integer((*res)[1], jsonPointerChild(resPtr, 1), 1, kMaxSide, 256));
        }
    }
    cam.lensRadius =
        r.getNumber(c, ptr, "lens_radius", Presence::Optional, NumberRange::nonNegative(), 0.0f);
    float targetDistance = length(cam.target - cam.position);
    cam.focusDistance = r.getNumber(c, ptr, "focus_distance", Presence::Optional,
                                    NumberRange::positive(), targetDistance);
    if (r.errorCount() != before) return;
    if (!(targetDistance > 0.0f)) {
        r.error(jsonPointerChild(ptr, "target"),
                "the camera target equals its position (expected a different point to look at)");
        return;
    }
    Vec3 forward = normalize(cam.target - cam.position);
    if (length(cross(forward, cam.up)) < 1e-4f)
        r.error(jsonPointerChild(ptr, "up"),
                "the up vector is parallel to the viewing direction (expected a direction not "
                "parallel to target - position)");
    parts.hasCamera = true;
}

void readSettings(JsonReader& r, const Json& s, JsonSceneParts& parts) {
    const std::string ptr = "/settings";
    if (!r.isObject(s, ptr, "a settings object")) return;
    r.checkKeys(s, ptr, {"max_path_length", "min_path_length", "seed"}, "settings");
    RenderSettings& st = parts.settings;
    st.maxPathLength =
        int(r.getInteger(s, ptr, "max_path_length", Presence::Optional, 1, 1000, 10));
    st.minPathLength =
        int(r.getInteger(s, ptr, "min_path_length", Presence::Optional, 0, st.maxPathLength, 0));
    st.seed = uint64_t(r.getInteger(s, ptr, "seed", Presence::Optional, 0,
                                    std::numeric_limits<int64_t>::max(), 1));
}

/// Checks an environment map's pixels: finite, non-negative, not all black.
void checkEnvMap(JsonReader& r, const Image& img, const std::string& filePtr,
                 const std::string& file) {
    size_t bad = 0;
    int firstX = -1, firstY = -1;
    bool anyLight = false;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            const Rgb& p = img.at(x, y);
            if (!isFinite(p) || minComponent(p) < 0.0f) {
                if (bad++ == 0) firstX = x, firstY = y;
            } else if (maxComponent(p) > 0.0f) {
                anyLight = true;
            }
        }
    if (bad > 0)
        r.error(filePtr, "environment map '" + file + "' has " + std::to_string(bad) +
                             " negative or non-finite pixels (first at x " +
                             std::to_string(firstX) + ", y " + std::to_string(firstY) +
                             "); expected radiance >= 0");
    else if (!anyLight)
        r.error(filePtr, "environment map '" + file + "' is black everywhere");
}

void readLight(JsonReader& r, const Json& v, const std::string& ptr, size_t index,
               JsonSceneParts& parts) {
    if (!r.isObject(v, ptr, "a light object with a \"type\" key")) return;
    const Json* typeJson = r.member(v, ptr, "type", Presence::Required,
                                    "a light type: one of " + joinNames(kLightTypes));
    if (!typeJson) return;
    std::string typePtr = jsonPointerChild(ptr, "type");
    std::string type = r.string(*typeJson, typePtr);
    if (type.empty()) return;
    size_t before = r.errorCount();
    Light light;
    light.name = type + " " + std::to_string(index);
    std::vector<std::string> keys = {"type", "name"};
    const NumberRange nonNeg = NumberRange::nonNegative();
    if (type == "point") {
        keys.insert(keys.end(), {"position", "intensity"});
        r.checkKeys(v, ptr, keys, "point light");
        light.type = LightType::Point;
        light.position = r.getVec3(v, ptr, "position", Presence::Required, Vec3(0.0f));
        light.intensity = r.getRgb(v, ptr, "intensity", Presence::Required, nonNeg, Rgb(0.0f));
    } else if (type == "spot") {
        keys.insert(keys.end(),
                    {"position", "direction", "target", "intensity", "cutoff_angle", "beam_width"});
        r.checkKeys(v, ptr, keys, "spot light");
        light.type = LightType::Spot;
        light.position = r.getVec3(v, ptr, "position", Presence::Required, Vec3(0.0f));
        light.intensity = r.getRgb(v, ptr, "intensity", Presence::Required, nonNeg, Rgb(0.0f));
        const bool hasDirection = v.contains("direction"), hasTarget = v.contains("target");
        if (hasDirection == hasTarget) {
            r.error(hasTarget ? jsonPointerChild(ptr, "target") : ptr,
                    "a spot light needs exactly one of \"direction\" (the axis of its cone) or "
                    "\"target\" (a point on the axis)");
        } else if (hasDirection) {
            light.direction =
                r.getDirection(v, ptr, "direction", Presence::Required, Vec3(0, 0, -1));
        } else {
            const Vec3 target = r.getVec3(v, ptr, "target", Presence::Required, Vec3(0.0f));
            if (lengthSqr(target - light.position) > 0.0f)
                light.direction = normalize(target - light.position);
            else
                r.error(jsonPointerChild(ptr, "target"),
                        "the target equals the position: the spot light has no direction");
        }
        light.cutoffAngleDeg = r.getNumber(v, ptr, "cutoff_angle", Presence::Optional,
                                           NumberRange::leftOpen(0.0, 180.0), 20.0f);
        // Mitsuba's default: 3/4 of the cutoff angle.
        light.beamWidthDeg =
            r.getNumber(v, ptr, "beam_width", Presence::Optional, NumberRange::closed(0.0, 180.0),
                        0.75f * light.cutoffAngleDeg);
        if (light.beamWidthDeg > light.cutoffAngleDeg)
            r.error(jsonPointerChild(ptr, "beam_width"),
                    "beam_width " + formatNumber(light.beamWidthDeg) + " exceeds cutoff_angle " +
                        formatNumber(light.cutoffAngleDeg) +
                        " (expected a number in [0, cutoff_angle] degrees)");
    } else if (type == "directional") {
        keys.insert(keys.end(), {"direction", "irradiance"});
        r.checkKeys(v, ptr, keys, "directional light");
        light.type = LightType::Directional;
        light.direction = r.getDirection(v, ptr, "direction", Presence::Required, Vec3(0, 0, -1));
        light.radiance = r.getRgb(v, ptr, "irradiance", Presence::Required, nonNeg, Rgb(0.0f));
    } else if (type == "constant") {
        keys.insert(keys.end(), {"radiance"});
        r.checkKeys(v, ptr, keys, "constant light");
        light.type = LightType::ConstantEnv;
        light.radiance = r.getRgb(v, ptr, "radiance", Presence::Required, nonNeg, Rgb(0.0f));
    } else if (type == "envmap") {
        keys.insert(keys.end(), {"file", "scale", "rotate", "filter"});
        r.checkKeys(v, ptr, keys, "envmap light");
        light.type = LightType::EnvMap;
        light.envFilter = EnvFilter::Bilinear;  // smooth by default, as Mitsuba 3's envmap
        if (v.contains("filter")) {
            const std::vector<std::string> filters = {"bilinear", "nearest"};
            const std::string filter = r.getString(v, ptr, "filter", Presence::Optional);
            if (filter == "nearest")
                light.envFilter = EnvFilter::Nearest;
            else if (filter != "bilinear" && !filter.empty())  // "" was reported by getString
                r.error(jsonPointerChild(ptr, "filter"),
                        "unknown environment map filter '" + filter + "'" +
                            didYouMean(filter, filters) + "; valid filters: " + joinNames(filters));
        }
        light.radiance = r.getRgb(v, ptr, "scale", Presence::Optional, nonNeg, Rgb(1.0f));
        if (const Json* rot = r.member(v, ptr, "rotate", Presence::Optional, "")) {
            light.envToWorld = readJsonRotation(r, *rot, jsonPointerChild(ptr, "rotate"));
            light.worldToEnv = light.envToWorld.inverse();
        }
        std::string file = r.getString(v, ptr, "file", Presence::Required);
        std::string filePtr = jsonPointerChild(ptr, "file");
        if (!file.empty()) {
            std::string path = resolveScenePath(parts.baseDir, file);
            if (!isRegularFile(path)) {
                r.error(filePtr, "environment map '" + file + "' not found (looked for '" + path +
                                     "'; paths are relative to the scene file)");
            } else {
                try {
                    auto img = std::make_shared<Image>(readExr(path));
                    checkEnvMap(r, *img, filePtr, file);
                    light.envMap = std::move(img);
                } catch (const InputError& e) {
                    for (const Diagnostic& d : e.diagnostics())
                        r.error(filePtr,
                                "cannot read environment map '" + file + "': " + d.message);
                }
            }
        }
    } else {
        r.error(typePtr, "unknown light type '" + type + "'" + didYouMean(type, kLightTypes) +
                             "; valid types: " + joinNames(kLightTypes) +
                             " (area lights are shapes with an \"emission\")");
        return;
    }
    if (v.contains("name")) light.name = r.getString(v, ptr, "name", Presence::Optional);
    if (r.errorCount() != before) return;

    bool black = light.type == LightType::Point || light.type == LightType::Spot
                     ? isBlack(light.intensity)
                     : isBlack(light.radiance);
    if (black) r.warning(ptr, "this light is black: it emits nothing");
    if (light.isEnvironment()) {
        if (parts.backgroundLight >= 0) {
            r.error(typePtr, "more than one environment light: " + parts.environmentPtr +
                                 " is one already (a scene has at most one)");
            return;
        }
        parts.backgroundLight = int(parts.lights.size());
        parts.environmentPtr = ptr;
    }
    parts.lights.push_back(std::move(light));
}

void readJsonLights(JsonReader& r, const Json& lights, JsonSceneParts& parts) {
    const std::string ptr = "/lights";
    if (!r.isArray(lights, ptr, "an array of light objects")) return;
    for (size_t i = 0; i < lights.size(); ++i)
        readLight(r, lights[i], jsonPointerChild(ptr, i), i, parts);
}

void readRoot(JsonReader& r, const Json& root, JsonSceneParts& parts) {
    if (!r.isObject(root, "", "a scene object with \"camera\", \"materials\", \"shapes\" ..."))
        return;
    r.checkKeys(
        root, "",
        {"description", "camera", "settings", "materials", "media", "medium", "shapes", "lights"},
        "the scene");
    if (const Json* d = r.member(root, "", "description", Presence::Optional, ""))
        r.string(*d, "/description", true);
    if (const Json* c = r.member(root, "", "camera", Presence::Required,
                                 "a camera object with \"position\" and \"target\""))
        readCamera(r, *c, parts);
    if (const Json* s = r.member(root, "", "settings", Presence::Optional, ""))
        readSettings(r, *s, parts);
    if (const Json* m = r.member(root, "", "materials", Presence::Optional, ""))
        readJsonMaterials(r, *m, parts);
    // Media before shapes (shapes name their interior medium) and the global medium.
    if (const Json* m = r.member(root, "", "media", Presence::Optional, ""))
        readJsonMedia(r, *m, parts);
    if (const Json* g = r.member(root, "", "medium", Presence::Optional, ""))
        readJsonMediumRef(r, *g, "/medium", parts, &parts.globalMedium);
    // Shapes before lights: area lights of emissive shapes come first in Scene::lights
    // (in shape order), then the entries of "lights".
    size_t lightEntries = 0;
    if (const Json* s = r.member(root, "", "shapes", Presence::Optional, "")) {
        readJsonShapes(r, *s, parts);
        if (s->is_array())
            for (const auto& shape : *s)
                if (shape.is_object() && shape.contains("emission")) ++lightEntries;
    }
    if (const Json* l = r.member(root, "", "lights", Presence::Optional, "")) {
        readJsonLights(r, *l, parts);
        lightEntries += l->is_array() ? l->size() : 1;
    }
    // Only when nothing was even attempted: a light with an error was reported already.
    if (lightEntries == 0)
        r.error("",
                "the scene has no light (expected an entry in \"lights\" or a shape with "
                "an \"emission\")");
}

std::unique_ptr<Scene> buildScene(JsonSceneParts& parts, const std::string& fileName,
                                  JsonReader& reader) {
    auto scene = std::make_unique<Scene>();
    scene->sourceFile = fileName;
    const JsonCameraDesc& c = parts.camera;
    scene->camera.setup(c.position, c.target, c.up, c.fovYDeg, c.width, c.height, c.lensRadius,
                        c.focusDistance);
    scene->settings = parts.settings;
    // Textures first: materials refer to them by index (parts' indices are the scene's).
    try {
        for (const Texture& t : parts.textures) scene->addTexture(t);
    } catch (const InputError& e) {
        std::vector<Diagnostic> d = e.diagnostics();
        for (auto& x : d)
            if (x.file.empty()) x.file = fileName;
        throw InputError(std::move(d));
    }
    std::vector<int> materialIds;
    for (const Material& m : parts.materials) materialIds.push_back(scene->addMaterial(m));
    std::vector<int> lightIds;
    try {
        for (Light& l : parts.lights) lightIds.push_back(scene->addLight(std::move(l)));
    } catch (const InputError& e) {
        // Light::prepare reports without a file; name ours.
        std::vector<Diagnostic> d = e.diagnostics();
        for (auto& x : d)
            if (x.file.empty()) x.file = fileName;
        throw InputError(std::move(d));
    }
    for (size_t i = 0; i < parts.media.size(); ++i)
        scene->addMedium(parts.media[i], parts.mediumNames[i]);
    scene->globalMediumId = parts.globalMedium;
    for (JsonShapeDesc& s : parts.shapes) {
        int lightId = s.lightIndex >= 0 ? lightIds[size_t(s.lightIndex)] : -1;
        int materialId = s.materialId >= 0 ? materialIds[size_t(s.materialId)] : -1;
        uint32_t id = s.isSphere ? scene->addSphere(s.center, s.radius, materialId, lightId, s.name)
                                 : scene->addMesh(std::move(s.mesh), materialId, lightId, s.name);
        if (s.isMediumBoundary)
            scene->setMediumBoundary(id, s.interiorMedium, s.priority, s.imaginary);
    }
    // Media set-up errors (open boundary meshes, conflicting priorities), at the shape.
    for (const MediumIssue& issue : scene->mediumIssues()) {
        if (issue.warning) continue;  // none arise under the priority stack
        std::string ptr = issue.shapeId >= 0    ? parts.shapes[size_t(issue.shapeId)].ptr
                          : issue.mediumId >= 0 ? parts.mediumPtrs[size_t(issue.mediumId)]
                                                : std::string("/shapes");
        reader.error(ptr, issue.message);
    }
    reader.diagnostics().throwIfErrors();
    scene->backgroundLightId =
        parts.backgroundLight >= 0 ? lightIds[size_t(parts.backgroundLight)] : -1;
    scene->commit();
    return scene;
}

}  // namespace

std::unique_ptr<Scene> loadJsonSceneFromString(const std::string& text, const std::string& fileName,
                                               const std::string& baseDir,
                                               std::vector<Diagnostic>* warnings) {
    Diagnostics diags;
    Json root;
    if (!parseText(text, fileName, diags, &root)) diags.throwIfErrors();

    JsonPositionIndex index(text);
    JsonReader reader(fileName, index, diags);
    for (const auto& dup : index.duplicates())
        reader.errorAtKey(dup.pointer, "duplicate key (first given at line " +
                                           std::to_string(dup.first.line) + ", column " +
                                           std::to_string(dup.first.column) +
                                           "; keys must be unique)");
    JsonSceneParts parts;
    parts.baseDir = baseDir;
    readRoot(reader, root, parts);
    diags.throwIfErrors();
    if (warnings) *warnings = diags.warnings();
    return buildScene(parts, fileName, reader);
}

std::unique_ptr<Scene> loadJsonScene(const std::string& path, std::vector<Diagnostic>* warnings) {
    std::ifstream in(path, std::ios::binary);
    if (!isRegularFile(path) || !in)
        throw InputError(path, "cannot open the scene file (not found or not readable)");
    std::stringstream ss;
    ss << in.rdbuf();
    std::string baseDir = fs::path(path).parent_path().string();
    return loadJsonSceneFromString(ss.str(), path, baseDir, warnings);
}

}  // namespace ub
