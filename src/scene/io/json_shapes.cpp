// "shapes" and "transform" of the native JSON scene format
// (docs/scene-format.md). Meshes are transformed to world space here; an
// emissive shape also creates its area light.
#include <cmath>
#include <filesystem>
#include <utility>

#include "core/file_status.h"
#include "scene/io/json_scene_parts.h"
#include "scene/mesh_io.h"
#include "scene/shapes.h"

namespace ub {

namespace fs = std::filesystem;

std::string resolveScenePath(const std::string& baseDir, const std::string& path) {
    fs::path p(path);
    if (p.is_absolute() || baseDir.empty()) return p.lexically_normal().string();
    return (fs::path(baseDir) / p).lexically_normal().string();
}

namespace {

Transform readOneRotation(JsonReader& r, const Json& v, const std::string& ptr) {
    if (!r.isObject(v, ptr, "a rotation {\"axis\": [x, y, z], \"angle\": degrees}")) return {};
    r.checkKeys(v, ptr, {"axis", "angle"}, "rotation");
    Vec3 axis = r.getDirection(v, ptr, "axis", Presence::Required, Vec3(0, 0, 1));
    float angle = r.getNumber(v, ptr, "angle", Presence::Required, NumberRange::any(), 0.0f);
    return Transform::rotate(angle, axis);
}

bool isAffine(const Transform& t) {
    return t.m[3][0] == 0 && t.m[3][1] == 0 && t.m[3][2] == 0 && t.m[3][3] == 1;
}

Transform readMatrix(JsonReader& r, const Json& v, const std::string& ptr) {
    const std::string expected = "a 4x4 row-major matrix: 16 numbers, or 4 rows of 4 numbers";
    Transform t;
    std::vector<std::pair<const Json*, std::string>> entries;
    if (v.is_array() && v.size() == 16) {
        for (size_t i = 0; i < 16; ++i) entries.push_back({&v[i], jsonPointerChild(ptr, i)});
    } else if (v.is_array() && v.size() == 4) {
        for (size_t row = 0; row < 4; ++row) {
            std::string rowPtr = jsonPointerChild(ptr, row);
            if (!v[row].is_array() || v[row].size() != 4) {
                r.error(rowPtr,
                        "expected a row of 4 numbers, got " + JsonReader::describeValue(v[row]));
                return {};
            }
            for (size_t c = 0; c < 4; ++c)
                entries.push_back({&v[row][c], jsonPointerChild(rowPtr, c)});
        }
    } else {
        r.error(ptr, "expected " + expected + ", got " + JsonReader::describeValue(v));
        return {};
    }
    size_t before = r.errorCount();
    for (size_t i = 0; i < 16; ++i)
        t.m[i / 4][i % 4] = r.number(*entries[i].first, entries[i].second, NumberRange::any(),
                                     i / 4 == i % 4 ? 1.0f : 0.0f);
    if (r.errorCount() != before) return {};
    if (!isAffine(t)) {
        r.error(ptr,
                "the last row of the matrix must be [0, 0, 0, 1] (only affine transforms "
                "are supported)");
        return {};
    }
    return t;
}

}  // namespace

Transform readJsonRotation(JsonReader& r, const Json& v, const std::string& ptr) {
    if (!v.is_array()) return readOneRotation(r, v, ptr);
    // A list of rotations is applied in order: the first listed acts first.
    Transform t;
    for (size_t i = 0; i < v.size(); ++i)
        t = readOneRotation(r, v[i], jsonPointerChild(ptr, i)) * t;
    return t;
}

Transform readJsonTransform(JsonReader& r, const Json& v, const std::string& ptr) {
    if (!r.isObject(v, ptr,
                    "a transform object with \"scale\", \"rotate\", \"translate\" or \"matrix\""))
        return {};
    r.checkKeys(v, ptr, {"scale", "rotate", "translate", "matrix"}, "transform");
    Transform result;
    if (const Json* m = r.member(v, ptr, "matrix", Presence::Optional, "")) {
        std::string mPtr = jsonPointerChild(ptr, "matrix");
        if (v.size() > 1) {
            r.error(mPtr,
                    "\"matrix\" cannot be combined with \"scale\", \"rotate\" or "
                    "\"translate\"; use one form");
            return {};
        }
        result = readMatrix(r, *m, mPtr);
    } else {
        // Points are scaled first, then rotated, then translated: M = T * R * S.
        Transform s, rot, t;
        if (const Json* sv = r.member(v, ptr, "scale", Presence::Optional, "")) {
            std::string sPtr = jsonPointerChild(ptr, "scale");
            Vec3 scale = sv->is_number() ? Vec3(r.number(*sv, sPtr, NumberRange::any(), 1.0f))
                                         : r.vec3(*sv, sPtr, Vec3(1.0f));
            if (scale.x == 0 || scale.y == 0 || scale.z == 0)
                r.error(sPtr,
                        "a scale factor is zero: the shape would be flattened (expected "
                        "non-zero factors)");
            else
                s = Transform::scale(scale);
        }
        if (const Json* rv = r.member(v, ptr, "rotate", Presence::Optional, ""))
            rot = readJsonRotation(r, *rv, jsonPointerChild(ptr, "rotate"));
        t = Transform::translate(r.getVec3(v, ptr, "translate", Presence::Optional, Vec3(0.0f)));
        result = t * rot * s;
    }
    float det = result.determinant3();
    if (!std::isfinite(det) || det == 0.0f) {
        r.error(ptr, "the transform is singular (determinant " + formatNumber(det) +
                         "): the shape would be flattened");
        return {};
    }
    return result;
}

namespace {

const std::vector<std::string> kShapeTypes = {"obj",    "ply",  "rectangle", "cube",
                                              "sphere", "disk", "cylinder"};

/// True if t maps spheres to spheres (rotation/reflection times a uniform scale); its
/// scale factor goes to *scale.
bool isSimilarity(const Transform& t, float* scale) {
    Vec3 c[3];
    for (int j = 0; j < 3; ++j) c[j] = Vec3(t.m[0][j], t.m[1][j], t.m[2][j]);
    float l0 = length(c[0]), l1 = length(c[1]), l2 = length(c[2]);
    *scale = l0;
    const float tol = 1e-4f;
    if (std::fabs(l1 - l0) > tol * l0 || std::fabs(l2 - l0) > tol * l0) return false;
    float l0sq = l0 * l0;
    return std::fabs(dot(c[0], c[1])) <= tol * l0sq && std::fabs(dot(c[0], c[2])) <= tol * l0sq &&
           std::fabs(dot(c[1], c[2])) <= tol * l0sq;
}

int blackEmitterMaterial(JsonSceneParts& parts) {
    const std::string name = "(black emitter)";
    auto it = parts.materialIds.find(name);
    if (it != parts.materialIds.end()) return it->second;
    Material m;
    m.type = MaterialType::Diffuse;
    m.name = name;
    m.diffuse = Rgb(0.0f);
    parts.materialIds[name] = int(parts.materials.size());
    parts.materials.push_back(m);
    return int(parts.materials.size()) - 1;
}

void readShape(JsonReader& r, const Json& v, const std::string& ptr, size_t index,
               JsonSceneParts& parts) {
    if (!r.isObject(v, ptr, "a shape object with a \"type\" key")) return;
    const Json* typeJson = r.member(v, ptr, "type", Presence::Required,
                                    "a shape type: one of " + joinNames(kShapeTypes));
    if (!typeJson) return;
    std::string typePtr = jsonPointerChild(ptr, "type");
    std::string type = r.string(*typeJson, typePtr);
    if (type.empty()) return;
    std::vector<std::string> keys = {"type",
                                     "name",
                                     "material",
                                     "transform",
                                     "emission",
                                     "emission_two_sided",
                                     "interior_medium",
                                     "priority",
                                     "imaginary"};
    if (type == "obj" || type == "ply") {
        keys.push_back("file");
    } else if (type == "sphere") {
        keys.insert(keys.end(), {"center", "radius"});
    } else if (type == "disk") {
        keys.push_back("flip_normals");
    } else if (type == "cylinder") {
        keys.insert(keys.end(), {"p0", "p1", "radius", "flip_normals"});
    } else if (type != "rectangle" && type != "cube") {
        r.error(typePtr, "unknown shape type '" + type + "'" + didYouMean(type, kShapeTypes) +
                             "; valid types: " + joinNames(kShapeTypes));
        return;
    }
    r.checkKeys(v, ptr, keys, type + " shape");
    size_t errorsBefore = r.errorCount();

    JsonShapeDesc shape;
    shape.name = v.contains("name") ? r.getString(v, ptr, "name", Presence::Optional)
                                    : type + " " + std::to_string(index);

    // Emission (optional): RGB radiance [W/(m^2 sr)] on the front side (or both sides).
    Rgb emission(0.0f);
    bool emissive = false;
    if (v.contains("emission")) {
        emission =
            r.getRgb(v, ptr, "emission", Presence::Required, NumberRange::nonNegative(), Rgb(0.0f));
        emissive = !isBlack(emission);
        if (!emissive && r.errorCount() == errorsBefore)
            r.warning(jsonPointerChild(ptr, "emission"),
                      "emission is black: the shape does not emit light");
    }
    bool twoSidedEmission = r.getBool(v, ptr, "emission_two_sided", false);
    if (v.contains("emission_two_sided") && !v.contains("emission"))
        r.error(jsonPointerChild(ptr, "emission_two_sided"),
                "\"emission_two_sided\" needs an \"emission\" on the same shape");

    // Medium boundary (docs/scene-format.md, "Media in shapes").
    shape.ptr = ptr;
    shape.imaginary = r.getBool(v, ptr, "imaginary", false);
    if (const Json* im = r.member(v, ptr, "interior_medium", Presence::Optional, "")) {
        shape.isMediumBoundary = readJsonMediumRef(r, *im, jsonPointerChild(ptr, "interior_medium"),
                                                   parts, &shape.interiorMedium);
    }
    shape.priority =
        int(r.getInteger(v, ptr, "priority", Presence::Optional, -1000000, 1000000, 0));
    if (!v.contains("interior_medium")) {
        for (const char* key : {"priority", "imaginary"})
            if (v.contains(key))
                r.error(jsonPointerChild(ptr, key),
                        std::string("\"") + key +
                            "\" needs an \"interior_medium\" on the same shape (a medium name, "
                            "or null for vacuum)");
    }
    if (shape.imaginary) {
        if (v.contains("emission"))
            r.error(jsonPointerChild(ptr, "emission"),
                    "an imaginary shape only changes the medium: it cannot emit light");
        if (v.contains("material"))
            r.error(jsonPointerChild(ptr, "material"),
                    "an imaginary shape has no surface: remove its \"material\"");
    }

    // Material: required, except on emitters (which are then black) and imaginary shapes.
    if (shape.imaginary) {
        // no material: the surface is never a path vertex
    } else if (const Json* mj =
                   r.member(v, ptr, "material",
                            v.contains("emission") ? Presence::Optional : Presence::Required,
                            "the name of a material defined in \"materials\"")) {
        std::string mPtr = jsonPointerChild(ptr, "material");
        std::string name = r.string(*mj, mPtr);
        auto it = parts.materialIds.find(name);
        if (it != parts.materialIds.end()) {
            shape.materialId = it->second;
        } else if (!name.empty()) {
            r.error(mPtr, "unknown material '" + name + "'" +
                              didYouMean(name, parts.materialNames) +
                              (parts.materialNames.empty()
                                   ? std::string(" (no materials are defined in \"materials\")")
                                   : " (defined: " + joinNames(parts.materialNames) + ")"));
        }
    } else if (v.contains("emission")) {
        shape.materialId = blackEmitterMaterial(parts);
    }

    Transform toWorld;
    if (const Json* tj = r.member(v, ptr, "transform", Presence::Optional, ""))
        toWorld = readJsonTransform(r, *tj, jsonPointerChild(ptr, "transform"));

    if (type == "sphere") {
        shape.isSphere = true;
        Vec3 center = r.getVec3(v, ptr, "center", Presence::Optional, Vec3(0.0f));
        float radius =
            r.getNumber(v, ptr, "radius", Presence::Required, NumberRange::positive(), 1.0f);
        float scale = 1.0f;
        if (!isSimilarity(toWorld, &scale)) {
            r.error(jsonPointerChild(ptr, "transform"),
                    "a sphere's transform must keep it a sphere: rotations, translations and "
                    "uniform scales only (this one scales non-uniformly or shears)");
        }
        shape.center = toWorld.point(center);
        shape.radius = radius * scale;
    } else {
        if (type == "rectangle") {
            shape.mesh = makeRectangle();
        } else if (type == "cube") {
            shape.mesh = makeCube();
        } else if (type == "disk") {
            shape.mesh = makeDisk();
        } else if (type == "cylinder") {
            // Mitsuba's cylinder: axis p0 -> p1, open (no caps); the transform may not make
            // it elliptic (docs/scene-format.md).
            const Vec3 p0 = r.getVec3(v, ptr, "p0", Presence::Optional, Vec3(0.0f));
            const Vec3 p1 = r.getVec3(v, ptr, "p1", Presence::Optional, Vec3(0, 0, 1));
            const float radius =
                r.getNumber(v, ptr, "radius", Presence::Optional, NumberRange::positive(), 1.0f);
            if (!(length(p1 - p0) > 0.0f)) {
                r.error(jsonPointerChild(ptr, v.contains("p1") ? "p1" : "p0"),
                        "p0 and p1 are the same point: they must differ (they give the "
                        "cylinder's axis)");
            } else if (radius > 0.0f) {
                const Transform placed = toWorld * cylinderPlacement(p0, p1, radius);
                if (!keepsCylinderCircular(placed))
                    r.error(jsonPointerChild(ptr, "transform"),
                            "a cylinder's transform must keep it circular: rotations, "
                            "translations and scales that are the same in every direction "
                            "across its axis, no mirroring");
                shape.mesh = makeCylinder();
                toWorld = placed;
            }
        } else {
            std::string file = r.getString(v, ptr, "file", Presence::Required);
            std::string filePtr = jsonPointerChild(ptr, "file");
            if (!file.empty()) {
                std::string ext = fs::path(file).extension().string();
                for (auto& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
                std::string path = resolveScenePath(parts.baseDir, file);
                if (ext != "." + type) {
                    r.error(filePtr, "a shape of type '" + type + "' needs a ." + type +
                                         " file, got '" + file + "'");
                } else if (!isRegularFile(path)) {
                    r.error(filePtr, "mesh file '" + file + "' not found (looked for '" + path +
                                         "'; paths are relative to the scene file)");
                } else {
                    size_t before = r.errorCount();
                    shape.mesh = loadMeshFile(path, r.diagnostics(), ptr);
                    // OBJ texture coordinates put t = 0 at the bottom of the image, textures
                    // put row 0 at v = 0: flip v as Mitsuba 3's OBJ reader does by default
                    // (its PLY reader does not, nor do we).
                    if (type == "obj")
                        for (Vec2& uv : shape.mesh.uvs) uv.y = 1.0f - uv.y;
                    if (r.errorCount() != before)
                        r.error(filePtr, "mesh file '" + file +
                                             "' could not be loaded (see the "
                                             "errors reported for it)");
                }
            }
        }
        if (shape.mesh.triangleCount() > 0) {
            if (r.getBool(v, ptr, "flip_normals", false)) {
                // Turns the normals (and the emitting side) inwards, as Mitsuba's flip_normals.
                for (size_t t = 0; t + 2 < shape.mesh.indices.size(); t += 3)
                    std::swap(shape.mesh.indices[t + 1], shape.mesh.indices[t + 2]);
                for (Vec3& n : shape.mesh.normals) n = -n;
            }
            transformMesh(shape.mesh, toWorld);
            float area = meshArea(shape.mesh);
            if (!(area > 0.0f) || !std::isfinite(area))
                r.error(ptr, std::string(emissive ? "zero-area emitter: " : "degenerate shape: ") +
                                 "the surface area of this " + type + " after its transform is " +
                                 formatNumber(area) + " (expected > 0)");
        }
    }
    if (r.errorCount() != errorsBefore) return;

    if (emissive) {
        Light light;
        light.type = LightType::Area;
        light.name = shape.name;
        light.radiance = emission;
        light.twoSided = twoSidedEmission;
        if (shape.isSphere) {
            light.isSphere = true;
            light.position = shape.center;
            light.sphereRadius = shape.radius;
        } else {
            const TriangleMesh& m = shape.mesh;
            light.triangles.reserve(m.indices.size());
            for (uint32_t idx : m.indices) light.triangles.push_back(m.positions[idx]);
        }
        shape.lightIndex = int(parts.lights.size());
        parts.lights.push_back(std::move(light));
    }
    parts.shapes.push_back(std::move(shape));
}

}  // namespace

void readJsonShapes(JsonReader& r, const Json& shapes, JsonSceneParts& parts) {
    const std::string ptr = "/shapes";
    if (!r.isArray(shapes, ptr, "an array of shape objects")) return;
    for (size_t i = 0; i < shapes.size(); ++i)
        readShape(r, shapes[i], jsonPointerChild(ptr, i), i, parts);
}

}  // namespace ub
