// unibeam's own PLY reader (scene/ply_reader.h): ASCII, binary little and big endian.
//
// Why not a library: Assimp 5.2 (Debian 12), which read PLY here before, crashed, hung,
// leaked or tried to allocate tens of GB on malformed files in fuzzing (docs/fuzzing.md: a
// bad header line, no end_header, a list count of 41015555... in an ASCII body), and each
// fix was a guard in front of a library that trusts its input. Debian packages no small PLY
// library (no rply, tinyply or happly; PCL's reader comes with the whole point-cloud
// library). PLY is small: a header of elements and typed properties, then the elements in
// order (Turk, "The PLY Polygon File Format", 1994; Bourke's description of it). This
// reader checks every count against the bytes the file has before it allocates, every
// value against its type, and names the line (ASCII) or byte offset (binary) of a problem.
#include "scene/ply_reader.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>

namespace ub {

namespace {

enum class PlyType { kNone, kI8, kU8, kI16, kU16, kI32, kU32, kF32, kF64 };

PlyType plyType(const std::string& t) {
    if (t == "char" || t == "int8") return PlyType::kI8;
    if (t == "uchar" || t == "uint8") return PlyType::kU8;
    if (t == "short" || t == "int16") return PlyType::kI16;
    if (t == "ushort" || t == "uint16") return PlyType::kU16;
    if (t == "int" || t == "int32") return PlyType::kI32;
    if (t == "uint" || t == "uint32") return PlyType::kU32;
    if (t == "float" || t == "float32") return PlyType::kF32;
    if (t == "double" || t == "float64") return PlyType::kF64;
    return PlyType::kNone;
}

int typeBytes(PlyType t) {
    switch (t) {
        case PlyType::kI8:
        case PlyType::kU8:
            return 1;
        case PlyType::kI16:
        case PlyType::kU16:
            return 2;
        case PlyType::kI32:
        case PlyType::kU32:
        case PlyType::kF32:
            return 4;
        case PlyType::kF64:
            return 8;
        case PlyType::kNone:
            break;
    }
    return 0;
}

bool isIntegerType(PlyType t) {
    return t != PlyType::kF32 && t != PlyType::kF64 && t != PlyType::kNone;
}

/// The range of an integer type, for messages and checks.
void integerRange(PlyType t, double* lo, double* hi) {
    switch (t) {
        case PlyType::kI8:
            *lo = -128, *hi = 127;
            return;
        case PlyType::kU8:
            *lo = 0, *hi = 255;
            return;
        case PlyType::kI16:
            *lo = -32768, *hi = 32767;
            return;
        case PlyType::kU16:
            *lo = 0, *hi = 65535;
            return;
        case PlyType::kI32:
            *lo = -2147483648.0, *hi = 2147483647.0;
            return;
        default:
            *lo = 0, *hi = 4294967295.0;
    }
}

struct Property {
    std::string name, typeName, countTypeName;
    PlyType type = PlyType::kNone;       // the value type (list: its entries)
    PlyType countType = PlyType::kNone;  // lists only
    bool list = false;
};

struct Element {
    std::string name;
    uint64_t count = 0;
    int line = 0;
    std::vector<Property> props;
    uint64_t minBytes = 0;  // per element: binary scalars and list counts, ASCII 2 per value
};

enum class Format { kAscii, kLittle, kBig };

/// Reads the body value by value, from ASCII tokens or binary fields, with the position of
/// the last value for messages.
class BodyReader {
  public:
    BodyReader(const std::string& data, size_t begin, Format f, int headerLines)
        : data_(data), pos_(begin), format_(f), line_(headerLines + 1) {}

    /// The next value as a double (every PLY type fits one exactly); false at the end of the
    /// file or, with *bad set, for an ASCII token that is no number of the type.
    bool next(PlyType t, double* v, std::string* bad) {
        bad->clear();
        return format_ == Format::kAscii ? nextText(t, v, bad) : nextBinary(t, v);
    }
    /// Where the last value started: "line L" (ASCII) or "byte offset B" (binary).
    std::string where() const {
        return format_ == Format::kAscii ? "line " + std::to_string(tokenLine_)
                                         : "byte offset " + std::to_string(tokenPos_);
    }
    int line() const { return format_ == Format::kAscii ? tokenLine_ : 0; }
    int column() const { return format_ == Format::kAscii ? tokenColumn_ : 0; }
    size_t remaining() const { return data_.size() - std::min(pos_, data_.size()); }
    /// What is left after the last element: ASCII tokens (not whitespace) or binary bytes.
    size_t leftover() {
        if (format_ != Format::kAscii) return remaining();
        size_t n = 0;
        while (skipSpace()) {
            ++n;
            while (pos_ < data_.size() && !std::isspace((unsigned char)data_[pos_])) ++pos_;
        }
        return n;
    }

  private:
    bool skipSpace() {
        while (pos_ < data_.size() && std::isspace((unsigned char)data_[pos_])) {
            if (data_[pos_] == '\n') {
                ++line_;
                lineStart_ = pos_ + 1;
            }
            ++pos_;
        }
        return pos_ < data_.size();
    }
    bool nextText(PlyType t, double* v, std::string* bad) {
        if (!skipSpace()) return false;
        tokenLine_ = line_;
        tokenColumn_ = int(pos_ - lineStart_) + 1;
        const size_t b = pos_;
        while (pos_ < data_.size() && !std::isspace((unsigned char)data_[pos_])) ++pos_;
        const std::string tok = data_.substr(b, std::min<size_t>(pos_ - b, 64));
        char* end = nullptr;
        errno = 0;
        if (isIntegerType(t)) {
            const long long x = std::strtoll(tok.c_str(), &end, 10);
            double lo = 0, hi = 0;
            integerRange(t, &lo, &hi);
            if (end == tok.c_str() || *end != '\0' || errno == ERANGE || pos_ - b > 64 ||
                double(x) < lo || double(x) > hi) {
                *bad = tok;
                return false;
            }
            *v = double(x);
        } else {
            const double x = std::strtod(tok.c_str(), &end);
            // Overflow to inf is a value (reported later as non-finite where it matters).
            if (end == tok.c_str() || *end != '\0' || pos_ - b > 64) {
                *bad = tok;
                return false;
            }
            *v = x;
        }
        return true;
    }
    bool nextBinary(PlyType t, double* v) {
        const int n = typeBytes(t);
        if (remaining() < size_t(n)) return false;
        tokenPos_ = pos_;
        unsigned char b[8];
        std::memcpy(b, data_.data() + pos_, size_t(n));
        pos_ += size_t(n);
        const bool little = format_ == Format::kLittle;
        uint64_t u = 0;
        for (int i = 0; i < n; ++i) u |= uint64_t(b[little ? i : n - 1 - i]) << (8 * i);
        switch (t) {
            case PlyType::kI8:
                *v = double(int8_t(uint8_t(u)));
                break;
            case PlyType::kU8:
                *v = double(uint8_t(u));
                break;
            case PlyType::kI16:
                *v = double(int16_t(uint16_t(u)));
                break;
            case PlyType::kU16:
                *v = double(uint16_t(u));
                break;
            case PlyType::kI32:
                *v = double(int32_t(uint32_t(u)));
                break;
            case PlyType::kU32:
                *v = double(uint32_t(u));
                break;
            case PlyType::kF32: {
                const uint32_t w = uint32_t(u);
                float f;
                std::memcpy(&f, &w, 4);
                *v = double(f);
                break;
            }
            case PlyType::kF64: {
                double d;
                std::memcpy(&d, &u, 8);
                *v = d;
                break;
            }
            case PlyType::kNone:
                return false;
        }
        return true;
    }

    const std::string& data_;
    size_t pos_;
    Format format_;
    int line_;
    size_t lineStart_ = 0;
    int tokenLine_ = 0, tokenColumn_ = 0;
    size_t tokenPos_ = 0;
};

/// Index of the property named one of `names` (in order of preference), or -1.
int findProperty(const Element& e, std::initializer_list<const char*> names, bool list) {
    for (const char* n : names)
        for (size_t i = 0; i < e.props.size(); ++i)
            if (e.props[i].name == n && e.props[i].list == list) return int(i);
    return -1;
}

/// A mesh attribute being read: the properties of its channels in an element.
struct AttributeGroup {
    std::string prefix;
    std::vector<int> props;     ///< property index per channel (-1: missing)
    std::vector<double> scale;  ///< per channel: 1, or 1 / max of an integer type
};

/// Mitsuba 3's naming of the properties it keeps as mesh attributes: red/green/blue (or
/// r/g/b) form "color"; NAME_0, NAME_1, ... form "NAME" with one channel each; any other
/// scalar property is a 1-channel attribute of its own name. `used` marks the properties
/// read as geometry (positions, normals, uvs, vertex indices). Integer colour channels are
/// divided by their type's maximum (uchar 255).
std::vector<AttributeGroup> attributeGroups(const Element& e, const std::vector<bool>& used) {
    std::vector<AttributeGroup> groups;
    auto group = [&](const std::string& prefix) -> AttributeGroup& {
        for (AttributeGroup& g : groups)
            if (g.prefix == prefix) return g;
        groups.push_back(AttributeGroup{prefix, {}, {}});
        return groups.back();
    };
    for (size_t i = 0; i < e.props.size(); ++i) {
        const Property& p = e.props[i];
        if (used[i] || p.list) continue;
        std::string prefix = p.name;
        size_t channel = 0;
        double scale = 1.0;
        static const char* const kRgb[2][3] = {{"r", "g", "b"}, {"red", "green", "blue"}};
        bool colour = false;
        for (auto& names : kRgb)
            for (size_t c = 0; c < 3; ++c)
                if (p.name == names[c]) colour = true, prefix = "color", channel = c;
        if (colour) {
            if (p.type != PlyType::kF32 && p.type != PlyType::kF64) {
                double lo = 0, hi = 1;
                integerRange(p.type, &lo, &hi);
                scale = 1.0 / hi;
            }
        } else if (const size_t us = p.name.rfind('_');
                   us != std::string::npos && us > 0 && us + 1 < p.name.size() &&
                   p.name.find_first_not_of("0123456789", us + 1) == std::string::npos &&
                   p.name.size() - us - 1 <= 2) {
            prefix = p.name.substr(0, us);
            channel = size_t(std::stoi(p.name.substr(us + 1)));
        }
        AttributeGroup& g = group(prefix);
        if (g.props.size() <= channel) g.props.resize(channel + 1, -1), g.scale.resize(channel + 1);
        g.props[channel] = int(i);
        g.scale[channel] = scale;
    }
    return groups;
}

}  // namespace

bool readPly(const std::string& path, const PlyReport& report, TriangleMesh* out) {
    std::ifstream file(path, std::ios::binary);
    std::ostringstream ss;
    if (!file || !(ss << file.rdbuf()) || file.bad()) {
        // (An empty file reads nothing: it is reported as no PLY below.)
        if (file.bad() || !file.is_open()) {
            report.error("cannot read PLY file", 0, 0);
            return false;
        }
    }
    const std::string data = ss.str();

    // ---- header ----
    size_t pos = 0;
    int lineNo = 0;
    auto nextLine = [&](std::string* line) {
        if (pos >= data.size()) return false;
        size_t e = data.find('\n', pos);
        if (e == std::string::npos) e = data.size();
        *line = data.substr(pos, e - pos);
        pos = e + 1;
        ++lineNo;
        if (!line->empty() && line->back() == '\r') line->pop_back();
        return true;
    };
    std::string line;
    if (!nextLine(&line) || line != "ply") {
        std::string first = line.substr(0, 20);
        for (char& c : first)
            if (!std::isprint((unsigned char)c)) c = '?';
        report.error("not a PLY file: the first line is '" + first + "' (expected 'ply')", 1, 0);
        return false;
    }
    Format format = Format::kAscii;
    bool haveFormat = false, ended = false;
    std::vector<Element> elements;
    while (lineNo < 10000 && nextLine(&line)) {
        // Printable text only (tab allowed): a \v or \f is no separator of PLY's.
        for (size_t i = 0; i < line.size(); ++i) {
            const unsigned char c = static_cast<unsigned char>(line[i]);
            if (c < 0x20 && c != '\t') {
                char hex[8];
                std::snprintf(hex, sizeof(hex), "0x%02x", unsigned(c));
                report.error(std::string("PLY header line has control character ") + hex +
                                 " at column " + std::to_string(i + 1) +
                                 " (expected header lines of printable text, words separated by "
                                 "spaces)",
                             lineNo, int(i) + 1);
                return false;
            }
        }
        std::istringstream ls(line);
        std::string kw;
        ls >> kw;
        if (kw == "end_header") {
            ended = true;
            break;
        }
        if (kw.empty() || kw == "comment" || kw == "obj_info") continue;
        if (kw == "format") {
            if (haveFormat) {
                report.error("PLY header has a second 'format' line (expected one, on line 2)",
                             lineNo, 0);
                return false;
            }
            std::string f, version;
            ls >> f >> version;
            if (f == "ascii")
                format = Format::kAscii;
            else if (f == "binary_little_endian")
                format = Format::kLittle;
            else if (f == "binary_big_endian")
                format = Format::kBig;
            else {
                report.error("PLY format '" + f +
                                 "' (expected ascii, binary_little_endian or binary_big_endian)",
                             lineNo, 0);
                return false;
            }
            haveFormat = true;
        } else if (kw == "element") {
            Element e;
            std::string count;
            ls >> e.name >> count;
            e.line = lineNo;
            const bool digits = !count.empty() && count.size() <= 19 &&
                                count.find_first_not_of("0123456789") == std::string::npos;
            if (!digits) {
                report.error("PLY element '" + e.name + "' has count '" + count +
                                 "' (expected a non-negative integer)",
                             lineNo, 0);
                return false;
            }
            e.count = std::stoull(count);
            elements.push_back(e);
        } else if (kw == "property") {
            Property p;
            std::string t1, t2, t3, name;
            ls >> t1;
            bool ok = false;
            if (t1 == "list") {
                ok = bool(ls >> t2 >> t3 >> name) && plyType(t2) != PlyType::kNone &&
                     isIntegerType(plyType(t2)) && plyType(t3) != PlyType::kNone;
                p.list = true;
                p.countType = plyType(t2);
                p.countTypeName = t2;
                p.type = plyType(t3);
                p.typeName = t3;
            } else {
                ok = plyType(t1) != PlyType::kNone && bool(ls >> name);
                p.type = plyType(t1);
                p.typeName = t1;
            }
            if (!ok) {
                report.error("PLY property line '" + line.substr(0, 60) +
                                 "' (expected 'property TYPE NAME' or 'property list "
                                 "COUNT_TYPE INDEX_TYPE NAME' with PLY's scalar types, an "
                                 "integer COUNT_TYPE)",
                             lineNo, 0);
                return false;
            }
            if (elements.empty()) {
                report.error("PLY property '" + name + "' before any element line", lineNo, 0);
                return false;
            }
            p.name = name;
            Element& e = elements.back();
            e.minBytes +=
                format == Format::kAscii ? 2 : uint64_t(typeBytes(p.list ? p.countType : p.type));
            e.props.push_back(p);
        } else {
            report.error("unknown PLY header line '" + line.substr(0, 40) +
                             "' (expected format, element, property, comment, obj_info or "
                             "end_header)",
                         lineNo, 0);
            return false;
        }
    }
    if (!ended) {
        report.error("PLY header has no 'end_header' line" +
                         std::string(lineNo >= 10000 ? " in its first 10000 lines" : "") +
                         " (expected the element and property lines to end with 'end_header'; "
                         "truncated or corrupt file?)",
                     lineNo, 0);
        return false;
    }
    if (!haveFormat) {
        report.error(
            "PLY header has no 'format' line (expected 'format ascii 1.0' or a binary "
            "format)",
            2, 0);
        return false;
    }
    // Every element needs its minimum bytes: counts the file cannot hold are errors before
    // anything is allocated (compared by division so that nothing overflows). ASCII: one
    // byte of slack, for a last value without a separator after it.
    const size_t headerBytes = std::min(pos, data.size());
    const uint64_t available = data.size() - headerBytes + (format == Format::kAscii ? 1u : 0u);
    uint64_t needed = 0;
    for (const Element& e : elements) {
        const uint64_t per = std::max<uint64_t>(1, e.minBytes);
        if (e.count > (available - std::min(needed, available)) / per) {
            report.error("PLY header announces " + std::to_string(e.count) + " '" + e.name +
                             "' elements (at least " + std::to_string(per) +
                             " bytes each), but the file has only " + std::to_string(available) +
                             " bytes after the header (truncated or corrupt file?)",
                         e.line, 0);
            return false;
        }
        needed += e.count * per;
    }

    // ---- what is read ----
    const Element* vertexElement = nullptr;
    uint64_t vertexCount = 0;
    for (const Element& e : elements)
        if (e.name == "vertex") {
            vertexElement = &e;
            vertexCount = e.count;
        }
    int px = -1, py = -1, pz = -1, nx = -1, ny = -1, nz = -1, tu = -1, tv = -1;
    if (vertexElement) {
        px = findProperty(*vertexElement, {"x"}, false);
        py = findProperty(*vertexElement, {"y"}, false);
        pz = findProperty(*vertexElement, {"z"}, false);
        if (px < 0 || py < 0 || pz < 0) {
            report.error("PLY element 'vertex' has no '" +
                             std::string(px < 0 ? "x" : (py < 0 ? "y" : "z")) +
                             "' property (expected float properties x, y and z)",
                         vertexElement->line, 0);
            return false;
        }
        nx = findProperty(*vertexElement, {"nx"}, false);
        ny = findProperty(*vertexElement, {"ny"}, false);
        nz = findProperty(*vertexElement, {"nz"}, false);
        if (nx < 0 || ny < 0 || nz < 0) nx = ny = nz = -1;  // normals: all three or none
        tu = findProperty(*vertexElement, {"u", "s", "texture_u", "texture_s"}, false);
        tv = findProperty(*vertexElement, {"v", "t", "texture_v", "texture_t"}, false);
        if (tu < 0 || tv < 0) tu = tv = -1;
    }
    if (vertexCount > std::numeric_limits<uint32_t>::max()) {
        report.error("PLY file has " + std::to_string(vertexCount) +
                         " vertices (at most 4294967295 are supported)",
                     vertexElement->line, 0);
        return false;
    }

    // ---- body ----
    TriangleMesh& m = *out;
    m = TriangleMesh();
    m.positions.reserve(size_t(vertexCount));
    if (nx >= 0) m.normals.reserve(size_t(vertexCount));
    if (tu >= 0) m.uvs.reserve(size_t(vertexCount));
    // Mesh attributes (Mitsuba's "vertex_*" and "face_*"): the other scalar properties of the
    // vertex and face elements.
    const Element* faceElement = nullptr;
    for (const Element& e : elements)
        if (e.name == "face" && !faceElement) faceElement = &e;
    std::vector<AttributeGroup> vertexGroups, faceGroups;
    if (vertexElement) {
        std::vector<bool> used(vertexElement->props.size(), false);
        for (int i : {px, py, pz, nx, ny, nz, tu, tv})
            if (i >= 0) used[size_t(i)] = true;
        vertexGroups = attributeGroups(*vertexElement, used);
    }
    if (faceElement)
        faceGroups =
            attributeGroups(*faceElement, std::vector<bool>(faceElement->props.size(), false));
    auto startAttributes = [&](const std::vector<AttributeGroup>& groups, bool perFace) {
        for (const AttributeGroup& g : groups) {
            MeshAttribute a;
            a.name = (perFace ? "face_" : "vertex_") + g.prefix;
            a.perFace = perFace;
            a.channels = int(g.props.size());
            m.attributes.push_back(std::move(a));
        }
    };
    startAttributes(vertexGroups, false);
    const size_t firstFaceAttribute = m.attributes.size();
    startAttributes(faceGroups, true);
    BodyReader body(data, headerBytes, format, lineNo);
    size_t ignoredFaces = 0;
    std::vector<double> values;
    std::vector<uint32_t> polygon;
    for (const Element& e : elements) {
        const bool isVertex = &e == vertexElement;
        const bool isFace = e.name == "face";
        const int indexProp =
            isFace ? findProperty(e, {"vertex_indices", "vertex_index"}, true) : -1;
        if (isFace && indexProp < 0) {
            report.error(
                "PLY element 'face' has no list property 'vertex_indices' (expected "
                "'property list uchar int vertex_indices')",
                e.line, 0);
            return false;
        }
        values.assign(e.props.size(), 0.0);
        const bool isAttributeFace = &e == faceElement;
        for (uint64_t k = 0; k < e.count; ++k) {
            size_t faceTriangles = 0;  // triangles this face element became
            for (size_t pi = 0; pi < e.props.size(); ++pi) {
                const Property& p = e.props[pi];
                std::string bad;
                // A value that is no number of its type, or the end of the file.
                auto fail = [&](const char* what, const std::string& typeName) {
                    if (!bad.empty())
                        report.error("PLY " + std::string(what) + " '" + bad + "' of property '" +
                                         p.name + "' of '" + e.name + "' element " +
                                         std::to_string(k) + " (expected a " + typeName +
                                         (plyType(typeName) == PlyType::kF32 ||
                                                  plyType(typeName) == PlyType::kF64
                                              ? " number)"
                                              : " integer in its range)"),
                                     body.line(), body.column());
                    else
                        report.error("PLY file ends inside '" + e.name + "' element " +
                                         std::to_string(k) + " of " + std::to_string(e.count) +
                                         " (truncated or corrupt file?)",
                                     0, 0);
                    return false;
                };
                if (!p.list) {
                    double v = 0;
                    if (!body.next(p.type, &v, &bad)) return fail("value", p.typeName);
                    values[pi] = v;
                    continue;
                }
                double count = 0;
                if (!body.next(p.countType, &count, &bad))
                    return fail("list count", p.countTypeName);
                if (count < 0.0) {  // a signed count type
                    report.error("PLY list '" + p.name + "' of '" + e.name + "' element " +
                                     std::to_string(k) + " has count " +
                                     std::to_string(static_cast<long long>(count)) +
                                     " (expected a non-negative count; at " + body.where() + ")",
                                 body.line(), body.column());
                    return false;
                }
                // A list needs its entries' bytes (binary) or a character and a separator
                // each (ASCII): a count the rest of the file cannot hold is an error.
                const uint64_t n = uint64_t(count);
                const uint64_t per = format == Format::kAscii ? 2 : uint64_t(typeBytes(p.type));
                if (n > (body.remaining() + 1) / per) {
                    report.error("PLY list '" + p.name + "' of '" + e.name + "' element " +
                                     std::to_string(k) + " has " + std::to_string(n) +
                                     " entries, more than the rest of the file holds (at " +
                                     body.where() + "; truncated or corrupt file?)",
                                 body.line(), body.column());
                    return false;
                }
                const bool keep = int(pi) == indexProp;
                if (keep) polygon.clear();
                for (uint64_t j = 0; j < n; ++j) {
                    double v = 0;
                    if (!body.next(p.type, &v, &bad)) return fail("list entry", p.typeName);
                    if (!keep) continue;
                    if (!(v >= 0.0) || v >= double(vertexCount) || v != std::floor(v)) {
                        report.error("vertex index " +
                                         (v == std::floor(v) && std::fabs(v) < 1e19
                                              ? std::to_string(static_cast<long long>(v))
                                              : std::to_string(v)) +
                                         " out of range (mesh has " + std::to_string(vertexCount) +
                                         " vertices)",
                                     body.line(), body.column());
                        return false;
                    }
                    polygon.push_back(uint32_t(v));
                }
                if (!keep) continue;
                if (polygon.size() < 3) {
                    ++ignoredFaces;
                    continue;
                }
                // A polygon as a fan around its first vertex (PLY faces are convex in
                // practice; pbrt-v4 and Mitsuba triangulate them the same way).
                for (size_t j = 1; j + 1 < polygon.size(); ++j)
                    m.indices.insert(m.indices.end(), {polygon[0], polygon[j], polygon[j + 1]});
                faceTriangles = polygon.size() - 2;
            }
            // Attribute values: once per vertex, or once per triangle of the face's fan.
            auto pushAttributes = [&](const std::vector<AttributeGroup>& groups, size_t first,
                                      size_t times) {
                for (size_t gi = 0; gi < groups.size(); ++gi) {
                    std::vector<float>& dst = m.attributes[first + gi].values;
                    for (size_t rep = 0; rep < times; ++rep)
                        for (size_t c = 0; c < groups[gi].props.size(); ++c) {
                            const int pi = groups[gi].props[c];
                            dst.push_back(pi < 0 ? 0.0f
                                                 : float(values[size_t(pi)] * groups[gi].scale[c]));
                        }
                }
            };
            if (isAttributeFace) pushAttributes(faceGroups, firstFaceAttribute, faceTriangles);
            if (!isVertex) continue;
            pushAttributes(vertexGroups, 0, 1);
            m.positions.push_back(Vec3(float(values[size_t(px)]), float(values[size_t(py)]),
                                       float(values[size_t(pz)])));
            if (nx >= 0)
                m.normals.push_back(Vec3(float(values[size_t(nx)]), float(values[size_t(ny)]),
                                         float(values[size_t(nz)])));
            if (tu >= 0)
                m.uvs.push_back(Vec2(float(values[size_t(tu)]), float(values[size_t(tv)])));
        }
    }
    if (const size_t extra = body.leftover())
        report.warning(std::to_string(extra) + (format == Format::kAscii ? " values" : " bytes") +
                           " after the last element ignored",
                       0);
    if (ignoredFaces > 0)
        report.warning("ignored " + std::to_string(ignoredFaces) + " point and line primitives", 0);
    for (size_t v = 0; v < m.positions.size(); ++v)
        if (!isFinite(m.positions[v])) {
            report.error("non-finite vertex position at vertex " + std::to_string(v), 0, 0);
            return false;
        }
    if (m.indices.empty()) {
        report.error("PLY file has no triangles (expected a 'face' element)", 0, 0);
        return false;
    }
    return true;
}

}  // namespace ub
