// Internal to the Mitsuba XML loader: typed, use-tracking access to the
// properties of an XmlObject, and the state shared by the builder's parts
// (mitsuba_loader.cpp: scene, sensor, integrator, shapes, emitters;
// mitsuba_bsdfs.cpp: materials; mitsuba_media.cpp: media).
//
// Every getter marks what it reads as used; checkUnused() then reports each
// property or nested object the builder did not consume as an error naming
// the plugin, so unsupported parameters never pass silently.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"
#include "scene/io/mitsuba_xml.h"
#include "scene/medium.h"
#include "scene/scene.h"

namespace ub {

/// How a colour property is converted (Mitsuba's rgb-variant rules differ between
/// reflectances, which are bounded, and emission or media coefficients).
enum class ColorUse { Reflectance, Emission, Unbounded };

class XmlReader {
  public:
    explicit XmlReader(Diagnostics& diags) : diags_(diags) {}

    void error(const XmlPos& p, const std::string& msg);
    void warning(const XmlPos& p, const std::string& msg);
    size_t errorCount() const { return errors_; }

    bool has(const XmlObject& o, const std::string& name) const { return o.find(name) != nullptr; }
    float getFloat(const XmlObject& o, const std::string& name, float def);
    /// A float required to lie in [lo, hi] (open ends with strict flags).
    float getFloatIn(const XmlObject& o, const std::string& name, float def, float lo, float hi,
                     bool loOpen = false, bool hiOpen = false);
    int getInt(const XmlObject& o, const std::string& name, int def, int lo, int hi);
    bool getBool(const XmlObject& o, const std::string& name, bool def);
    std::string getString(const XmlObject& o, const std::string& name, const std::string& def);
    /// rgb, spectrum or float; negative values are errors, reflectances must be <= 1.
    Rgb getColor(const XmlObject& o, const std::string& name, const Rgb& def, ColorUse use);
    Vec3 getPoint(const XmlObject& o, const std::string& name, const Vec3& def);
    Vec3 getVector(const XmlObject& o, const std::string& name, const Vec3& def);
    Transform getTransform(const XmlObject& o, const std::string& name);
    /// An IOR given as a number or a material name (namedIor()).
    float getIor(const XmlObject& o, const std::string& name, float def);

    /// The nested object or reference attached as `name` (or, when name is empty, the
    /// only child with tag `tag`); marks it used. nullptr if absent.
    const XmlObject* child(const XmlObject& o, const std::string& tag, const std::string& name);
    /// Where the last child() found its object attached (the nested tag or the <ref>).
    const XmlPos& lastChildPos() const { return lastChildPos_; }
    /// All children with the given tag (marked used).
    std::vector<const XmlObject*> children(const XmlObject& o, const std::string& tag);

    /// Reports every property and child of o not read by the builder.
    void checkUnused(const XmlObject& o);
    /// Error "<tag type=...>: unsupported plugin 'type' (supported: ...)".
    void unsupportedPlugin(const XmlObject& o, const std::vector<std::string>& supported,
                           const std::string& note = "");

    const XmlProperty* prop(const XmlObject& o, const std::string& name,
                            std::initializer_list<XmlValueKind> kinds, const char* expected);

  private:
    Diagnostics& diags_;
    size_t errors_ = 0;
    XmlPos lastChildPos_;
};

/// Options of loadMitsubaScene.
struct MitsubaLoadOptions {
    std::map<std::string, std::string> defines;  ///< -D name=value
};

/// State shared by the parts of the builder.
struct MitsubaBuild {
    XmlReader& r;
    const XmlScene& xml;
    Scene& scene;
    std::map<const XmlObject*, int> materialIds;  ///< bsdf object -> material id
    /// (texture object, ColorUse of its colours) -> texture id
    std::map<std::pair<const XmlObject*, ColorUse>, int> textureIds;
    std::map<const XmlObject*, int> mediumIds;  ///< medium object -> Scene::media index
    /// Media (volscene's Scene::media is not in main yet): objects seen, for messages.
    bool cameraSet = false;
    int nullPassId = -1;  ///< the pass-through material of masks and null emitters (or -1)

    /// Resolves a file name property through the search path; reports an error and returns
    /// "" if not found.
    std::string resolveFile(const XmlObject& o, const std::string& prop, const std::string& name);
};

/// Builds a material from a <bsdf>. Returns the material id (cached per object), -1 for a
/// `null` BSDF, or -2 on an error (already reported). *oneSidedEmit is unused here.
int buildMitsubaBsdf(MitsubaBuild& b, const XmlObject& bsdf);

/// The material of a surface that lets rays pass straight through (Mitsuba's null BSDF where
/// it must be a surface: the transparent part of a `mask`, a `null` BSDF on an emitter),
/// added once per scene.
int nullPassMaterial(MitsubaBuild& b);

/// A <texture> (checkerboard, bitmap) -> index into Scene::textures (cached per object and
/// use); -1 on an error (already reported). `use` reads a checkerboard's colours: reflectance
/// (at most 1) in a BSDF; ColorUse::Unbounded as an emitter's radiance, where Mitsuba's rgb
/// variants take any value (its checkerboard reads color0/color1 as plain textures).
int buildMitsubaTexture(MitsubaBuild& b, const XmlObject& t, ColorUse use = ColorUse::Reflectance);

/// Builds a medium from a <medium>; false on an error (already reported).
bool buildMitsubaMedium(MitsubaBuild& b, const XmlObject& medium, Medium* out);

}  // namespace ub
