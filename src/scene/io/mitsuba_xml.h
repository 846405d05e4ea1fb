// Mitsuba 3 XML, first stage: the file (and its <include>s) read into a tree of
// plugin objects with typed properties; the scene builder (mitsuba_loader.cpp)
// then turns the tree into a Scene.
//
// This stage handles everything that does not depend on a plugin's meaning:
//   * <default name value> and `$name` substitution in every attribute, with
//     -D overrides from the command line taking precedence over <default>;
//   * <include filename> (the included file's <scene> children are spliced in
//     place) and <path value> (prepended to the search path, as Mitsuba does);
//   * ids and <ref id [name]>: a reference attaches the object with that id;
//   * property tags float, integer, boolean, string, rgb, spectrum, point,
//     vector and transform (translate, rotate, scale, matrix, lookat, composed
//     in Mitsuba's order: each child is applied after the previous ones, i.e.
//     M = op_n * ... * op_1).
// Positions (file:line:column) come from pugixml's offset_debug(). Every
// property and child remembers whether the builder consumed it, so that an
// unsupported parameter is reported as an error instead of being ignored.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/vec.h"

namespace ub {

struct XmlPos {
    std::string file;
    int line = 0, column = 0;
};

enum class XmlValueKind {
    Float,
    Integer,
    Boolean,
    String,
    Rgb,
    Spectrum,
    Point,
    Vector,
    Transform
};

struct XmlProperty {
    std::string name;
    XmlValueKind kind = XmlValueKind::Float;
    XmlPos pos;
    double number = 0.0;              ///< Float, Integer; Spectrum given as one constant value
    bool boolean = false;             ///< Boolean
    std::string text;                 ///< String (also the raw value of every other kind)
    Vec3 vec;                         ///< Rgb, Point, Vector; Spectrum converted to linear sRGB
    bool spectrumIsConstant = false;  ///< Spectrum: a single value (not wavelength pairs)
    std::vector<double> wavelengths, values;  ///< Spectrum given as wavelength:value pairs
    Transform transform;                      ///< Transform
    mutable bool used = false;
};

struct XmlObject;

/// A nested object or a <ref>, attached under `name` (may be empty).
struct XmlChild {
    std::string name;
    std::shared_ptr<XmlObject> object;
    XmlPos pos;  ///< where the nested tag or the <ref> is
    mutable bool used = false;
};

struct XmlObject {
    std::string tag;   ///< shape, bsdf, emitter, medium, phase, volume, texture, sensor, ...
    std::string type;  ///< plugin name (the `type` attribute)
    std::string id;    ///< `id` attribute or empty
    XmlPos pos;
    std::vector<XmlProperty> properties;
    std::vector<XmlChild> children;

    /// "<bsdf type='diffuse'>" for messages.
    std::string label() const;
    const XmlProperty* find(const std::string& name) const;
};

/// A parsed scene file: top-level objects in file order (includes spliced in).
struct XmlScene {
    std::string file;
    std::vector<std::shared_ptr<XmlObject>> objects;
    /// Directories searched for relative file names (<path> entries first, then the scene's
    /// directory), in search order.
    std::vector<std::string> searchPath;
};

/// Tags that define plugin objects, for error messages.
const std::vector<std::string>& xmlObjectTags();

/// Reads `path` and its includes. `defines` are -D name=value overrides. Errors go to diags
/// (the returned tree holds what could be read).
XmlScene parseMitsubaXml(const std::string& path, const std::map<std::string, std::string>& defines,
                         Diagnostics& diags);
/// Same from text in memory (fileName for messages, baseDir for relative paths).
XmlScene parseMitsubaXmlString(const std::string& text, const std::string& fileName,
                               const std::string& baseDir,
                               const std::map<std::string, std::string>& defines,
                               Diagnostics& diags);

/// Resolves a file name through the search path; returns "" if not found.
std::string resolveXmlPath(const XmlScene& scene, const std::string& name);

/// 1-based line and column of byte `offset` in `text`.
XmlPos xmlPosOfOffset(const std::string& file, const std::string& text, size_t offset);

}  // namespace ub
