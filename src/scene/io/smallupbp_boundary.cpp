#include "scene/io/smallupbp_boundary.h"

#include <cstring>
#include <numeric>
#include <unordered_map>

namespace ub {

namespace {

struct UnionFind {
    std::vector<uint32_t> parent;
    explicit UnionFind(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
    uint32_t find(uint32_t x) {
        while (parent[x] != x) x = parent[x] = parent[parent[x]];
        return x;
    }
    void unite(uint32_t a, uint32_t b) { parent[find(a)] = find(b); }
};

struct PosKey {
    uint32_t b[3];
    bool operator==(const PosKey& o) const {
        return b[0] == o.b[0] && b[1] == o.b[1] && b[2] == o.b[2];
    }
};
struct PosKeyHash {
    size_t operator()(const PosKey& k) const {
        uint64_t h = uint64_t(k.b[0]) * 0x9E3779B97F4A7C15ull;
        h ^= uint64_t(k.b[1]) * 0xC2B2AE3D27D4EB4Full + (h >> 29);
        h ^= uint64_t(k.b[2]) * 0x165667B19E3779F9ull + (h >> 31);
        return size_t(h);
    }
};

uint64_t edgeKey(uint32_t a, uint32_t b) {
    return (uint64_t(a) << 32) | b;
}

bool contains(const Bounds3& outer, const Bounds3& inner) {
    return outer.lo.x <= inner.lo.x && outer.lo.y <= inner.lo.y && outer.lo.z <= inner.lo.z &&
           inner.hi.x <= outer.hi.x && inner.hi.y <= outer.hi.y && inner.hi.z <= outer.hi.z;
}

}  // namespace

BoundarySplit splitMediumBoundary(const TriangleMesh& in) {
    BoundarySplit out;
    // Working copy: fans add one vertex per hole.
    std::vector<Vec3> positions = in.positions;
    std::vector<Vec3> normals = in.normals;
    std::vector<Vec2> uvs = in.uvs;
    std::vector<uint32_t> indices = in.indices;
    const size_t inputTriangles = indices.size() / 3;

    // Weld vertices by exact position (what Scene::mediumIssues does).
    std::unordered_map<PosKey, uint32_t, PosKeyHash> weldMap;
    std::vector<uint32_t> weld(positions.size());
    for (size_t i = 0; i < positions.size(); ++i) {
        PosKey k;
        std::memcpy(k.b, &positions[i].x, 12);
        weld[i] = weldMap.emplace(k, uint32_t(weldMap.size())).first->second;
    }
    const size_t welded = weldMap.size();

    // Connected pieces.
    UnionFind pieceOf(welded);
    for (size_t t = 0; t < inputTriangles; ++t) {
        pieceOf.unite(weld[indices[3 * t]], weld[indices[3 * t + 1]]);
        pieceOf.unite(weld[indices[3 * t]], weld[indices[3 * t + 2]]);
    }

    // Boundary edges: a directed edge whose reverse no triangle has.
    std::unordered_map<uint64_t, int> directed;
    directed.reserve(indices.size());
    for (size_t t = 0; t < inputTriangles; ++t)
        for (int e = 0; e < 3; ++e)
            ++directed[edgeKey(weld[indices[3 * t + e]], weld[indices[3 * t + (e + 1) % 3]])];
    struct Edge {
        uint32_t a, b;  ///< mesh vertex indices, a -> b as in the triangle
    };
    std::vector<Edge> boundary;
    for (size_t t = 0; t < inputTriangles; ++t)
        for (int e = 0; e < 3; ++e) {
            const uint32_t a = indices[3 * t + e], b = indices[3 * t + (e + 1) % 3];
            const uint64_t key = edgeKey(weld[a], weld[b]);
            if (directed[key] == 1 && directed.find(edgeKey(weld[b], weld[a])) == directed.end())
                boundary.push_back({a, b});
        }

    // Holes: boundary edges connected through their (welded) vertices; a fan around
    // each hole's centroid, triangle (b, a, centroid) per boundary edge a -> b, pairs
    // every edge with an opposite one.
    if (!boundary.empty()) {
        UnionFind loopOf(welded);
        for (const Edge& e : boundary) loopOf.unite(weld[e.a], weld[e.b]);
        std::unordered_map<uint32_t, uint32_t> centre;  // loop root -> new vertex
        std::unordered_map<uint32_t, std::pair<Vec3, int>> sum;
        std::vector<char> counted(welded, 0);
        for (const Edge& e : boundary)
            for (uint32_t v : {e.a, e.b}) {
                if (counted[weld[v]]) continue;
                counted[weld[v]] = 1;
                auto& s = sum[loopOf.find(weld[v])];
                s.first += positions[v];
                ++s.second;
            }
        for (const auto& [root, s] : sum) {
            centre[root] = uint32_t(positions.size());
            positions.push_back(s.first / float(s.second));
            if (!normals.empty()) normals.push_back(Vec3(0.0f));
            if (!uvs.empty()) uvs.push_back(Vec2(0.0f, 0.0f));
        }
        for (const Edge& e : boundary) {
            const uint32_t c = centre[loopOf.find(weld[e.a])];
            indices.insert(indices.end(), {e.b, e.a, c});
            if (!normals.empty())
                normals[c] += cross(positions[e.a] - positions[e.b], positions[c] - positions[e.b]);
        }
        if (!normals.empty())
            for (const auto& [root, c] : centre) {
                (void)root;
                const float l = length(normals[c]);
                normals[c] = l > 0.0f ? normals[c] / l : Vec3(0.0f, 0.0f, 1.0f);
            }
        out.holes = sum.size();
        out.holeEdges = boundary.size();
    }

    // Triangles per piece (fans belong to the piece of their boundary edge).
    const size_t triangles = indices.size() / 3;
    std::unordered_map<uint32_t, int> pieceIndex;
    std::vector<std::vector<uint32_t>> pieceTris;
    for (size_t t = 0; t < triangles; ++t) {
        const uint32_t root = pieceOf.find(weld[indices[3 * t]]);
        auto it = pieceIndex.emplace(root, int(pieceTris.size())).first;
        if (size_t(it->second) == pieceTris.size()) pieceTris.emplace_back();
        pieceTris[size_t(it->second)].push_back(uint32_t(t));
    }

    // Signed volume (divergence theorem) and bounds of each piece.
    const size_t n = pieceTris.size();
    std::vector<double> volume(n, 0.0);
    std::vector<Bounds3> bounds(n);
    for (size_t p = 0; p < n; ++p)
        for (uint32_t t : pieceTris[p]) {
            const Vec3 a = positions[indices[3 * t]], b = positions[indices[3 * t + 1]],
                       c = positions[indices[3 * t + 2]];
            volume[p] += double(dot(a, cross(b, c))) / 6.0;
            bounds[p].extend(a);
            bounds[p].extend(b);
            bounds[p].extend(c);
        }
    // Cavities join the smallest outward piece whose bounds contain them.
    std::vector<int> owner(n);
    for (size_t p = 0; p < n; ++p) {
        owner[p] = int(p);
        if (volume[p] >= 0.0) continue;
        int best = -1;
        for (size_t q = 0; q < n; ++q)
            if (volume[q] > 0.0 && contains(bounds[q], bounds[p]) &&
                (best < 0 || volume[q] < volume[size_t(best)]))
                best = int(q);
        if (best >= 0) {
            owner[p] = best;
            ++out.cavities;
        } else {
            ++out.insideOut;
        }
    }
    for (size_t p = 0; p < n; ++p) {
        if (owner[p] != int(p)) continue;
        TriangleMesh m;
        std::unordered_map<uint32_t, uint32_t> remap;
        auto addTriangles = [&](const std::vector<uint32_t>& tris) {
            for (uint32_t t : tris)
                for (int k = 0; k < 3; ++k) {
                    const uint32_t v = indices[3 * t + k];
                    auto it = remap.find(v);
                    if (it == remap.end()) {
                        it = remap.emplace(v, uint32_t(m.positions.size())).first;
                        m.positions.push_back(positions[v]);
                        if (!normals.empty()) m.normals.push_back(normals[v]);
                        if (!uvs.empty()) m.uvs.push_back(uvs[v]);
                    }
                    m.indices.push_back(it->second);
                }
        };
        addTriangles(pieceTris[p]);
        for (size_t q = 0; q < n; ++q)
            if (q != p && owner[q] == int(p)) addTriangles(pieceTris[q]);
        out.pieces.push_back(std::move(m));
    }
    return out;
}

}  // namespace ub
