// Mesh files: OBJ through tinyobjloader, PLY (ASCII and binary) through Assimp.
//
// tinyobjloader reads unparsable numbers as 0 and accepts out-of-range face
// indices in triangles, so OBJ files get a light validation pass first that
// reports such problems with their line and column; only a valid file is handed
// to tinyobjloader. OBJ has one index per attribute (v/vt/vn); the result has one
// vertex per distinct (v, vt, vn) combination used by a face. Normals and uvs are
// kept only if every face corner has them. Assimp reports PLY errors without
// positions; its output is checked for non-finite positions and bad indices here.
// Vertex numbers in messages are the file's own: 1-based for OBJ, 0-based for PLY.
#include "scene/mesh_io.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <tiny_obj_loader.h>

#include <algorithm>
#include <assimp/Importer.hpp>
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

/// Checks the element counts of a PLY header against the file size before Assimp sees the
/// file: Assimp reserves memory for every announced element first, so a corrupt or hostile
/// count (`element vertex 4000000000`) would end in an allocation failure rather than a
/// message. Each element needs at least its scalar properties' bytes (binary; a list at least
/// its count) or two characters per property (ASCII: a digit and a separator). Anything else
/// in the header is left to Assimp. Returns false (with an error) on a count the file cannot
/// hold.
bool checkPlyCounts(const std::string& path, Reporter& rep) {
    std::ifstream in(path, std::ios::binary);
    std::error_code ec;
    const uintmax_t fileBytes = std::filesystem::file_size(path, ec);
    if (!in || ec) return true;  // Assimp reports unreadable files
    auto scalarBytes = [](const std::string& t) -> int {
        if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
        if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
        if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" ||
            t == "float32")
            return 4;
        if (t == "double" || t == "float64") return 8;
        return 0;
    };
    struct Element {
        std::string name;
        unsigned long long count = 0;
        int line = 0;
        uintmax_t minBytes = 0;  // per element
    };
    std::vector<Element> elements;
    bool ascii = false;
    std::string line;
    int lineNo = 0;
    uintmax_t headerBytes = 0;
    bool ended = false;
    while (lineNo < 10000 && std::getline(in, line)) {
        ++lineNo;
        headerBytes += line.size() + 1;
        // Control characters other than tab (and a final CR): the stream reads \v or \f as a
        // separator, Assimp does not, and it then looks for end_header for ever (found by
        // fuzz_mesh_ply: "end_header\v0 0 0 ..." hung).
        // (Not on the first line: Assimp reports a file without the magic itself.)
        for (size_t i = 0; lineNo > 1 && i < line.size(); ++i) {
            const unsigned char c = static_cast<unsigned char>(line[i]);
            if (c < 0x20 && c != '\t' && !(c == '\r' && i + 1 == line.size())) {
                char hex[8];
                std::snprintf(hex, sizeof(hex), "0x%02x", unsigned(c));
                rep.error(std::string("PLY header line has control character ") + hex +
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
        // Every header line must be one of PLY's: Assimp 5.2 crashes on some it cannot read
        // (found by fuzz_mesh_ply: "format binary_comment" and a "propert|" line, SEGV).
        if (kw == "format") {
            std::string f;
            ls >> f;
            ascii = f == "ascii";
            if (f != "ascii" && f != "binary_little_endian" && f != "binary_big_endian") {
                rep.error("PLY format '" + f +
                              "' (expected ascii, binary_little_endian or binary_big_endian)",
                          lineNo);
                return false;
            }
        } else if (lineNo > 1 && !kw.empty() && kw != "element" && kw != "property" &&
                   kw != "comment" && kw != "obj_info") {
            rep.error("unknown PLY header line '" + line.substr(0, 40) +
                          "' (expected format, element, property, comment, obj_info or "
                          "end_header)",
                      lineNo);
            return false;
        }
        if (kw == "element") {
            Element e;
            std::string count;
            ls >> e.name >> count;
            e.line = lineNo;
            const bool digits = !count.empty() && count.size() <= 19 &&
                                count.find_first_not_of("0123456789") == std::string::npos;
            if (!digits) {
                rep.error("PLY element '" + e.name + "' has count '" + count +
                              "' (expected a non-negative integer)",
                          lineNo);
                return false;
            }
            e.count = std::stoull(count);
            elements.push_back(e);
        } else if (kw == "property" && !elements.empty()) {
            std::string type;
            ls >> type;
            {
                std::istringstream check(line);
                std::string k, t1, t2, t3, name;
                check >> k >> t1;
                const bool ok = t1 == "list" ? bool(check >> t2 >> t3 >> name) &&
                                                   scalarBytes(t2) > 0 && scalarBytes(t3) > 0
                                             : scalarBytes(t1) > 0 && bool(check >> name);
                if (!ok) {
                    rep.error("PLY property line '" + line.substr(0, 60) +
                                  "' (expected 'property TYPE NAME' or 'property list "
                                  "COUNT_TYPE INDEX_TYPE NAME' with PLY's scalar types)",
                              lineNo);
                    return false;
                }
            }
            if (ascii) {
                elements.back().minBytes += 2;
            } else if (type == "list") {
                std::string countType;
                ls >> countType;
                elements.back().minBytes += uintmax_t(scalarBytes(countType));
            } else {
                elements.back().minBytes += uintmax_t(scalarBytes(type));
            }
        }
    }
    if (!ended) {
        // Without the magic Assimp reports the file as no PLY at all. With it, Assimp 5.2
        // looks for end_header for ever (found by fuzz_mesh_ply: a 79-byte file hung).
        in.clear();
        in.seekg(0);
        std::string first;
        std::getline(in, first);
        // Assimp takes any file starting with these three letters, in any case, for a PLY
        // (found by fuzz_mesh_ply: "ply" then NUL bytes, and "plY", hung as well).
        const bool magic = first.size() >= 3 && std::tolower((unsigned char)first[0]) == 'p' &&
                           std::tolower((unsigned char)first[1]) == 'l' &&
                           std::tolower((unsigned char)first[2]) == 'y';
        if (!magic) return true;
        rep.error("PLY header has no 'end_header' line" +
                      std::string(lineNo >= 10000 ? " in its first 10000 lines" : "") +
                      " (expected the element and property lines to end with 'end_header'; "
                      "truncated or corrupt file?)",
                  lineNo);
        return false;
    }
    const uintmax_t available = fileBytes > headerBytes ? fileBytes - headerBytes : 0;
    uintmax_t needed = 0;
    for (const Element& e : elements) {
        const uintmax_t per = std::max<uintmax_t>(1, e.minBytes);
        // Compared by division so that count * per cannot overflow.
        if (e.count > (available - std::min(needed, available)) / per) {
            rep.error("PLY header announces " + std::to_string(e.count) + " '" + e.name +
                          "' elements (at least " + std::to_string(per) +
                          " bytes each), but the file has only " + std::to_string(available) +
                          " bytes after the header (truncated or corrupt file?)",
                      e.line);
            return false;
        }
        needed += e.count * per;
    }
    return true;
}

bool loadPly(const std::string& path, Reporter& rep, TriangleMesh* out) {
    if (!checkPlyCounts(path, rep)) return false;
    Assimp::Importer importer;
    // Read without post-processing, check the face indices ourselves (Assimp's own
    // validation names no index values), then validate and triangulate; no vertex
    // joining or any other step that changes topology.
    const aiScene* scene = importer.ReadFile(path, 0);
    if (!scene) {
        std::string why = trimmed(importer.GetErrorString());
        rep.error("cannot read PLY file" + (why.empty() ? std::string() : ": " + why));
        return false;
    }
    size_t faceCount = 0;
    for (unsigned i = 0; i < scene->mNumMeshes; ++i) {
        const aiMesh* mesh = scene->mMeshes[i];
        faceCount += mesh->mNumFaces;
        for (unsigned f = 0; f < mesh->mNumFaces; ++f)
            for (unsigned k = 0; k < mesh->mFaces[f].mNumIndices; ++k)
                if (mesh->mFaces[f].mIndices[k] >= mesh->mNumVertices) {
                    rep.error("vertex index " + std::to_string(mesh->mFaces[f].mIndices[k]) +
                              " out of range (mesh has " + std::to_string(mesh->mNumVertices) +
                              " vertices)");
                    return false;
                }
    }
    if (faceCount == 0) {
        rep.error("PLY file has no triangles (expected a 'face' element)");
        return false;
    }
    scene = importer.ApplyPostProcessing(aiProcess_ValidateDataStructure | aiProcess_Triangulate);
    if (!scene) {
        std::string why = trimmed(importer.GetErrorString());
        rep.error("cannot read PLY file" + (why.empty() ? std::string() : ": " + why));
        return false;
    }
    TriangleMesh& m = *out;
    size_t ignored = 0;
    bool hasNormals = true, hasUvs = true;
    for (unsigned i = 0; i < scene->mNumMeshes; ++i) {
        hasNormals = hasNormals && scene->mMeshes[i]->HasNormals();
        hasUvs = hasUvs && scene->mMeshes[i]->HasTextureCoords(0);
    }
    for (unsigned i = 0; i < scene->mNumMeshes; ++i) {
        const aiMesh* mesh = scene->mMeshes[i];
        const uint32_t base = uint32_t(m.positions.size());
        for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
            const aiVector3D& p = mesh->mVertices[v];
            m.positions.push_back(Vec3(p.x, p.y, p.z));
            if (hasNormals) {
                const aiVector3D& n = mesh->mNormals[v];
                m.normals.push_back(Vec3(n.x, n.y, n.z));
            }
            if (hasUvs) {
                const aiVector3D& t = mesh->mTextureCoords[0][v];
                m.uvs.push_back(Vec2(t.x, t.y));
            }
        }
        for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
            const aiFace& face = mesh->mFaces[f];
            if (face.mNumIndices != 3) {
                ++ignored;
                continue;
            }
            for (int k = 0; k < 3; ++k) {
                if (face.mIndices[k] >= mesh->mNumVertices) {
                    rep.error("vertex index " + std::to_string(face.mIndices[k]) +
                              " out of range (mesh has " + std::to_string(mesh->mNumVertices) +
                              " vertices)");
                    return false;
                }
                m.indices.push_back(base + face.mIndices[k]);
            }
        }
    }
    if (ignored > 0)
        rep.warning("ignored " + std::to_string(ignored) + " point and line primitives");
    for (size_t v = 0; v < m.positions.size(); ++v)
        if (!isFinite(m.positions[v])) {
            rep.error("non-finite vertex position at vertex " + std::to_string(v));
            return false;
        }
    if (m.indices.empty()) {
        rep.error("PLY file has no triangles (expected a 'face' element)");
        return false;
    }
    return true;
}

/// Drops zero-area triangles (one warning with their count); false if none is left.
bool dropDegenerateTriangles(TriangleMesh& m, Reporter& rep, const char* kind) {
    std::vector<uint32_t> kept;
    kept.reserve(m.indices.size());
    size_t dropped = 0;
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
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) {
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
