// SmallUPBP's scene files as read, before they become a Scene: the .mtl
// materials, the .obj.aux camera / media / material extras / lights, and the
// .obj triangles grouped by material (SmallUPBP groups faces by `usemtl`).
// docs/smallupbp.md describes every keyword and how it maps to unibeam.
//
// Each reader follows SmallUPBP's reader (SmallUPBP/src/Misc/ObjReader.cxx):
// keywords are recognised by their first letters, so a misspelling SmallUPBP
// accepts (`scaterring`) is accepted with a warning that names the keyword it
// was read as; a keyword SmallUPBP would skip or reject is an error. Every
// diagnostic names the file, line and column.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/vec.h"

namespace ub {

/// Where a statement is, for messages after reading (references resolved at the end).
struct UpbpPos {
    int line = 0;
    int column = 0;
};

struct UpbpMaterial {
    std::string name;
    UpbpPos pos;  ///< its `newmtl` line in the .mtl
    // From the .mtl.
    Rgb diffuse{0.0f};       ///< Kd
    Rgb specular{0.0f};      ///< Ks (Phong lobe reflectance)
    float shininess = 0.0f;  ///< Ns (Phong exponent; 0 turns the Phong lobe off)
    Rgb emission{0.0f};      ///< Ke (.mtl or .aux: the later one wins, as in SmallUPBP)
    // From the .obj.aux.
    Rgb mirror{0.0f};
    float ior = -1.0f;  ///< < 0: no refraction
    int priority = -1;  ///< -1: SmallUPBP's "thin wall", never changes the medium
    bool imaginary = false;
    int mediumId = -1;        ///< index into UpbpAux::media, -1 none
    int enclosingMatId = -1;  ///< material whose medium holds this emitter
    bool hasAuxBlock = false;
    UpbpPos auxPos;  ///< its `material` line in the .aux (if hasAuxBlock)

    bool isEmissive() const { return emission.x > 0.0f || emission.y > 0.0f || emission.z > 0.0f; }
};

struct UpbpMedium {
    std::string name;
    UpbpPos pos;  ///< its `medium` line
    Rgb absorption{0.0f};
    Rgb scattering{0.5f};  ///< SmallUPBP's default when `scattering` is absent
    Rgb emission{0.0f};    ///< source term per unit length (SmallUPBP: emission * distance)
    float g = 0.0f;
    bool hasScattering = false;
    bool defined = false;  ///< false: only referenced (mediumId / globalMediumId), never defined
    UpbpPos gPos;
};

enum class UpbpLightType { Point, Directional, BackgroundConstant, BackgroundEnvMap };

struct UpbpLight {
    UpbpLightType type = UpbpLightType::Point;
    UpbpPos pos;
    Vec3 position{0.0f};  ///< point: position; directional: direction light travels
    Rgb emission{0.0f};   ///< point: intensity; directional: irradiance; constant: radiance
    float envScale = 1.0f;
    float envRotate = 0.0f;  ///< fraction of a turn, [0, 1]
    std::string envMapPath;  ///< resolved path
    std::string envMapName;  ///< as written
};

struct UpbpAux {
    Vec3 tmRows[4];
    bool hasTmRow[4] = {false, false, false, false};
    float fovXRad = 0.0f;  ///< CAMERA_FOV: horizontal field of view in radians
    bool hasFov = false;
    UpbpPos fovPos;
    int cameraMaterial = -1;  ///< CAMERA_MATERIAL (informational: unibeam finds the camera's media)
    std::vector<UpbpMedium> media;
    int globalMediumId = -1;
    std::vector<UpbpLight> lights;
};

/// Triangles of one material (SmallUPBP's group). Corner indices into UpbpObj arrays.
struct UpbpGroup {
    int material = -1;        ///< index into the material list
    UpbpPos firstUse;         ///< its first `usemtl`
    std::vector<int32_t> v;   ///< 3 per triangle
    std::vector<int32_t> vn;  ///< 3 per triangle, -1 where the corner has no normal
};

struct UpbpObj {
    std::vector<Vec3> positions;
    std::vector<Vec3> normals;
    std::vector<UpbpGroup> groups;  ///< in order of first use
    std::vector<std::string> mtlFiles;
};

/// Reads `path` (.mtl) appending to *materials. Problems go to diags.
void readUpbpMtl(const std::string& path, std::vector<UpbpMaterial>* materials, Diagnostics& diags);

/// Reads the .obj (geometry; reads the .mtl files it names through readUpbpMtl).
void readUpbpObj(const std::string& path, UpbpObj* obj, std::vector<UpbpMaterial>* materials,
                 Diagnostics& diags);

/// Reads the .obj.aux; materials must already hold the .mtl materials (the .aux refers
/// to them by name and adds its properties to them).
void readUpbpAux(const std::string& path, UpbpAux* aux, std::vector<UpbpMaterial>* materials,
                 Diagnostics& diags);

/// Reads a whole file; false (with an error naming `what`) if it cannot be opened.
bool readUpbpTextFile(const std::string& path, const std::string& what, std::string* text,
                      Diagnostics& diags, const std::string& referrer = "", int line = 0,
                      int column = 0);

}  // namespace ub
