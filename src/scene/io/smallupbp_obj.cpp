// SmallUPBP's .obj reading (ObjReader::readObj): v, vn, vt, f (fans of
// triangles, corners v, v/vt, v//vn or v/vt/vn), `mtllib` (the .mtl, relative to
// the .obj) and `usemtl` (faces are grouped by material, wherever they are in
// the file). It skips g, o and s; it recognises statements by their first
// letter, so other m... and u... words act as mtllib / usemtl (accepted here
// with a warning). Any other statement is an error. Unlike SmallUPBP, indices
// may also be negative (relative, as in the OBJ specification) and every index is
// checked. The file is read line by line with hand-written number parsing: the
// paper scenes have ~10^5 faces.
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include "core/file_status.h"
#include "scene/io/json_reader.h"
#include "scene/io/smallupbp_files.h"

namespace ub {

namespace {

constexpr int kMaxErrors = 20;

struct ObjLine {
    const char* begin;  ///< first character of the line
    const char* end;    ///< line end (before '\n' / "\r\n")
    int number;
};

bool isBlank(char c) {
    return c == ' ' || c == '\t' || c == '\r';
}

class ObjParser {
  public:
    ObjParser(const std::string& path, const std::string& text, UpbpObj* obj,
              std::vector<UpbpMaterial>* materials, Diagnostics& diags)
        : path_(path), text_(text), obj_(obj), materials_(materials), diags_(diags) {}

    void run();

  private:
    void error(const ObjLine& l, const char* at, const std::string& msg) {
        if (++errors_ > kMaxErrors) {
            if (errors_ == kMaxErrors + 1)
                diags_.error({path_, l.number, 0, "", "too many errors; stopped reporting"});
            return;
        }
        diags_.error({path_, l.number, int(at - l.begin) + 1, "", msg});
    }
    void warning(const ObjLine& l, const char* at, const std::string& msg) {
        diags_.warning({path_, l.number, int(at - l.begin) + 1, "", msg});
    }
    /// Reads n floats from *p; false with an error if one is missing or bad.
    bool floats(const ObjLine& l, const char** p, int n, const char* what, float* out);
    void face(const ObjLine& l, const char* p);
    void useMaterial(const ObjLine& l, const char* p, const std::string& keyword);
    void materialLibrary(const ObjLine& l, const char* p, const std::string& keyword);
    static std::string word(const char* p, const char* end, const char** after);

    const std::string& path_;
    const std::string& text_;
    UpbpObj* obj_;
    std::vector<UpbpMaterial>* materials_;
    Diagnostics& diags_;
    int errors_ = 0;
    size_t totalV_ = 0, totalVt_ = 0, totalVn_ = 0;
    size_t seenVt_ = 0;
    int group_ = -1;            ///< current group (index into obj_->groups)
    std::vector<int> groupOf_;  ///< material -> group
    bool warnedNoMaterial_ = false, warnedLines_ = false, warnedVp_ = false;
};

std::string ObjParser::word(const char* p, const char* end, const char** after) {
    while (p < end && isBlank(*p)) ++p;
    const char* s = p;
    while (p < end && !isBlank(*p)) ++p;
    if (after) *after = p;
    return std::string(s, p);
}

bool ObjParser::floats(const ObjLine& l, const char** p, int n, const char* what, float* out) {
    const char* s = *p;
    for (int i = 0; i < n; ++i) {
        while (s < l.end && isBlank(*s)) ++s;
        if (s >= l.end) {
            error(l, s,
                  std::string("missing value: '") + what + "' expects " + std::to_string(n) +
                      " numbers, found " + std::to_string(i));
            return false;
        }
        char* e = nullptr;
        const float v = std::strtof(s, &e);
        if (e == s || (e < l.end && !isBlank(*e)) || !std::isfinite(v)) {
            const char* we = s;
            while (we < l.end && !isBlank(*we)) ++we;
            error(l, s,
                  "'" + std::string(s, we) + "' is not a finite number ('" + what + "' expects " +
                      std::to_string(n) + " numbers)");
            return false;
        }
        out[i] = v;
        s = e;
    }
    *p = s;
    return true;
}

void ObjParser::useMaterial(const ObjLine& l, const char* p, const std::string& keyword) {
    const char* after = nullptr;
    const std::string name = word(p, l.end, &after);
    if (name.empty()) {
        error(l, p, "missing value: '" + keyword + "' expects a material name");
        group_ = -1;
        return;
    }
    int mat = -1;
    for (size_t i = 0; i < materials_->size(); ++i)
        if ((*materials_)[i].name == name) {
            mat = int(i);
            break;
        }
    if (mat < 0) {
        std::vector<std::string> names;
        for (const UpbpMaterial& m : *materials_) names.push_back(m.name);
        error(l, after - name.size(),
              "unknown material '" + name + "'" + didYouMean(name, names) +
                  (names.empty() ? std::string(" (no material library was read: expected "
                                               "'mtllib FILE.mtl' before 'usemtl')")
                                 : " (the .mtl defines: " + joinNames(names) + ")"));
        group_ = -1;
        return;
    }
    if (groupOf_.size() < materials_->size()) groupOf_.resize(materials_->size(), -1);
    if (groupOf_[size_t(mat)] < 0) {
        groupOf_[size_t(mat)] = int(obj_->groups.size());
        UpbpGroup g;
        g.material = mat;
        g.firstUse = {l.number, int(p - l.begin) + 1};
        obj_->groups.push_back(std::move(g));
    }
    group_ = groupOf_[size_t(mat)];
}

void ObjParser::materialLibrary(const ObjLine& l, const char* p, const std::string& keyword) {
    const char* after = nullptr;
    const std::string name = word(p, l.end, &after);
    if (name.empty()) {
        error(l, p, "missing value: '" + keyword + "' expects a .mtl file name");
        return;
    }
    namespace fs = std::filesystem;
    const std::string mtlPath = (fs::path(path_).parent_path() / name).string();
    if (!isRegularFile(mtlPath)) {
        error(l, after - name.size(),
              "material library '" + name + "' not found (looked for '" + mtlPath +
                  "'; SmallUPBP reads it from the folder of the .obj)");
        return;
    }
    obj_->mtlFiles.push_back(mtlPath);
    readUpbpMtl(mtlPath, materials_, diags_);
}

void ObjParser::face(const ObjLine& l, const char* p) {
    int32_t v[3], vn[3];
    int corners = 0;
    bool bad = false;
    while (true) {
        while (p < l.end && isBlank(*p)) ++p;
        if (p >= l.end) break;
        const char* c = p;
        while (p < l.end && !isBlank(*p)) ++p;
        // Fields v[/vt[/vn]]: parse each as an integer (empty allowed for vt and vn).
        long idx[3] = {0, 0, 0};
        bool has[3] = {false, false, false};
        const char* f = c;
        for (int a = 0; a < 3 && f <= p; ++a) {
            const char* fe = f;
            while (fe < p && *fe != '/') ++fe;
            if (fe > f) {
                char* e = nullptr;
                idx[a] = std::strtol(f, &e, 10);
                if (e != fe) {
                    error(l, c,
                          "invalid face corner '" + std::string(c, p) +
                              "' (expected v, v/vt, v//vn or v/vt/vn with integers)");
                    return;
                }
                has[a] = true;
            }
            f = fe + 1;
            if (fe >= p) break;
        }
        if (!has[0]) {
            error(l, c, "face corner '" + std::string(c, p) + "' has no vertex index");
            return;
        }
        const size_t seen[3] = {obj_->positions.size(), seenVt_, obj_->normals.size()};
        const size_t total[3] = {totalV_, totalVt_, totalVn_};
        const char* names[3] = {"vertex", "texture coordinate", "normal"};
        const char* plural[3] = {"vertices", "texture coordinates", "normals"};
        long resolved[3] = {-1, -1, -1};
        for (int a = 0; a < 3; ++a) {
            if (!has[a]) continue;
            if (idx[a] == 0) {
                error(l, c, std::string(names[a]) + " index 0 is invalid (OBJ indices start at 1)");
                bad = true;
                continue;
            }
            const long r = idx[a] > 0 ? idx[a] - 1 : long(seen[a]) + idx[a];
            const long limit = idx[a] > 0 ? long(total[a]) : long(seen[a]);
            if (r < 0 || r >= limit) {
                error(l, c,
                      std::string(names[a]) + " index " + std::to_string(idx[a]) +
                          " out of range (the file has " + std::to_string(limit) + " " + plural[a] +
                          ")");
                bad = true;
                continue;
            }
            resolved[a] = r;
        }
        if (bad) return;
        const int32_t cv = int32_t(resolved[0]), cn = has[2] ? int32_t(resolved[2]) : -1;
        if (corners < 3) {
            v[corners] = cv;
            vn[corners] = cn;
        } else {
            // Fan: (v0, previous, this), as SmallUPBP triangulates.
            v[1] = v[2];
            vn[1] = vn[2];
            v[2] = cv;
            vn[2] = cn;
        }
        ++corners;
        if (corners >= 3 && group_ >= 0) {
            UpbpGroup& g = obj_->groups[size_t(group_)];
            g.v.insert(g.v.end(), v, v + 3);
            g.vn.insert(g.vn.end(), vn, vn + 3);
        }
    }
    if (corners < 3) {
        error(l, l.begin, "face has " + std::to_string(corners) + " corners (expected at least 3)");
        return;
    }
    if (group_ < 0 && !warnedNoMaterial_) {
        warnedNoMaterial_ = true;
        error(l, l.begin,
              "face without a material (expected 'usemtl NAME' before the faces: SmallUPBP "
              "gives such faces no material)");
    }
}

void ObjParser::run() {
    // Pre-pass: counts, so positive indices may refer forward (as in SmallUPBP).
    const char* s = text_.c_str();
    const char* end = s + text_.size();
    for (const char* p = s; p < end;) {
        while (p < end && isBlank(*p)) ++p;
        if (p + 1 < end && p[0] == 'v') {
            if (isBlank(p[1]))
                ++totalV_;
            else if (p[1] == 'n' && p + 2 < end && isBlank(p[2]))
                ++totalVn_;
            else if (p[1] == 't' && p + 2 < end && isBlank(p[2]))
                ++totalVt_;
        }
        const void* nl = std::memchr(p, '\n', size_t(end - p));
        p = nl ? static_cast<const char*>(nl) + 1 : end;
    }
    obj_->positions.reserve(totalV_);
    obj_->normals.reserve(totalVn_);

    int number = 0;
    for (const char* p = s; p < end;) {
        const void* nl = std::memchr(p, '\n', size_t(end - p));
        const char* le = nl ? static_cast<const char*>(nl) : end;
        ObjLine l{p, le, ++number};
        const char* next = nl ? le + 1 : end;
        const char* after = nullptr;
        const std::string k = word(p, le, &after);
        p = next;
        if (k.empty() || k[0] == '#') continue;
        float x[3];
        const char* q = after;
        switch (k[0]) {
            case 'v':
                if (k == "v") {
                    if (floats(l, &q, 3, "v", x))
                        obj_->positions.push_back(Vec3(x[0], x[1], x[2]));
                    else
                        obj_->positions.push_back(Vec3(0.0f));  // keep later indices aligned
                } else if (k == "vn") {
                    if (floats(l, &q, 3, "vn", x))
                        obj_->normals.push_back(Vec3(x[0], x[1], x[2]));
                    else
                        obj_->normals.push_back(Vec3(0.0f, 0.0f, 1.0f));
                } else if (k == "vt") {
                    ++seenVt_;
                    floats(l, &q, 2, "vt", x);
                } else if (!warnedVp_) {
                    warnedVp_ = true;
                    warning(l, l.begin, "'" + k + "' ignored (SmallUPBP reads only v, vn and vt)");
                }
                break;
            case 'm':
                if (k != "mtllib")
                    warning(l, after - k.size(),
                            "'" + k + "' read as 'mtllib' (as SmallUPBP does)");
                materialLibrary(l, after, k);
                break;
            case 'u':
                if (k != "usemtl")
                    warning(l, after - k.size(),
                            "'" + k + "' read as 'usemtl' (as SmallUPBP does)");
                useMaterial(l, after, k);
                break;
            case 'f':
                if (k != "f")
                    warning(l, after - k.size(), "'" + k + "' read as 'f' (as SmallUPBP does)");
                face(l, after);
                break;
            default:
                if (k == "g" || k == "o" || k == "s") break;  // grouping, smoothing: unused
                if (k == "l" || k == "p") {
                    if (!warnedLines_)
                        warning(l, after - k.size(),
                                "'" + k + "' (lines and points) ignored: only faces are rendered");
                    warnedLines_ = true;
                    break;
                }
                error(l, after - k.size(),
                      "unknown .obj statement '" + k +
                          "' (SmallUPBP reads v, vn, vt, f, mtllib and usemtl and skips g, o, s)");
        }
    }
    if (obj_->mtlFiles.empty() && errors_ == 0)
        diags_.error({path_, 0, 0, "",
                      "no 'mtllib' statement: a SmallUPBP scene takes its materials from the "
                      ".mtl file the .obj names"});
}

}  // namespace

void readUpbpObj(const std::string& path, UpbpObj* obj, std::vector<UpbpMaterial>* materials,
                 Diagnostics& diags) {
    std::string text;
    if (!readUpbpTextFile(path, "OBJ file", &text, diags)) return;
    ObjParser p(path, text, obj, materials, diags);
    p.run();
}

}  // namespace ub
