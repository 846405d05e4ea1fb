// Mitsuba 3 XML scene builder: top level, integrator, sensor and film, shapes
// and emitters. BSDFs are in mitsuba_bsdfs.cpp, media in mitsuba_media.cpp.
#include "scene/io/mitsuba_loader.h"

#include <cmath>
#include <filesystem>
#include <memory>
#include <set>

#include "core/file_status.h"
#include "core/image.h"
#include "scene/aov_types.h"
#include "scene/io/mitsuba_build.h"
#include "scene/mesh_io.h"
#include "scene/sdf_grid.h"
#include "scene/serialized_mesh.h"
#include "scene/shapes.h"
#include "scene/vol_grid.h"

namespace ub {

namespace fs = std::filesystem;

namespace {

const std::vector<std::string> kShapes = {"obj",     "ply",        "serialized", "rectangle",
                                          "cube",    "sphere",     "disk",       "cylinder",
                                          "sdfgrid", "shapegroup", "instance"};
const std::vector<std::string> kEmitters = {"area",     "point",       "spot",  "projector",
                                            "constant", "directional", "envmap"};
const std::vector<std::string> kIntegrators = {"path",    "volpath", "volpathmis", "direct",
                                               "ptracer", "moment",  "aov"};
const std::vector<std::string> kRfilters = {"box", "tent", "gaussian"};
const std::vector<std::string> kSamplers = {"independent", "stratified", "multijitter",
                                            "orthogonal", "ldsampler"};

/// Rotation + translation + uniform scale? Returns the scale (0 if not a similarity).
float similarityScale(const Transform& t) {
    Vec3 c0(t.m[0][0], t.m[1][0], t.m[2][0]), c1(t.m[0][1], t.m[1][1], t.m[2][1]),
        c2(t.m[0][2], t.m[1][2], t.m[2][2]);
    float s = length(c0);
    auto near = [&](float a, float b) { return std::fabs(a - b) <= 1e-4f * std::max(1.0f, s * s); };
    if (!near(length(c1) * length(c1), s * s) || !near(length(c2) * length(c2), s * s)) return 0;
    if (!near(dot(c0, c1), 0) || !near(dot(c0, c2), 0) || !near(dot(c1, c2), 0)) return 0;
    return s;
}

/// A shape's geometry: a triangle mesh, a sphere's centre and radius, or an sdfgrid's samples
/// with its to_world (an instance composes its own, so the grid is built where it is added).
struct ShapeGeometry {
    TriangleMesh mesh;
    bool isSphere = false;
    Vec3 center;
    float radius = 1.0f;
    bool isSdfGrid = false;
    std::shared_ptr<const VolGrid> sdfSamples;
    Transform sdfToWorld;
    bool sdfSmooth = true;
    std::string sdfLabel;
};

/// The shapes of a `shapegroup`, built once in the group's space and copied per instance.
struct ShapeGroupShapes {
    struct Member {
        std::string name;
        ShapeGeometry geometry;
        int materialId = -1;
    };
    bool ok = false;  ///< false: the group had errors (reported once, where it is defined)
    std::vector<Member> members;
};

class Builder {
  public:
    Builder(MitsubaBuild& b) : b_(b), r_(b.r) {}
    void build();

  private:
    void readIntegrator(const XmlObject& o);
    void checkDirect();
    void readSensor(const XmlObject& o);
    void readOrthographic(const XmlObject& o, int w, int h);
    /// The horizontal field of view in degrees of a perspective sensor or a projector
    /// (Mitsuba's parse_fov: `fov` along `fov_axis`, or `focal_length` on 36 x 24 mm film).
    float readFovX(const XmlObject& o, float aspect);
    void readFilm(const XmlObject& o, int* w, int* h);
    void readShape(const XmlObject& o);
    void readGeometry(const XmlObject& o, ShapeGeometry* g);
    /// Keeps the mesh attribute that the material's mesh_attribute textures look up (at most
    /// one name per shape) and drops the others; false after an error at o.
    bool bindMeshAttribute(const XmlObject& o, int materialId, ShapeGeometry* g);
    const ShapeGroupShapes& shapeGroup(const XmlObject& group);
    void readInstance(const XmlObject& o);
    void readEmitter(const XmlObject& o);
    /// The projected texture of a spot or projector (a bitmap, evaluated as an emission) and
    /// the light's frame from to_world, which must be a rotation and translation.
    void readProjectedTexture(const XmlObject& o, const XmlObject& tex, const XmlPos& at,
                              const Transform& toWorld, Light* light);
    void setLightFrame(const XmlObject& o, const Transform& toWorld, Light* light);
    int defaultMaterial();
    int blackMaterial();
    int oneSidedDiffuse(float reflectance, const char* name, int* cachedId);
    int mediumId(const XmlObject& medium);

    MitsubaBuild& b_;
    XmlReader& r_;
    bool integratorSeen_ = false;
    const XmlObject* direct_ = nullptr;  ///< the `direct` integrator, if the scene uses it
    int directEmitterSamples_ = 1, directBsdfSamples_ = 1;
    int defaultMaterial_ = -1;
    int blackMaterial_ = -1;
    const XmlObject* envObject_ = nullptr;
    std::map<const XmlObject*, ShapeGroupShapes> groups_;
    int instanceCount_ = 0;
};

void Builder::build() {
    const XmlObject* sensor = nullptr;
    for (const auto& op : b_.xml.objects) {
        const XmlObject& o = *op;
        if (o.tag == "integrator") {
            if (integratorSeen_) r_.error(o.pos, "more than one <integrator>");
            integratorSeen_ = true;
            readIntegrator(o);
        } else if (o.tag == "sensor") {
            if (sensor) {
                r_.error(o.pos, "more than one <sensor> (unibeam renders one camera)");
                continue;
            }
            sensor = &o;
            readSensor(o);
        } else if (o.tag == "shape") {
            readShape(o);
        } else if (o.tag == "emitter" && o.type == "area" && !o.id.empty()) {
            // A named area emitter: attached to shapes with <ref id="..."/> (read there).
        } else if (o.tag == "emitter") {
            readEmitter(o);
        } else if (o.tag == "bsdf" || o.tag == "medium" || o.tag == "texture" ||
                   o.tag == "volume" || o.tag == "phase" || o.tag == "sampler" ||
                   o.tag == "rfilter" || o.tag == "film") {
            if (o.id.empty())
                r_.error(o.pos, "top-level " + o.label() +
                                    " without an id cannot be used (give "
                                    "it an id and attach it with <ref id=\"...\"/>)");
            else if (o.tag == "bsdf")
                buildMitsubaBsdf(b_, o);  // validate even when unused
        } else {
            r_.error(o.pos, o.label() + " cannot appear at the top level of a scene");
        }
    }
    // Mitsuba's ptracer normalises its splats over the whole filter footprint (border pixels
    // are not renormalised); its image is rendered with that convention whatever -a chooses.
    if (b_.scene.settings.defaultAlgorithm == "lt")
        b_.scene.settings.pixelFilter =
            b_.scene.settings.pixelFilter.withBorder(PixelFilterBorder::kPartitionOfUnity);
    checkDirect();
    if (!sensor)
        r_.error(XmlPos{b_.xml.file, 0, 0},
                 "the scene has no <sensor> (expected one "
                 "perspective sensor)");
    if (b_.scene.lights.empty() && r_.errorCount() == 0)
        r_.error(XmlPos{b_.xml.file, 0, 0}, "the scene has no emitter");
}

namespace {

/// Whether material id (of scene) scatters through a delta lobe: light that only Mitsuba's
/// BSDF sampling reaches.
bool hasDeltaLobe(const Scene& scene, int id) {
    if (id < 0 || size_t(id) >= scene.materials.size()) return false;
    const Material& m = scene.materials[size_t(id)];
    switch (m.type) {
        case MaterialType::Mirror:
        case MaterialType::Dielectric:
        case MaterialType::Plastic:
        case MaterialType::ThinDielectric:
            return true;
        case MaterialType::MultiLobe:
            return m.refract || maxComponent(m.specular) > 0.0f;
        case MaterialType::Blend:
            return hasDeltaLobe(scene, m.blendParts[0]) || hasDeltaLobe(scene, m.blendParts[1]);
        default:
            return false;
    }
}

}  // namespace

void Builder::checkDirect() {
    if (!direct_) return;
    if (directEmitterSamples_ == 0 && directBsdfSamples_ > 0) {
        for (const Light& l : b_.scene.lights)
            if (l.isDelta()) {
                r_.error(direct_->find("emitter_samples")->pos,
                         direct_->label() + ": emitter_samples = 0 leaves the delta emitter '" +
                             l.name +
                             "' dark in Mitsuba, which unibeam's estimators do not reproduce "
                             "(expected emitter_samples >= 1 in a scene with point, spot, "
                             "projector or directional emitters)");
                return;
            }
    }
    if (directBsdfSamples_ == 0 && directEmitterSamples_ > 0) {
        for (const ShapeInfo& shape : b_.scene.shapes)
            if (const int i = shape.materialId; hasDeltaLobe(b_.scene, i)) {
                r_.error(direct_->find("bsdf_samples")->pos,
                         direct_->label() +
                             ": bsdf_samples = 0 leaves light reflected or "
                             "refracted by the smooth BSDF '" +
                             b_.scene.materials[size_t(i)].name +
                             "' dark in Mitsuba, which unibeam's estimators do not reproduce "
                             "(expected bsdf_samples >= 1 in a scene with smooth BSDFs)");
                return;
            }
    }
}

namespace {

/// The attribute names the material's mesh_attribute textures look up (blend parts too).
void meshAttributeNames(const Scene& scene, int id, std::set<std::string>* names) {
    if (id < 0 || size_t(id) >= scene.materials.size()) return;
    const Material& m = scene.materials[size_t(id)];
    for (int t : {m.textures.diffuse, m.textures.glossy, m.textures.specular,
                  m.textures.transmittance, m.textures.weight})
        if (t >= 0 && scene.textures[size_t(t)].type == TextureType::MeshAttribute)
            names->insert(scene.textures[size_t(t)].attributeName);
    for (int t : m.textures.principled)
        if (t >= 0 && scene.textures[size_t(t)].type == TextureType::MeshAttribute)
            names->insert(scene.textures[size_t(t)].attributeName);
    if (m.type == MaterialType::Blend)
        for (int part : m.blendParts) meshAttributeNames(scene, part, names);
}

}  // namespace

bool Builder::bindMeshAttribute(const XmlObject& o, int materialId, ShapeGeometry* g) {
    std::set<std::string> names;
    meshAttributeNames(b_.scene, materialId, &names);
    TriangleMesh& mesh = g->mesh;
    mesh.boundAttribute = -1;
    if (names.empty()) {
        mesh.attributes.clear();
        return true;
    }
    const std::string& name = *names.begin();
    if (names.size() > 1) {
        r_.error(o.pos, o.label() + ": its BSDF looks up the mesh attributes '" + name + "' and '" +
                            *std::next(names.begin()) +
                            "' (unibeam supports one mesh attribute per shape)");
        return false;
    }
    std::string have;
    for (size_t i = 0; i < mesh.attributes.size(); ++i) {
        const MeshAttribute& a = mesh.attributes[i];
        have += (have.empty() ? "" : ", ") + a.name;
        if (a.name != name) continue;
        if (a.channels != 1 && a.channels != 3) {
            r_.error(o.pos, o.label() + ": mesh attribute '" + name + "' has " +
                                std::to_string(a.channels) +
                                " channels (a mesh_attribute texture needs 1 or 3)");
            return false;
        }
        MeshAttribute kept = std::move(mesh.attributes[i]);
        mesh.attributes.clear();
        mesh.attributes.push_back(std::move(kept));
        mesh.boundAttribute = 0;
        return true;
    }
    r_.error(o.pos, o.label() + ": its BSDF looks up the mesh attribute '" + name + "', which " +
                        (g->isSphere ? std::string("a sphere does not have")
                                     : "the mesh does not have (it has " +
                                           (have.empty() ? std::string("none") : have) +
                                           "; PLY files carry mesh attributes)"));
    return false;
}

void Builder::readIntegrator(const XmlObject& top) {
    const XmlObject* o = &top;
    if (o->type == "aov") {
        const size_t before = r_.errorCount();
        // Mitsuba's aov: "name:type" pairs, written as extra EXR layers (render/aov.h), beside
        // the image of its nested integrator.
        const std::string list = r_.getString(*o, "aovs", "");
        const XmlPos& at = o->find("aovs") ? o->find("aovs")->pos : o->pos;
        size_t start = 0;
        while (start <= list.size()) {
            size_t end = list.find(',', start);
            if (end == std::string::npos) end = list.size();
            std::string item = list.substr(start, end - start);
            item.erase(0, item.find_first_not_of(" \t"));
            item.erase(item.find_last_not_of(" \t") + 1);
            start = end + 1;
            if (item.empty()) continue;
            const size_t colon = item.find(':');
            const std::string name = colon == std::string::npos ? "" : item.substr(0, colon);
            const std::string type = colon == std::string::npos ? "" : item.substr(colon + 1);
            bool knownType = false;
            for (const std::string& t : aovTypes()) knownType = knownType || t == type;
            if (name.empty() || !knownType) {
                std::string types;
                for (const std::string& t : aovTypes()) types += (types.empty() ? "" : ", ") + t;
                r_.error(at, o->label() + ": aov '" + item +
                                 "': expected NAME:TYPE with TYPE one of " + types +
                                 " (the others, e.g. albedo or dp_du, are not supported)");
                continue;
            }
            b_.scene.settings.aovs.push_back({name, type});
        }
        if (b_.scene.settings.aovs.empty() && r_.errorCount() == before)
            r_.error(at, o->label() + ": needs <string name=\"aovs\"> with NAME:TYPE entries");
        std::vector<const XmlObject*> inner = r_.children(*o, "integrator");
        r_.checkUnused(*o);
        if (inner.size() != 1) {
            r_.error(o->pos, o->label() +
                                 ": expected exactly one nested <integrator> (the image; "
                                 "unibeam always renders one)");
            return;
        }
        o = inner[0];
    }
    if (o->type == "moment") {
        // `moment` only adds a second-moment output; it renders its nested integrator.
        std::vector<const XmlObject*> inner = r_.children(*o, "integrator");
        r_.checkUnused(*o);
        if (inner.size() != 1) {
            r_.error(o->pos, o->label() + ": expected exactly one nested <integrator>");
            return;
        }
        o = inner[0];
    }
    const bool known = o->type == "path" || o->type == "volpath" || o->type == "volpathmis" ||
                       o->type == "direct" || o->type == "ptracer";
    if (!known) {
        r_.unsupportedPlugin(*o, kIntegrators,
                             "choose unibeam's algorithm with `unibeam render -a`");
        return;
    }
    // Parameters of every Mitsuba integrator that only change the work schedule.
    if (o->find("samples_per_pass")) r_.getInt(*o, "samples_per_pass", 1, 1, 1 << 30);
    if (o->find("block_size")) r_.getInt(*o, "block_size", 0, 0, 1 << 16);
    if (r_.getBool(*o, "hide_emitters", false))
        r_.error(o->find("hide_emitters")->pos,
                 o->label() + ": hide_emitters = true is not supported");
    if (o->type == "direct") {
        // Mitsuba's direct: directly visible emitters plus emitter and BSDF sampling at the
        // first hit, combined by MIS. That is a path of at most 2 segments (max_depth 2); the
        // sample counts change the variance only. A count of 0 drops a strategy: with no
        // emitter samples delta lights (point, spot, projector, directional) vanish, with no
        // BSDF samples so does light reflected or refracted by delta lobes. The image keeps
        // its expectation where the scene has none of those (checked in checkDirect once the
        // scene is read), and unibeam renders it with its own estimators; with both counts 0
        // only directly visible emitters remain (1 segment).
        const int shading = r_.getInt(*o, "shading_samples", 1, 1, 1 << 20);
        directEmitterSamples_ = r_.getInt(*o, "emitter_samples", shading, 0, 1 << 20);
        directBsdfSamples_ = r_.getInt(*o, "bsdf_samples", shading, 0, 1 << 20);
        direct_ = o;
        b_.scene.settings.maxPathLength =
            directEmitterSamples_ == 0 && directBsdfSamples_ == 0 ? 1 : 2;
        r_.checkUnused(*o);
        return;
    }
    // Mitsuba's max_depth counts scattering vertices (null / index-matched interfaces do not
    // count): 1 = directly visible emitters only. That is the number of path segments of
    // unibeam's maxPathLength (SmallVCM semantics). -1 means unlimited.
    int maxDepth = r_.getInt(*o, "max_depth", -1, -1, 1 << 20);
    if (maxDepth == 0)
        r_.error(o->find("max_depth")->pos, o->label() +
                                                ": max_depth 0 renders nothing (expected "
                                                "-1 or a value >= 1)");
    b_.scene.settings.maxPathLength = maxDepth < 0 ? (1 << 20) : maxDepth;
    r_.getInt(*o, "rr_depth", 5, 1, 1 << 20);  // Russian roulette: variance only
    // Mitsuba's ptracer traces paths from the emitters and connects them to the sensor:
    // unibeam's light tracing, the algorithm used when `render` is given no -a.
    if (o->type == "ptracer") b_.scene.settings.defaultAlgorithm = "lt";
    r_.checkUnused(*o);
}

void Builder::readFilm(const XmlObject& f, int* w, int* h) {
    if (f.type != "hdrfilm") {
        r_.unsupportedPlugin(f, {"hdrfilm"});
        return;
    }
    *w = r_.getInt(f, "width", 768, 1, 16384);
    *h = r_.getInt(f, "height", 576, 1, 16384);
    std::string pf = r_.getString(f, "pixel_format", "rgb");
    if (pf != "rgb" && pf != "rgba")
        r_.error(f.find("pixel_format")->pos,
                 f.label() + ": pixel_format '" + pf + "' is not supported (expected rgb or rgba)");
    std::string cf = r_.getString(f, "component_format", "float16");
    if (cf != "float16" && cf != "float32")
        r_.error(f.find("component_format")->pos, f.label() + ": component_format '" + cf +
                                                      "' is not supported (unibeam writes "
                                                      "32-bit float EXR)");
    std::string ff = r_.getString(f, "file_format", "openexr");
    if (ff != "openexr" && ff != "exr")
        r_.error(f.find("file_format")->pos, f.label() + ": file_format '" + ff +
                                                 "' is not supported (unibeam writes OpenEXR)");
    // Reconstruction filter (scene/pixel_filter.h): sampled per camera path, spread over the
    // footprint by light-tracing splats. No <rfilter> means Mitsuba's default Gaussian.
    const XmlObject* rf = r_.child(f, "rfilter", "");
    if (!rf) {
        b_.scene.settings.pixelFilter = PixelFilter::gaussian(0.5f);
    } else if (rf->type == "box") {
        b_.scene.settings.pixelFilter = PixelFilter::box();
        r_.checkUnused(*rf);
    } else if (rf->type == "tent") {
        // Mitsuba's tent: radius default 1 pixel. Radii beyond 64 pixels are refused (each
        // light-tracing splat is spread over (2 radius + 1)^2 pixels).
        float radius = r_.getFloatIn(*rf, "radius", 1.0f, 0.0f, 64.0f, true);
        if (radius > 0.0f) b_.scene.settings.pixelFilter = PixelFilter::tent(radius);
        r_.checkUnused(*rf);
    } else if (rf->type == "gaussian") {
        // Mitsuba's gaussian: stddev default 0.5 pixel, cut off at 4 stddev.
        float stddev = r_.getFloatIn(*rf, "stddev", 0.5f, 0.0f, 16.0f, true);
        if (stddev > 0.0f) b_.scene.settings.pixelFilter = PixelFilter::gaussian(stddev);
        r_.checkUnused(*rf);
    } else {
        r_.unsupportedPlugin(*rf, kRfilters,
                             "mitchell, catmullrom and lanczos have negative lobes, which "
                             "filter importance sampling cannot reproduce with weight 1");
    }
    r_.checkUnused(f);
}

float Builder::readFovX(const XmlObject& o, float aspect) {
    float fovX = 0.0f;
    if (o.find("fov") && o.find("focal_length"))
        r_.error(o.find("focal_length")->pos,
                 o.label() + ": give either 'fov' or 'focal_length', not both");
    if (o.find("fov")) {
        float fov = r_.getFloatIn(o, "fov", 45.0f, 0.0f, 180.0f, true, true);
        std::string axis = r_.getString(o, "fov_axis", "x");
        if (axis == "smaller") axis = aspect > 1 ? "y" : "x";
        if (axis == "larger") axis = aspect > 1 ? "x" : "y";
        const float t = std::tan(0.5f * fov * kPi / 180.0f);
        if (axis == "x") {
            fovX = fov;
        } else if (axis == "y") {
            fovX = 2.0f * std::atan(t * aspect) * 180.0f / kPi;
        } else if (axis == "diagonal") {
            float width = 2.0f * t / std::sqrt(1.0f + 1.0f / (aspect * aspect));
            fovX = 2.0f * std::atan(0.5f * width) * 180.0f / kPi;
        } else {
            r_.error(o.find("fov_axis")->pos, o.label() + ": fov_axis '" + axis +
                                                  "' is not one of x, y, diagonal, smaller, "
                                                  "larger");
        }
    } else {
        // Mitsuba's default: a 50 mm lens on a 36 x 24 mm film, fov along the diagonal.
        std::string f = r_.getString(o, "focal_length", "50mm");
        std::string num =
            f.size() > 2 && f.substr(f.size() - 2) == "mm" ? f.substr(0, f.size() - 2) : f;
        char* end = nullptr;
        double mm = std::strtod(num.c_str(), &end);
        if (num.empty() || *end != '\0' || !(mm > 0)) {
            r_.error(o.find("focal_length")->pos,
                     o.label() + ": focal_length '" + f + "' is not of the form <x>mm");
            mm = 50;
        }
        double diag = 2.0 * std::atan(std::sqrt(36.0 * 36.0 + 24.0 * 24.0) / (2.0 * mm));
        double width = 2.0 * std::tan(0.5 * diag) / std::sqrt(1.0 + 1.0 / (aspect * aspect));
        fovX = float(2.0 * std::atan(0.5 * width) * 180.0 / kPi);
    }
    return fovX;
}

void Builder::readSensor(const XmlObject& o) {
    if (o.type != "perspective" && o.type != "thinlens" && o.type != "orthographic") {
        r_.unsupportedPlugin(o, {"perspective", "thinlens", "orthographic"});
        return;
    }
    int w = 768, h = 576;
    if (const XmlObject* film = r_.child(o, "film", "")) readFilm(*film, &w, &h);
    if (const XmlObject* s = r_.child(o, "sampler", "")) {
        bool known = false;
        for (const auto& k : kSamplers) known = known || s->type == k;
        if (!known) r_.unsupportedPlugin(*s, kSamplers);
        // unibeam draws independent uniform samples; the count is chosen on the command line.
        const int count = r_.getInt(*s, "sample_count", 4, 1, 1 << 30);
        r_.getInt(*s, "seed", 0, 0, 1 << 30);
        if (s->type != "independent" && s->type != "ldsampler") r_.getBool(*s, "jitter", true);
        if (s->type == "orthogonal") r_.getInt(*s, "strength", 2, 1, 1 << 20);
        r_.checkUnused(*s);
        if (known)
            r_.warning(s->pos, s->label() +
                                   ": unibeam uses its own independent sampler; "
                                   "sample_count " +
                                   std::to_string(count) +
                                   " is not used (one sample per pixel per iteration: set "
                                   "the iterations with `unibeam render -i`)");
    }
    const float aspect = float(w) / float(h);
    if (o.type == "orthographic") {
        readOrthographic(o, w, h);
        return;
    }
    const float fovX = readFovX(o, aspect);
    if (o.find("near_clip") || o.find("far_clip")) {
        r_.getFloatIn(o, "near_clip", 0.01f, 0.0f, kInf, true);
        r_.getFloatIn(o, "far_clip", 1e4f, 0.0f, kInf, true);
        r_.warning(o.pos, o.label() +
                              ": near_clip/far_clip are not applied (unibeam's camera "
                              "has no clipping planes)");
    }
    // Thin lens (Mitsuba's thinlens: aperture_radius, required, and focus_distance, the
    // distance of the plane in focus along the view axis, default far_clip). Mitsuba's
    // perspective sensor reads focus_distance and ignores it.
    float lensRadius = 0.0f, focusDistance = 1.0f;
    if (o.type == "thinlens") {
        if (!o.find("aperture_radius"))
            r_.error(o.pos, o.label() + ": needs <float name=\"aperture_radius\">");
        lensRadius = r_.getFloatIn(o, "aperture_radius", 0.0f, 0.0f, kInf);
        focusDistance = r_.getFloatIn(o, "focus_distance", 1e4f, 0.0f, kInf, true);
    } else if (o.find("focus_distance")) {
        r_.getFloatIn(o, "focus_distance", 1e4f, 0.0f, kInf, true);
    }
    Transform m = r_.getTransform(o, "to_world");
    r_.checkUnused(o);
    // Camera space: +z forward, +y up, +x to the left of the image (Mitsuba's convention).
    Vec3 origin = m.point(Vec3(0.0f)), fwd = m.vector(Vec3(0, 0, 1)), up = m.vector(Vec3(0, 1, 0)),
         left = m.vector(Vec3(1, 0, 0));
    const XmlProperty* tp = o.find("to_world");
    float s = similarityScale(m);
    if (!(s > 0) || std::fabs(s - 1.0f) > 1e-3f || dot(cross(up, fwd), left) <= 0) {
        r_.error(tp ? tp->pos : o.pos,
                 o.label() +
                     ": to_world must be a rotation and translation (no scale or "
                     "mirroring; use <lookat>)");
        return;
    }
    if (!(fovX > 0.0f)) return;
    float fovY = 2.0f * std::atan(std::tan(0.5f * fovX * kPi / 180.0f) / aspect) * 180.0f / kPi;
    b_.scene.camera.setup(origin, origin + normalize(fwd), normalize(up), fovY, w, h, lensRadius,
                          focusDistance);
    b_.cameraSet = true;
}

// Mitsuba 3.9.1's orthographic sensor (src/sensors/orthographic.cpp, orthographic_projection
// in include/mitsuba/render/sensor.h): camera space x in [-1, 1] (+x at the image's left), y in
// [-1 / aspect, 1 / aspect], rays from the near plane z = near_clip along +z, all mapped by
// to_world, whose scale sets the size of the viewed region. far_clip is not applied.
void Builder::readOrthographic(const XmlObject& o, int w, int h) {
    const float nearClip = r_.getFloatIn(o, "near_clip", 0.01f, 0.0f, kInf, true);
    const float farClip = r_.getFloatIn(o, "far_clip", 1e4f, 0.0f, kInf, true);
    if (o.find("far_clip"))
        r_.warning(o.find("far_clip")->pos,
                   o.label() + ": far_clip is not applied (rays are not cut off at " +
                       std::to_string(farClip) + ")");
    Transform m = r_.getTransform(o, "to_world");
    r_.checkUnused(o);
    const Vec3 ax = m.vector(Vec3(1, 0, 0)), ay = m.vector(Vec3(0, 1, 0)),
               az = m.vector(Vec3(0, 0, 1));
    const float lx = length(ax), ly = length(ay), lz = length(az);
    const XmlProperty* tp = o.find("to_world");
    const bool orthogonal =
        lx > 0 && ly > 0 && lz > 0 && std::fabs(dot(ax, ay)) <= 1e-4f * lx * ly &&
        std::fabs(dot(ax, az)) <= 1e-4f * lx * lz && std::fabs(dot(ay, az)) <= 1e-4f * ly * lz;
    if (!orthogonal || !std::isfinite(lx * ly * lz) || dot(cross(ay, az), ax) <= 0) {
        r_.error(tp ? tp->pos : o.pos, o.label() +
                                           ": to_world must map the camera axes to orthogonal, "
                                           "non-mirrored directions (a rotation, a translation and "
                                           "a scale along the camera axes)");
        return;
    }
    const Vec3 forward = az / lz, up = ay / ly, right = -ax / lx;
    const Vec3 nearCentre = m.point(Vec3(0.0f, 0.0f, nearClip));
    const float aspect = float(w) / float(h);
    b_.scene.camera.setupOrthographic(nearCentre, forward, right, up, lx, ly / aspect, w, h);
    b_.scene.settings.keepHorizontalFov = true;  // Mitsuba fixes the x extent
    b_.cameraSet = true;
}

int Builder::mediumId(const XmlObject& med) {
    auto it = b_.mediumIds.find(&med);
    if (it != b_.mediumIds.end()) return it->second;
    Medium m;
    int id = -1;
    if (buildMitsubaMedium(b_, med, &m))
        id = b_.scene.addMedium(m, med.id.empty() ? med.type : med.id);
    b_.mediumIds[&med] = id;
    return id;
}

// Mitsuba's BSDF for a shape that names none: one-sided diffuse of reflectance 0.5, or 0
// (black) when the shape carries an area emitter: an emitter does not reflect unless given
// a BSDF. Each is added to the scene once, on first use.
int Builder::oneSidedDiffuse(float reflectance, const char* name, int* cachedId) {
    if (*cachedId < 0) {
        Material m;
        m.name = name;
        m.type = MaterialType::Diffuse;
        m.diffuse = Rgb(reflectance);
        m.twoSided = false;
        *cachedId = b_.scene.addMaterial(m);
    }
    return *cachedId;
}

int Builder::defaultMaterial() {
    return oneSidedDiffuse(0.5f, "default diffuse", &defaultMaterial_);
}

int Builder::blackMaterial() {
    return oneSidedDiffuse(0.0f, "emitter default (black diffuse)", &blackMaterial_);
}

// The geometry of a shape plugin in world space (or, for a shape in a shapegroup, in the
// group's space): its mesh, or the centre and radius of a sphere.
void Builder::readGeometry(const XmlObject& o, ShapeGeometry* g) {
    Transform toWorld = r_.getTransform(o, "to_world");
    if (o.type == "sdfgrid") {
        // Mitsuba's sdfgrid (scene/sdf_grid.h): a one-channel .vol of distances over [0, 1]^3.
        g->isSdfGrid = true;
        g->sdfToWorld = toWorld;
        const std::string normals = r_.getString(o, "normals", "smooth");
        if (normals != "smooth" && normals != "analytic")
            r_.error(o.find("normals")->pos,
                     o.label() + ": normals '" + normals + "' is not one of smooth, analytic");
        g->sdfSmooth = normals != "analytic";
        const std::string file = r_.getString(o, "filename", "");
        if (file.empty()) {
            r_.error(o.pos, o.label() +
                                ": needs <string name=\"filename\"> (a .vol grid of "
                                "distances)");
            return;
        }
        const std::string path = b_.resolveFile(o, "filename", file);
        if (path.empty()) return;
        try {
            auto vol = std::make_shared<VolGrid>(readVolFile(path));
            if (vol->channels != 1)
                r_.error(o.find("filename")->pos, o.label() + ": '" + file + "' has " +
                                                      std::to_string(vol->channels) +
                                                      " channels (expected 1: signed distances)");
            g->sdfSamples = vol;
            g->sdfLabel = path;
            // Validated now (resolution, values, a surface), built again where it is added.
            SdfGrid::make(vol->nx, vol->ny, vol->nz, vol->values, toWorld, g->sdfSmooth, path);
        } catch (const InputError& e) {
            for (const Diagnostic& d : e.diagnostics())
                r_.error(o.find("filename")->pos, o.label() + ": " + d.message);
        }
        return;
    }
    bool flipNormals = r_.getBool(o, "flip_normals", false);
    TriangleMesh& mesh = g->mesh;
    const XmlProperty* toWorldProp = o.find("to_world");
    const XmlPos& toWorldPos = toWorldProp ? toWorldProp->pos : o.pos;
    if (o.type == "obj" || o.type == "ply" || o.type == "serialized") {
        std::string file = r_.getString(o, "filename", "");
        bool faceNormals = r_.getBool(o, "face_normals", false);
        bool flipTex = o.type == "obj" ? r_.getBool(o, "flip_tex_coords", true) : false;
        const int shapeIndex =
            o.type == "serialized" ? r_.getInt(o, "shape_index", 0, 0, (1 << 30)) : 0;
        if (file.empty()) {
            r_.error(o.pos, o.label() + ": needs <string name=\"filename\">");
        } else {
            std::string path = b_.resolveFile(o, "filename", file);
            if (!path.empty()) {
                Diagnostics meshDiags;
                mesh = o.type == "serialized"
                           ? loadSerializedMesh(path, shapeIndex, faceNormals, meshDiags, o.label())
                           : loadMeshFile(path, meshDiags, o.label());
                for (const Diagnostic& d : meshDiags.all()) {
                    const XmlProperty* p = o.find("filename");
                    std::string msg = o.label() + ": " + d.format();
                    if (d.warning)
                        r_.warning(p->pos, msg);
                    else
                        r_.error(p->pos, msg);
                }
            }
        }
        if (faceNormals) mesh.normals.clear();
        if (flipTex)  // Mitsuba's OBJ reader flips v by default
            for (Vec2& uv : mesh.uvs) uv.y = 1.0f - uv.y;
    } else if (o.type == "rectangle") {
        mesh = makeRectangle();
    } else if (o.type == "cube") {
        mesh = makeCube();
    } else if (o.type == "disk") {
        // Mitsuba's disk: the unit disk in z = 0 with normal +z, any to_world except one that
        // shears its plane (Mitsuba refuses those); a non-uniform scale makes an ellipse,
        // which the transformed mesh represents exactly.
        mesh = makeDisk();
        const Vec3 du = toWorld.vector(Vec3(1, 0, 0)), dv = toWorld.vector(Vec3(0, 1, 0));
        if (std::fabs(dot(du, dv)) > 1e-4f * length(du) * length(dv))
            r_.error(toWorldPos, o.label() +
                                     ": to_world shears the disk (its x and y axes are not "
                                     "perpendicular after it), which Mitsuba's disk rejects");
    } else if (o.type == "cylinder") {
        // Mitsuba's cylinder: the unit cylinder (radius 1, z in [0, 1]) placed by
        // translate(p0) * frame(p1 - p0) * scale(radius, radius, |p1 - p0|), then to_world.
        // The frame is Mitsuba's (Duff et al. 2017, unibeam's Frame), which fixes where
        // u = 0 lies around the axis.
        const Vec3 p0 = r_.getPoint(o, "p0", Vec3(0.0f)), p1 = r_.getPoint(o, "p1", Vec3(0, 0, 1));
        const float radius = r_.getFloatIn(o, "radius", 1.0f, 0.0f, kInf, true);
        const float len = length(p1 - p0);
        if (!(len > 0.0f)) {
            r_.error(o.find("p1") ? o.find("p1")->pos : o.pos,
                     o.label() + ": p0 and p1 must differ (they give the cylinder's axis)");
        } else if (radius > 0.0f) {
            toWorld = toWorld * cylinderPlacement(p0, p1, radius);
            // Mitsuba keeps the cylinder circular: it takes the radius from one axis and warns
            // about shear or unequal scales across the axis. unibeam refuses those instead of
            // rendering a different shape, and mirroring (Mitsuba's normals would point in).
            if (!keepsCylinderCircular(toWorld))
                r_.error(toWorldPos, o.label() +
                                         ": to_world must keep the cylinder circular: a "
                                         "rotation, translation and scale, the scale the same "
                                         "in every direction across the axis, and no "
                                         "mirroring");
            mesh = makeCylinder();
        }
    } else {
        g->isSphere = true;
        Vec3 center = r_.getPoint(o, "center", Vec3(0.0f));
        float radius = r_.getFloatIn(o, "radius", 1.0f, 0.0f, kInf, true);
        float s = similarityScale(toWorld);
        if (!(s > 0)) {
            r_.error(toWorldPos, o.label() +
                                     ": a sphere's to_world must be a rotation, "
                                     "translation and uniform scale");
        }
        g->center = toWorld.point(center);
        g->radius = radius * s;
        if (flipNormals)
            r_.error(o.find("flip_normals")->pos,
                     o.label() + ": flip_normals is not supported for spheres");
    }
    if (!g->isSphere && !mesh.indices.empty()) {
        if (flipNormals) {
            for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3)
                std::swap(mesh.indices[t + 1], mesh.indices[t + 2]);
            for (Vec3& n : mesh.normals) n = -n;
        }
        transformMesh(mesh, toWorld);
    }
}

void Builder::readShape(const XmlObject& o) {
    const size_t before = r_.errorCount();
    bool known = false;
    for (const auto& k : kShapes) known = known || o.type == k;
    if (!known) {
        r_.unsupportedPlugin(o, kShapes);
        return;
    }
    if (o.type == "shapegroup") {
        // Not rendered itself: validated (and its shapes built) once, copied per instance.
        shapeGroup(o);
        if (o.id.empty())
            r_.warning(o.pos, o.label() +
                                  " has no id: no instance can reference it, so it is not "
                                  "rendered");
        return;
    }
    if (o.type == "instance") {
        readInstance(o);
        return;
    }
    const std::string name =
        o.id.empty() ? o.type + " " + std::to_string(b_.scene.shapes.size()) : o.id;
    ShapeGeometry g;
    readGeometry(o, &g);
    TriangleMesh& mesh = g.mesh;
    const bool isSphere = g.isSphere;
    const Vec3 center = g.center;
    const float radius = g.radius;

    const XmlObject* em = r_.child(o, "emitter", "");
    int materialId = -2;
    if (const XmlObject* bsdf = r_.child(o, "bsdf", ""))
        materialId = buildMitsubaBsdf(b_, *bsdf);
    else
        materialId = em ? blackMaterial() : defaultMaterial();
    if (!bindMeshAttribute(o, materialId, &g)) return;
    if (g.isSdfGrid && em) {
        r_.error(em->pos, o.label() + " '" + name + "': an sdfgrid cannot emit (nor in Mitsuba)");
        return;
    }

    int lightId = -1;
    Light light;
    if (em) {
        if (em->type != "area") {
            r_.error(em->pos, "a shape can only carry an 'area' emitter, got '" + em->type + "'");
        } else {
            light.type = LightType::Area;
            light.name = name;
            // A `radiance` texture (Mitsuba: the emitted radiance at the shape's uv) or a colour.
            if (const XmlObject* tex = r_.child(*em, "texture", "radiance")) {
                const int id = buildMitsubaTexture(b_, *tex, ColorUse::Unbounded);
                if (id >= 0) {
                    const Texture& t = b_.scene.textures[size_t(id)];
                    if (t.type == TextureType::MeshAttribute)
                        r_.error(tex->pos,
                                 em->label() + ": a mesh_attribute radiance is not supported");
                    light.radianceTexture = std::make_shared<const Texture>(t);
                }
                light.radiance = Rgb(1.0f);
            } else {
                light.radiance = r_.getColor(*em, "radiance", Rgb(1.0f), ColorUse::Emission);
            }
            light.twoSided = false;  // Mitsuba's area emitters emit on the normal's side only
            r_.checkUnused(*em);
            if (isSphere) {
                light.isSphere = true;
                light.position = center;
                light.sphereRadius = radius;
            } else {
                for (uint32_t idx : mesh.indices) light.triangles.push_back(mesh.positions[idx]);
                // The mesh's uvs, as Scene::intersect interpolates them (none: barycentric).
                if (light.radianceTexture && !mesh.uvs.empty())
                    for (uint32_t idx : mesh.indices) light.triangleUvs.push_back(mesh.uvs[idx]);
            }
        }
    }
    // Media on both sides (Mitsuba's rule: entering gives the interior, leaving the exterior;
    // an absent one is vacuum). Either makes the shape a medium boundary.
    int interiorId = -1, exteriorId = -1;
    const XmlObject* interior = r_.child(o, "medium", "interior");
    if (interior) interiorId = mediumId(*interior);
    const XmlObject* exterior = r_.child(o, "medium", "exterior");
    if (exterior) exteriorId = mediumId(*exterior);
    const bool boundary = interior || exterior;
    r_.checkUnused(o);
    if (r_.errorCount() != before) return;
    if (materialId == -1 && !em && !boundary) {
        r_.warning(o.pos, o.label() + " '" + name +
                              "' has a null BSDF and no medium: it is "
                              "invisible and is left out");
        return;
    }
    // A null BSDF on an emitter: Mitsuba lets rays pass through the shape, which still emits.
    // unibeam gives it the pass-through material (nullPassMaterial: a straight delta
    // transmission), so paths pick up the emission where they cross it and continue; light
    // sampling reaches it as any area light (docs/mitsuba.md).
    if (materialId == -1 && em) {
        if (boundary) {
            r_.error(em->pos, o.label() + " '" + name +
                                  "': a shape with a null BSDF and a medium cannot emit (not "
                                  "supported)");
            return;
        }
        materialId = nullPassMaterial(b_);
    }
    const bool imaginary = materialId == -1;  // null BSDF + medium: an index-matched boundary
    if (em) {
        try {
            lightId = b_.scene.addLight(std::move(light));
        } catch (const InputError& e) {
            for (const Diagnostic& d : e.diagnostics())
                r_.error(em->pos, em->label() + ": " + d.message);
            return;
        }
    }
    if (g.isSdfGrid) {
        if (boundary) {
            r_.error(o.pos, o.label() + " '" + name +
                                "': an sdfgrid cannot bound a medium (not supported)");
            return;
        }
        const VolGrid& v = *g.sdfSamples;
        b_.scene.addSdfGrid(
            SdfGrid::make(v.nx, v.ny, v.nz, v.values, g.sdfToWorld, g.sdfSmooth, g.sdfLabel),
            materialId, name);
        return;
    }
    const uint32_t shapeId = isSphere
                                 ? b_.scene.addSphere(center, radius, materialId, lightId, name)
                                 : b_.scene.addMesh(std::move(mesh), materialId, lightId, name);
    if (boundary) {
        b_.scene.setMediumBoundary(shapeId, interiorId, 0, imaginary);
        b_.scene.setExteriorMedium(shapeId, exteriorId);
    }
}

// Mitsuba's shapegroup holds shapes that only appear through instances. unibeam flattens
// instancing: the members are built once here (in the group's space) and every instance adds
// transformed copies of them (docs/mitsuba.md). As in Mitsuba, a member cannot be a
// shapegroup or an instance, nor carry an emitter; unibeam also refuses media on members.
const ShapeGroupShapes& Builder::shapeGroup(const XmlObject& group) {
    auto found = groups_.find(&group);
    if (found != groups_.end()) return found->second;
    ShapeGroupShapes& out = groups_[&group];
    const size_t before = r_.errorCount();
    const std::string groupName = group.id.empty() ? std::string("shapegroup") : group.id;
    int index = 0;
    for (const XmlObject* member : r_.children(group, "shape")) {
        const XmlObject& o = *member;
        ++index;
        if (o.type == "shapegroup" || o.type == "instance") {
            r_.error(o.pos, group.label() + ": a shapegroup cannot hold a " + o.type +
                                " (nested instancing is not permitted, as in Mitsuba)");
            continue;
        }
        bool known = false;
        for (const auto& k : kShapes) known = known || o.type == k;
        if (!known) {
            r_.unsupportedPlugin(o, kShapes);
            continue;
        }
        const size_t memberBefore = r_.errorCount();
        ShapeGroupShapes::Member m;
        m.name = o.id.empty() ? o.type + " " + std::to_string(index - 1) : o.id;
        readGeometry(o, &m.geometry);
        if (const XmlObject* bsdf = r_.child(o, "bsdf", ""))
            m.materialId = buildMitsubaBsdf(b_, *bsdf);
        else
            m.materialId = defaultMaterial();
        if (r_.child(o, "emitter", ""))
            r_.error(r_.lastChildPos(), o.label() + " in " + group.label() +
                                            ": instancing of emitters is not supported (nor "
                                            "in Mitsuba)");
        for (const char* side : {"interior", "exterior"})
            if (r_.child(o, "medium", side))
                r_.error(r_.lastChildPos(), o.label() + " in " + group.label() +
                                                ": a shape in a shapegroup cannot be a medium "
                                                "boundary (not supported)");
        r_.checkUnused(o);
        if (r_.errorCount() != memberBefore) continue;
        if (!bindMeshAttribute(o, m.materialId, &m.geometry)) continue;
        if (m.materialId == -1) {
            r_.warning(o.pos, o.label() + " '" + m.name + "' in shapegroup '" + groupName +
                                  "' has a null BSDF and no medium: it is invisible and is "
                                  "left out");
            continue;
        }
        out.members.push_back(std::move(m));
    }
    r_.checkUnused(group);
    out.ok = r_.errorCount() == before;
    return out;
}

void Builder::readInstance(const XmlObject& o) {
    const size_t before = r_.errorCount();
    const std::string name = o.id.empty() ? "instance " + std::to_string(instanceCount_) : o.id;
    ++instanceCount_;
    const Transform toWorld = r_.getTransform(o, "to_world");
    const XmlProperty* toWorldProp = o.find("to_world");
    const XmlObject* group = nullptr;
    for (const XmlChild& c : o.children) {
        const XmlObject& obj = *c.object;
        c.used = true;
        const bool isRef = c.pos.file != obj.pos.file || c.pos.line != obj.pos.line ||
                           c.pos.column != obj.pos.column;
        const std::string what = isRef ? "<ref id=\"" + obj.id + "\"> names " + obj.label() +
                                             " (defined at " + obj.pos.file + ":" +
                                             std::to_string(obj.pos.line) + ")"
                                       : "nested " + obj.label();
        if (obj.tag != "shape" || obj.type != "shapegroup")
            r_.error(c.pos, o.label() + ": " + what + "; expected a shapegroup");
        else if (group)
            r_.error(c.pos, o.label() + ": " + what +
                                ", a second shapegroup (an instance references exactly one)");
        else
            group = &obj;
    }
    if (!group && r_.errorCount() == before)
        r_.error(o.pos, o.label() +
                            ": needs the shapegroup it instantiates (<ref id=\"...\"/> to a "
                            "<shape type=\"shapegroup\" id=\"...\">)");
    r_.checkUnused(o);
    if (r_.errorCount() != before || !group) return;
    const ShapeGroupShapes& shapes = shapeGroup(*group);
    if (!shapes.ok) return;  // its errors were reported with the group
    const float scale = similarityScale(toWorld);
    for (const ShapeGroupShapes::Member& m : shapes.members) {
        const std::string memberName = name + "/" + m.name;
        if (m.geometry.isSdfGrid) {
            const VolGrid& v = *m.geometry.sdfSamples;
            try {
                b_.scene.addSdfGrid(
                    SdfGrid::make(v.nx, v.ny, v.nz, v.values, toWorld * m.geometry.sdfToWorld,
                                  m.geometry.sdfSmooth, m.geometry.sdfLabel),
                    m.materialId, memberName);
            } catch (const InputError& e) {
                for (const Diagnostic& d : e.diagnostics())
                    r_.error(toWorldProp ? toWorldProp->pos : o.pos, o.label() + ": " + d.message);
                return;
            }
        } else if (m.geometry.isSphere) {
            if (!(scale > 0)) {
                r_.error(toWorldProp ? toWorldProp->pos : o.pos,
                         o.label() +
                             ": to_world must be a rotation, translation and uniform "
                             "scale, since shapegroup member '" +
                             m.name + "' is a sphere");
                return;
            }
            b_.scene.addSphere(toWorld.point(m.geometry.center), m.geometry.radius * scale,
                               m.materialId, -1, memberName);
        } else {
            TriangleMesh mesh = m.geometry.mesh;
            transformMesh(mesh, toWorld);
            b_.scene.addMesh(std::move(mesh), m.materialId, -1, memberName);
        }
    }
}

void Builder::setLightFrame(const XmlObject& o, const Transform& toWorld, Light* light) {
    const Vec3 x = toWorld.vector(Vec3(1, 0, 0)), y = toWorld.vector(Vec3(0, 1, 0)),
               z = toWorld.vector(Vec3(0, 0, 1));
    const float s = similarityScale(toWorld);
    if (!(s > 0) || std::fabs(s - 1.0f) > 1e-3f) {
        const XmlProperty* tp = o.find("to_world");
        r_.error(tp ? tp->pos : o.pos, o.label() +
                                           ": to_world must be a rotation and translation (no "
                                           "scale or shear) for a projected texture");
        return;
    }
    light->frameX = x;
    light->frameY = y;
    light->direction = z;
}

void Builder::readProjectedTexture(const XmlObject& o, const XmlObject& tex, const XmlPos& at,
                                   const Transform& toWorld, Light* light) {
    const int id = buildMitsubaTexture(b_, tex);
    if (id < 0) return;  // reported
    const Texture& t = b_.scene.textures[size_t(id)];
    if (t.type != TextureType::Bitmap) {
        r_.error(at, o.label() + ": the projected texture must be a bitmap (got " + tex.label() +
                         "; Mitsuba requires a spatially varying one)");
        return;
    }
    light->projTexture = std::make_shared<Texture>(t);
    setLightFrame(o, toWorld, light);
}

void Builder::readEmitter(const XmlObject& o) {
    const size_t before = r_.errorCount();
    Light light;
    light.name = o.id.empty() ? o.type : o.id;
    if (o.type == "point") {
        light.type = LightType::Point;
        light.intensity = r_.getColor(o, "intensity", Rgb(1.0f), ColorUse::Emission);
        if (o.find("position") && o.find("to_world"))
            r_.error(o.find("position")->pos, o.label() + ": give either 'position' or 'to_world'");
        light.position = o.find("position") ? r_.getPoint(o, "position", Vec3(0.0f))
                                            : r_.getTransform(o, "to_world").point(Vec3(0.0f));
    } else if (o.type == "spot") {
        light.type = LightType::Spot;
        light.intensity = r_.getColor(o, "intensity", Rgb(1.0f), ColorUse::Emission);
        light.cutoffAngleDeg = r_.getFloatIn(o, "cutoff_angle", 20.0f, 0.0f, 180.0f, true);
        light.beamWidthDeg = r_.getFloatIn(o, "beam_width", 0.75f * light.cutoffAngleDeg, 0.0f,
                                           light.cutoffAngleDeg);
        // Mitsuba's spot shines along +z of to_world from its origin.
        Transform m = r_.getTransform(o, "to_world");
        light.position = m.point(Vec3(0.0f));
        light.direction = m.vector(Vec3(0, 0, 1));
        if (const XmlObject* tex = r_.child(o, "texture", "texture")) {
            const XmlPos at = r_.lastChildPos();
            readProjectedTexture(o, *tex, at, m, &light);
        } else if (o.find("texture")) {
            // Mitsuba: "The parameter 'texture' must be spatially varying".
            r_.error(o.find("texture")->pos,
                     o.label() + ": 'texture' must be a spatially varying texture (a bitmap)");
        }
    } else if (o.type == "projector") {
        light.type = LightType::Projector;
        light.intensity = Rgb(r_.getFloatIn(o, "scale", 1.0f, 0.0f, kInf));
        Transform m = r_.getTransform(o, "to_world");
        light.position = m.point(Vec3(0.0f));
        light.direction = m.vector(Vec3(0, 0, 1));
        if (const XmlObject* tex = r_.child(o, "texture", "irradiance")) {
            const XmlPos at = r_.lastChildPos();
            readProjectedTexture(o, *tex, at, m, &light);
        } else {
            // A constant irradiance: a 1 x 1 texture (Mitsuba's resolution of a constant).
            Texture t;
            t.type = TextureType::Constant;
            t.name = "irradiance";
            t.color0 = r_.getColor(o, "irradiance", Rgb(1.0f), ColorUse::Emission);
            light.projTexture = std::make_shared<Texture>(t);
            setLightFrame(o, m, &light);
        }
        if (light.projTexture && light.projTexture->type == TextureType::Bitmap &&
            light.projTexture->image)
            light.projAspect =
                float(light.projTexture->image->width) / float(light.projTexture->image->height);
        light.projFovXDeg = readFovX(o, light.projAspect);
    } else if (o.type == "directional") {
        light.type = LightType::Directional;
        light.radiance = r_.getColor(o, "irradiance", Rgb(1.0f), ColorUse::Emission);
        if (o.find("direction") && o.find("to_world"))
            r_.error(o.find("direction")->pos,
                     o.label() + ": give either 'direction' or 'to_world'");
        light.direction = o.find("direction")
                              ? r_.getVector(o, "direction", Vec3(0, 0, 1))
                              : r_.getTransform(o, "to_world").vector(Vec3(0, 0, 1));
        if (!(length(light.direction) > 0))
            r_.error(o.pos, o.label() + ": the direction must not be zero");
    } else if (o.type == "constant") {
        light.type = LightType::ConstantEnv;
        light.radiance = r_.getColor(o, "radiance", Rgb(1.0f), ColorUse::Emission);
    } else if (o.type == "envmap") {
        light.type = LightType::EnvMap;
        light.envFilter = EnvFilter::Bilinear;  // Mitsuba 3's envmap interpolates bilinearly
        light.radiance = Rgb(r_.getFloatIn(o, "scale", 1.0f, 0.0f, kInf));
        Transform m = r_.getTransform(o, "to_world");
        light.envToWorld = m;
        light.worldToEnv = m.inverse();
        std::string file = r_.getString(o, "filename", "");
        if (file.empty())
            r_.error(o.pos, o.label() + ": needs <string name=\"filename\">");
        else if (std::string path = b_.resolveFile(o, "filename", file); !path.empty()) {
            try {
                light.envMap = std::make_shared<Image>(readExr(path));
            } catch (const InputError& e) {
                for (const Diagnostic& d : e.diagnostics())
                    r_.error(o.find("filename")->pos, o.label() + ": " + d.format());
            }
        }
    } else if (o.type == "area") {
        r_.error(o.pos,
                 "an 'area' emitter must be nested inside a <shape> (or given an id and "
                 "attached to shapes with <ref id=\"...\"/>)");
        return;
    } else {
        r_.unsupportedPlugin(o, kEmitters);
        return;
    }
    r_.checkUnused(o);
    if (r_.errorCount() != before) return;
    if (light.isEnvironment()) {
        if (envObject_) {
            r_.error(o.pos,
                     "more than one environment emitter (constant/envmap); the first is at "
                     "line " +
                         std::to_string(envObject_->pos.line));
            return;
        }
        envObject_ = &o;
    }
    try {
        int id = b_.scene.addLight(std::move(light));
        if (b_.scene.lights[size_t(id)].isEnvironment()) b_.scene.backgroundLightId = id;
    } catch (const InputError& e) {
        for (const Diagnostic& d : e.diagnostics()) r_.error(o.pos, o.label() + ": " + d.message);
    }
}

std::unique_ptr<Scene> buildFromXml(const XmlScene& xml, Diagnostics& diags,
                                    std::vector<Diagnostic>* warnings) {
    diags.throwIfErrors();
    auto scene = std::make_unique<Scene>();
    scene->sourceFile = xml.file;
    // Mitsuba 3's volpath semantics (docs/mitsuba.md): a crossed shape sets the medium, and
    // null-lobe events do not count towards max_depth, and no geometric-normal guard.
    scene->settings.mediumTransitions = MediumTransitions::kShapeSides;
    scene->settings.depthCounting = DepthCounting::kNonNullVertices;
    scene->settings.shadingNormals = ShadingNormals::kShadingOnly;
    XmlReader reader(diags);
    MitsubaBuild b{reader, xml, *scene, {}, {}, {}, false};
    Builder(b).build();
    diags.throwIfErrors();
    for (const MediumIssue& issue : scene->mediumIssues())
        if (issue.warning) {
            Diagnostic d;
            d.file = xml.file;
            d.where = issue.shapeId >= 0
                          ? "shape '" + scene->shapes[size_t(issue.shapeId)].name + "'"
                          : std::string();
            d.message = issue.message;
            diags.warning(d);
        }
    if (warnings) *warnings = diags.warnings();
    scene->commit();
    return scene;
}

}  // namespace

std::unique_ptr<Scene> loadMitsubaScene(const std::string& path,
                                        const std::map<std::string, std::string>& defines,
                                        std::vector<Diagnostic>* warnings) {
    Diagnostics diags;
    if (!isRegularFile(path))
        throw InputError(path, "cannot open the scene file (not found or not a file)");
    XmlScene xml = parseMitsubaXml(path, defines, diags);
    return buildFromXml(xml, diags, warnings);
}

std::unique_ptr<Scene> loadMitsubaSceneFromString(const std::string& text,
                                                  const std::string& fileName,
                                                  const std::string& baseDir,
                                                  const std::map<std::string, std::string>& defines,
                                                  std::vector<Diagnostic>* warnings) {
    Diagnostics diags;
    XmlScene xml = parseMitsubaXmlString(text, fileName, baseDir, defines, diags);
    return buildFromXml(xml, diags, warnings);
}

}  // namespace ub
