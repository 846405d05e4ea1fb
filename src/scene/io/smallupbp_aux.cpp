// SmallUPBP's .obj.aux reading (ObjReader::readAux). SmallUPBP tells keywords
// apart by a few characters (TM_ROW by its 7th, CAMERA_* by the 8th, medium vs
// mediumId by the 7th, ...), so `scaterring` is its scattering and `Kd` its
// emission. classify() reproduces that dispatch; a token that reaches a
// keyword under another spelling is accepted with a warning naming the keyword
// it was read as; a token SmallUPBP would skip or reject is an error.
// Names (material, medium, CAMERA_MATERIAL, ...) are the first word of the rest
// of the line; numbers are the next tokens. References to media are resolved
// at the end of the file, so a material may name a medium defined later.
#include <algorithm>
#include <filesystem>

#include "scene/io/json_reader.h"
#include "scene/io/smallupbp_files.h"
#include "scene/io/smallupbp_lexer.h"

namespace ub {

namespace {

enum class AuxKw {
    Unknown,
    Comment,
    TmRow,
    CameraFov,
    CameraTdist,
    CameraMaterial,
    CameraResX,
    CameraResY,
    Material,
    Medium,
    MediumId,
    Mirror,
    Ior,
    Priority,
    G,
    GeometryType,
    GlobalMediumId,
    Ke,
    Absorption,
    ContinuationProbability,
    Emission,
    EnclosingMatId,
    Scattering,
    LightPoint,
    LightDirectional,
    LightBackgroundConstant,
    LightBackgroundEm,
};

char at(const std::string& s, size_t i) {
    return i < s.size() ? s[i] : '\0';
}

/// SmallUPBP's dispatch; *canonical receives the keyword's documented spelling.
AuxKw classify(const std::string& k, std::string* canonical) {
    switch (k[0]) {
        case '#':
            return AuxKw::Comment;
        case 'T': {
            const char d = at(k, 6);
            if (d < '0' || d > '3') return AuxKw::Unknown;
            *canonical = std::string("TM_ROW") + d;
            return AuxKw::TmRow;
        }
        case 'C':
            switch (at(k, 7)) {
                case 'F':
                    *canonical = "CAMERA_FOV";
                    return AuxKw::CameraFov;
                case 'T':
                    *canonical = "CAMERA_TDIST";
                    return AuxKw::CameraTdist;
                case 'M':
                    *canonical = "CAMERA_MATERIAL";
                    return AuxKw::CameraMaterial;
                case 'R':
                    if (at(k, 18) == 'X') {
                        *canonical = "CAMERA_RESOLUTION_X";
                        return AuxKw::CameraResX;
                    }
                    if (at(k, 18) == 'Y') {
                        *canonical = "CAMERA_RESOLUTION_Y";
                        return AuxKw::CameraResY;
                    }
                    return AuxKw::Unknown;
                default:
                    return AuxKw::Unknown;
            }
        case 'm':
            if (at(k, 1) == 'a') {
                *canonical = "material";
                return AuxKw::Material;
            }
            if (at(k, 1) == 'i') {
                *canonical = "mirror";
                return AuxKw::Mirror;
            }
            if (at(k, 1) == 'e') {
                if (at(k, 6) == 'I') {
                    *canonical = "mediumId";
                    return AuxKw::MediumId;
                }
                if (k.size() == 6) {
                    *canonical = "medium";
                    return AuxKw::Medium;
                }
            }
            return AuxKw::Unknown;
        case 'i':
            *canonical = "ior";
            return AuxKw::Ior;
        case 'p':
            *canonical = "priority";
            return AuxKw::Priority;
        case 'g':
            if (k.size() == 1) {
                *canonical = "g";
                return AuxKw::G;
            }
            if (at(k, 1) == 'e') {
                *canonical = "geometryType";
                return AuxKw::GeometryType;
            }
            if (at(k, 1) == 'l') {
                *canonical = k == "globalMediumID" ? "globalMediumID" : "globalMediumId";
                return AuxKw::GlobalMediumId;
            }
            return AuxKw::Unknown;
        case 'K':
            *canonical = "Ke";
            return AuxKw::Ke;
        case 'a':
            *canonical = "absorption";
            return AuxKw::Absorption;
        case 'c':
            *canonical = "continuation_probability";
            return AuxKw::ContinuationProbability;
        case 'e':
            if (at(k, 1) == 'm') {
                *canonical = "emission";
                return AuxKw::Emission;
            }
            if (at(k, 1) == 'n') {
                *canonical = "enclosingMatId";
                return AuxKw::EnclosingMatId;
            }
            return AuxKw::Unknown;
        case 's':
            *canonical = "scattering";
            return AuxKw::Scattering;
        case 'l':
            switch (at(k, 6)) {
                case 'p':
                    *canonical = "light_point";
                    return AuxKw::LightPoint;
                case 'd':
                    *canonical = "light_directional";
                    return AuxKw::LightDirectional;
                case 'b':
                    if (at(k, 17) == 'c') {
                        *canonical = "light_background_constant";
                        return AuxKw::LightBackgroundConstant;
                    }
                    if (at(k, 17) == 'e') {
                        *canonical = "light_background_em";
                        return AuxKw::LightBackgroundEm;
                    }
                    return AuxKw::Unknown;
                default:
                    return AuxKw::Unknown;
            }
        default:
            return AuxKw::Unknown;
    }
}

const char* kAuxKeywords =
    "TM_ROW0..TM_ROW3, CAMERA_FOV, CAMERA_TDIST, CAMERA_MATERIAL, CAMERA_RESOLUTION_X/Y, "
    "medium, absorption, scattering, emission, g, continuation_probability, material, "
    "mirror, ior, priority, mediumId, geometryType, Ke, enclosingMatId, globalMediumId, "
    "light_point, light_directional, light_background_constant, light_background_em";

struct MediumRef {
    int* target;
    std::string name;
    UpbpToken at;
};

class AuxParser {
  public:
    AuxParser(const std::string& path, std::string text, UpbpAux* aux,
              std::vector<UpbpMaterial>* materials, Diagnostics& diags)
        : path_(path), r_(path, std::move(text), diags), aux_(aux), materials_(materials) {}

    void run();

  private:
    bool needMaterial(const UpbpToken& kw, const std::string& name);
    bool needMedium(const UpbpToken& kw, const std::string& name);
    int findMaterial(const UpbpToken& name);
    int findOrAddMedium(const std::string& name);
    bool nonNegative(const UpbpToken& kw, const std::string& name, const float* v);
    void statement(const UpbpToken& kw, AuxKw type, const std::string& name);
    void resolveMediumRefs();

    std::string path_;
    UpbpReader r_;
    UpbpAux* aux_;
    std::vector<UpbpMaterial>* materials_;
    int material_ = -1;  ///< selected by `material`
    int medium_ = -1;    ///< selected by `medium`
    std::vector<MediumRef> mediumRefs_;
    std::vector<std::string> materialNames_;
    bool sawBackground_ = false;
};

int AuxParser::findMaterial(const UpbpToken& name) {
    for (size_t i = 0; i < materials_->size(); ++i)
        if ((*materials_)[i].name == name.text) return int(i);
    if (materialNames_.empty())
        for (const UpbpMaterial& m : *materials_) materialNames_.push_back(m.name);
    r_.error(name, "unknown material '" + name.text + "'" + didYouMean(name.text, materialNames_) +
                       " (materials come from the .mtl file; it defines: " +
                       joinNames(materialNames_) + ")");
    return -1;
}

int AuxParser::findOrAddMedium(const std::string& name) {
    for (size_t i = 0; i < aux_->media.size(); ++i)
        if (aux_->media[i].name == name) return int(i);
    UpbpMedium m;
    m.name = name;
    aux_->media.push_back(m);
    return int(aux_->media.size()) - 1;
}

bool AuxParser::needMaterial(const UpbpToken& kw, const std::string& name) {
    if (material_ >= 0) return true;
    r_.error(kw, "'" + name + "' outside a material block (expected 'material NAME' before it)");
    r_.lexer().restOfLine();
    return false;
}

bool AuxParser::needMedium(const UpbpToken& kw, const std::string& name) {
    if (medium_ >= 0) return true;
    r_.error(kw, "'" + name + "' outside a medium block (expected 'medium NAME' before it)");
    r_.lexer().restOfLine();
    return false;
}

bool AuxParser::nonNegative(const UpbpToken& kw, const std::string& name, const float* v) {
    if (v[0] >= 0.0f && v[1] >= 0.0f && v[2] >= 0.0f) return true;
    r_.error(kw, "'" + name + "' must not be negative (got " + formatNumber(v[0]) + " " +
                     formatNumber(v[1]) + " " + formatNumber(v[2]) + ")");
    return false;
}

void AuxParser::statement(const UpbpToken& kw, AuxKw type, const std::string& name) {
    float v[6];
    UpbpToken word;
    switch (type) {
        case AuxKw::Comment:
        case AuxKw::Unknown:
            break;  // handled by run()
        case AuxKw::TmRow: {
            const int row = kw.text[6] - '0';
            if (!r_.numbers(kw, name, 3, "x y z", v)) return;
            aux_->tmRows[row] = Vec3(v[0], v[1], v[2]);
            aux_->hasTmRow[row] = true;
            return;
        }
        case AuxKw::CameraFov:
            if (!r_.numbers(kw, name, 1, "horizontal field of view in radians", v)) return;
            if (!(v[0] > 0.0f && v[0] < 3.1415f)) {
                r_.error(kw,
                         "'CAMERA_FOV' is the horizontal field of view in radians: expected a "
                         "number in (0, pi), got " +
                             formatNumber(v[0]));
                return;
            }
            aux_->fovXRad = v[0];
            aux_->hasFov = true;
            aux_->fovPos = {kw.line, kw.column};
            return;
        case AuxKw::CameraTdist:
            // SmallUPBP's camera is a pinhole: it reads the focal distance and never uses it.
            r_.numbers(kw, name, 1, "focal distance", v);
            return;
        case AuxKw::CameraMaterial:
            if (!r_.word(kw, name, "a material name", &word)) return;
            aux_->cameraMaterial = findMaterial(word);
            return;
        case AuxKw::CameraResX:
        case AuxKw::CameraResY: {
            int res = 0;
            if (!r_.integer(kw, name, "pixels", &res)) return;
            r_.warning(kw, "'" + name +
                               "' ignored, as SmallUPBP ignores it (the image size comes from the "
                               "command line: use --resolution WxH; the default is 256x256)");
            return;
        }
        case AuxKw::Material: {
            if (!r_.word(kw, name, "a material name", &word)) return;
            material_ = findMaterial(word);
            if (material_ >= 0) {
                UpbpMaterial& m = (*materials_)[size_t(material_)];
                if (!m.hasAuxBlock) m.auxPos = {kw.line, kw.column};
                m.hasAuxBlock = true;
            }
            return;
        }
        case AuxKw::Medium:
            if (!r_.word(kw, name, "a medium name", &word)) return;
            medium_ = findOrAddMedium(word.text);
            {
                UpbpMedium& m = aux_->media[size_t(medium_)];
                if (m.defined)
                    r_.warning(kw, "medium '" + word.text + "' is defined again (first at line " +
                                       std::to_string(m.pos.line) +
                                       "); as in SmallUPBP, the values that follow change it");
                if (!m.defined) m.pos = {kw.line, kw.column};
                m.defined = true;
            }
            return;
        case AuxKw::MediumId:
            if (!needMaterial(kw, name) || !r_.word(kw, name, "a medium name", &word)) return;
            mediumRefs_.push_back({&(*materials_)[size_t(material_)].mediumId, word.text, word});
            return;
        case AuxKw::Mirror:
            if (!needMaterial(kw, name) || !r_.numbers(kw, name, 3, "r g b", v)) return;
            if (nonNegative(kw, name, v))
                (*materials_)[size_t(material_)].mirror = Rgb(v[0], v[1], v[2]);
            return;
        case AuxKw::Ior:
            if (!needMaterial(kw, name) || !r_.numbers(kw, name, 1, "index of refraction", v))
                return;
            if (v[0] == 0.0f) {
                r_.error(kw,
                         "'ior' 0 is invalid (expected a positive index of refraction, or a "
                         "negative number for a material that does not refract)");
                return;
            }
            (*materials_)[size_t(material_)].ior = v[0];
            return;
        case AuxKw::Priority: {
            int p = 0;
            if (!needMaterial(kw, name) || !r_.integer(kw, name, "medium priority", &p)) return;
            if (p < -1) {
                r_.error(kw,
                         "'priority' must be >= 0 (or -1, the default: a thin wall that does "
                         "not change the medium), got " +
                             std::to_string(p));
                return;
            }
            (*materials_)[size_t(material_)].priority = p;
            return;
        }
        case AuxKw::G:
            if (!needMedium(kw, name) ||
                !r_.numbers(kw, name, 1, "Henyey-Greenstein mean cosine", v))
                return;
            if (!(v[0] > -1.0f && v[0] < 1.0f)) {
                r_.error(kw, "'g' must be in (-1, 1), got " + formatNumber(v[0]));
                return;
            }
            aux_->media[size_t(medium_)].g = v[0];
            return;
        case AuxKw::GeometryType: {
            if (!needMaterial(kw, name) || !r_.word(kw, name, "'real' or 'imaginary'", &word))
                return;
            const char c = word.text[0];
            if (c != 'r' && c != 'i') {
                r_.error(word,
                         "unknown geometry type '" + word.text + "' (expected real or imaginary)");
                return;
            }
            const std::string canon = c == 'r' ? "real" : "imaginary";
            if (word.text != canon)
                r_.warning(word, "geometry type '" + word.text + "' read as '" + canon +
                                     "' (SmallUPBP looks at the first letter)");
            (*materials_)[size_t(material_)].imaginary = c == 'i';
            return;
        }
        case AuxKw::GlobalMediumId:
            if (!r_.word(kw, name, "a medium name", &word)) return;
            mediumRefs_.push_back({&aux_->globalMediumId, word.text, word});
            return;
        case AuxKw::Ke:
            if (!needMaterial(kw, name) || !r_.numbers(kw, name, 3, "r g b", v)) return;
            if (nonNegative(kw, name, v))
                (*materials_)[size_t(material_)].emission = Rgb(v[0], v[1], v[2]);
            return;
        case AuxKw::Absorption:
        case AuxKw::Scattering:
        case AuxKw::Emission: {
            if (!needMedium(kw, name) || !r_.numbers(kw, name, 3, "r g b", v)) return;
            if (!nonNegative(kw, name, v)) return;
            UpbpMedium& m = aux_->media[size_t(medium_)];
            const Rgb c(v[0], v[1], v[2]);
            if (type == AuxKw::Absorption) m.absorption = c;
            if (type == AuxKw::Emission) m.emission = c;
            if (type == AuxKw::Scattering) {
                m.scattering = c;
                m.hasScattering = true;
            }
            return;
        }
        case AuxKw::ContinuationProbability:
            if (!needMedium(kw, name) || !r_.numbers(kw, name, 1, "probability", v)) return;
            r_.warning(kw,
                       "'continuation_probability' ignored: it only tunes SmallUPBP's Russian "
                       "roulette in this medium, not the image (unibeam uses its own)");
            return;
        case AuxKw::EnclosingMatId:
            if (!needMaterial(kw, name) || !r_.word(kw, name, "a material name", &word)) return;
            (*materials_)[size_t(material_)].enclosingMatId = findMaterial(word);
            return;
        case AuxKw::LightPoint:
        case AuxKw::LightDirectional: {
            const bool point = type == AuxKw::LightPoint;
            if (!r_.numbers(kw, name, 6, point ? "x y z r g b" : "dx dy dz r g b", v)) return;
            if (!nonNegative(kw, name + " colour", v + 3)) return;
            UpbpLight l;
            l.type = point ? UpbpLightType::Point : UpbpLightType::Directional;
            l.pos = {kw.line, kw.column};
            l.position = Vec3(v[0], v[1], v[2]);
            l.emission = Rgb(v[3], v[4], v[5]);
            if (!point && v[0] == 0.0f && v[1] == 0.0f && v[2] == 0.0f) {
                r_.error(kw, "'light_directional' direction is zero");
                return;
            }
            aux_->lights.push_back(l);
            return;
        }
        case AuxKw::LightBackgroundConstant:
        case AuxKw::LightBackgroundEm: {
            UpbpLight l;
            l.pos = {kw.line, kw.column};
            if (type == AuxKw::LightBackgroundConstant) {
                if (!r_.numbers(kw, name, 3, "r g b", v) || !nonNegative(kw, name, v)) return;
                l.type = UpbpLightType::BackgroundConstant;
                l.emission = Rgb(v[0], v[1], v[2]);
            } else {
                if (!r_.numbers(kw, name, 2, "scale rotation", v)) return;
                if (!r_.word(kw, name, "an OpenEXR file name", &word)) return;
                if (v[0] < 0.0f) {
                    r_.error(kw, "environment map scale must be >= 0, got " + formatNumber(v[0]));
                    return;
                }
                if (!(v[1] >= 0.0f && v[1] <= 1.0f)) {
                    r_.error(kw,
                             "environment map rotation is a fraction of a turn: expected a "
                             "number in [0, 1], got " +
                                 formatNumber(v[1]));
                    return;
                }
                l.type = UpbpLightType::BackgroundEnvMap;
                l.envScale = v[0];
                l.envRotate = v[1];
                l.envMapName = word.text;
                namespace fs = std::filesystem;
                const bool absolute = fs::path(word.text).is_absolute() ||
                                      (word.text.size() > 1 && word.text[1] == ':');
                l.envMapPath =
                    absolute ? word.text : (fs::path(path_).parent_path() / word.text).string();
            }
            if (sawBackground_) {
                r_.warning(kw, "ignored: SmallUPBP uses only the first background light");
                return;
            }
            sawBackground_ = true;
            aux_->lights.push_back(l);
            return;
        }
    }
}

void AuxParser::resolveMediumRefs() {
    std::vector<std::string> defined;
    for (const UpbpMedium& m : aux_->media)
        if (m.defined) defined.push_back(m.name);
    for (const MediumRef& ref : mediumRefs_) {
        int id = -1;
        for (size_t i = 0; i < aux_->media.size(); ++i)
            if (aux_->media[i].name == ref.name && aux_->media[i].defined) id = int(i);
        if (id < 0) {
            r_.error(ref.at, "unknown medium '" + ref.name + "'" + didYouMean(ref.name, defined) +
                                 (defined.empty() ? std::string(" (the file defines no medium)")
                                                  : " (defined: " + joinNames(defined) + ")") +
                                 "; SmallUPBP would silently create a default medium (scattering "
                                 "0.5) here");
            continue;
        }
        *ref.target = id;
    }
    for (UpbpMedium& m : aux_->media)
        if (m.defined && !m.hasScattering)
            r_.warning(m.pos.line, m.pos.column,
                       "medium '" + m.name +
                           "' has no 'scattering': SmallUPBP's default "
                           "0.5 0.5 0.5 is used");
}

void AuxParser::run() {
    UpbpLexer& lex = r_.lexer();
    UpbpToken kw;
    while (lex.next(&kw)) {
        std::string canonical;
        const AuxKw type = classify(kw.text, &canonical);
        if (type == AuxKw::Comment) {
            lex.restOfLine();
            continue;
        }
        if (type == AuxKw::Unknown) {
            r_.error(kw, "unknown keyword '" + kw.text +
                             "' (SmallUPBP's .aux keywords: " + kAuxKeywords + ")");
            lex.restOfLine();
            continue;
        }
        if (kw.text != canonical) {
            if (type == AuxKw::Ke && (kw.text == "Kd" || kw.text == "Ks" || kw.text == "Ka"))
                r_.warning(kw, "'" + kw.text +
                                   "' in an .aux file is read as 'Ke' (emission), as SmallUPBP "
                                   "reads every keyword starting with 'K' there; diffuse and "
                                   "specular colours belong in the .mtl file");
            else
                r_.warning(kw, "'" + kw.text + "' read as '" + canonical +
                                   "' (SmallUPBP recognises .aux keywords by their first "
                                   "letters)");
        }
        statement(kw, type, canonical);
    }
    resolveMediumRefs();
    for (int i = 0; i < 4; ++i)
        if (!aux_->hasTmRow[i])
            r_.error(0, 0,
                     "missing 'TM_ROW" + std::to_string(i) +
                         "': the camera matrix needs rows TM_ROW0..TM_ROW3 (right, up, "
                         "backward, position)");
    if (!aux_->hasFov)
        r_.error(0, 0, "missing 'CAMERA_FOV' (the horizontal field of view in radians)");
}

}  // namespace

void readUpbpAux(const std::string& path, UpbpAux* aux, std::vector<UpbpMaterial>* materials,
                 Diagnostics& diags) {
    std::string text;
    if (!readUpbpTextFile(path, "auxiliary scene file", &text, diags)) return;
    AuxParser p(path, std::move(text), aux, materials, diags);
    p.run();
}

}  // namespace ub
