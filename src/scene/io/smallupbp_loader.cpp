// SmallUPBP scene -> Scene. The mapping (docs/smallupbp.md has the table):
//  * Camera: the .aux matrix rows are the camera's right (TM_ROW0), up (TM_ROW1),
//    backward (TM_ROW2: the camera looks along -TM_ROW2) and position (TM_ROW3), the
//    3ds Max convention SmallUPBP reads (ObjReader::fillCameraInfo uses rows 1-3;
//    the right vector follows from up x backward). CAMERA_FOV is the horizontal
//    field of view in radians; unibeam's camera takes the vertical one:
//    tan(fovY / 2) = tan(fovX / 2) * height / width. Default image 256 x 256.
//  * Materials: SmallUPBP's BSDF is a sum of lobes (Bsdf.hxx): Lambert Kd, Phong Ks
//    with exponent Ns (off when Ns = 0), mirror (Fresnel-weighted when ior >= 0) and,
//    when ior >= 0, smooth refraction weighted by 1 - F. A material with refraction, or
//    with a mirror and a diffuse/Phong lobe, becomes a MultiLobe material (every lobe, as
//    SmallUPBP samples them); a mirror alone a Mirror, Kd with Ks (Ns > 0) a Phong, else a
//    Diffuse material (the same BSDFs). Sides as SmallUPBP's: the Lambert and Phong lobes
//    reflect in front of the shading normal only (none is two-sided), the mirror on both sides.
//  * Media: homogeneous; SmallUPBP's emission is the source term per unit length,
//    unibeam's is sigma_a * Le, so Le = emission / absorption.
//  * Shapes: one per material (SmallUPBP groups faces by material and identifies a
//    medium boundary by its material). A material with a mediumId makes its shape a
//    medium boundary with that interior medium and priority, imaginary if its
//    geometryType is imaginary; such a shape is split into its closed pieces, holes
//    closed (scene/io/smallupbp_boundary.h). A material without a medium is
//    SmallUPBP's thin wall: a plain surface.
//  * Lights: one area light per emissive material, sampled by area (SmallUPBP makes
//    one light per triangle and picks them uniformly: the same image, other
//    variance), then the .aux lights in order.
#include "scene/io/smallupbp_loader.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <unordered_map>

#include "core/file_status.h"
#include "core/image.h"
#include "scene/io/json_reader.h"
#include "scene/io/smallupbp_boundary.h"
#include "scene/io/smallupbp_files.h"

namespace ub {

namespace {

struct Context {
    std::string objPath, auxPath;
    Diagnostics& diags;
    void auxError(const UpbpPos& p, const std::string& msg) {
        diags.error({auxPath, p.line, p.column, "", msg});
    }
    void auxWarning(const UpbpPos& p, const std::string& msg) {
        diags.warning({auxPath, p.line, p.column, "", msg});
    }
    /// A material's own position: its .aux block if it has one, else its newmtl line.
    void materialWarning(const UpbpMaterial& m, const std::string& mtlFile,
                         const std::string& msg) {
        if (m.hasAuxBlock)
            auxWarning(m.auxPos, "material '" + m.name + "': " + msg);
        else
            diags.warning(
                {mtlFile, m.pos.line, m.pos.column, "", "material '" + m.name + "': " + msg});
    }
};

/// SmallUPBP's lobes -> a unibeam material (see the banner).
Material mapMaterial(const UpbpMaterial& u, const std::string& mtlFile, Context& ctx) {
    Material m;
    m.name = u.name;
    // One-sided, as SmallUPBP's BSDF: it evaluates its Lambert and Phong lobes to zero where
    // the fixed direction is behind the shading normal. A MultiLobe keeps its normal's side
    // (scene/bsdf.cpp keepsNormalSide): with refraction the normal tells inside from outside,
    // and behind it the Lambert and Phong lobes are black while the mirror reflects. Only a
    // plain Mirror is two-sided. (SmallUPBP's Phong sampler alone does sample behind the
    // normal, so its sampling and its evaluation disagree; unibeam keeps them consistent,
    // docs/smallupbp.md.)
    m.twoSided = false;
    const Rgb phong = u.shininess > 0.0f ? u.specular : Rgb(0.0f);
    const bool hasDiffuse = !isBlack(u.diffuse), hasPhong = !isBlack(phong);
    const bool hasMirror = !isBlack(u.mirror);
    if (u.ior >= 0.0f || (hasMirror && (hasDiffuse || hasPhong))) {
        // Every lobe, as SmallUPBP combines them (MaterialType::MultiLobe, scene/bsdf.cpp).
        m.type = MaterialType::MultiLobe;
        m.diffuse = u.diffuse;
        m.glossy = phong;
        m.exponent = u.shininess > 0.0f ? u.shininess : 1.0f;
        m.specular = u.mirror;
        m.refract = u.ior >= 0.0f;
        if (m.refract) m.ior = u.ior;
        // The lobes add: with refraction the transmitted part alone may carry albedo 1.
        const Rgb sum = u.diffuse + phong + (m.refract ? Rgb(0.0f) : u.mirror);
        const float most = maxComponent(sum) + (m.refract ? 1.0f : 0.0f);
        if (most > 1.0f + 1e-6f && (hasDiffuse || hasPhong))
            ctx.materialWarning(u, mtlFile,
                                "its lobes add up to an albedo of up to " + formatNumber(most) +
                                    " (> 1: the surface creates energy); kept, as SmallUPBP "
                                    "renders it");
        return m;
    }
    if (hasMirror) {
        m.type = MaterialType::Mirror;
        m.specular = u.mirror;
        m.twoSided = true;  // SmallUPBP's mirror reflects on both sides
        return m;
    }
    if (hasPhong) {
        m.type = MaterialType::Phong;
        m.diffuse = u.diffuse;
        m.glossy = phong;
        m.exponent = u.shininess;
    } else {
        m.type = MaterialType::Diffuse;
        m.diffuse = u.diffuse;
    }
    return m;
}

/// Triangles of one group as a mesh: one vertex per distinct (v, vn) corner.
/// Orientation: SmallUPBP flips a triangle's geometric normal towards the mean of its
/// shading normals; here the triangle is rewound instead (same effect on which side is
/// the inside of a medium or a dielectric). Emitters keep their winding: SmallUPBP's
/// area lights emit on the winding side.
TriangleMesh buildMesh(const UpbpObj& obj, const UpbpGroup& g, bool keepWinding, size_t* degenerate,
                       bool* droppedNormals) {
    const size_t n = g.v.size() / 3;
    bool normals = true;
    for (size_t i = 0; i < g.vn.size() && normals; ++i) {
        if (g.vn[i] < 0)
            normals = false;
        else {
            const Vec3& nn = obj.normals[size_t(g.vn[i])];
            if (!isFinite(nn) || !(length(nn) > 0.0f)) normals = false;
        }
    }
    *droppedNormals =
        !normals && std::any_of(g.vn.begin(), g.vn.end(), [](int x) { return x >= 0; });
    TriangleMesh m;
    std::unordered_map<uint64_t, uint32_t> remap;
    remap.reserve(g.v.size());
    *degenerate = 0;
    for (size_t t = 0; t < n; ++t) {
        int32_t v[3] = {g.v[3 * t], g.v[3 * t + 1], g.v[3 * t + 2]};
        int32_t vn[3] = {g.vn[3 * t], g.vn[3 * t + 1], g.vn[3 * t + 2]};
        const Vec3 p0 = obj.positions[size_t(v[0])], p1 = obj.positions[size_t(v[1])],
                   p2 = obj.positions[size_t(v[2])];
        const Vec3 c = cross(p1 - p0, p2 - p0);
        const float area2 = length(c);
        if (!(area2 > 0.0f) || !std::isfinite(area2)) {
            ++*degenerate;
            continue;
        }
        if (normals && !keepWinding) {
            const Vec3 mean = obj.normals[size_t(vn[0])] + obj.normals[size_t(vn[1])] +
                              obj.normals[size_t(vn[2])];
            if (dot(c, mean) < 0.0f) {
                std::swap(v[1], v[2]);
                std::swap(vn[1], vn[2]);
            }
        }
        for (int k = 0; k < 3; ++k) {
            const uint64_t key =
                (uint64_t(uint32_t(v[k])) << 32) | uint64_t(uint32_t(normals ? vn[k] : -1));
            auto it = remap.find(key);
            if (it == remap.end()) {
                it = remap.emplace(key, uint32_t(m.positions.size())).first;
                m.positions.push_back(obj.positions[size_t(v[k])]);
                if (normals) m.normals.push_back(normalize(obj.normals[size_t(vn[k])]));
            }
            m.indices.push_back(it->second);
        }
    }
    return m;
}

Camera buildCamera(const UpbpAux& aux, Context& ctx) {
    const Vec3 position = aux.tmRows[3];
    const Vec3 backward = aux.tmRows[2], up = aux.tmRows[1];
    Camera cam;
    const float lb = length(backward), lu = length(up);
    if (!(lb > 0.0f) || !(lu > 0.0f) || !isFinite(position) ||
        !(length(cross(backward / lb, up / lu)) > 1e-4f)) {
        ctx.auxError({},
                     "the camera matrix is degenerate: TM_ROW2 (backward) and TM_ROW1 (up) "
                     "must be non-zero and not parallel");
        return cam;
    }
    const int width = 256, height = 256;  // SmallUPBP's default -r
    const float tanHalfY = std::tan(0.5f * aux.fovXRad) * float(height) / float(width);
    const float fovYDeg = 2.0f * std::atan(tanHalfY) * 180.0f / kPi;
    cam.setup(position, position - backward / lb, up / lu, fovYDeg, width, height);
    return cam;
}

bool buildMedium(const UpbpMedium& u, Medium* out, Context& ctx) {
    Rgb Le(0.0f);
    for (int c = 0; c < 3; ++c) {
        if (u.emission[c] <= 0.0f) continue;
        if (!(u.absorption[c] > 0.0f)) {
            ctx.auxError(u.pos, "medium '" + u.name +
                                    "': emission without absorption in a colour channel is "
                                    "not representable (unibeam's medium emits sigma_a * Le)");
            return false;
        }
        Le[c] = u.emission[c] / u.absorption[c];
    }
    try {
        *out = Medium::homogeneous(u.absorption, u.scattering, u.g, Le);
    } catch (const std::invalid_argument& e) {
        ctx.auxError(u.pos, "medium '" + u.name + "': " + e.what());
        return false;
    }
    return true;
}

bool buildAuxLight(const UpbpLight& u, Light* l, Context& ctx) {
    switch (u.type) {
        case UpbpLightType::Point:
            l->type = LightType::Point;
            l->name = "light_point";
            l->position = u.position;
            l->intensity = u.emission;
            return true;
        case UpbpLightType::Directional:
            l->type = LightType::Directional;
            l->name = "light_directional";
            l->direction = normalize(u.position);
            l->radiance = u.emission;
            return true;
        case UpbpLightType::BackgroundConstant:
            l->type = LightType::ConstantEnv;
            l->name = "light_background_constant";
            l->radiance = u.emission;
            return true;
        case UpbpLightType::BackgroundEnvMap: {
            l->type = LightType::EnvMap;
            l->name = "light_background_em";
            l->radiance = Rgb(u.envScale);
            if (!isRegularFile(u.envMapPath)) {
                ctx.auxError(u.pos, "environment map '" + u.envMapName +
                                        "' not found (looked for '" + u.envMapPath +
                                        "'; relative paths start at the .aux file)");
                return false;
            }
            try {
                auto img = std::make_shared<Image>(readExr(u.envMapPath));
                // SmallUPBP turns the map by whole pixels: column x shows file column
                // x - int(rotate * width) (EnvMap::LoadImage).
                const int rotatePixels = int(u.envRotate * float(img->width));
                l->envToWorld = smallUpbpEnvToWorld(rotatePixels, img->width);
                l->worldToEnv = l->envToWorld.inverse();
                l->envMap = std::move(img);
            } catch (const InputError& e) {
                for (const Diagnostic& d : e.diagnostics())
                    ctx.auxError(
                        u.pos, "cannot read environment map '" + u.envMapName + "': " + d.message);
                return false;
            }
            return true;
        }
    }
    return false;
}

}  // namespace

Transform smallUpbpEnvToWorld(int rotatePixels, int width) {
    // unibeam looks up e = worldToEnv(w) at u = atan2(e.x, -e.z) / 2pi, v = acos(e.y) / pi.
    // SmallUPBP looks up w at u' = 1/2 - atan2(w.y, w.x) / 2pi, v = acos(w.z) / pi, in a map
    // whose column u' shows file column u' - r (r = rotatePixels / width). With
    // alpha = atan2(w.y, w.x) and gamma = 2 pi r, u = u' - r needs
    // atan2(e.x, -e.z) = pi - alpha - gamma, i.e. e = P Rz(gamma) w with
    // P (x, y, z) = (y, z, x): e.x = sin(alpha + gamma), -e.z = -cos(alpha + gamma) (times
    // the horizontal length), e.y = w.z. envToWorld = Rz(-gamma) P^-1.
    Transform pInv;  // (e.x, e.y, e.z) -> (e.z, e.x, e.y)
    pInv.m[0][0] = 0.0f, pInv.m[0][1] = 0.0f, pInv.m[0][2] = 1.0f;
    pInv.m[1][0] = 1.0f, pInv.m[1][1] = 0.0f, pInv.m[1][2] = 0.0f;
    pInv.m[2][0] = 0.0f, pInv.m[2][1] = 1.0f, pInv.m[2][2] = 0.0f;
    const float gammaDeg = width > 0 ? 360.0f * float(rotatePixels) / float(width) : 0.0f;
    return Transform::rotate(-gammaDeg, Vec3(0.0f, 0.0f, 1.0f)) * pInv;
}

std::unique_ptr<Scene> loadSmallUpbpScene(const std::string& objPath,
                                          std::vector<Diagnostic>* warnings) {
    Diagnostics diags;
    Context ctx{objPath, objPath + ".aux", diags};
    UpbpObj obj;
    std::vector<UpbpMaterial> materials;
    readUpbpObj(objPath, &obj, &materials, diags);
    UpbpAux aux;
    if (!diags.hasErrors()) readUpbpAux(ctx.auxPath, &aux, &materials, diags);
    if (diags.hasErrors()) diags.throwIfErrors();
    const std::string mtlFile = obj.mtlFiles.empty() ? objPath : obj.mtlFiles.front();

    auto scene = std::make_unique<Scene>();
    scene->sourceFile = objPath;
    scene->camera = buildCamera(aux, ctx);
    scene->settings.maxPathLength = 10;        // SmallUPBP's default -l
    scene->settings.seed = 1234;               // SmallUPBP's default -seed
    scene->settings.keepHorizontalFov = true;  // SmallUPBP's -r keeps CAMERA_FOV

    // Materials, in .mtl order.
    int maxBoundaryPriority = -1;
    for (const UpbpMaterial& u : materials)
        if (u.mediumId >= 0) maxBoundaryPriority = std::max(maxBoundaryPriority, u.priority);
    for (const UpbpMaterial& u : materials) {
        scene->addMaterial(mapMaterial(u, mtlFile, ctx));
        if (u.mediumId >= 0 && u.priority < 0)
            ctx.auxError(u.auxPos, "material '" + u.name +
                                       "' has a mediumId but no priority (SmallUPBP requires "
                                       "one: expected 'priority N' with N >= 0)");
        if (u.mediumId < 0 && u.imaginary)
            ctx.auxWarning(u.auxPos, "material '" + u.name +
                                         "' is imaginary without a medium: its faces change "
                                         "nothing and are left out");
        if (u.mediumId < 0 && u.priority >= 0 && u.priority < maxBoundaryPriority)
            ctx.auxWarning(u.auxPos,
                           "material '" + u.name + "' has priority " + std::to_string(u.priority) +
                               " but no medium: unibeam treats it as a plain surface, always "
                               "hit; SmallUPBP skips it inside media of higher priority");
        if (u.imaginary && u.isEmissive())
            ctx.auxError(u.auxPos, "material '" + u.name +
                                       "' is imaginary and emissive (an imaginary surface "
                                       "cannot emit)");
    }

    // Media.
    for (const UpbpMedium& u : aux.media) {
        Medium m;
        if (buildMedium(u, &m, ctx))
            scene->addMedium(m, u.name);
        else
            scene->addMedium(Medium(), u.name);  // keep ids aligned; errors thrown below
    }
    scene->globalMediumId = aux.globalMediumId;

    // Shapes and their area lights (in order of first use in the .obj).
    std::vector<std::pair<uint32_t, const UpbpMaterial*>> boundaries;
    for (const UpbpGroup& g : obj.groups) {
        const UpbpMaterial& u = materials[size_t(g.material)];
        if (g.v.empty()) continue;
        if (u.imaginary && u.mediumId < 0) continue;
        size_t degenerate = 0;
        bool droppedNormals = false;
        TriangleMesh mesh = buildMesh(obj, g, u.isEmissive(), &degenerate, &droppedNormals);
        if (degenerate > 0)
            diags.warning({objPath, g.firstUse.line, g.firstUse.column, "",
                           std::to_string(degenerate) + " zero-area triangles of material '" +
                               u.name + "' dropped"});
        if (droppedNormals)
            diags.warning({objPath, g.firstUse.line, g.firstUse.column, "",
                           "faces of material '" + u.name +
                               "' mix corners with and without (valid) normals: shading "
                               "normals dropped for this material"});
        if (mesh.indices.empty()) continue;
        std::vector<TriangleMesh> pieces;
        if (u.mediumId >= 0) {
            BoundarySplit split = splitMediumBoundary(mesh);
            const UpbpPos at = u.auxPos;
            if (split.holes > 0)
                ctx.auxWarning(at, "material '" + u.name + "': its mesh has " +
                                       std::to_string(split.holes) + " holes (" +
                                       std::to_string(split.holeEdges) +
                                       " open edges), closed here with fans around their "
                                       "centres: a medium boundary must be closed (SmallUPBP "
                                       "leaves them open and rays leak through them)");
            if (split.insideOut > 0)
                ctx.auxWarning(at, "material '" + u.name + "': " + std::to_string(split.insideOut) +
                                       " closed pieces of its mesh face inwards with nothing "
                                       "around them (their inside is the outside)");
            pieces = std::move(split.pieces);
        } else {
            pieces.push_back(std::move(mesh));
        }
        for (size_t k = 0; k < pieces.size(); ++k) {
            TriangleMesh& piece = pieces[k];
            const std::string name = pieces.size() == 1
                                         ? u.name
                                         : u.name + " (piece " + std::to_string(k + 1) + " of " +
                                               std::to_string(pieces.size()) + ")";
            int lightId = -1;
            if (u.isEmissive()) {
                Light l;
                l.type = LightType::Area;
                l.name = name;
                l.radiance = u.emission;
                l.twoSided = false;
                l.triangles.reserve(piece.indices.size());
                for (uint32_t idx : piece.indices) l.triangles.push_back(piece.positions[idx]);
                try {
                    lightId = scene->addLight(std::move(l));
                } catch (const InputError& e) {
                    for (Diagnostic d : e.diagnostics()) {
                        d.file = objPath;
                        diags.error(d);
                    }
                }
            }
            const uint32_t shapeId = scene->addMesh(std::move(piece), g.material, lightId, name);
            if (u.mediumId >= 0) boundaries.push_back({shapeId, &u});
        }
    }
    for (const auto& [shapeId, u] : boundaries)
        scene->setMediumBoundary(shapeId, u->mediumId, std::max(u->priority, 0), u->imaginary);

    // Lights of the .aux.
    for (const UpbpLight& u : aux.lights) {
        Light l;
        if (!buildAuxLight(u, &l, ctx)) continue;
        try {
            const bool env = l.isEnvironment();
            const int id = scene->addLight(std::move(l));
            if (env) scene->backgroundLightId = id;
        } catch (const InputError& e) {
            for (const Diagnostic& d : e.diagnostics()) ctx.auxError(u.pos, d.message);
        }
    }
    if (scene->lights.empty() && !diags.hasErrors())
        ctx.auxError({},
                     "the scene has no light (expected a material with emission 'Ke' in the "
                     ".mtl or .aux, or a light_* line in the .aux)");

    // Medium set-up problems, placed at the material block of the offending shape.
    if (!diags.hasErrors()) {
        for (const MediumIssue& issue : scene->mediumIssues()) {
            if (issue.warning) continue;  // none arise under the priority stack
            UpbpPos at;
            if (issue.shapeId >= 0) {
                const int mat = scene->shapes[size_t(issue.shapeId)].materialId;
                if (mat >= 0) at = materials[size_t(mat)].auxPos;
            } else if (issue.mediumId >= 0 && size_t(issue.mediumId) < aux.media.size()) {
                at = aux.media[size_t(issue.mediumId)].pos;
            }
            ctx.auxError(at, issue.message);
        }
    }
    diags.throwIfErrors();
    scene->commit();
    if (warnings) {
        std::vector<Diagnostic> w = diags.warnings();
        warnings->insert(warnings->end(), w.begin(), w.end());
    }
    return scene;
}

}  // namespace ub
