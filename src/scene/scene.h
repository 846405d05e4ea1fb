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
#include "scene/medium.h"
#include "scene/medium_stack.h"
#include "scene/medium_trace.h"
#include "scene/pixel_filter.h"
#include "scene/texture.h"

namespace ub {

class Rng;

class Bsdf;
struct SurfaceColors;

/// A named per-vertex or per-triangle value of a mesh (Mitsuba 3's mesh attributes, read
/// from PLY files: `vertex_color`, `face_weight`, ...), looked up by `mesh_attribute`
/// textures. Per-vertex values are interpolated with the hit's barycentrics.
struct MeshAttribute {
    std::string name;           ///< "vertex_<prefix>" or "face_<prefix>" (Mitsuba's naming)
    bool perFace = false;       ///< one value per triangle (else per vertex)
    int channels = 3;           ///< 1 (grey, replicated to RGB) or 3
    std::vector<float> values;  ///< channels per vertex or triangle
};

/// Triangle mesh in world space (loaders apply transforms before adding).
struct TriangleMesh {
    std::vector<Vec3> positions;
    std::vector<Vec3>
        normals;            ///< optional per-vertex shading normals (empty or = positions.size())
    std::vector<Vec2> uvs;  ///< optional per-vertex uvs
    std::vector<uint32_t> indices;  ///< 3 per triangle
    /// Attributes read from the file (PLY). Scene::addMesh keeps the one at index
    /// boundAttribute, which the shape's material looks up (set by the Mitsuba loader), and
    /// fills Hit::attribute with it; -1: none.
    std::vector<MeshAttribute> attributes;
    int boundAttribute = -1;
    size_t triangleCount() const { return indices.size() / 3; }
};

/// Surface interaction returned by Scene::intersect.
struct Hit {
    float dist = kInf;  ///< ray parameter of the hit (ray.dir is unit: distance)
    Vec3 pos;
    Vec3 geoNormal;      ///< unit geometric normal as defined by the shape (front side)
    Vec3 shadingNormal;  ///< unit shading normal, in the same hemisphere as geoNormal (with
                         ///< the material's normal or bump map applied)
    Vec2 uv;
    /// The value of the shape's mesh attribute here (MeshAttribute; 0 without one): what a
    /// `mesh_attribute` texture of its material returns.
    Rgb attribute{0.0f, 0.0f, 0.0f};
    /// Mitsuba's shading tangent s: dp/du of the shape's uv parameterisation made orthogonal
    /// to the shading normal before its normal or bump map is applied, unit; set only where
    /// the material needs it (anisotropic roughness or a perturbed normal; zero elsewhere).
    Vec3 tangent{0.0f, 0.0f, 0.0f};
    uint32_t shapeId = 0;
    uint32_t primId = 0;
    int materialId = -1;
    int lightId = -1;  ///< index into Scene::lights if the shape is emissive, else -1
    /// Set by Scene::intersectNearest: only dist, shapeId, primId, materialId, lightId and the
    /// ray point pos = org + dist dir are set; Scene::completeHit fills in the rest (from
    /// Embree's barycentrics below) and clears it.
    bool detailPending = false;
    float baryU = 0.0f, baryV = 0.0f;  ///< Embree's: p = (1-u-v) p0 + u p1 + v p2
};

/// How the medium of a path changes where it crosses a medium boundary.
enum class MediumTransitions : uint8_t {
    /// Nested media with priorities (scene/medium_stack.h; SmallUPBP): the medium is the
    /// highest-priority one among the boundaries the path is inside. JSON and SmallUPBP scenes.
    kPriorityStack,
    /// Mitsuba 3: crossing a boundary sets the medium to that shape's interior medium when
    /// entering it and to its exterior medium (ShapeInfo::exteriorMediumId, vacuum if none)
    /// when leaving it, whatever other boundaries the path is inside; every boundary that is
    /// not imaginary is a real surface. Set by the Mitsuba XML loader.
    kShapeSides,
};

/// Which vertices count towards RenderSettings::maxPathLength.
enum class DepthCounting : uint8_t {
    /// Every surface and medium vertex (SmallVCM): a path of k segments has length k.
    kAllVertices,
    /// Mitsuba 3's volpath: a surface vertex whose sampled lobe continues the ray unchanged
    /// (Bsdf::isNullEvent, Mitsuba's Null flag: thin-sheet transmission) is not counted,
    /// like an imaginary boundary. Set by the Mitsuba XML loader.
    kNonNullVertices,
};

/// Which BSDF directions survive where a shading normal disagrees with the geometric one.
enum class ShadingNormals : uint8_t {
    /// Geometric-normal guard (scene/bsdf.h): a reflected direction must stay on the incoming
    /// side of the geometric surface and a transmitted one must cross it, otherwise it is
    /// dropped (no light leaks through smooth-shaded meshes). JSON and SmallUPBP scenes.
    kGeometricGuard,
    /// Mitsuba 3: the lobe in the shading frame alone decides (its BSDFs never look at the
    /// geometric normal), so at grazing hits on smooth-shaded meshes a refracted ray may stay
    /// on the incoming side and a reflected one cross. Set by the Mitsuba XML loader.
    kShadingOnly,
};

/// What the renderer needs from the scene file besides geometry.
struct RenderSettings {
    int maxPathLength = 10;  ///< max number of path segments (SmallVCM semantics)
    int minPathLength = 0;   ///< paths with fewer segments do not contribute
    uint64_t seed = 1;
    /// --resolution keeps the horizontal field of view instead of the vertical one
    /// (SmallUPBP scenes: its -r keeps CAMERA_FOV, a horizontal angle).
    bool keepHorizontalFov = false;
    MediumTransitions mediumTransitions = MediumTransitions::kPriorityStack;
    DepthCounting depthCounting = DepthCounting::kAllVertices;
    ShadingNormals shadingNormals = ShadingNormals::kGeometricGuard;
    /// Reconstruction filter, sampled per camera path and spread over by light-tracing splats
    /// (scene/pixel_filter.h). Box for JSON and SmallUPBP scenes; Mitsuba's `rfilter`.
    PixelFilter pixelFilter;
    /// Algorithm `unibeam render` uses when -a is not given (empty: pt). Mitsuba's `ptracer`
    /// integrator sets lt.
    std::string defaultAlgorithm;
    /// Mitsuba's `aov` integrator: arbitrary output variables written as extra EXR layers
    /// beside the image (render/aov.h); name and type (depth, position, uv, geo_normal,
    /// sh_normal, prim_index, shape_index).
    struct Aov {
        std::string name, type;
    };
    std::vector<Aov> aovs;
};

struct SdfGrid;

struct ShapeInfo {
    std::string name;
    bool isSphere = false;
    bool isSdfGrid = false;  ///< Mitsuba's sdfgrid (scene/sdf_grid.h): no triangles, no uvs
    int materialId = -1;
    int lightId = -1;
    size_t triangleCount = 0;  ///< 0 for spheres
    Bounds3 bounds;
    // Medium boundary (scene/medium_stack.h); set by Scene::setMediumBoundary.
    bool isMediumBoundary = false;
    int interiorMediumId = -1;  ///< index into Scene::media, -1 = vacuum
    /// Medium outside the shape (-1 = vacuum); MediumTransitions::kShapeSides only.
    int exteriorMediumId = -1;
    int mediumPriority = 0;
    bool imaginary = false;  ///< changes the medium only: never scatters nor emits
};

/// Largest |coordinate| of the camera, shapes and point lights a scene may have (see
/// Scene::commit).
constexpr float kMaxCoordinate = 1e7f;

class Scene {
  public:
    Scene();
    ~Scene();
    Scene(const Scene&) = delete;
    Scene& operator=(const Scene&) = delete;

    // ---- building ----
    int addMaterial(const Material& m);
    int addLight(Light l);  ///< calls l.prepare() if not yet done; returns its index
    /// Validates t (Texture::validate) and returns its index for MaterialTextures.
    int addTexture(const Texture& t);
    /// Adds a triangle mesh; returns the shape id. lightId links an area light (or -1).
    uint32_t addMesh(TriangleMesh mesh, int materialId, int lightId, const std::string& name);
    uint32_t addSphere(const Vec3& center, float radius, int materialId, int lightId,
                       const std::string& name);
    /// Adds a Mitsuba `sdfgrid` (scene/sdf_grid.h), one Embree user primitive per voxel the
    /// surface crosses. It cannot emit nor bound a medium.
    uint32_t addSdfGrid(std::shared_ptr<const SdfGrid> grid, int materialId,
                        const std::string& name);
    /// Adds a participating medium; returns its id (index into media).
    int addMedium(const Medium& m, const std::string& name);
    /// Declares shape shapeId a medium boundary (scene/medium_stack.h): interior medium
    /// (-1 = vacuum), priority, imaginary or not.
    void setMediumBoundary(uint32_t shapeId, int interiorMediumId, int priority, bool imaginary);
    /// Sets the exterior medium of boundary shapeId (after setMediumBoundary); only valid with
    /// settings.mediumTransitions == kShapeSides (mediumIssues() reports it otherwise).
    void setExteriorMedium(uint32_t shapeId, int exteriorMediumId);
    /// Problems with the media set-up (open boundary meshes, conflicting priorities, too
    /// deep nesting, bad medium ids), one per offending shape or medium; empty if valid.
    /// Callable before commit() (loaders use it to point at the file position).
    std::vector<MediumIssue> mediumIssues() const;
    /// Builds the BVH and the scene bounding sphere. Must be called once, after which the
    /// scene is read-only. Throws InputError (naming sourceFile and each shape) if
    /// mediumIssues() is not empty; computes cameraMediumStack.
    void commit();

    // ---- queries (thread-safe after commit) ----
    /// Closest hit along ray in (ray.tMin, ray.tMax). Returns false on a miss.
    bool intersect(const Ray& ray, Hit* hit) const;
    /// The same hit, with only what tells where it is and what it is (Hit::detailPending):
    /// a medium walk whose path scatters before the surface needs no more. The rest (point on
    /// the triangle, normals, uv, tangent, attribute) reads the mesh's indices and vertices,
    /// two dependent cache misses that were half of intersect()'s own time (perf, the
    /// bunny's bb1d camera pass).
    bool intersectNearest(const Ray& ray, Hit* hit) const;
    /// Completes a hit of intersectNearest along the same ray (nothing if already complete):
    /// the same values as intersect() gives.
    void completeHit(const Ray& ray, Hit* hit) const;
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
    /// The origin offset spawnRay/occluded use: p moved off the surface with unit normal n
    /// (zero: not on a surface, not moved) to the side of dir.
    static Vec3 offsetRayOrigin(const Vec3& p, const Vec3& n, const Vec3& dir);
    /// The length of that offset at p.
    static float rayOffsetLength(const Vec3& p);
    /// True if every surface a ray starting with this medium stack can meet is real for it
    /// (no boundary is imaginary or of a lower priority than the stack's): the first hit
    /// ends a shadow walk, so an any-hit query answers it.
    bool everyHitIsReal(const MediumStack& stack) const;
    /// True if the ray org + t dir meets any surface for t in [0, tMax] (Embree's any-hit
    /// query; false where intersect() would find nothing, e.g. on a NaN ray).
    bool anyHitWithin(const Vec3& org, const Vec3& dir, float tMax) const;
    /// A surface a shadow ray passes without being blocked by it for certain: a medium
    /// boundary that is imaginary, or of a priority some medium stack can exceed.
    struct ShadowCrossing {
        float t;           ///< ray parameter
        uint32_t shapeId;  ///< a triangle mesh
        bool entering;     ///< against the geometric normal intersect() gives (crossBoundary)
    };
    /// How shadowCrossings answered.
    enum class ShadowQuery { kBlocked, kOpen, kUnavailable };
    /// One Embree any-hit traversal of the open segment org + t dir, t in (0, tMax) (tMax
    /// kInf: to infinity), for a shadow walk through media (walkShadow in scene_media.cpp).
    /// kBlocked: the segment meets a surface that is real for every medium stack (not a
    /// boundary, or a boundary that is not imaginary and of the highest priority). kOpen: it
    /// does not; crossings[0 .. *count) are the other surfaces it meets, by increasing t, a
    /// crossing reported twice (a ray through a shared edge or vertex, a triangle Embree
    /// references from two leaves) once. kUnavailable: the caller walks hit by hit instead (a
    /// sphere or SDF boundary could be such a surface, since their intersectors do not call
    /// Embree's filter, or more than `capacity` crossings).
    ShadowQuery shadowCrossings(const Vec3& org, const Vec3& dir, float tMax,
                                ShadowCrossing* crossings, int capacity, int* count) const;
    /// Vertices of triangle `tri` of mesh shape shapeId (world space).
    void meshTriangle(uint32_t shapeId, uint32_t tri, Vec3 p[3]) const;

    // ---- media (thread-safe after commit; scene/medium_trace.h) ----
    /// True if any medium can be met: a global medium or a boundary.
    bool hasMedia() const;
    /// Stack of the media containing point p (traces to infinity, counting crossings). With
    /// kShapeSides: the medium on p's side of the nearest boundary (majority of three rays).
    MediumStack mediumStackAt(const Vec3& p) const;
    /// Crosses boundary shapeId along direction dir at a hit with geometric normal n
    /// (push or pop; with kShapeSides the stack becomes that side's medium alone). False if
    /// the stack is full (the path must end).
    bool crossBoundary(uint32_t shapeId, const Vec3& geoNormal, const Vec3& dir,
                       MediumStack* stack) const;
    /// Crosses boundary shapeId, entering or leaving it, by the scene's MediumTransitions.
    bool applyCrossing(uint32_t shapeId, bool entering, MediumStack* stack) const;
    /// Whether a hit on shape shapeId is a real surface for a medium stack of this priority
    /// (scene/medium_stack.h): not a boundary, or a boundary that is not imaginary and of at
    /// least that priority; else the path passes it and crosses.
    bool realFor(uint32_t shapeId, int32_t stackPriority) const {
        const ShapeInfo& s = shapes[shapeId];
        return !s.isMediumBoundary || (!s.imaginary && s.mediumPriority >= stackPriority);
    }
    /// At a real surface hit reached along -dirFix with stack *stack (the incoming side):
    /// updates the stack for a continuation dirGen (crosses the shape if dirGen leaves on the
    /// other side of the geometric surface). False on stack overflow.
    bool crossSurface(const Hit& hit, const Vec3& dirFix, const Vec3& dirGen,
                      MediumStack* stack) const;
    /// Traces ray to the next real surface (or to infinity), recording the medium segments
    /// it crosses; imaginary and skipped boundaries update *stack and create no vertex.
    /// On return *stack is the stack on the incoming side of the real hit, *hit the hit
    /// (valid if trace->hitSurface; hit->dist is the distance from the last crossing), still
    /// to be completed (Scene::completeHit with trace->hitRay) where the path reaches it. The
    /// last segment ends at the ray's point at hit->dist.
    ///
    /// lookahead (optional): a copy of the generator that will sample free flight along the
    /// chain (render/medium_walk.h: two numbers per medium segment, channel then distance).
    /// In a homogeneous segment the sampled distance t does not depend on where the segment
    /// ends, so the ray is cut just past t: if it meets nothing there, sampling stops inside
    /// this segment and what lies beyond is never needed (trace->truncated). A short ray
    /// costs Embree far fewer nodes than one to the next wall. Callers that need the whole
    /// chain (long beams) pass none.
    void traceMedia(const Ray& ray, MediumStack* stack, MediumTrace* trace, Hit* hit,
                    Rng* lookahead = nullptr) const;
    /// The media that traceMedia crossed up to (not including) segment k: applies the first
    /// k crossings of trace to *stack (which must be the stack the trace started with).
    void replayCrossings(const MediumTrace& trace, int k, MediumStack* stack) const;
    /// Transmittance (0 if a real surface blocks) of the segment a -> b through media and
    /// imaginary/skipped boundaries, with the distance pdfs of both directions. stackA is
    /// the stack at a for the direction towards b. Ends are offset as in occluded().
    MediumShadow shadowTransmittance(const Vec3& a, const Vec3& geoNormalA,
                                     const MediumStack& stackA, const Vec3& b,
                                     const Vec3& geoNormalB) const;
    /// Same towards infinity along dir (directional and environment lights).
    MediumShadow shadowTransmittanceToInfinity(const Vec3& a, const Vec3& geoNormalA,
                                               const MediumStack& stackA, const Vec3& dir) const;
    /// Sets up the BSDF of the hit's material with its textures looked up at hit.uv
    /// (scene_textures.cpp). Every integrator builds its BSDFs through this. Returns
    /// Bsdf::setup's result; false (and an invalid Bsdf) if the hit has no material.
    bool setupBsdf(Bsdf* bsdf, const Hit& hit, const Vec3& dirFix, bool fromLight) const;
    /// The same from stored vertex data (e.g. a light vertex kept for later connections):
    /// uv and the mesh attribute value (Hit::attribute) where the textures are looked up,
    /// and the shading tangent (Hit::tangent).
    bool setupBsdf(Bsdf* bsdf, int materialId, const Vec2& uv, const Rgb& attribute,
                   const Vec3& dirFix, const Vec3& geoNormal, const Vec3& shadingNormal,
                   const Vec3& tangent, bool fromLight) const;
    /// The material's RGB parameters and roughness at uv (textures looked up,
    /// `mesh_attribute` textures give attribute, constants otherwise).
    SurfaceColors surfaceColors(const Material& m, const Vec2& uv, const Rgb& attribute) const;

    // ---- data ----
    Camera camera;
    RenderSettings settings;
    std::vector<Material> materials;
    std::vector<Light> lights;
    std::vector<Texture> textures;  ///< referenced by Material::textures
    int backgroundLightId = -1;     ///< environment light hit by escaping rays, or -1
    SceneSphere sceneSphere;  ///< bounding sphere of the geometry only (as SmallVCM; the camera may
                              ///< lie outside)
    Bounds3 bounds;
    std::vector<ShapeInfo> shapes;
    std::string sourceFile;  ///< path the scene was loaded from
    std::vector<Medium> media;
    std::vector<std::string> mediumNames;  ///< parallel to media
    int globalMediumId = -1;               ///< medium outside every boundary (-1 = vacuum)
    MediumStack cameraMediumStack;         ///< set by commit(): media at the camera position

  private:
    MediumStack mediumStackAtShapeSides(const Vec3& p) const;
    /// True if material materialId has a normal or bump map (Material::perturbation).
    bool perturbs(int materialId) const;
    /// True if the material's BSDF needs Hit::tangent (a perturbed normal, or anisotropic
    /// roughness, also in a blend's parts).
    bool needsTangent(int materialId) const;
    /// Replaces hit->shadingNormal by its material's perturbed normal (tangents dpdu, dpdv).
    void perturbShadingNormal(Hit* hit, const Vec3& dpdu, const Vec3& dpdv) const;

    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace ub
