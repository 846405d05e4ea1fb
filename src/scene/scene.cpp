// Scene geometry on Embree 3: triangle meshes (RTC_GEOMETRY_TYPE_TRIANGLE) and
// analytic spheres (user geometry), one Embree geometry per shape, geomID = shapeId.
//
// ---- Self-intersection ---------------------------------------------------------
// A hit point computed in floating point lies only near the surface, so a ray
// leaving it can hit the same surface again at t ~ 0 ("surface acne"), or a ray
// entering a closed object can start on the wrong side and escape. We avoid both
// by moving ray origins off the surface along the geometric normal, to the side
// of the outgoing direction (pbrt-v4 Sec. 6.8.6 does the same with a per-hit
// error bound; Mitsuba 3 uses a relative epsilon as we do):
//
//     origin = p + sign(dot(n_g, dir)) * eps(p) * n_g,
//     eps(p) = kRayEpsilon * (1 + max_i |p_i|).
//
// Why this bound suffices:
//  * Triangle hits: p is interpolated from the vertices with the barycentrics
//    Embree returns (not org + t*dir, whose error grows with t), so its distance
//    to the triangle's plane is a few ulps of the coordinates, ~1e-7 * |p|.
//    kRayEpsilon = 1e-5 leaves a margin of ~100 over that and over the error of
//    Embree's own watertight (RTC_SCENE_FLAG_ROBUST) test on the plane side.
//  * Sphere hits: solved in double with the cancellation-free quadratic of
//    Haines et al., "Precision Improvements for Ray/Sphere Intersection" (Ray
//    Tracing Gems, ch. 7, 2019), then re-projected onto the sphere, so p is within
//    an ulp or two of the surface.
//  * The "1 +" term is an absolute floor for points near the world origin on
//    triangles whose vertices are far away (unit-scale scenes).
// Because the offset is along the normal (not along dir), the origin is at
// distance eps from the tangent plane for every direction: a ray leaving a plane
// or the convex side of a sphere cannot re-hit it, and a ray entering a closed
// surface starts strictly inside it. Offsets are applied in spawnRay(),
// occluded() (both ends, each towards the other) and occludedToInfinity(); a zero
// normal marks a point not on a surface (camera, point light) and is not moved.
// Cost: contact shadows and inter-reflections closer than eps(p) are lost,
// i.e. features below ~1e-5 of the coordinate magnitude.
// ---------------------------------------------------------------------------------
#include "scene/scene.h"

#include <embree3/rtcore.h>
#if defined(__SSE2__)
#include <pmmintrin.h>
#endif

#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

#include "core/error.h"
#include "scene/bsdf.h"
#include "scene/normal_perturbation.h"
#include "scene/ray_stats.h"
#include "scene/sdf_grid.h"

namespace ub {

namespace {

#if defined(__SSE2__)
/// One floating-point mode for every rendering thread: denormal results flushed to zero and
/// denormal inputs read as zero (MXCSR's FTZ and DAZ bits), as Embree asks of every thread
/// that traces (Embree 3 API manual, "Performance Recommendations"). Embree's scene builds
/// leave TBB's worker threads in that mode, and TBB applies to its tasks the mode of the
/// thread that started the arena, so before this setting whether a render flushed depended on
/// which came first, and a one-thread arena the main thread started later did not flush: two
/// of 576 bunny pixels (upbp:bb1d, long photon beams) differed between one thread and two, at
/// 2e-36 and 3e-42 (Upbp.BeamOnlySetsTraceOnlyTheBeamPaths, tests/upbp_test.cpp). Set before
/// main() on the main thread, so every thread started later (TBB's, PoCL's) inherits it and
/// every arena captures it. PoCL's kernels run in a mode of their own that keeps denormals
/// (docs/opencl.md, floating point).
[[maybe_unused]] const bool kFlushDenormals = [] {
    _mm_setcsr(_mm_getcsr() | _MM_FLUSH_ZERO_ON | _MM_DENORMALS_ZERO_ON);
    return true;
}();
#endif

/// Embree's own check (RayK::valid): finite origin and direction within 1.844e18, tnear and
/// tfar not NaN. An invalid ray would abort in Embree's assertion; such rays come only from
/// NaN arithmetic upstream (a contribution the film's guard drops anyway).
bool embreeRayValid(const Vec3& o, const Vec3& d, float tNear, float tFar) {
    const float kLarge = 1.844e18f;
    for (int a = 0; a < 3; ++a)
        if (!(std::fabs(o[a]) <= kLarge) || !(std::fabs(d[a]) <= kLarge)) return false;
    return !std::isnan(tNear) && !std::isnan(tFar);
}

/// Embree's ray for org + t dir, t in [tNear, tFar], every mask bit set.
RTCRay embreeRay(const Vec3& org, const Vec3& dir, float tNear, float tFar) {
    RTCRay r;
    r.org_x = org.x;
    r.org_y = org.y;
    r.org_z = org.z;
    r.dir_x = dir.x;
    r.dir_y = dir.y;
    r.dir_z = dir.z;
    r.tnear = tNear;
    r.tfar = tFar;
    r.time = 0.0f;
    r.mask = ~0u;
    r.id = 0;
    r.flags = 0;
    return r;
}

}  // namespace

namespace {

constexpr float kRayEpsilon = 1e-5f;
constexpr double kPiD = 3.14159265358979323846;

float maxAbs(const Vec3& p) {
    return std::max(std::abs(p.x), std::max(std::abs(p.y), std::abs(p.z)));
}

/// Origin offset of the comment block above; n is a unit normal or zero.
Vec3 offsetOrigin(const Vec3& p, const Vec3& n, const Vec3& dir) {
    const float eps = Scene::rayOffsetLength(p);
    return p + n * (dot(n, dir) >= 0.0f ? eps : -eps);
}

const char* embreeErrorName(RTCError e) {
    switch (e) {
        case RTC_ERROR_NONE:
            return "no error";
        case RTC_ERROR_UNKNOWN:
            return "unknown error";
        case RTC_ERROR_INVALID_ARGUMENT:
            return "invalid argument";
        case RTC_ERROR_INVALID_OPERATION:
            return "invalid operation";
        case RTC_ERROR_OUT_OF_MEMORY:
            return "out of memory";
        case RTC_ERROR_UNSUPPORTED_CPU:
            return "unsupported CPU (Embree needs at least SSE2)";
        case RTC_ERROR_CANCELLED:
            return "cancelled";
    }
    return "unrecognised error code";
}

/// Last error message reported by Embree on this thread (Embree keeps error codes
/// per thread too, so queries and builds on different threads do not mix).
thread_local std::string tlsEmbreeMessage;

void embreeErrorCallback(void*, RTCError code, const char* str) {
    tlsEmbreeMessage = std::string(embreeErrorName(code)) + (str ? std::string(": ") + str : "");
}

struct SphereGeom {
    Vec3 center;
    float radius;
};

/// Both roots of |o + t d - c|^2 = r^2 in double, without catastrophic
/// cancellation (Haines et al. 2019, Eqs. 7.5-7.8): the discriminant is formed from
/// the squared distance of c to the ray line, and the smaller-magnitude root from
/// Vieta's formula. Returns false if the line misses the sphere.
bool solveSphere(const SphereGeom& s, double ox, double oy, double oz, double dx, double dy,
                 double dz, double* t0, double* t1) {
    double fx = ox - s.center.x, fy = oy - s.center.y, fz = oz - s.center.z;
    double a = dx * dx + dy * dy + dz * dz;
    double b = fx * dx + fy * dy + fz * dz;  // half the linear coefficient
    double r2 = double(s.radius) * double(s.radius);
    double lx = fx - (b / a) * dx, ly = fy - (b / a) * dy, lz = fz - (b / a) * dz;
    double disc = a * (r2 - (lx * lx + ly * ly + lz * lz));  // = b^2 - a c
    if (disc < 0.0) return false;
    double c = fx * fx + fy * fy + fz * fz - r2;
    double q = -(b + std::copysign(std::sqrt(disc), b));
    double ta, tb;
    if (q == 0.0) {
        ta = tb = 0.0;  // tangent ray through the origin's closest point
    } else {
        ta = q / a;
        tb = c / q;
    }
    *t0 = std::min(ta, tb);
    *t1 = std::max(ta, tb);
    return true;
}

void sphereBounds(const RTCBoundsFunctionArguments* args) {
    const auto* s = static_cast<const SphereGeom*>(args->geometryUserPtr);
    // Slightly enlarged so that float rounding of the box never clips the sphere.
    float r = s->radius * (1.0f + 1e-6f) + 1e-7f * (1.0f + maxAbs(s->center));
    RTCBounds* b = args->bounds_o;
    b->lower_x = s->center.x - r;
    b->lower_y = s->center.y - r;
    b->lower_z = s->center.z - r;
    b->upper_x = s->center.x + r;
    b->upper_y = s->center.y + r;
    b->upper_z = s->center.z + r;
}

void sphereIntersect(const RTCIntersectFunctionNArguments* args) {
    const auto* s = static_cast<const SphereGeom*>(args->geometryUserPtr);
    const unsigned N = args->N;
    RTCRayN* ray = RTCRayHitN_RayN(args->rayhit, N);
    RTCHitN* hit = RTCRayHitN_HitN(args->rayhit, N);
    for (unsigned i = 0; i < N; ++i) {
        if (!args->valid[i]) continue;
        double ox = RTCRayN_org_x(ray, N, i), oy = RTCRayN_org_y(ray, N, i),
               oz = RTCRayN_org_z(ray, N, i);
        double dx = RTCRayN_dir_x(ray, N, i), dy = RTCRayN_dir_y(ray, N, i),
               dz = RTCRayN_dir_z(ray, N, i);
        double t0, t1;
        if (!solveSphere(*s, ox, oy, oz, dx, dy, dz, &t0, &t1)) continue;
        double tnear = RTCRayN_tnear(ray, N, i), tfar = RTCRayN_tfar(ray, N, i);
        // Nearest root inside (tnear, tfar): the far root when the origin is inside.
        double t = (t0 > tnear) ? t0 : t1;
        if (!(t > tnear && t < tfar)) continue;
        RTCRayN_tfar(ray, N, i) = float(t);
        RTCHitN_Ng_x(hit, N, i) = float(ox + t * dx - s->center.x);
        RTCHitN_Ng_y(hit, N, i) = float(oy + t * dy - s->center.y);
        RTCHitN_Ng_z(hit, N, i) = float(oz + t * dz - s->center.z);
        RTCHitN_u(hit, N, i) = 0.0f;
        RTCHitN_v(hit, N, i) = 0.0f;
        RTCHitN_primID(hit, N, i) = args->primID;
        RTCHitN_geomID(hit, N, i) = args->geomID;
        RTCHitN_instID(hit, N, i, 0) = args->context->instID[0];
    }
}

void sphereOccluded(const RTCOccludedFunctionNArguments* args) {
    const auto* s = static_cast<const SphereGeom*>(args->geometryUserPtr);
    const unsigned N = args->N;
    RTCRayN* ray = args->ray;
    for (unsigned i = 0; i < N; ++i) {
        if (!args->valid[i]) continue;
        double t0, t1;
        if (!solveSphere(*s, RTCRayN_org_x(ray, N, i), RTCRayN_org_y(ray, N, i),
                         RTCRayN_org_z(ray, N, i), RTCRayN_dir_x(ray, N, i),
                         RTCRayN_dir_y(ray, N, i), RTCRayN_dir_z(ray, N, i), &t0, &t1))
            continue;
        double tnear = RTCRayN_tnear(ray, N, i), tfar = RTCRayN_tfar(ray, N, i);
        if ((t0 > tnear && t0 < tfar) || (t1 > tnear && t1 < tfar))
            RTCRayN_tfar(ray, N, i) = -std::numeric_limits<float>::infinity();
    }
}

void sdfBounds(const RTCBoundsFunctionArguments* args) {
    const auto* g = static_cast<const SdfGrid*>(args->geometryUserPtr);
    const Bounds3& b = g->voxelBounds[args->primID];
    RTCBounds* o = args->bounds_o;
    o->lower_x = b.lo.x;
    o->lower_y = b.lo.y;
    o->lower_z = b.lo.z;
    o->upper_x = b.hi.x;
    o->upper_y = b.hi.y;
    o->upper_z = b.hi.z;
}

void sdfIntersect(const RTCIntersectFunctionNArguments* args) {
    const auto* g = static_cast<const SdfGrid*>(args->geometryUserPtr);
    const unsigned N = args->N;
    RTCRayN* ray = RTCRayHitN_RayN(args->rayhit, N);
    RTCHitN* hit = RTCRayHitN_HitN(args->rayhit, N);
    for (unsigned i = 0; i < N; ++i) {
        if (!args->valid[i]) continue;
        const Vec3 o(RTCRayN_org_x(ray, N, i), RTCRayN_org_y(ray, N, i), RTCRayN_org_z(ray, N, i));
        const Vec3 d(RTCRayN_dir_x(ray, N, i), RTCRayN_dir_y(ray, N, i), RTCRayN_dir_z(ray, N, i));
        float t;
        if (!g->intersect(args->primID, o, d, RTCRayN_tnear(ray, N, i), RTCRayN_tfar(ray, N, i),
                          &t))
            continue;
        Vec3 ng, ns;
        g->normals(args->primID, o + t * d, &ng, &ns);
        RTCRayN_tfar(ray, N, i) = t;
        RTCHitN_Ng_x(hit, N, i) = ng.x;
        RTCHitN_Ng_y(hit, N, i) = ng.y;
        RTCHitN_Ng_z(hit, N, i) = ng.z;
        RTCHitN_u(hit, N, i) = 0.0f;
        RTCHitN_v(hit, N, i) = 0.0f;
        RTCHitN_primID(hit, N, i) = args->primID;
        RTCHitN_geomID(hit, N, i) = args->geomID;
        RTCHitN_instID(hit, N, i, 0) = args->context->instID[0];
    }
}

void sdfOccluded(const RTCOccludedFunctionNArguments* args) {
    const auto* g = static_cast<const SdfGrid*>(args->geometryUserPtr);
    const unsigned N = args->N;
    RTCRayN* ray = args->ray;
    for (unsigned i = 0; i < N; ++i) {
        if (!args->valid[i]) continue;
        const Vec3 o(RTCRayN_org_x(ray, N, i), RTCRayN_org_y(ray, N, i), RTCRayN_org_z(ray, N, i));
        const Vec3 d(RTCRayN_dir_x(ray, N, i), RTCRayN_dir_y(ray, N, i), RTCRayN_dir_z(ray, N, i));
        float t;
        if (g->intersect(args->primID, o, d, RTCRayN_tnear(ray, N, i), RTCRayN_tfar(ray, N, i), &t))
            RTCRayN_tfar(ray, N, i) = -std::numeric_limits<float>::infinity();
    }
}

/// Per-shape data needed to fill a Hit. Vertex and index arrays live in Embree's
/// buffers (no second copy).
struct ShapeGeom {
    bool isSphere = false;
    std::unique_ptr<SphereGeom> sphere;  // stable address: Embree's user data pointer
    std::shared_ptr<const SdfGrid> sdf;  // sdfgrid shapes
    const float* vertices = nullptr;     // 3 floats per vertex (Embree buffer)
    const uint32_t* indices = nullptr;   // 3 per triangle (Embree buffer)
    std::vector<Vec3> normals;
    std::vector<Vec2> uvs;
    MeshAttribute attribute;  // the one bound to the shape's material (channels 0: none)
};

}  // namespace

struct Scene::Impl {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    std::vector<ShapeGeom> geoms;
    bool committed = false;
    /// Every medium boundary is a real surface for a stack of at most this priority (the
    /// lowest boundary priority; INT32_MAX if there are none), unless some boundary is
    /// imaginary. Set by commit().
    int32_t allBoundariesRealUpTo = INT32_MAX;
    bool anyImaginaryBoundary = false;
    /// Per shape: real for every medium stack (shadowCrossings). Set by commit().
    std::vector<uint8_t> alwaysReal;
    /// Every shape that is not always real is a triangle mesh (shadowCrossings).
    bool crossingsByFilter = false;

    ~Impl() {
        if (scene) rtcReleaseScene(scene);
        if (device) rtcReleaseDevice(device);
    }

    /// Throws std::runtime_error if Embree reported an error on this thread.
    void check(const char* what) const {
        RTCError e = rtcGetDeviceError(device);
        if (e != RTC_ERROR_NONE)
            throw std::runtime_error(
                std::string("Embree error while ") + what + ": " +
                (tlsEmbreeMessage.empty() ? embreeErrorName(e) : tlsEmbreeMessage));
    }

    Vec3 vertex(const ShapeGeom& g, uint32_t i) const {
        const float* v = g.vertices + 3 * size_t(i);
        return {v[0], v[1], v[2]};
    }
};

Scene::Scene() : impl_(std::make_unique<Impl>()) {
    tlsEmbreeMessage.clear();
    impl_->device = rtcNewDevice(nullptr);
    if (!impl_->device) {
        RTCError e = rtcGetDeviceError(nullptr);
        throw std::runtime_error(std::string("cannot create the Embree ray tracing device: ") +
                                 embreeErrorName(e));
    }
    rtcSetDeviceErrorFunction(impl_->device, embreeErrorCallback, nullptr);
    impl_->scene = rtcNewScene(impl_->device);
    impl_->check("creating the scene");
    // The context filter serves shadowCrossings; other queries leave it null.
    rtcSetSceneFlags(impl_->scene, RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
    rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
}

Scene::~Scene() = default;

int Scene::addMaterial(const Material& m) {
    std::vector<int> ids = {m.textures.diffuse,       m.textures.glossy, m.textures.specular,
                            m.textures.transmittance, m.textures.weight, m.textures.alpha,
                            m.textures.alphaV};
    ids.insert(ids.end(), m.textures.principled.begin(), m.textures.principled.end());
    if (m.type != MaterialType::Principled && m.type != MaterialType::PrincipledThin)
        for (int t : m.textures.principled)
            if (t >= 0)
                throw std::logic_error("Scene::addMaterial: material '" + m.name +
                                       "' has principled weight textures but is not principled");
    for (int t : ids)
        if (t >= int(textures.size()))
            throw std::logic_error("Scene::addMaterial: material '" + m.name +
                                   "' refers to texture " + std::to_string(t) +
                                   ", which was not added");
    if (m.perturbation != NormalPerturbation::kNone &&
        (m.perturbationTexture < 0 || m.perturbationTexture >= int(textures.size())))
        throw std::logic_error("Scene::addMaterial: material '" + m.name +
                               "' has a normal or bump map without a texture");
    const bool microfacet =
        m.type == MaterialType::RoughConductor || m.type == MaterialType::RoughDielectric;
    const bool principled =
        m.type == MaterialType::Principled || m.type == MaterialType::PrincipledThin;
    if (principled && (m.textures.alphaV >= 0 || m.alphaV >= 0.0f))
        throw std::logic_error("Scene::addMaterial: principled material '" + m.name +
                               "' takes its anisotropy from principled.anisotropic, not alphaV");
    if (!microfacet && !principled &&
        (m.textures.alpha >= 0 || m.textures.alphaV >= 0 || m.alphaV >= 0.0f))
        throw std::logic_error("Scene::addMaterial: material '" + m.name +
                               "' has a textured or anisotropic roughness, which only rough "
                               "conductors and rough dielectrics take");
    // A blend's parts are added before it, so no blend contains itself (nesting is finite).
    if (m.type == MaterialType::Blend)
        for (int part : m.blendParts)
            if (part < 0 || part >= int(materials.size()))
                throw std::logic_error("Scene::addMaterial: blend '" + m.name +
                                       "' refers to material " + std::to_string(part) +
                                       ", which was not added");
    materials.push_back(m);
    prepareMaterial(materials.back());  // plastic tables (scene/bsdf.h)
    return int(materials.size()) - 1;
}

uint32_t Scene::addMesh(TriangleMesh mesh, int materialId, int lightId, const std::string& name) {
    if (impl_->committed) throw std::logic_error("Scene::addMesh called after commit()");
    const std::string label = "mesh '" + name + "'";
    const size_t nv = mesh.positions.size();
    if (mesh.indices.size() % 3 != 0)
        throw InputError(sourceFile, label + ": index count " +
                                         std::to_string(mesh.indices.size()) +
                                         " is not a multiple of 3");
    if (mesh.triangleCount() == 0) throw InputError(sourceFile, label + " has no triangles");
    if (nv > size_t(std::numeric_limits<uint32_t>::max()))
        throw InputError(sourceFile, label + " has too many vertices");
    if (!mesh.normals.empty() && mesh.normals.size() != nv)
        throw InputError(sourceFile, label + ": " + std::to_string(mesh.normals.size()) +
                                         " normals for " + std::to_string(nv) +
                                         " vertices (expected none or one per vertex)");
    if (!mesh.uvs.empty() && mesh.uvs.size() != nv)
        throw InputError(sourceFile, label + ": " + std::to_string(mesh.uvs.size()) + " uvs for " +
                                         std::to_string(nv) +
                                         " vertices (expected none or one per vertex)");
    if (mesh.boundAttribute >= int(mesh.attributes.size()))
        throw std::logic_error(label + ": boundAttribute out of range");
    if (mesh.boundAttribute >= 0) {
        const MeshAttribute& a = mesh.attributes[size_t(mesh.boundAttribute)];
        const size_t n = a.perFace ? mesh.triangleCount() : nv;
        if ((a.channels != 1 && a.channels != 3) || a.values.size() != n * size_t(a.channels))
            throw InputError(sourceFile, label + ": mesh attribute '" + a.name + "' has " +
                                             std::to_string(a.values.size()) + " values in " +
                                             std::to_string(a.channels) + " channels (expected " +
                                             std::to_string(n) + " values of 1 or 3 channels)");
        for (float v : a.values)
            if (!std::isfinite(v))
                throw InputError(
                    sourceFile, label + ": mesh attribute '" + a.name + "' has a non-finite value");
    }
    Bounds3 box;
    for (size_t i = 0; i < nv; ++i) {
        if (!isFinite(mesh.positions[i]))
            throw InputError(sourceFile,
                             label + ": non-finite vertex position at vertex " + std::to_string(i));
        box.extend(mesh.positions[i]);
    }
    for (size_t i = 0; i < mesh.indices.size(); ++i)
        if (mesh.indices[i] >= nv)
            throw InputError(sourceFile,
                             label + ": vertex index " + std::to_string(mesh.indices[i]) +
                                 " out of range (mesh has " + std::to_string(nv) + " vertices)");

    RTCGeometry geom = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    impl_->check("creating a triangle mesh");
    auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(
        geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), nv));
    auto* ib = static_cast<uint32_t*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                3 * sizeof(uint32_t), mesh.triangleCount()));
    if (!vb || !ib) {
        rtcReleaseGeometry(geom);
        impl_->check("allocating mesh buffers");
        throw std::runtime_error("Embree could not allocate the buffers of " + label);
    }
    for (size_t i = 0; i < nv; ++i) {
        vb[3 * i + 0] = mesh.positions[i].x;
        vb[3 * i + 1] = mesh.positions[i].y;
        vb[3 * i + 2] = mesh.positions[i].z;
    }
    std::copy(mesh.indices.begin(), mesh.indices.end(), ib);
    rtcCommitGeometry(geom);
    uint32_t id = uint32_t(impl_->geoms.size());
    rtcAttachGeometryByID(impl_->scene, geom, id);
    rtcReleaseGeometry(geom);
    impl_->check("adding a triangle mesh");

    ShapeGeom g;
    g.vertices = vb;
    g.indices = ib;
    g.normals = std::move(mesh.normals);
    g.uvs = std::move(mesh.uvs);
    if (mesh.boundAttribute >= 0)
        g.attribute = std::move(mesh.attributes[size_t(mesh.boundAttribute)]);
    else
        g.attribute.channels = 0;
    impl_->geoms.push_back(std::move(g));

    ShapeInfo info;
    info.name = name;
    info.isSphere = false;
    info.materialId = materialId;
    info.lightId = lightId;
    info.triangleCount = mesh.triangleCount();
    info.bounds = box;
    shapes.push_back(info);
    return id;
}

uint32_t Scene::addSphere(const Vec3& center, float radius, int materialId, int lightId,
                          const std::string& name) {
    if (impl_->committed) throw std::logic_error("Scene::addSphere called after commit()");
    if (!isFinite(center) || !std::isfinite(radius) || !(radius > 0.0f))
        throw InputError(sourceFile,
                         "sphere '" + name + "': expected a finite center and a radius > 0");
    ShapeGeom g;
    g.isSphere = true;
    g.sphere = std::make_unique<SphereGeom>(SphereGeom{center, radius});
    uint32_t id = uint32_t(impl_->geoms.size());

    RTCGeometry geom = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_USER);
    impl_->check("creating a sphere");
    rtcSetGeometryUserPrimitiveCount(geom, 1);
    rtcSetGeometryUserData(geom, g.sphere.get());
    rtcSetGeometryBoundsFunction(geom, sphereBounds, nullptr);
    rtcSetGeometryIntersectFunction(geom, sphereIntersect);
    rtcSetGeometryOccludedFunction(geom, sphereOccluded);
    rtcCommitGeometry(geom);
    rtcAttachGeometryByID(impl_->scene, geom, id);
    rtcReleaseGeometry(geom);
    impl_->check("adding a sphere");
    impl_->geoms.push_back(std::move(g));

    ShapeInfo info;
    info.name = name;
    info.isSphere = true;
    info.materialId = materialId;
    info.lightId = lightId;
    info.triangleCount = 0;
    info.bounds.extend(center - Vec3(radius));
    info.bounds.extend(center + Vec3(radius));
    shapes.push_back(info);
    return id;
}

uint32_t Scene::addSdfGrid(std::shared_ptr<const SdfGrid> grid, int materialId,
                           const std::string& name) {
    if (impl_->committed) throw std::logic_error("Scene::addSdfGrid called after commit()");
    if (!grid || grid->voxels.empty()) throw std::logic_error("Scene::addSdfGrid: empty grid");
    ShapeGeom g;
    g.sdf = std::move(grid);
    const uint32_t id = uint32_t(impl_->geoms.size());
    RTCGeometry geom = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_USER);
    impl_->check("creating an sdfgrid");
    rtcSetGeometryUserPrimitiveCount(geom, unsigned(g.sdf->voxels.size()));
    rtcSetGeometryUserData(geom, const_cast<SdfGrid*>(g.sdf.get()));
    rtcSetGeometryBoundsFunction(geom, sdfBounds, nullptr);
    rtcSetGeometryIntersectFunction(geom, sdfIntersect);
    rtcSetGeometryOccludedFunction(geom, sdfOccluded);
    rtcCommitGeometry(geom);
    rtcAttachGeometryByID(impl_->scene, geom, id);
    rtcReleaseGeometry(geom);
    impl_->check("adding an sdfgrid");
    ShapeInfo info;
    info.name = name;
    info.isSdfGrid = true;
    info.materialId = materialId;
    for (const Bounds3& b : g.sdf->voxelBounds) info.bounds.extend(b);
    impl_->geoms.push_back(std::move(g));
    shapes.push_back(info);
    return id;
}

int Scene::addMedium(const Medium& m, const std::string& name) {
    if (impl_->committed) throw std::logic_error("Scene::addMedium called after commit()");
    media.push_back(m);
    mediumNames.push_back(name);
    return int(media.size()) - 1;
}

void Scene::setMediumBoundary(uint32_t shapeId, int interiorMediumId, int priority,
                              bool imaginary) {
    if (impl_->committed) throw std::logic_error("Scene::setMediumBoundary called after commit()");
    if (shapeId >= shapes.size()) throw std::out_of_range("Scene::setMediumBoundary: bad shape id");
    ShapeInfo& s = shapes[shapeId];
    s.isMediumBoundary = true;
    s.interiorMediumId = interiorMediumId;
    s.mediumPriority = priority;
    s.imaginary = imaginary;
}

void Scene::setExteriorMedium(uint32_t shapeId, int exteriorMediumId) {
    if (impl_->committed) throw std::logic_error("Scene::setExteriorMedium called after commit()");
    if (shapeId >= shapes.size() || !shapes[shapeId].isMediumBoundary)
        throw std::out_of_range("Scene::setExteriorMedium: not a medium boundary");
    shapes[shapeId].exteriorMediumId = exteriorMediumId;
}

void Scene::meshTriangle(uint32_t shapeId, uint32_t tri, Vec3 p[3]) const {
    const ShapeGeom& g = impl_->geoms.at(shapeId);
    if (g.isSphere || g.sdf)
        throw std::logic_error("Scene::meshTriangle called on a sphere or an sdfgrid");
    const uint32_t* idx = g.indices + 3 * size_t(tri);
    for (int i = 0; i < 3; ++i) p[i] = impl_->vertex(g, idx[i]);
}

Vec3 Scene::offsetRayOrigin(const Vec3& p, const Vec3& n, const Vec3& dir) {
    return offsetOrigin(p, n, dir);
}

float Scene::rayOffsetLength(const Vec3& p) {
    return kRayEpsilon * (1.0f + maxAbs(p));
}

void Scene::commit() {
    if (impl_->committed) throw std::logic_error("Scene::commit called twice");
    {
        std::vector<MediumIssue> issues = mediumIssues();
        if (!issues.empty()) {
            std::vector<Diagnostic> diags;
            for (const MediumIssue& i : issues) {
                if (i.warning) continue;
                Diagnostic d;
                d.file = sourceFile;
                d.where = i.shapeId >= 0 ? "shape '" + shapes[size_t(i.shapeId)].name + "'"
                                         : (i.mediumId >= 0
                                                ? "medium '" + mediumNames[size_t(i.mediumId)] + "'"
                                                : std::string());
                d.message = i.message;
                diags.push_back(d);
            }
            if (!diags.empty()) throw InputError(std::move(diags));
        }
    }
    // Coordinates the tracer handles: Embree asserts |origin| <= 1.8e18 on every ray, and
    // float's spacing reaches 1 unit at 1.7e7, where the origin offsets of secondary rays
    // (offsetOrigin) no longer move a point off its surface. Scenes reaching beyond
    // kMaxCoordinate are rejected with the value; rays built at run time are guarded in
    // intersect() / occluded().
    {
        auto checkPoint = [&](const Vec3& p, const std::string& where) {
            for (int a = 0; a < 3; ++a)
                if (!(std::fabs(p[a]) <= kMaxCoordinate)) {
                    Diagnostic d;
                    d.file = sourceFile;
                    d.where = where;
                    d.message = std::string("coordinate ") + "xyz"[a] + " = " +
                                std::to_string(p[a]) +
                                " is out of the range the tracer handles (|value| <= 1e7: "
                                "beyond it float spacing exceeds 1 unit and rays cannot "
                                "leave surfaces); scale or move the scene";
                    throw InputError({d});
                }
        };
        checkPoint(camera.position(), "camera position");
        for (const ShapeInfo& s : shapes) {
            if (s.bounds.empty()) continue;
            checkPoint(s.bounds.lo, "shape '" + s.name + "'");
            checkPoint(s.bounds.hi, "shape '" + s.name + "'");
        }
        for (size_t i = 0; i < lights.size(); ++i)
            if (lights[i].isDeltaPosition())
                checkPoint(lights[i].position, "light " + std::to_string(i));
    }
    rtcCommitScene(impl_->scene);
    impl_->check("building the BVH");

    bounds = Bounds3();
    for (const ShapeInfo& s : shapes) bounds.extend(s.bounds);
    // Bounding sphere of the box (as SmallVCM), slightly enlarged so that rounding
    // never leaves geometry outside; never degenerate (radius > 0).
    if (bounds.empty()) {
        sceneSphere.center = Vec3(0.0f);
        sceneSphere.radius = 1.0f;
    } else {
        sceneSphere.center = bounds.center();
        float halfDiag = 0.5f * length(bounds.hi - bounds.lo);
        float scale = 1.0f + std::max(maxAbs(bounds.lo), maxAbs(bounds.hi));
        sceneSphere.radius = std::max(halfDiag * (1.0f + 1e-5f) + 1e-6f * scale, 1e-4f * scale);
    }
    sceneSphere.invRadiusSqr = 1.0f / (sceneSphere.radius * sceneSphere.radius);
    impl_->committed = true;
    for (const ShapeInfo& s : shapes)
        if (s.isMediumBoundary) {
            impl_->anyImaginaryBoundary = impl_->anyImaginaryBoundary || s.imaginary;
            impl_->allBoundariesRealUpTo = std::min(impl_->allBoundariesRealUpTo, s.mediumPriority);
        }
    // A stack's priority is the global one or a boundary's, so a boundary that is not
    // imaginary and of the highest priority is real for every stack; so is a shape that is
    // not a boundary (scene/medium_stack.h).
    int32_t highest = INT32_MIN;
    for (const ShapeInfo& s : shapes)
        if (s.isMediumBoundary) highest = std::max(highest, s.mediumPriority);
    impl_->alwaysReal.assign(shapes.size(), 1);
    impl_->crossingsByFilter = true;
    for (size_t i = 0; i < shapes.size(); ++i) {
        if (realFor(uint32_t(i), highest)) continue;
        impl_->alwaysReal[i] = 0;
        const ShapeGeom& g = impl_->geoms[i];
        if (g.isSphere || g.sdf) impl_->crossingsByFilter = false;
    }
    cameraMediumStack = mediumStackAt(camera.position());
}

bool Scene::intersect(const Ray& ray, Hit* hit) const {
    if (!intersectNearest(ray, hit)) return false;
    completeHit(ray, hit);
    return true;
}

bool Scene::intersectNearest(const Ray& ray, Hit* hit) const {
    if (!impl_->committed) throw std::logic_error("Scene::intersect called before commit()");
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh;
    rh.ray = embreeRay(ray.org, ray.dir, ray.tMin, ray.tMax);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    if (!embreeRayValid(ray.org, ray.dir, ray.tMin, ray.tMax)) return false;  // e.g. NaN
    raystats::timed(raystats::kNearest, [&] { rtcIntersect1(impl_->scene, &ctx, &rh); });
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;

    const uint32_t id = rh.hit.geomID;
    hit->dist = rh.ray.tfar;
    hit->shapeId = id;
    hit->primId = rh.hit.primID;
    hit->materialId = shapes[id].materialId;
    hit->lightId = shapes[id].lightId;
    hit->baryU = rh.hit.u;
    hit->baryV = rh.hit.v;
    hit->pos = ray.org + rh.ray.tfar * ray.dir;
    hit->detailPending = true;
    return true;
}

void Scene::completeHit(const Ray& ray, Hit* hit) const {
    if (!hit->detailPending) return;
    hit->detailPending = false;
    hit->attribute = Rgb(0.0f);
    const ShapeGeom& g = impl_->geoms[hit->shapeId];
    if (g.sdf) {
        // The hit point is not projected onto the level set (as Mitsuba): its error is the
        // root finder's 1e-5 along the ray, below the origin offset of the next ray.
        hit->pos = ray.org + hit->dist * ray.dir;
        g.sdf->normals(hit->primId, hit->pos, &hit->geoNormal, &hit->shadingNormal);
        hit->uv = Vec2(0.0f, 0.0f);  // no parameterisation, as in Mitsuba
        hit->tangent = Vec3(0.0f);
        if (needsTangent(hit->materialId)) {
            hit->tangent = Frame(hit->shadingNormal).s;  // any: the shape has no dp/du
        }
        return;
    }
    if (g.isSphere) {
        // Re-project the hit onto the sphere (double precision) so that the point
        // lies within an ulp or two of the surface.
        const Vec3& c = g.sphere->center;
        double t = hit->dist;
        double px = double(ray.org.x) + t * ray.dir.x - c.x;
        double py = double(ray.org.y) + t * ray.dir.y - c.y;
        double pz = double(ray.org.z) + t * ray.dir.z - c.z;
        double len = std::sqrt(px * px + py * py + pz * pz);
        double nx = px / len, ny = py / len, nz = pz / len;
        double r = g.sphere->radius;
        hit->pos = Vec3(float(c.x + r * nx), float(c.y + r * ny), float(c.z + r * nz));
        hit->geoNormal = normalize(Vec3(float(nx), float(ny), float(nz)));
        hit->shadingNormal = hit->geoNormal;
        hit->uv = sphereUv(nx, ny, nz);  // spherical coordinates about +z
        hit->tangent = Vec3(0.0f);
        if (needsTangent(hit->materialId)) {
            // Derivatives of c + r (sin v' cos u', sin v' sin u', cos v'), u' = 2 pi u,
            // v' = pi v.
            const double sinTheta = std::sqrt(std::max(0.0, 1.0 - nz * nz));
            const double cosPhi = sinTheta > 0.0 ? nx / sinTheta : 1.0;
            const double sinPhi = sinTheta > 0.0 ? ny / sinTheta : 0.0;
            const Vec3 dpdu(float(-2.0 * kPiD * r * ny), float(2.0 * kPiD * r * nx), 0.0f);
            const Vec3 dpdv(float(kPiD * r * nz * cosPhi), float(kPiD * r * nz * sinPhi),
                            float(-kPiD * r * sinTheta));
            hit->tangent = shadingTangent(hit->shadingNormal, dpdu);
            if (perturbs(hit->materialId)) perturbShadingNormal(hit, dpdu, dpdv);
        }
        return;
    }

    const uint32_t* tri = g.indices + 3 * size_t(hit->primId);
    const Vec3 p0 = impl_->vertex(g, tri[0]), p1 = impl_->vertex(g, tri[1]),
               p2 = impl_->vertex(g, tri[2]);
    // Embree's barycentrics: p = (1-u-v) p0 + u p1 + v p2.
    const float b1 = hit->baryU, b2 = hit->baryV, b0 = 1.0f - b1 - b2;
    hit->pos = b0 * p0 + b1 * p1 + b2 * p2;
    Vec3 ng = cross(p1 - p0, p2 - p0);
    float ngLen = length(ng);
    // A zero-area triangle cannot be hit by Embree's test; guard anyway.
    hit->geoNormal = ngLen > 0.0f ? ng / ngLen : -ray.dir;
    hit->shadingNormal = hit->geoNormal;
    if (!g.normals.empty()) {
        Vec3 ns = b0 * g.normals[tri[0]] + b1 * g.normals[tri[1]] + b2 * g.normals[tri[2]];
        float nsLen = length(ns);
        if (nsLen > 0.0f && std::isfinite(nsLen)) {
            ns = ns / nsLen;
            hit->shadingNormal = dot(ns, hit->geoNormal) < 0.0f ? -ns : ns;
        }
    }
    if (!g.uvs.empty()) {
        const Vec2 &t0 = g.uvs[tri[0]], &t1 = g.uvs[tri[1]], &t2 = g.uvs[tri[2]];
        hit->uv = Vec2(b0 * t0.x + b1 * t1.x + b2 * t2.x, b0 * t0.y + b1 * t1.y + b2 * t2.y);
    } else {
        hit->uv = Vec2(b1, b2);  // barycentrics when the mesh has no uvs
    }
    if (const MeshAttribute& a = g.attribute; a.channels > 0) {
        // Mitsuba's mesh_attribute: a triangle's value, or the vertices' values interpolated.
        const int c = a.channels;
        auto value = [&](size_t i, int k) { return a.values[size_t(c) * i + size_t(k)]; };
        float rgb[3];
        for (int k = 0; k < c; ++k)
            rgb[k] = a.perFace
                         ? value(hit->primId, k)
                         : b0 * value(tri[0], k) + b1 * value(tri[1], k) + b2 * value(tri[2], k);
        hit->attribute = c == 1 ? Rgb(rgb[0]) : Rgb(rgb[0], rgb[1], rgb[2]);
    }
    hit->tangent = Vec3(0.0f);
    if (needsTangent(hit->materialId)) {
        // Tangents of the uv parameterisation (scene/normal_perturbation.h).
        const Vec3 e1 = p1 - p0, e2 = p2 - p0;
        Vec3 dpdu = e1, dpdv = e2;
        if (!g.uvs.empty()) {
            const Vec2 &t0 = g.uvs[tri[0]], &t1 = g.uvs[tri[1]], &t2 = g.uvs[tri[2]];
            const float du1 = t1.x - t0.x, dv1 = t1.y - t0.y;
            const float du2 = t2.x - t0.x, dv2 = t2.y - t0.y;
            const float det = du1 * dv2 - dv1 * du2;
            if (det != 0.0f && std::isfinite(1.0f / det)) {
                dpdu = (dv2 * e1 - dv1 * e2) / det;
                dpdv = (du1 * e2 - du2 * e1) / det;
            } else {
                const Frame f(hit->geoNormal);
                dpdu = f.s;
                dpdv = f.t;
            }
        }
        hit->tangent = shadingTangent(hit->shadingNormal, dpdu);
        if (perturbs(hit->materialId)) perturbShadingNormal(hit, dpdu, dpdv);
    }
}

bool Scene::perturbs(int materialId) const {
    return materialId >= 0 && size_t(materialId) < materials.size() &&
           materials[size_t(materialId)].perturbation != NormalPerturbation::kNone;
}

bool Scene::needsTangent(int materialId) const {
    if (materialId < 0 || size_t(materialId) >= materials.size()) return false;
    const Material& m = materials[size_t(materialId)];
    if (m.perturbation != NormalPerturbation::kNone || m.anisotropic()) return true;
    // A blend's parts precede it (Scene::addMaterial checks), so this recursion ends.
    return m.type == MaterialType::Blend &&
           (needsTangent(m.blendParts[0]) || needsTangent(m.blendParts[1]));
}

void Scene::perturbShadingNormal(Hit* hit, const Vec3& dpdu, const Vec3& dpdv) const {
    const Material& m = materials[size_t(hit->materialId)];
    hit->shadingNormal = perturbedShadingNormal(m, textures[size_t(m.perturbationTexture)], hit->uv,
                                                hit->shadingNormal, hit->geoNormal, dpdu, dpdv);
}

namespace {

bool occludedRay(RTCScene scene, const Vec3& org, const Vec3& dir, float tMax) {
    // A ray Embree would reject (NaN, beyond its range): no light passes it.
    if (!embreeRayValid(org, dir, 0.0f, tMax)) return true;
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay r = embreeRay(org, dir, 0.0f, tMax);
    raystats::timed(raystats::kAnyHit, [&] { rtcOccluded1(scene, &ctx, &r); });
    return r.tfar < 0.0f;  // Embree sets tfar = -inf on a hit
}

}  // namespace

bool Scene::occluded(const Vec3& a, const Vec3& geoNormalA, const Vec3& b,
                     const Vec3& geoNormalB) const {
    if (!impl_->committed) throw std::logic_error("Scene::occluded called before commit()");
    Vec3 oa = offsetOrigin(a, geoNormalA, b - a);
    Vec3 ob = offsetOrigin(b, geoNormalB, a - b);
    Vec3 d = ob - oa;
    float len = length(d);
    if (!(len > 0.0f)) return false;
    // Both ends are already off their surfaces, so the open segment is (0, len).
    return occludedRay(impl_->scene, oa, d / len, len);
}

bool Scene::occludedToInfinity(const Vec3& from, const Vec3& geoNormal, const Vec3& dir) const {
    if (!impl_->committed)
        throw std::logic_error("Scene::occludedToInfinity called before commit()");
    return occludedRay(impl_->scene, offsetOrigin(from, geoNormal, dir), dir,
                       std::numeric_limits<float>::infinity());
}

bool Scene::everyHitIsReal(const MediumStack& stack) const {
    return !impl_->anyImaginaryBoundary && stack.priority() <= impl_->allBoundariesRealUpTo;
}

bool Scene::anyHitWithin(const Vec3& org, const Vec3& dir, float tMax) const {
    if (!impl_->committed) throw std::logic_error("Scene::anyHitWithin called before commit()");
    // intersect() finds nothing on a ray Embree would reject; neither does this.
    if (!embreeRayValid(org, dir, 0.0f, tMax)) return false;
    return occludedRay(impl_->scene, org, dir, tMax);
}

namespace {

/// What the filter of a shadowCrossings traversal records: Embree's context first, so the
/// filter reaches the rest through the context pointer it is given.
struct CrossingContext {
    RTCIntersectContext embree;
    const uint8_t* alwaysReal;
    struct Entry {
        float t;
        uint32_t shapeId, primId;
    } * entries;
    int capacity;
    int count;
};

/// Accepts a hit on a surface real for every stack (the any-hit query then ends, blocked);
/// records any other hit and rejects it, so the traversal goes on.
void crossingFilter(const RTCFilterFunctionNArguments* args) {
    auto* c = reinterpret_cast<CrossingContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0) continue;
        const unsigned geomID = RTCHitN_geomID(args->hit, args->N, i);
        if (c->alwaysReal[geomID]) continue;
        if (c->count < c->capacity)
            c->entries[c->count] = {RTCRayN_tfar(args->ray, args->N, i), geomID,
                                    RTCHitN_primID(args->hit, args->N, i)};
        ++c->count;  // past capacity: counted, so the caller sees the overflow
        args->valid[i] = 0;
    }
}

}  // namespace

Scene::ShadowQuery Scene::shadowCrossings(const Vec3& org, const Vec3& dir, float tMax,
                                          ShadowCrossing* crossings, int capacity,
                                          int* count) const {
    if (!impl_->committed) throw std::logic_error("Scene::shadowCrossings called before commit()");
    *count = 0;
    if (!impl_->crossingsByFilter || capacity <= 0) return ShadowQuery::kUnavailable;
    // intersect() finds nothing on a ray Embree would reject; neither does this.
    if (!embreeRayValid(org, dir, 0.0f, tMax)) return ShadowQuery::kOpen;
    // Twice the capacity: a crossing can be reported twice (shared edges, split references).
    constexpr int kMaxEntries = 64;
    CrossingContext::Entry entries[kMaxEntries];
    CrossingContext c;
    rtcInitIntersectContext(&c.embree);
    c.embree.filter = crossingFilter;
    c.alwaysReal = impl_->alwaysReal.data();
    c.entries = entries;
    c.capacity = std::min(kMaxEntries, 2 * capacity);
    c.count = 0;
    RTCRay r = embreeRay(org, dir, 0.0f, tMax);
    raystats::timed(raystats::kCrossings, [&] { rtcOccluded1(impl_->scene, &c.embree, &r); });
    if (r.tfar < 0.0f) return ShadowQuery::kBlocked;  // Embree sets tfar = -inf on a hit
    if (c.count > c.capacity) return ShadowQuery::kUnavailable;
    // By increasing t (ties by shape and triangle, so the order never depends on Embree's):
    // insertion sort, a handful of entries.
    for (int i = 1; i < c.count; ++i) {
        const CrossingContext::Entry e = entries[i];
        int j = i;
        for (; j > 0; --j) {
            const CrossingContext::Entry& p = entries[j - 1];
            const bool after =
                p.t > e.t || (p.t == e.t && (p.shapeId > e.shapeId ||
                                             (p.shapeId == e.shapeId && p.primId > e.primId)));
            if (!after) break;
            entries[j] = p;
        }
        entries[j] = e;
    }
    for (int i = 0; i < c.count; ++i) {
        const CrossingContext::Entry& e = entries[i];
        const ShapeGeom& g = impl_->geoms[e.shapeId];
        const uint32_t* tri = g.indices + 3 * size_t(e.primId);
        const Vec3 p0 = impl_->vertex(g, tri[0]), p1 = impl_->vertex(g, tri[1]),
                   p2 = impl_->vertex(g, tri[2]);
        // The geometric normal as intersect() computes it, so the crossing's side is the same.
        const Vec3 ng = cross(p1 - p0, p2 - p0);
        const float ngLen = length(ng);
        const Vec3 n = ngLen > 0.0f ? ng / ngLen : -dir;
        const bool entering = dot(dir, n) < 0.0f;
        // The same crossing again: the previous crossing of this shape, on the same side and
        // within the origin offset a walk moves past after a crossing (a closed boundary is
        // left before it is entered again, so two real crossings alternate sides).
        bool again = false;
        for (int k = *count - 1; k >= 0; --k) {
            const ShadowCrossing& q = crossings[k];
            if (q.shapeId != e.shapeId) continue;
            again = q.entering == entering && e.t - q.t <= 4.0f * rayOffsetLength(org + dir * e.t);
            break;
        }
        if (again) continue;
        if (*count == capacity) return ShadowQuery::kUnavailable;
        crossings[(*count)++] = {e.t, e.shapeId, entering};
    }
    return ShadowQuery::kOpen;
}

Ray Scene::spawnRay(const Hit& hit, const Vec3& dir) const {
    Ray r;
    r.org = offsetOrigin(hit.pos, hit.geoNormal, dir);
    r.dir = dir;
    r.tMin = 0.0f;
    r.tMax = kInf;
    return r;
}

}  // namespace ub
