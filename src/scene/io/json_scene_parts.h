// Internal to the JSON loader: what is read from a scene file before a Scene
// is built. Reading fills this and the diagnostics; only a file without
// errors is turned into a Scene (json_loader.cpp), so a Scene never sees a
// fallback value.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/vec.h"
#include "scene/io/json_reader.h"
#include "scene/light.h"
#include "scene/material.h"
#include "scene/medium.h"
#include "scene/scene.h"

namespace ub {

struct JsonCameraDesc {
    Vec3 position{0, 0, 0}, target{0, 0, 1}, up{0, 1, 0};
    float fovYDeg = 45.0f;
    int width = 256, height = 256;
    float lensRadius = 0.0f, focusDistance = 1.0f;
};

struct JsonShapeDesc {
    std::string name;
    bool isSphere = false;
    TriangleMesh mesh;    ///< world space (not spheres)
    Vec3 center;          ///< spheres, world space
    float radius = 0.0f;  ///< spheres, world space
    int materialId = -1;  ///< index into JsonSceneParts::materials
    int lightIndex = -1;  ///< index into JsonSceneParts::lights, or -1
    std::string ptr;      ///< JSON pointer of the shape, for messages after reading
    // Medium boundary ("interior_medium", "priority", "imaginary").
    bool isMediumBoundary = false;
    int interiorMedium = -1;  ///< index into JsonSceneParts::media, -1 = vacuum
    int priority = 0;
    bool imaginary = false;
};

struct JsonSceneParts {
    std::string baseDir;  ///< folder of the scene file; relative paths start here
    bool hasCamera = false;
    JsonCameraDesc camera;
    RenderSettings settings;
    std::vector<Material> materials;
    std::vector<Texture> textures;  ///< Material::textures index these (and Scene's)
    std::map<std::string, std::shared_ptr<const Image>> bitmapCache;  ///< by path (+ "|raw")
    std::map<std::string, int> materialIds;                           ///< by name
    std::vector<std::string> materialNames;  ///< in file order, for messages
    std::vector<JsonShapeDesc> shapes;
    std::vector<Light> lights;
    int backgroundLight = -1;    ///< index into lights
    std::string environmentPtr;  ///< JSON pointer of the environment light, for messages
    std::vector<Medium> media;
    std::vector<std::string> mediumNames;  ///< in file order
    std::vector<std::string> mediumPtrs;   ///< JSON pointer of each medium
    std::map<std::string, int> mediumIds;  ///< by name
    int globalMedium = -1;                 ///< "medium" at the top level, -1 vacuum
};

/// Resolves a path from the scene file: absolute paths stay, others start at baseDir.
std::string resolveScenePath(const std::string& baseDir, const std::string& path);

/// Reads "/materials" (an object: name -> material).
void readJsonMaterials(JsonReader& r, const Json& materials, JsonSceneParts& parts);
/// Reads "/media" (an object: name -> medium).
void readJsonMedia(JsonReader& r, const Json& media, JsonSceneParts& parts);
/// Reads a medium reference: a medium name, or null for vacuum. Returns false (after an
/// error) on an unknown name or a wrong type; *id = -1 for vacuum.
bool readJsonMediumRef(JsonReader& r, const Json& v, const std::string& ptr,
                       const JsonSceneParts& parts, int* id);
/// Reads obj[key] (optional) as an RGB colour in `range` or a texture object
/// (json_textures.cpp). Returns the index of the new texture in parts.textures, or -1 for a
/// plain colour, which goes to *value (fallback when absent or wrong; a texture's mean).
int readJsonTexturedRgb(JsonReader& r, const Json& obj, const std::string& objPtr,
                        const std::string& key, const NumberRange& range, const Rgb& fallback,
                        JsonSceneParts& parts, Rgb* value);
/// Reads "/shapes" (an array), creating area lights for emissive shapes.
void readJsonShapes(JsonReader& r, const Json& shapes, JsonSceneParts& parts);
/// Reads a "transform" value: {"scale", "rotate", "translate"} or {"matrix"}.
Transform readJsonTransform(JsonReader& r, const Json& v, const std::string& ptr);
/// Reads a "rotate" value: {"axis", "angle"} or an array of them (applied in order).
Transform readJsonRotation(JsonReader& r, const Json& v, const std::string& ptr);

}  // namespace ub
