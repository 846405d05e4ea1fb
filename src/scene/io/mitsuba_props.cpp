// Typed, use-tracking property access for the Mitsuba XML builder (mitsuba_build.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "scene/io/mitsuba_build.h"
#include "scene/io/mitsuba_spectra.h"

namespace ub {

namespace {

const char* kindName(XmlValueKind k) {
    switch (k) {
        case XmlValueKind::Float:
            return "float";
        case XmlValueKind::Integer:
            return "integer";
        case XmlValueKind::Boolean:
            return "boolean";
        case XmlValueKind::String:
            return "string";
        case XmlValueKind::Rgb:
            return "rgb";
        case XmlValueKind::Spectrum:
            return "spectrum";
        case XmlValueKind::Point:
            return "point";
        case XmlValueKind::Vector:
            return "vector";
        case XmlValueKind::Transform:
            return "transform";
    }
    return "?";
}

std::string join(const std::vector<std::string>& v) {
    std::string s;
    for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
    return s;
}

}  // namespace

void XmlReader::error(const XmlPos& p, const std::string& msg) {
    Diagnostic d;
    d.file = p.file;
    d.line = p.line;
    d.column = p.column;
    d.message = msg;
    diags_.error(d);
    ++errors_;
}

void XmlReader::warning(const XmlPos& p, const std::string& msg) {
    Diagnostic d;
    d.file = p.file;
    d.line = p.line;
    d.column = p.column;
    d.message = msg;
    diags_.warning(d);
}

const XmlProperty* XmlReader::prop(const XmlObject& o, const std::string& name,
                                   std::initializer_list<XmlValueKind> kinds,
                                   const char* expected) {
    const XmlProperty* p = o.find(name);
    if (!p) return nullptr;
    p->used = true;
    if (std::find(kinds.begin(), kinds.end(), p->kind) == kinds.end()) {
        error(p->pos, o.label() + ": parameter '" + name + "' must be " + expected + ", got <" +
                          kindName(p->kind) + ">");
        return nullptr;
    }
    return p;
}

float XmlReader::getFloat(const XmlObject& o, const std::string& name, float def) {
    const XmlProperty* p = prop(o, name, {XmlValueKind::Float, XmlValueKind::Integer}, "a <float>");
    return p ? float(p->number) : def;
}

float XmlReader::getFloatIn(const XmlObject& o, const std::string& name, float def, float lo,
                            float hi, bool loOpen, bool hiOpen) {
    const XmlProperty* p = prop(o, name, {XmlValueKind::Float, XmlValueKind::Integer}, "a <float>");
    if (!p) return def;
    double v = p->number;
    bool ok = (loOpen ? v > lo : v >= lo) && (hiOpen ? v < hi : v <= hi);
    if (!ok) {
        // %g: "(0, 1e+30]", not "(0.000000, inf]" (kInf is 1e30, and larger values fail).
        char range[96];
        std::snprintf(range, sizeof(range), "%s%g, %g%s", loOpen ? "(" : "[", double(lo),
                      double(hi), hiOpen ? ")" : "]");
        error(p->pos, o.label() + ": parameter '" + name + "' = " + p->text +
                          " is out of range (expected a value in " + range + ")");
        return def;
    }
    return float(v);
}

int XmlReader::getInt(const XmlObject& o, const std::string& name, int def, int lo, int hi) {
    const XmlProperty* p = prop(o, name, {XmlValueKind::Integer}, "an <integer>");
    if (!p) return def;
    if (p->number < lo || p->number > hi) {
        error(p->pos, o.label() + ": parameter '" + name + "' = " + p->text +
                          " is out of range (expected an integer in [" + std::to_string(lo) + ", " +
                          std::to_string(hi) + "])");
        return def;
    }
    return int(p->number);
}

bool XmlReader::getBool(const XmlObject& o, const std::string& name, bool def) {
    const XmlProperty* p = prop(o, name, {XmlValueKind::Boolean}, "a <boolean>");
    return p ? p->boolean : def;
}

std::string XmlReader::getString(const XmlObject& o, const std::string& name,
                                 const std::string& def) {
    const XmlProperty* p = prop(o, name, {XmlValueKind::String}, "a <string>");
    return p ? p->text : def;
}

Rgb XmlReader::getColor(const XmlObject& o, const std::string& name, const Rgb& def, ColorUse use) {
    const XmlProperty* p = prop(
        o, name,
        {XmlValueKind::Rgb, XmlValueKind::Spectrum, XmlValueKind::Float, XmlValueKind::Integer},
        "a colour (<rgb>, <spectrum> or <float>)");
    if (!p) return def;
    Rgb c = p->kind == XmlValueKind::Float || p->kind == XmlValueKind::Integer
                ? Rgb(float(p->number))
                : p->vec;
    if (p->kind == XmlValueKind::Spectrum && use == ColorUse::Emission) {
        // Mitsuba's rgb variants: a constant emission spectrum becomes value * XYZ->sRGB of
        // (1, 1, 1) (equal-energy white seen with a D65 white point); sampled spectra are
        // integrated without the D65 weighting.
        if (p->spectrumIsConstant)
            c = float(p->number) * Rgb(1.2047843f, 0.9483008f, 0.9088427f);
        else
            c = spectrumToLinearSrgb(p->wavelengths, p->values, /*illuminant=*/true);
    } else if (p->kind == XmlValueKind::Spectrum && use == ColorUse::Unbounded &&
               !p->spectrumIsConstant) {
        c = spectrumToLinearSrgb(p->wavelengths, p->values, true);
    }
    if (!isFinite(c) || minComponent(c) < 0.0f) {
        error(p->pos,
              o.label() + ": parameter '" + name + "' = " + p->text + " must be finite and >= 0");
        return def;
    }
    if (use == ColorUse::Reflectance && maxComponent(c) > 1.0f) {
        error(p->pos, o.label() + ": reflectance '" + name + "' = " + p->text +
                          " exceeds 1 (expected values in [0, 1])");
        return def;
    }
    return c;
}

Vec3 XmlReader::getPoint(const XmlObject& o, const std::string& name, const Vec3& def) {
    const XmlProperty* p = prop(o, name, {XmlValueKind::Point, XmlValueKind::Vector}, "a <point>");
    return p ? p->vec : def;
}

Vec3 XmlReader::getVector(const XmlObject& o, const std::string& name, const Vec3& def) {
    const XmlProperty* p = prop(o, name, {XmlValueKind::Vector, XmlValueKind::Point}, "a <vector>");
    return p ? p->vec : def;
}

Transform XmlReader::getTransform(const XmlObject& o, const std::string& name) {
    const XmlProperty* p = prop(o, name, {XmlValueKind::Transform}, "a <transform>");
    if (!p) return Transform();
    if (!(std::fabs(p->transform.determinant3()) > 1e-12f)) {
        error(p->pos, o.label() + ": transform '" + name + "' is singular");
        return Transform();
    }
    return p->transform;
}

float XmlReader::getIor(const XmlObject& o, const std::string& name, float def) {
    const XmlProperty* p =
        prop(o, name, {XmlValueKind::Float, XmlValueKind::Integer, XmlValueKind::String},
             "a <float> or a <string> naming a material");
    if (!p) return def;
    if (p->kind == XmlValueKind::String) {
        float v = 0;
        if (namedIor(p->text, &v)) return v;
        error(p->pos, o.label() + ": unknown IOR name '" + p->text + "' in '" + name +
                          "' (known: " + join(namedIorNames()) + ")");
        return def;
    }
    if (!(p->number >= 1.0) || p->number > 10.0) {
        error(p->pos, o.label() + ": IOR '" + name + "' = " + p->text +
                          " out of range (expected a value in [1, 10])");
        return def;
    }
    return float(p->number);
}

const XmlObject* XmlReader::child(const XmlObject& o, const std::string& tag,
                                  const std::string& name) {
    const XmlChild* found = nullptr;
    for (const XmlChild& c : o.children) {
        if (c.object->tag != tag) continue;
        if (!name.empty() && c.name != name) continue;
        if (name.empty() && !c.name.empty() && tag != "bsdf" && tag != "emitter" && tag != "film" &&
            tag != "sampler" && tag != "rfilter" && tag != "integrator" && tag != "phase")
            continue;
        if (found) {
            error(c.pos, o.label() + ": more than one nested <" + tag + ">" +
                             (name.empty() ? std::string() : " named '" + name + "'"));
            break;
        }
        found = &c;
    }
    if (!found) return nullptr;
    found->used = true;
    lastChildPos_ = found->pos;
    return found->object.get();
}

std::vector<const XmlObject*> XmlReader::children(const XmlObject& o, const std::string& tag) {
    std::vector<const XmlObject*> v;
    for (const XmlChild& c : o.children)
        if (c.object->tag == tag) {
            c.used = true;
            v.push_back(c.object.get());
        }
    return v;
}

void XmlReader::checkUnused(const XmlObject& o) {
    for (const XmlProperty& p : o.properties)
        if (!p.used)
            error(p.pos, o.label() + ": unsupported parameter '" + p.name + "' (<" +
                             kindName(p.kind) + ">); see docs/mitsuba.md for what unibeam reads");
    for (const XmlChild& c : o.children)
        if (!c.used)
            error(c.pos, o.label() + ": unsupported nested " + c.object->label() +
                             (c.name.empty() ? std::string() : " named '" + c.name + "'") +
                             "; see docs/mitsuba.md");
}

void XmlReader::unsupportedPlugin(const XmlObject& o, const std::vector<std::string>& supported,
                                  const std::string& note) {
    error(o.pos, "unsupported " + o.tag + " plugin '" + o.type + "' (supported: " +
                     join(supported) + ")" + (note.empty() ? std::string() : "; " + note));
}

std::string MitsubaBuild::resolveFile(const XmlObject& o, const std::string& propName,
                                      const std::string& name) {
    std::string path = resolveXmlPath(xml, name);
    if (path.empty()) {
        const XmlProperty* p = o.find(propName);
        r.error(p ? p->pos : o.pos, o.label() + ": file '" + name +
                                        "' not found (searched: " + join(xml.searchPath) + ")");
    }
    return path;
}

}  // namespace ub
