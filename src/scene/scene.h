// The scene: camera, shapes in an Embree 3 BVH, materials, lights and render
// settings. Built by a loader (scene/io/) through addMesh/addSphere/addLight,
// then commit(). After commit() it is immutable and safe to share between threads.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/vec.h"
#include "scene/camera.h"
#include "scene/light.h"
#include "scene/material.h"

namespace ub {

/// Triangle mesh in world space (loaders apply transforms before adding).
struct TriangleMesh {
    std::vector<Vec3> positions;
    std::vector<Vec3> normals;          ///< optional per-vertex shading normals (empty or = positions.size())
    std::vector<Vec2> uvs;              ///< optional per-vertex uvs
    std::vector<uint32_t> indices;      ///< 3 per triangle
    size_t triangleCount() const { return indices.size() / 3; }
};

/// Surface interaction returned by Scene::intersect.
struct Hit {
    float dist = kInf;         ///< ray parameter of the hit (ray.dir is unit: distance)
    Vec3 pos;
    Vec3 geoNormal;            ///< unit geometric normal as defined by the shape (front side)
    Vec3 shadingNormal;        ///< unit shading normal, in the same hemisphere as geoNormal
    Vec2 uv;
    uint32_t shapeId = 0;
    uint32_t primId = 0;
    int materialId = -1;
    int lightId = -1;          ///< index into Scene::lights if the shape is emissive, else -1
};

/// What the renderer needs from the scene file besides geometry.
struct RenderSettings {
    int maxPathLength = 10;    ///< max number of path segments (SmallVCM semantics)
    int minPathLength = 0;     ///< paths with fewer segments do not contribute
    uint64_t seed = 1;
};

struct ShapeInfo {
    std::string name;
    bool isSphere = false;
    int materialId = -1;
    int lightId = -1;
    size_t triangleCount = 0;  ///< 0 for spheres
    Bounds3 bounds;
};

class Scene {
public:
    Scene();
    ~Scene();
    Scene(const Scene&) = delete;
    Scene& operator=(const Scene&) = delete;

    // ---- building ----
    int addMaterial(const Material& m);
    int addLight(Light l);  ///< calls l.prepare() if not yet done; returns its index
    /// Adds a triangle mesh; returns the shape id. lightId links an area light (or -1).
    uint32_t addMesh(TriangleMesh mesh, int materialId, int lightId, const std::string& name);
    uint32_t addSphere(const Vec3& center, float radius, int materialId, int lightId,
                       const std::string& name);
    /// Builds the BVH and the scene bounding sphere. Must be called once, after which the
    /// scene is read-only.
    void commit();

    // ---- queries (thread-safe after commit) ----
    /// Closest hit along ray in (ray.tMin, ray.tMax). Returns false on a miss.
    bool intersect(const Ray& ray, Hit* hit) const;
    /// True if anything blocks the open segment between the two points. Each end is
    /// offset along its geometric normal (pass a zero vector for points not on a
    /// surface, e.g. the camera or a point light) towards the other end.
    bool occluded(const Vec3& a, const Vec3& geoNormalA, const Vec3& b,
                  const Vec3& geoNormalB) const;
    /// True if anything blocks the ray from `from` (offset along geoNormal) in direction dir
    /// (used for lights at infinity).
    bool occludedToInfinity(const Vec3& from, const Vec3& geoNormal, const Vec3& dir) const;
    /// Ray leaving a surface hit in direction dir, with its origin offset to the side of dir.
    Ray spawnRay(const Hit& hit, const Vec3& dir) const;

    // ---- data ----
    Camera camera;
    RenderSettings settings;
    std::vector<Material> materials;
    std::vector<Light> lights;
    int backgroundLightId = -1;   ///< environment light hit by escaping rays, or -1
    SceneSphere sceneSphere;      ///< bounding sphere of the geometry (and camera)
    Bounds3 bounds;
    std::vector<ShapeInfo> shapes;
    std::string sourceFile;       ///< path the scene was loaded from

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace ub
