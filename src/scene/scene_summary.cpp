#include "scene/scene_summary.h"

#include <cstdio>
#include <map>
#include <sstream>

#include "scene/albedo_grid.h"

namespace ub {

const char* materialTypeName(MaterialType t) {
    switch (t) {
        case MaterialType::Diffuse:
            return "diffuse";
        case MaterialType::Phong:
            return "phong";
        case MaterialType::Mirror:
            return "mirror";
        case MaterialType::Dielectric:
            return "dielectric";
        case MaterialType::RoughConductor:
            return "rough_conductor";
        case MaterialType::RoughDielectric:
            return "rough_dielectric";
        case MaterialType::Plastic:
            return "plastic";
        case MaterialType::RoughPlastic:
            return "rough_plastic";
        case MaterialType::ThinDielectric:
            return "thin_dielectric";
        case MaterialType::MultiLobe:
            return "multi_lobe";
        case MaterialType::Blend:
            return "blend";
        case MaterialType::Principled:
            return "principled";
        case MaterialType::PrincipledThin:
            return "principled_thin";
    }
    return "unknown";
}

const char* lightTypeName(LightType t) {
    switch (t) {
        case LightType::Area:
            return "area";
        case LightType::Point:
            return "point";
        case LightType::Directional:
            return "directional";
        case LightType::ConstantEnv:
            return "constant";
        case LightType::EnvMap:
            return "envmap";
        case LightType::Spot:
            return "spot";
        case LightType::Projector:
            return "projector";
    }
    return "unknown";
}

namespace {

std::string num(float v) {
    char buf[32];
    std::snprintf(buf, sizeof(buf), "%g", double(v));
    return buf;
}

std::string albedoGridSummary(const AlbedoGrid& a) {
    return "grid " + a.label + " (" + std::to_string(a.channelCount) +
           (a.channelCount == 1 ? " channel, " : " channels, ") +
           (a.filter == GridFilter::kNearest ? "nearest)" : "trilinear)");
}

std::string vec(const Vec3& v) {
    return "(" + num(v.x) + ", " + num(v.y) + ", " + num(v.z) + ")";
}

/// "3 (diffuse 2, mirror 1)"; types in first-seen order.
template <class T, class NameFn>
std::string countByType(const std::vector<T>& items, NameFn name) {
    std::vector<std::string> order;
    std::map<std::string, int> count;
    for (const T& x : items) {
        std::string n = name(x);
        if (count[n]++ == 0) order.push_back(n);
    }
    std::string s = std::to_string(items.size());
    if (!order.empty()) {
        s += " (";
        for (size_t i = 0; i < order.size(); ++i)
            s += (i ? ", " : "") + order[i] + " " + std::to_string(count[order[i]]);
        s += ")";
    }
    return s;
}

}  // namespace

std::string describeScene(const Scene& scene) {
    std::ostringstream os;
    if (!scene.sourceFile.empty()) os << "scene: " << scene.sourceFile << "\n";

    size_t spheres = 0, meshes = 0, triangles = 0, sdfGrids = 0;
    for (const ShapeInfo& s : scene.shapes) {
        if (s.isSphere)
            ++spheres;
        else if (s.isSdfGrid)
            ++sdfGrids;
        else
            ++meshes, triangles += s.triangleCount;
    }
    os << "shapes: " << scene.shapes.size() << " (" << meshes << " meshes with " << triangles
       << " triangles, " << spheres << " spheres"
       << (sdfGrids ? ", " + std::to_string(sdfGrids) + " sdfgrids" : std::string()) << ")\n";

    os << "materials: " << countByType(scene.materials, [](const Material& m) {
        return materialTypeName(m.type);
    }) << "\n";
    for (size_t i = 0; i < scene.materials.size(); ++i)
        os << "  material " << i << ": " << scene.materials[i].name << " ("
           << materialTypeName(scene.materials[i].type) << ")\n";

    os << "lights: "
       << countByType(scene.lights, [](const Light& l) { return lightTypeName(l.type); }) << "\n";
    for (size_t i = 0; i < scene.lights.size(); ++i) {
        const Light& l = scene.lights[i];
        os << "  light " << i << ": " << lightTypeName(l.type);
        if (!l.name.empty()) os << " '" << l.name << "'";
        switch (l.type) {
            case LightType::Area:
                os << ", radiance " << vec(l.radiance)
                   << (l.radianceTexture ? " x texture '" + l.radianceTexture->name + "'" : "")
                   << ", "
                   << (l.isSphere ? "sphere"
                                  : std::to_string(l.triangles.size() / 3) + " triangles")
                   << ", area " << num(l.totalArea) << (l.twoSided ? ", two-sided" : "");
                break;
            case LightType::Point:
                os << ", intensity " << vec(l.intensity) << " at " << vec(l.position);
                break;
            case LightType::Spot:
                os << ", intensity " << vec(l.intensity) << " at " << vec(l.position) << " towards "
                   << vec(l.direction) << ", cutoff " << num(l.cutoffAngleDeg) << " deg, beam "
                   << num(l.beamWidthDeg) << " deg";
                if (l.projTexture) os << ", texture '" << l.projTexture->name << "'";
                break;
            case LightType::Projector:
                os << ", scale " << vec(l.intensity) << " at " << vec(l.position) << " towards "
                   << vec(l.direction) << ", fov " << num(l.projFovXDeg) << " deg, irradiance '"
                   << l.projTexture->name << "'";
                break;
            case LightType::Directional:
                os << ", irradiance " << vec(l.radiance) << " towards " << vec(l.direction);
                break;
            case LightType::ConstantEnv:
                os << ", radiance " << vec(l.radiance);
                break;
            case LightType::EnvMap:
                os << ", scale " << vec(l.radiance);
                if (l.envMap) os << ", " << l.envMap->width << "x" << l.envMap->height;
                break;
        }
        os << (int(i) == scene.backgroundLightId ? " (background)" : "") << "\n";
    }

    if (!scene.media.empty() || scene.hasMedia()) {
        os << "media: " << scene.media.size() << ", global medium "
           << (scene.globalMediumId >= 0
                   ? "'" + scene.mediumNames[size_t(scene.globalMediumId)] + "'"
                   : std::string("vacuum"))
           << "\n";
        for (size_t i = 0; i < scene.media.size(); ++i) {
            const Medium& m = scene.media[i];
            os << "  medium " << i << ": '" << scene.mediumNames[i] << "' ";
            if (m.type == MediumType::kHomogeneous)
                os << "homogeneous, sigma_a " << vec(m.sigmaA) << ", sigma_s " << vec(m.sigmaS);
            else
                os << "heterogeneous, grid '" << (m.grid ? m.grid->name() : "") << "'"
                   << (m.chromatic() ? " (chromatic sigma_t, 3 channels)" : "")
                   << ", density scale " << num(m.densityScale) << ", albedo "
                   << (m.albedoGrid ? albedoGridSummary(*m.albedoGrid) : vec(m.albedo));
            os << ", g " << num(m.g) << "\n";
        }
        for (const ShapeInfo& sh : scene.shapes)
            if (sh.isMediumBoundary)
                os << "  boundary '" << sh.name << "': interior "
                   << (sh.interiorMediumId >= 0
                           ? "'" + scene.mediumNames[size_t(sh.interiorMediumId)] + "'"
                           : std::string("vacuum"))
                   << ", priority " << sh.mediumPriority << (sh.imaginary ? ", imaginary" : "")
                   << "\n";
    }

    if (scene.bounds.empty())
        os << "bounds: empty\n";
    else
        os << "bounds: " << vec(scene.bounds.lo) << " to " << vec(scene.bounds.hi) << "\n";

    const Camera& c = scene.camera;
    os << "camera: " << c.width() << "x" << c.height() << ", position " << vec(c.position())
       << ", forward " << vec(c.forward()) << ", up " << vec(c.up());
    if (c.isOrthographic())
        os << ", orthographic " << num(2.0f * c.orthoHalfWidth()) << " x "
           << num(2.0f * c.orthoHalfHeight()) << "\n";
    else if (c.isPinhole())
        os << ", fov " << num(c.fovYDeg()) << " deg (vertical), pinhole\n";
    else
        os << ", fov " << num(c.fovYDeg()) << " deg (vertical), thin lens radius "
           << num(c.lensRadius()) << " focused at " << num(c.focusDistance()) << "\n";

    const RenderSettings& st = scene.settings;
    os << "settings: max_path_length " << st.maxPathLength << ", min_path_length "
       << st.minPathLength << ", seed " << st.seed;
    if (!st.pixelFilter.isBox()) os << ", pixel filter " << st.pixelFilter.describe();
    if (!st.defaultAlgorithm.empty()) os << ", default algorithm " << st.defaultAlgorithm;
    os << "\n";
    return os.str();
}

}  // namespace ub
