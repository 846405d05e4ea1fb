// Mitsuba 3 XML reading into XmlObject trees (see mitsuba_xml.h).
#include "scene/io/mitsuba_xml.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <pugixml.hpp>
#include <sstream>

#include "core/file_status.h"
#include "scene/io/mitsuba_spectra.h"

namespace ub {

namespace fs = std::filesystem;

namespace {

const std::vector<std::string> kObjectTags = {
    "scene",   "shape",  "bsdf", "emitter",    "medium",  "phase",  "volume",
    "texture", "sensor", "film", "integrator", "sampler", "rfilter"};
const std::vector<std::string> kPropertyTags = {"float",    "integer", "boolean", "string",   "rgb",
                                                "spectrum", "point",   "vector",  "transform"};
constexpr int kMaxIncludeDepth = 32;
// Files read in all (the top file and every <include>): a file that includes another twice at
// each of 32 levels would otherwise be read 2^32 times.
constexpr int kMaxIncludedFiles = 1000;
// Plugin objects nested inside each other (Mitsuba scenes nest a handful: shape > bsdf >
// texture); the bound keeps the recursive reading and the object tree's destruction off the
// end of the stack for hostile files.
constexpr int kMaxObjectDepth = 64;

std::string joinList(const std::vector<std::string>& v) {
    std::string s;
    for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
    return s;
}

bool isIn(const std::string& s, const std::vector<std::string>& v) {
    return std::find(v.begin(), v.end(), s) != v.end();
}

/// Whole-string number parse (no trailing garbage, finite).
bool parseDouble(const std::string& sIn, double* out) {
    std::string s = sIn;
    size_t a = s.find_first_not_of(" \t\r\n"), b = s.find_last_not_of(" \t\r\n");
    if (a == std::string::npos) return false;
    s = s.substr(a, b - a + 1);
    errno = 0;
    char* end = nullptr;
    double v = std::strtod(s.c_str(), &end);
    if (end != s.c_str() + s.size() || errno == ERANGE || !std::isfinite(v)) return false;
    *out = v;
    return true;
}

/// Splits on commas and/or whitespace.
std::vector<std::string> splitList(const std::string& s) {
    std::vector<std::string> out;
    std::string cur;
    for (char c : s) {
        if (c == ',' || c == ' ' || c == '\t' || c == '\n' || c == '\r') {
            if (!cur.empty()) out.push_back(cur);
            cur.clear();
        } else {
            cur += c;
        }
    }
    if (!cur.empty()) out.push_back(cur);
    return out;
}

/// One XML file being read (the top file or an include).
struct FileCtx {
    std::string path;  ///< for messages
    std::string text;
    std::string dir;  ///< directory of the file
};

class Parser {
  public:
    Parser(const std::map<std::string, std::string>& defines, Diagnostics& diags, XmlScene& scene)
        : params_(defines), overridden_(defines), diags_(diags), scene_(scene) {}

    void parseFile(const std::string& path, const XmlPos& includedFrom, int depth);
    void parseText(const FileCtx& f, int depth);
    void resolveRefs();
    void checkUnusedDefines();

  private:
    XmlPos pos(const FileCtx& f, const pugi::xml_node& n) const {
        // offset_debug() of an element is its name; report the '<' before it.
        size_t off = size_t(std::max<ptrdiff_t>(0, n.offset_debug()));
        if (off > 0 && off <= f.text.size() && f.text[off - 1] == '<') --off;
        return xmlPosOfOffset(f.path, f.text, off);
    }
    void error(const XmlPos& p, const std::string& msg) {
        Diagnostic d;
        d.file = p.file;
        d.line = p.line;
        d.column = p.column;
        d.message = msg;
        diags_.error(d);
    }
    /// Attribute value with $name substitution; false (and an error) on an undefined name.
    bool attr(const FileCtx& f, const pugi::xml_node& n, const char* name, std::string* out,
              bool required);
    bool checkAttributes(const FileCtx& f, const pugi::xml_node& n,
                         const std::vector<std::string>& allowed);
    void parseSceneChildren(const FileCtx& f, const pugi::xml_node& sceneNode, int depth);
    std::shared_ptr<XmlObject> parseObject(const FileCtx& f, const pugi::xml_node& n);
    void parseObjectBody(const FileCtx& f, const pugi::xml_node& n, XmlObject& obj);
    bool parseProperty(const FileCtx& f, const pugi::xml_node& n, XmlProperty* p);
    bool parseTransform(const FileCtx& f, const pugi::xml_node& n, Transform* out);
    bool parseVec3Attr(const FileCtx& f, const pugi::xml_node& n, const char* name, Vec3* out,
                       bool allowScalar);
    void registerId(const std::shared_ptr<XmlObject>& obj);

    std::map<std::string, std::string> params_;
    std::map<std::string, std::string> overridden_;
    std::map<std::string, bool> defaultSeen_;
    Diagnostics& diags_;
    XmlScene& scene_;
    std::map<std::string, std::shared_ptr<XmlObject>> ids_;
    struct PendingRef {
        XmlObject* parent;
        size_t childIndex;
        std::string id;
    };
    std::vector<PendingRef> refs_;
    std::vector<std::shared_ptr<XmlObject>> owned_;  // keeps objects alive for ref resolution
    std::vector<std::string> includeStack_;          ///< canonical paths of the files being read
    int filesRead_ = 0;
    int objectDepth_ = 0;
};

bool Parser::attr(const FileCtx& f, const pugi::xml_node& n, const char* name, std::string* out,
                  bool required) {
    pugi::xml_attribute a = n.attribute(name);
    if (!a) {
        if (required)
            error(pos(f, n), std::string("<") + n.name() + "> needs a '" + name + "' attribute");
        return false;
    }
    std::string v = a.value(), r;
    for (size_t i = 0; i < v.size();) {
        if (v[i] != '$') {
            r += v[i++];
            continue;
        }
        size_t j = i + 1;
        while (j < v.size() && (std::isalnum(uint8_t(v[j])) || v[j] == '_')) ++j;
        std::string key = v.substr(i + 1, j - i - 1);
        auto it = params_.find(key);
        if (key.empty() || it == params_.end()) {
            error(pos(f, n), std::string("attribute '") + name +
                                 "' uses the undefined parameter '$" + key +
                                 "' (define it with <default name=\"" + key +
                                 "\" value=\"...\"/> or -D " + key + "=VALUE)");
            return false;
        }
        r += it->second;
        i = j;
    }
    *out = r;
    return true;
}

bool Parser::checkAttributes(const FileCtx& f, const pugi::xml_node& n,
                             const std::vector<std::string>& allowed) {
    bool ok = true;
    for (pugi::xml_attribute a = n.first_attribute(); a; a = a.next_attribute()) {
        if (!isIn(a.name(), allowed)) {
            error(pos(f, n), std::string("<") + n.name() + ">: unexpected attribute '" + a.name() +
                                 "' (expected: " + joinList(allowed) + ")");
            ok = false;
        }
    }
    return ok;
}

void Parser::parseFile(const std::string& path, const XmlPos& includedFrom, int depth) {
    std::ifstream in(path, std::ios::binary);
    // Only regular files: a directory cannot be read and a device such as /dev/zero never ends.
    if (!in || !isRegularFile(path)) {
        if (includedFrom.file.empty())
            diags_.error(Diagnostic{path, 0, 0, "", "cannot open the scene file"});
        else
            error(includedFrom,
                  "cannot open the included file '" + path + "' (not a readable regular file)");
        return;
    }
    std::error_code ec;
    fs::path canonical = fs::weakly_canonical(fs::path(path), ec);
    const std::string key = ec ? path : canonical.string();
    if (std::find(includeStack_.begin(), includeStack_.end(), key) != includeStack_.end()) {
        error(includedFrom, "include cycle: '" + path +
                                "' is already being read (it includes "
                                "itself, directly or through other files)");
        return;
    }
    if (++filesRead_ > kMaxIncludedFiles) {
        error(includedFrom, "more than " + std::to_string(kMaxIncludedFiles) +
                                " files read through <include> (files included repeatedly?)");
        return;
    }
    std::stringstream ss;
    ss << in.rdbuf();
    FileCtx f{path, ss.str(), fs::path(path).parent_path().string()};
    includeStack_.push_back(key);
    parseText(f, depth);
    includeStack_.pop_back();
}

void Parser::parseText(const FileCtx& f, int depth) {
    pugi::xml_document doc;
    pugi::xml_parse_result res =
        doc.load_buffer(f.text.data(), f.text.size(), pugi::parse_default | pugi::parse_comments);
    if (!res) {
        error(xmlPosOfOffset(f.path, f.text, size_t(std::max<ptrdiff_t>(0, res.offset))),
              std::string("invalid XML: ") + res.description());
        return;
    }
    pugi::xml_node root;
    for (pugi::xml_node n = doc.first_child(); n; n = n.next_sibling()) {
        if (n.type() != pugi::node_element) continue;
        if (root) {
            error(pos(f, n), "more than one root element");
            return;
        }
        root = n;
    }
    if (!root || std::string(root.name()) != "scene") {
        error(root ? pos(f, root) : XmlPos{f.path, 1, 1},
              std::string("expected a <scene> root element") +
                  (root ? std::string(", got <") + root.name() + ">" : std::string()));
        return;
    }
    checkAttributes(f, root, {"version"});
    std::string version;
    if (attr(f, root, "version", &version, true)) {
        int major = std::atoi(version.c_str());
        if (major < 2 || major > 3)
            error(pos(f, root), "unsupported scene version '" + version +
                                    "' (expected 2.x or 3.x: Mitsuba 3 scenes; upgrade Mitsuba "
                                    "0.x scenes with Mitsuba 3's tools)");
    }
    parseSceneChildren(f, root, depth);
}

void Parser::parseSceneChildren(const FileCtx& f, const pugi::xml_node& sceneNode, int depth) {
    for (pugi::xml_node n = sceneNode.first_child(); n; n = n.next_sibling()) {
        if (n.type() == pugi::node_comment) continue;
        if (n.type() != pugi::node_element) {
            if (n.type() == pugi::node_pcdata &&
                std::string(n.value()).find_first_not_of(" \t\r\n") == std::string::npos)
                continue;
            error(pos(f, n), "unexpected text inside <scene>");
            continue;
        }
        const std::string tag = n.name();
        if (tag == "default") {
            checkAttributes(f, n, {"name", "value"});
            std::string name, value;
            if (!attr(f, n, "name", &name, true) || !attr(f, n, "value", &value, true)) continue;
            if (name.empty()) {
                error(pos(f, n), "<default> needs a non-empty name");
                continue;
            }
            // -D overrides win; otherwise the first <default> of a name defines it.
            if (!overridden_.count(name) && !params_.count(name)) params_[name] = value;
            defaultSeen_[name] = true;
        } else if (tag == "include") {
            checkAttributes(f, n, {"filename"});
            std::string file;
            if (!attr(f, n, "filename", &file, true)) continue;
            if (depth >= kMaxIncludeDepth) {
                error(pos(f, n), "includes nested more than " + std::to_string(kMaxIncludeDepth) +
                                     " deep (an include cycle?)");
                continue;
            }
            std::string resolved = resolveXmlPath(scene_, file);
            if (resolved.empty()) {
                error(pos(f, n), "included file '" + file +
                                     "' not found (searched: " + joinList(scene_.searchPath) + ")");
                continue;
            }
            parseFile(resolved, pos(f, n), depth + 1);
        } else if (tag == "path") {
            checkAttributes(f, n, {"value"});
            std::string value;
            if (!attr(f, n, "value", &value, true)) continue;
            fs::path p(value);
            if (p.is_relative()) {
                // As Mitsuba: relative to this file's folder, else through the search path
                // (an included file's <path> may be relative to the main scene's folder).
                p = fs::path(f.dir) / p;
                if (!isDirectory(p))
                    for (const auto& dir : scene_.searchPath)
                        if (isDirectory(fs::path(dir) / value)) {
                            p = fs::path(dir) / value;
                            break;
                        }
            }
            if (!isDirectory(p)) {
                error(pos(f, n), "<path> '" + value + "' is not a directory (resolved to '" +
                                     p.lexically_normal().string() + "', and not found in " +
                                     joinList(scene_.searchPath) + ")");
                continue;
            }
            scene_.searchPath.insert(scene_.searchPath.begin(), p.lexically_normal().string());
        } else if (isIn(tag, kObjectTags) && tag != "scene") {
            if (auto obj = parseObject(f, n)) scene_.objects.push_back(obj);
        } else if (tag == "ref") {
            error(pos(f, n),
                  "<ref> at the top level of a scene has no effect (a reference "
                  "attaches an object to another object)");
        } else if (isIn(tag, kPropertyTags)) {
            error(pos(f, n), "property <" + tag +
                                 "> directly inside <scene> (properties belong "
                                 "to a plugin object)");
        } else {
            error(pos(f, n), "unknown tag <" + tag +
                                 "> (expected one of: default, include, path, " +
                                 joinList(kObjectTags) + ")");
        }
    }
}

void Parser::registerId(const std::shared_ptr<XmlObject>& obj) {
    if (obj->id.empty()) return;
    auto it = ids_.find(obj->id);
    if (it != ids_.end()) {
        error(obj->pos, "duplicate id '" + obj->id + "' (first defined at " + it->second->pos.file +
                            ":" + std::to_string(it->second->pos.line) + ")");
        return;
    }
    ids_[obj->id] = obj;
}

std::shared_ptr<XmlObject> Parser::parseObject(const FileCtx& f, const pugi::xml_node& n) {
    if (objectDepth_ >= kMaxObjectDepth) {
        error(pos(f, n), std::string("<") + n.name() + "> is nested more than " +
                             std::to_string(kMaxObjectDepth) + " objects deep");
        return nullptr;
    }
    auto obj = std::make_shared<XmlObject>();
    owned_.push_back(obj);
    obj->tag = n.name();
    obj->pos = pos(f, n);
    checkAttributes(f, n, {"type", "id", "name"});
    if (!attr(f, n, "type", &obj->type, true)) obj->type = "?";
    attr(f, n, "id", &obj->id, false);
    registerId(obj);
    ++objectDepth_;
    parseObjectBody(f, n, *obj);
    --objectDepth_;
    return obj;
}

void Parser::parseObjectBody(const FileCtx& f, const pugi::xml_node& node, XmlObject& obj) {
    for (pugi::xml_node n = node.first_child(); n; n = n.next_sibling()) {
        if (n.type() == pugi::node_comment) continue;
        if (n.type() != pugi::node_element) {
            if (n.type() == pugi::node_pcdata &&
                std::string(n.value()).find_first_not_of(" \t\r\n") == std::string::npos)
                continue;
            error(pos(f, n), "unexpected text inside " + obj.label());
            continue;
        }
        const std::string tag = n.name();
        std::string name;
        if (tag == "ref") {
            checkAttributes(f, n, {"id", "name"});
            std::string id;
            if (!attr(f, n, "id", &id, true)) continue;
            attr(f, n, "name", &name, false);
            XmlChild c;
            c.name = name;
            c.pos = pos(f, n);
            obj.children.push_back(c);
            refs_.push_back({&obj, obj.children.size() - 1, id});
        } else if (isIn(tag, kObjectTags) && tag != "scene") {
            attr(f, n, "name", &name, false);
            XmlChild c;
            c.name = name;
            c.pos = pos(f, n);
            c.object = parseObject(f, n);
            if (!c.object) continue;
            obj.children.push_back(c);
        } else if (isIn(tag, kPropertyTags)) {
            XmlProperty p;
            if (!parseProperty(f, n, &p)) continue;
            if (obj.find(p.name)) {
                error(p.pos, "property '" + p.name + "' of " + obj.label() + " is given twice");
                continue;
            }
            obj.properties.push_back(p);
        } else {
            error(pos(f, n), "unknown tag <" + tag + "> inside " + obj.label() +
                                 " (expected a property: " + joinList(kPropertyTags) +
                                 ", a nested object, or <ref>)");
        }
    }
}

bool Parser::parseVec3Attr(const FileCtx& f, const pugi::xml_node& n, const char* name, Vec3* out,
                           bool allowScalar) {
    std::string v;
    if (!attr(f, n, name, &v, true)) return false;
    std::vector<std::string> parts = splitList(v);
    double x[3] = {0, 0, 0};
    bool ok = (parts.size() == 3 || (allowScalar && parts.size() == 1));
    for (size_t i = 0; ok && i < parts.size(); ++i) ok = parseDouble(parts[i], &x[i]);
    if (!ok) {
        error(pos(f, n), std::string("<") + n.name() + "> attribute '" + name + "': expected " +
                             (allowScalar ? "one or three numbers" : "three numbers") + ", got '" +
                             v + "'");
        return false;
    }
    if (parts.size() == 1) x[1] = x[2] = x[0];
    *out = Vec3(float(x[0]), float(x[1]), float(x[2]));
    return true;
}

bool Parser::parseProperty(const FileCtx& f, const pugi::xml_node& n, XmlProperty* p) {
    const std::string tag = n.name();
    p->pos = pos(f, n);
    if (!attr(f, n, "name", &p->name, true)) return false;
    if (tag == "transform") {
        p->kind = XmlValueKind::Transform;
        checkAttributes(f, n, {"name"});
        return parseTransform(f, n, &p->transform);
    }
    if (n.first_child() && n.first_child().type() == pugi::node_element) {
        error(p->pos, "<" + tag + "> property '" + p->name + "' cannot have child elements");
        return false;
    }
    auto bad = [&](const std::string& expected) {
        error(p->pos, "<" + tag + "> property '" + p->name + "': expected " + expected + ", got '" +
                          p->text + "'");
        return false;
    };
    if (tag == "point" || tag == "vector") {
        p->kind = tag == "point" ? XmlValueKind::Point : XmlValueKind::Vector;
        if (n.attribute("value")) {
            checkAttributes(f, n, {"name", "value"});
            attr(f, n, "value", &p->text, true);
            return parseVec3Attr(f, n, "value", &p->vec, false);
        }
        checkAttributes(f, n, {"name", "x", "y", "z"});
        const char* axes[3] = {"x", "y", "z"};
        for (int i = 0; i < 3; ++i) {
            std::string s;
            double v = 0;
            if (!n.attribute(axes[i])) continue;
            if (!attr(f, n, axes[i], &s, true)) return false;
            if (!parseDouble(s, &v)) {
                p->text = s;
                return bad(std::string("a number for '") + axes[i] + "'");
            }
            p->vec[i] = float(v);
        }
        return true;
    }
    checkAttributes(f, n, {"name", "value"});
    if (!attr(f, n, "value", &p->text, true)) return false;
    if (tag == "float") {
        p->kind = XmlValueKind::Float;
        return parseDouble(p->text, &p->number) || bad("a finite number");
    }
    if (tag == "integer") {
        p->kind = XmlValueKind::Integer;
        double v = 0;
        if (!parseDouble(p->text, &v) || v != std::floor(v) || std::fabs(v) > 2147483647.0)
            return bad("an integer");
        p->number = v;
        return true;
    }
    if (tag == "boolean") {
        p->kind = XmlValueKind::Boolean;
        std::string v = p->text;
        std::transform(v.begin(), v.end(), v.begin(), ::tolower);
        if (v == "true")
            p->boolean = true;
        else if (v == "false")
            p->boolean = false;
        else
            return bad("true or false");
        return true;
    }
    if (tag == "string") {
        p->kind = XmlValueKind::String;
        return true;
    }
    if (tag == "rgb") {
        p->kind = XmlValueKind::Rgb;
        std::vector<std::string> parts = splitList(p->text);
        double x[3] = {0, 0, 0};
        bool ok = parts.size() == 3 || parts.size() == 1;
        for (size_t i = 0; ok && i < parts.size(); ++i) ok = parseDouble(parts[i], &x[i]);
        if (!ok) return bad("one or three numbers");
        if (parts.size() == 1) x[1] = x[2] = x[0];
        p->vec = Vec3(float(x[0]), float(x[1]), float(x[2]));
        return true;
    }
    if (tag == "spectrum") {
        p->kind = XmlValueKind::Spectrum;
        std::vector<std::string> parts = splitList(p->text);
        double v = 0;
        if (parts.size() == 1 && parseDouble(parts[0], &v)) {
            p->spectrumIsConstant = true;
            p->number = v;
            p->vec = Vec3(float(v));
            return true;
        }
        std::vector<double> wl, val;
        for (const auto& s : parts) {
            size_t colon = s.find(':');
            double a = 0, b = 0;
            if (colon == std::string::npos || !parseDouble(s.substr(0, colon), &a) ||
                !parseDouble(s.substr(colon + 1), &b))
                return bad(
                    "a constant or wavelength:value pairs (\"400:0.1, 500:0.5\"); "
                    "spectrum files are not supported");
            if (!wl.empty() && a <= wl.back()) return bad("wavelengths in increasing order");
            wl.push_back(a);
            val.push_back(b);
        }
        if (wl.size() < 2) return bad("at least two wavelength:value pairs");
        p->wavelengths = wl;
        p->values = val;
        p->vec = spectrumToLinearSrgb(wl, val, /*illuminant=*/false);
        return true;
    }
    return bad("a known property type");
}

bool Parser::parseTransform(const FileCtx& f, const pugi::xml_node& node, Transform* out) {
    Transform m;
    bool ok = true;
    for (pugi::xml_node n = node.first_child(); n; n = n.next_sibling()) {
        if (n.type() == pugi::node_comment) continue;
        if (n.type() != pugi::node_element) {
            if (n.type() == pugi::node_pcdata &&
                std::string(n.value()).find_first_not_of(" \t\r\n") == std::string::npos)
                continue;
            error(pos(f, n), "unexpected text inside <transform>");
            ok = false;
            continue;
        }
        const std::string tag = n.name();
        Transform op;
        // Component form (x, y, z attributes) or value="x y z".
        auto readXyz = [&](Vec3 def, bool allowScalar, Vec3* v) {
            if (n.attribute("value")) {
                if (n.attribute("x") || n.attribute("y") || n.attribute("z")) {
                    error(pos(f, n), "<" + tag + ">: give either 'value' or x/y/z, not both");
                    return false;
                }
                return parseVec3Attr(f, n, "value", v, allowScalar);
            }
            *v = def;
            const char* axes[3] = {"x", "y", "z"};
            for (int i = 0; i < 3; ++i) {
                if (!n.attribute(axes[i])) continue;
                std::string s;
                double d = 0;
                if (!attr(f, n, axes[i], &s, true)) return false;
                if (!parseDouble(s, &d)) {
                    error(pos(f, n), "<" + tag + "> attribute '" + axes[i] +
                                         "': expected a number, got '" + s + "'");
                    return false;
                }
                (*v)[i] = float(d);
            }
            return true;
        };
        if (tag == "translate") {
            Vec3 v;
            if (!checkAttributes(f, n, {"x", "y", "z", "value"}) ||
                !readXyz(Vec3(0.0f), false, &v)) {
                ok = false;
                continue;
            }
            op = Transform::translate(v);
        } else if (tag == "scale") {
            Vec3 v;
            if (!checkAttributes(f, n, {"x", "y", "z", "value"}) ||
                !readXyz(Vec3(1.0f), true, &v)) {
                ok = false;
                continue;
            }
            op = Transform::scale(v);
        } else if (tag == "rotate") {
            Vec3 axis;
            std::string angleText;
            double angle = 0;
            if (!checkAttributes(f, n, {"x", "y", "z", "value", "angle"}) ||
                !readXyz(Vec3(0.0f), false, &axis) || !attr(f, n, "angle", &angleText, true)) {
                ok = false;
                continue;
            }
            if (!parseDouble(angleText, &angle)) {
                error(pos(f, n), "<rotate> attribute 'angle': expected a number of degrees, got '" +
                                     angleText + "'");
                ok = false;
                continue;
            }
            if (!(length(axis) > 0.0f)) {
                error(pos(f, n), "<rotate> needs a non-zero axis (x, y, z)");
                ok = false;
                continue;
            }
            op = Transform::rotate(float(angle), axis);
        } else if (tag == "matrix") {
            std::string v;
            if (!checkAttributes(f, n, {"value"}) || !attr(f, n, "value", &v, true)) {
                ok = false;
                continue;
            }
            std::vector<std::string> parts = splitList(v);
            double x[16];
            bool good = parts.size() == 16 || parts.size() == 9;
            for (size_t i = 0; good && i < parts.size(); ++i) good = parseDouble(parts[i], &x[i]);
            if (!good) {
                error(pos(f, n),
                      "<matrix> value: expected 16 (4x4) or 9 (3x3) numbers in "
                      "row-major order, got '" +
                          v + "'");
                ok = false;
                continue;
            }
            int dim = parts.size() == 16 ? 4 : 3;
            for (int r = 0; r < dim; ++r)
                for (int c = 0; c < dim; ++c) op.m[r][c] = float(x[r * dim + c]);
            if (dim == 4 &&
                (op.m[3][0] != 0 || op.m[3][1] != 0 || op.m[3][2] != 0 || op.m[3][3] != 1)) {
                error(pos(f, n),
                      "<matrix>: projective matrices are not supported (expected the "
                      "last row 0 0 0 1)");
                ok = false;
                continue;
            }
        } else if (tag == "lookat") {
            Vec3 origin, target, up(0, 1, 0);
            if (!checkAttributes(f, n, {"origin", "target", "up"}) ||
                !parseVec3Attr(f, n, "origin", &origin, false) ||
                !parseVec3Attr(f, n, "target", &target, false)) {
                ok = false;
                continue;
            }
            if (n.attribute("up") && !parseVec3Attr(f, n, "up", &up, false)) {
                ok = false;
                continue;
            }
            Vec3 dir = target - origin;
            if (!(length(dir) > 0.0f) || !(length(cross(normalize(dir), up)) > 1e-6f)) {
                error(pos(f, n),
                      "<lookat>: target must differ from origin and up must not be "
                      "parallel to the viewing direction");
                ok = false;
                continue;
            }
            // Mitsuba's look-at: columns (left, up', dir, origin) with left = up x dir.
            op = Transform::lookAt(origin, target, up);
        } else {
            error(pos(f, n), "unknown transform operation <" + tag +
                                 "> (expected translate, rotate, scale, matrix, lookat)");
            ok = false;
            continue;
        }
        m = op * m;  // Mitsuba: each operation is applied after the previous ones
    }
    *out = m;
    return ok;
}

void Parser::resolveRefs() {
    for (const PendingRef& r : refs_) {
        auto it = ids_.find(r.id);
        XmlChild& c = r.parent->children[r.childIndex];
        if (it == ids_.end()) {
            std::string known;
            for (const auto& kv : ids_) known += (known.empty() ? "" : ", ") + kv.first;
            error(c.pos, "<ref id=\"" + r.id + "\">: no object with this id (ids defined: " +
                             (known.empty() ? std::string("none") : known) + ")");
            continue;
        }
        if (it->second.get() == r.parent) {
            error(c.pos, "<ref id=\"" + r.id + "\"> refers to the object that contains it");
            continue;
        }
        c.object = it->second;
    }
    // Drop unresolved references so that the builder never sees a null object.
    for (auto& o : owned_)
        o->children.erase(std::remove_if(o->children.begin(), o->children.end(),
                                         [](const XmlChild& c) { return !c.object; }),
                          o->children.end());
}

void Parser::checkUnusedDefines() {
    for (const auto& kv : overridden_)
        if (!defaultSeen_.count(kv.first)) {
            std::string known;
            for (const auto& d : defaultSeen_) known += (known.empty() ? "" : ", ") + d.first;
            diags_.error(Diagnostic{scene_.file, 0, 0, "",
                                    "-D " + kv.first + ": the scene has no <default name=\"" +
                                        kv.first + "\"> parameter (parameters: " +
                                        (known.empty() ? std::string("none") : known) + ")"});
        }
}

}  // namespace

const std::vector<std::string>& xmlObjectTags() {
    return kObjectTags;
}

std::string XmlObject::label() const {
    return "<" + tag + " type=\"" + type + "\">";
}

const XmlProperty* XmlObject::find(const std::string& name) const {
    for (const auto& p : properties)
        if (p.name == name) return &p;
    return nullptr;
}

XmlPos xmlPosOfOffset(const std::string& file, const std::string& text, size_t offset) {
    XmlPos p;
    p.file = file;
    p.line = 1;
    p.column = 1;
    offset = std::min(offset, text.size());
    for (size_t i = 0; i < offset; ++i) {
        if (text[i] == '\n') {
            ++p.line;
            p.column = 1;
        } else if ((uint8_t(text[i]) & 0xC0) != 0x80) {  // count UTF-8 code points
            ++p.column;
        }
    }
    return p;
}

std::string resolveXmlPath(const XmlScene& scene, const std::string& name) {
    fs::path p(name);
    if (p.is_absolute()) return pathExists(p) ? p.string() : std::string();
    for (const auto& dir : scene.searchPath) {
        fs::path c = fs::path(dir) / p;
        if (pathExists(c)) return c.lexically_normal().string();
    }
    return {};
}

XmlScene parseMitsubaXml(const std::string& path, const std::map<std::string, std::string>& defines,
                         Diagnostics& diags) {
    XmlScene scene;
    scene.file = path;
    std::string dir = fs::path(path).parent_path().string();
    scene.searchPath.push_back(dir.empty() ? std::string(".") : dir);
    Parser p(defines, diags, scene);
    p.parseFile(path, XmlPos{}, 0);
    p.resolveRefs();
    p.checkUnusedDefines();
    return scene;
}

XmlScene parseMitsubaXmlString(const std::string& text, const std::string& fileName,
                               const std::string& baseDir,
                               const std::map<std::string, std::string>& defines,
                               Diagnostics& diags) {
    XmlScene scene;
    scene.file = fileName;
    scene.searchPath.push_back(baseDir.empty() ? std::string(".") : baseDir);
    Parser p(defines, diags, scene);
    p.parseText(FileCtx{fileName, text, baseDir}, 0);
    p.resolveRefs();
    p.checkUnusedDefines();
    return scene;
}

}  // namespace ub
