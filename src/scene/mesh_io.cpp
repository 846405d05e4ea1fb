// Mesh files: OBJ through tinyobjloader, PLY (ASCII and binary) through unibeam's own
// reader (scene/ply_reader.h, which says why).
//
// tinyobjloader reads unparsable numbers as 0 and accepts out-of-range face
// indices in triangles, so OBJ files get a light validation pass first that
// reports such problems with their line and column; only a valid file is handed
// to tinyobjloader. OBJ has one index per attribute (v/vt/vn); the result has one
// vertex per distinct (v, vt, vn) combination used by a face. Normals and uvs are
// kept only if every face corner has them.
// Vertex numbers in messages are the file's own: 1-based for OBJ, 0-based for PLY.
#include "scene/mesh_io.h"

#include <tiny_obj_loader.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <unordered_map>

#include "core/file_status.h"
#include "scene/ply_reader.h"

namespace ub {

namespace {

constexpr int kMaxErrorsPerFile = 20;

struct Reporter {
    Diagnostics& diags;
    const std::string& path;
    const std::string& where;
    int errors = 0;

    void error(const std::string& msg, int line = 0, int column = 0) {
        ++errors;
        if (errors == kMaxErrorsPerFile + 1)
            diags.error({path, 0, 0, where, "too many errors; stopped reporting"});
        if (errors > kMaxErrorsPerFile) return;
        diags.error({path, line, column, where, msg});
    }
    void warning(const std::string& msg, int line = 0) {
        diags.warning({path, line, 0, where, msg});
    }
};

std::string lowerExtension(const std::string& path) {
    size_t slash = path.find_last_of("/\\");
    size_t dot = path.find_last_of('.');
    if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
    std::string ext = path.substr(dot);
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

std::string trimmed(std::string s) {
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
    size_t b = 0;
    while (b < s.size() && std::isspace(static_cast<unsigned char>(s[b]))) ++b;
    return s.substr(b);
}

// ---- OBJ ----------------------------------------------------------------------

/// Validation pass over the OBJ text: numbers in `v` lines, face sizes and face
/// indices (with OBJ's relative negative indices). Returns false on any error.
bool validateObj(const std::string& text, Reporter& rep) {
    // First pass: totals (positive indices may refer forward, as tinyobjloader allows).
    size_t totalV = 0, totalVt = 0, totalVn = 0;
    {
        std::istringstream in(text);
        std::string line;
        while (std::getline(in, line)) {
            std::istringstream ls(line);
            std::string tok;
            ls >> tok;
            if (tok == "v")
                ++totalV;
            else if (tok == "vt")
                ++totalVt;
            else if (tok == "vn")
                ++totalVn;
        }
    }
    size_t seenV = 0, seenVt = 0, seenVn = 0;
    std::istringstream in(text);
    std::string line;
    int lineNo = 0;
    const int errorsBefore = rep.errors;
    while (std::getline(in, line)) {
        ++lineNo;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        size_t p = line.find_first_not_of(" \t");
        if (p == std::string::npos || line[p] == '#') continue;
        size_t e = line.find_first_of(" \t", p);
        std::string tok = line.substr(p, e == std::string::npos ? std::string::npos : e - p);
        if (tok == "vt") ++seenVt;
        if (tok == "vn") ++seenVn;
        if (tok == "v") {
            ++seenV;
            const char* s = line.c_str() + p + 1;
            for (int k = 0; k < 3; ++k) {
                while (*s == ' ' || *s == '\t') ++s;
                int col = int(s - line.c_str()) + 1;
                char* end = nullptr;
                errno = 0;
                double x = std::strtod(s, &end);
                bool sepOk = end != s && (*end == '\0' || *end == ' ' || *end == '\t');
                if (!sepOk) {
                    std::string word(s, std::strcspn(s, " \t"));
                    rep.error(word.empty() ? "vertex position has " + std::to_string(k) +
                                                 " coordinates (expected 3 numbers)"
                                           : "invalid number '" + word +
                                                 "' in vertex position (expected 3 numbers)",
                              lineNo, col);
                    break;
                }
                if (!std::isfinite(x)) {
                    rep.error("non-finite vertex position at vertex " + std::to_string(seenV),
                              lineNo, col);
                    break;
                }
                s = end;
            }
        } else if (tok == "f") {
            size_t q = e;
            int corners = 0;
            while (q != std::string::npos && q < line.size()) {
                q = line.find_first_not_of(" \t", q);
                if (q == std::string::npos) break;
                size_t qe = line.find_first_of(" \t", q);
                std::string corner =
                    line.substr(q, qe == std::string::npos ? std::string::npos : qe - q);
                const int col = int(q) + 1;
                ++corners;
                // v, v/vt, v//vn or v/vt/vn
                // A trailing '/' ("3/", "3/1/") is no corner: tinyobjloader would read the
                // next corner's number as its index (found by fuzz_mesh_obj: "f 3/ 2/1 3/1"
                // read texture coordinate 2 of 1, past the end of the array).
                if (corner.back() == '/') {
                    rep.error("face corner '" + corner +
                                  "' ends with '/' (expected v, v/vt, v//vn or v/vt/vn)",
                              lineNo, col);
                    q = qe;
                    continue;
                }
                const char* names[3] = {"vertex", "texture coordinate", "normal"};
                const size_t seen[3] = {seenV, seenVt, seenVn};
                const size_t total[3] = {totalV, totalVt, totalVn};
                size_t start = 0;
                for (int a = 0; a < 3 && start <= corner.size(); ++a) {
                    size_t slash = corner.find('/', start);
                    std::string field = corner.substr(
                        start, slash == std::string::npos ? std::string::npos : slash - start);
                    start = slash == std::string::npos ? corner.size() + 1 : slash + 1;
                    if (field.empty()) {
                        if (a == 0)
                            rep.error("face corner '" + corner + "' has no vertex index", lineNo,
                                      col);
                        continue;
                    }
                    char* end = nullptr;
                    long idx = std::strtol(field.c_str(), &end, 10);
                    if (*end != '\0') {
                        rep.error("invalid " + std::string(names[a]) + " index '" + field +
                                      "' in face (expected an integer)",
                                  lineNo, col);
                        continue;
                    }
                    if (idx == 0) {
                        rep.error(
                            std::string(names[a]) + " index 0 is invalid (OBJ indices start at 1)",
                            lineNo, col);
                        continue;
                    }
                    // Negative indices count back from the latest element.
                    long resolved = idx > 0 ? idx : long(seen[a]) + 1 + idx;
                    long limit = idx > 0 ? long(total[a]) : long(seen[a]);
                    if (resolved < 1 || resolved > limit)
                        rep.error(std::string(names[a]) + " index " + std::to_string(idx) +
                                      " out of range (mesh has " + std::to_string(limit) +
                                      (a == 0   ? " vertices)"
                                       : a == 1 ? " texture coordinates)"
                                                : " normals)"),
                                  lineNo, col);
                }
                q = qe;
            }
            if (corners < 3)
                rep.error("face has " + std::to_string(corners) + " vertices (expected at least 3)",
                          lineNo, int(p) + 1);
        }
        if (rep.errors > kMaxErrorsPerFile) break;
    }
    return rep.errors == errorsBefore;
}

/// Splits tinyobjloader's message text into diagnostics; "line N" becomes the line.
void reportLibraryText(const std::string& text, Reporter& rep, bool asError) {
    static const std::regex lineRe("line:? ?([0-9]+)");
    std::istringstream in(text);
    std::string msg;
    while (std::getline(in, msg)) {
        msg = trimmed(msg);
        if (msg.empty() || msg == ".") continue;
        // Materials come from the scene file: .mtl problems are irrelevant here.
        if (!asError && msg.find("aterial") != std::string::npos) continue;
        std::smatch m;
        int line = std::regex_search(msg, m, lineRe) ? std::atoi(m[1].str().c_str()) : 0;
        if (asError)
            rep.error(msg, line);
        else
            rep.warning(msg, line);
    }
}

struct CornerKey {
    int v, vt, vn;
    bool operator==(const CornerKey& o) const { return v == o.v && vt == o.vt && vn == o.vn; }
};
struct CornerHash {
    size_t operator()(const CornerKey& k) const {
        uint64_t h = uint64_t(uint32_t(k.v)) * 0x9E3779B97F4A7C15ull;
        h ^= uint64_t(uint32_t(k.vt)) * 0xC2B2AE3D27D4EB4Full + (h >> 29);
        h ^= uint64_t(uint32_t(k.vn)) * 0x165667B19E3779F9ull + (h >> 31);
        return size_t(h);
    }
};

bool loadObj(const std::string& path, const std::string& text, Reporter& rep, TriangleMesh* out) {
    if (!validateObj(text, rep)) return false;
    tinyobj::ObjReaderConfig config;
    config.triangulate = true;
    config.vertex_color = false;
    tinyobj::ObjReader reader;
    // Parse from the text already read (and validated); no .mtl is needed.
    bool ok = reader.ParseFromString(text, "", config);
    reportLibraryText(reader.Warning(), rep, false);
    if (!ok || !reader.Error().empty()) {
        if (reader.Error().empty())
            rep.error("tinyobjloader could not parse the OBJ file");
        else
            reportLibraryText(reader.Error(), rep, true);
        return false;
    }
    const tinyobj::attrib_t& attrib = reader.GetAttrib();
    bool hasNormals = true, hasUvs = true;
    size_t corners = 0;
    for (const tinyobj::shape_t& shape : reader.GetShapes()) {
        for (unsigned char n : shape.mesh.num_face_vertices)
            if (n != 3) {
                rep.error("OBJ face with " + std::to_string(int(n)) +
                          " vertices left after triangulation (expected 3)");
                return false;
            }
        for (const tinyobj::index_t& ix : shape.mesh.indices) {
            hasNormals = hasNormals && ix.normal_index >= 0;
            hasUvs = hasUvs && ix.texcoord_index >= 0;
            ++corners;
        }
    }
    if (corners == 0) {
        rep.error("OBJ file has no triangles (expected faces: 'f' lines)");
        return false;
    }
    // Every index within tinyobjloader's arrays, whatever validateObj accepted: a corner the
    // two read differently must be an error, never an out-of-bounds read.
    const size_t counts[3] = {attrib.vertices.size() / 3, attrib.texcoords.size() / 2,
                              attrib.normals.size() / 3};
    for (const tinyobj::shape_t& shape : reader.GetShapes())
        for (const tinyobj::index_t& ix : shape.mesh.indices) {
            const int idx[3] = {ix.vertex_index, hasUvs ? ix.texcoord_index : -1,
                                hasNormals ? ix.normal_index : -1};
            const char* names[3] = {"vertex", "texture coordinate", "normal"};
            for (int a = 0; a < 3; ++a)
                if ((a == 0 && idx[a] < 0) || (idx[a] >= 0 && size_t(idx[a]) >= counts[a])) {
                    rep.error("a face refers to " + std::string(names[a]) + " " +
                              std::to_string(idx[a] + 1) + " of " + std::to_string(counts[a]) +
                              " (expected indices within the file's 'v', 'vt' and 'vn' lines)");
                    return false;
                }
        }
    std::unordered_map<CornerKey, uint32_t, CornerHash> remap;
    TriangleMesh& m = *out;
    for (const tinyobj::shape_t& shape : reader.GetShapes()) {
        for (const tinyobj::index_t& ix : shape.mesh.indices) {
            CornerKey key{ix.vertex_index, hasUvs ? ix.texcoord_index : -1,
                          hasNormals ? ix.normal_index : -1};
            auto it = remap.find(key);
            if (it == remap.end()) {
                uint32_t id = uint32_t(m.positions.size());
                it = remap.emplace(key, id).first;
                const float* p = &attrib.vertices[3 * size_t(key.v)];
                m.positions.push_back(Vec3(p[0], p[1], p[2]));
                if (hasNormals) {
                    const float* n = &attrib.normals[3 * size_t(key.vn)];
                    m.normals.push_back(Vec3(n[0], n[1], n[2]));
                }
                if (hasUvs) {
                    const float* t = &attrib.texcoords[2 * size_t(key.vt)];
                    m.uvs.push_back(Vec2(t[0], t[1]));
                }
            }
            m.indices.push_back(it->second);
        }
    }
    return true;
}

// ---- PLY ----------------------------------------------------------------------

bool loadPly(const std::string& path, Reporter& rep, TriangleMesh* out) {
    PlyReport report;
    report.error = [&](const std::string& msg, int line, int column) {
        rep.error(msg, line, column);
    };
    report.warning = [&](const std::string& msg, int line) { rep.warning(msg, line); };
    return readPly(path, report, out);
}

/// Drops zero-area triangles (one warning with their count); false if none is left.
bool dropDegenerateTriangles(TriangleMesh& m, Reporter& rep, const char* kind) {
    std::vector<uint32_t> kept;
    kept.reserve(m.indices.size());
    size_t dropped = 0;
    // Per-triangle attributes keep the values of the kept triangles.
    std::vector<std::vector<float>> keptFace(m.attributes.size());
    for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
        const Vec3& p0 = m.positions[m.indices[t]];
        const Vec3& p1 = m.positions[m.indices[t + 1]];
        const Vec3& p2 = m.positions[m.indices[t + 2]];
        float area2 = length(cross(p1 - p0, p2 - p0));
        if (!(area2 > 0.0f) || !std::isfinite(area2)) {
            ++dropped;
            continue;
        }
        kept.insert(kept.end(), {m.indices[t], m.indices[t + 1], m.indices[t + 2]});
        for (size_t a = 0; a < m.attributes.size(); ++a) {
            const MeshAttribute& attr = m.attributes[a];
            if (!attr.perFace) continue;
            const size_t c = size_t(attr.channels), first = (t / 3) * c;
            keptFace[a].insert(keptFace[a].end(), attr.values.begin() + long(first),
                               attr.values.begin() + long(first + c));
        }
    }
    if (kept.empty()) {
        rep.error(std::string(kind) + " file has no triangles with non-zero area (all " +
                  std::to_string(dropped) + " are degenerate)");
        return false;
    }
    if (dropped > 0)
        rep.warning("dropped " + std::to_string(dropped) + " degenerate (zero-area) triangle" +
                    (dropped == 1 ? "" : "s"));
    m.indices = std::move(kept);
    for (size_t a = 0; a < m.attributes.size(); ++a)
        if (m.attributes[a].perFace) m.attributes[a].values = std::move(keptFace[a]);
    return true;
}

}  // namespace

TriangleMesh loadMeshFile(const std::string& path, Diagnostics& diags, const std::string& where) {
    Reporter rep{diags, path, where};
    const std::string ext = lowerExtension(path);
    if (ext != ".obj" && ext != ".ply") {
        rep.error(ext.empty()
                      ? "mesh file name has no extension (expected .obj or .ply)"
                      : "unsupported mesh file extension '" + ext + "' (expected .obj or .ply)");
        return {};
    }
    if (isDirectory(path)) {
        rep.error("cannot open mesh file (it is a directory)");
        return {};
    }
    std::ifstream file(path, std::ios::binary);
    if (!file) {
        rep.error(std::string("cannot open mesh file (") + std::strerror(errno) + ")");
        return {};
    }
    TriangleMesh mesh;
    bool ok;
    if (ext == ".obj") {
        std::ostringstream ss;
        ss << file.rdbuf();
        if (file.bad()) {
            rep.error("cannot read mesh file");
            return {};
        }
        ok = loadObj(path, ss.str(), rep, &mesh);
    } else {
        file.close();
        ok = loadPly(path, rep, &mesh);
    }
    if (!ok || !dropDegenerateTriangles(mesh, rep, ext == ".obj" ? "OBJ" : "PLY")) return {};
    return mesh;
}

}  // namespace ub
