// Albedo grids of grid media: validation and point lookups (see albedo_grid.h).
#include "scene/albedo_grid.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace ub {

namespace {

/// Voxel index of cell-space coordinate x, clamped to [lo, hi] (NaN goes to lo).
inline int nearestIndex(float x, int lo, int hi) {
    if (!(x >= float(lo))) return lo;
    if (x >= float(hi)) return hi;
    return std::min(int(std::floor(x)), hi);
}

/// Voxel index k (any integer) mapped into [lo, hi] by the wrap mode (clamp, repeat, mirror).
inline int wrapIndex(long long k, int lo, int hi, GridWrap wrap) {
    const long long n = (long long)hi - lo + 1;
    long long r = k - lo;
    switch (wrap) {
        case GridWrap::kRepeat:
            r %= n;
            if (r < 0) r += n;
            break;
        case GridWrap::kMirror:
            r %= 2 * n;
            if (r < 0) r += 2 * n;
            if (r >= n) r = 2 * n - 1 - r;
            break;
        case GridWrap::kClamp:
            r = std::clamp(r, 0LL, n - 1);
            break;
    }
    return int(lo + r);
}

/// floor(x) as an integer, for finite x of any magnitude (NaN and infinities: 0).
inline long long floorIndex(float x) {
    if (!(std::fabs(x) < 4e18f)) return 0;
    return (long long)std::floor(x);
}

inline float lerp(float a, float b, float w) {
    return a + (b - a) * w;
}

}  // namespace

std::shared_ptr<const AlbedoGrid> AlbedoGrid::make(
    std::vector<std::shared_ptr<const VdbGrid>> channels, GridFilter filter,
    const Transform& localToWorld, const int domainLo[3], const int domainHi[3],
    const std::string& label, GridWrap wrap) {
    auto fail = [&](const std::string& what) { throw InputError(label, "albedo grid: " + what); };
    if (channels.size() != 1 && channels.size() != 3)
        fail(std::to_string(channels.size()) + " channels (expected 1: grey, or 3: RGB)");
    for (const auto& c : channels)
        if (!c) fail("missing channel grid");
    auto out = std::make_shared<AlbedoGrid>();
    out->channelCount = int(channels.size());
    out->filter = filter;
    out->wrap = wrap;
    out->localToWorld = localToWorld;
    out->label = label;
    const Transform& indexToLocal = channels[0]->indexToLocal();
    nanovdb::CoordBBox bounds;
    for (size_t c = 0; c < channels.size(); ++c) {
        const VdbGrid& g = *channels[c];
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j)
                if (g.indexToLocal().m[i][j] != indexToLocal.m[i][j])
                    fail("its channel grids have different transforms");
        if (!(g.maxValue() <= 1.0f))
            fail("values up to " + std::to_string(g.maxValue()) +
                 " (an albedo must lie in [0, 1])");
        bounds.expand(g.indexBounds().min());
        bounds.expand(g.indexBounds().max());
        out->channels[c] = channels[c];
    }
    const bool given = domainLo && domainHi;
    for (int a = 0; a < 3; ++a) {
        out->domainLo[a] = given ? domainLo[a] : bounds.min()[a];
        out->domainHi[a] = given ? domainHi[a] : bounds.max()[a];
        if (out->domainLo[a] > out->domainHi[a]) fail("empty domain");
    }
    const Transform cellToWorld = localToWorld * indexToLocal * Transform::translate(Vec3(-0.5f));
    if (!(std::fabs(cellToWorld.determinant3()) > 0.0f)) fail("singular transform");
    out->worldToCell = cellToWorld.inverse();
    return out;
}

Rgb albedoGridAt(const AlbedoGrid& a, const Vec3& p) {
    const Vec3 q = a.worldToCell.point(p);
    // Per axis the two voxels to blend and the weight of the second (nearest: one voxel,
    // weight 0). Trilinear works in dual space, voxel k's centre at the integer point k.
    int k0[3], k1[3];
    float w[3];
    const bool trilinear = a.filter == GridFilter::kTrilinear;
    for (int i = 0; i < 3; ++i) {
        const int lo = a.domainLo[i], hi = a.domainHi[i];
        if (a.wrap != GridWrap::kClamp) {
            // Indices first, then wrapped (Mitsuba's texture address modes).
            const float d = trilinear ? q[i] - 0.5f : q[i];
            const long long f = floorIndex(d);
            w[i] = trilinear && std::isfinite(d) ? d - float(f) : 0.0f;
            k0[i] = wrapIndex(f, lo, hi, a.wrap);
            k1[i] = wrapIndex(f + 1, lo, hi, a.wrap);
        } else if (!trilinear) {
            k0[i] = k1[i] = nearestIndex(q[i], lo, hi);
            w[i] = 0.0f;
        } else {
            // Clamp-to-edge interpolation.
            float d = q[i] - 0.5f;
            if (!(d >= float(lo))) d = float(lo);
            if (d > float(hi)) d = float(hi);
            k0[i] = std::min(int(std::floor(d)), hi);
            k1[i] = std::min(k0[i] + 1, hi);
            w[i] = d - float(k0[i]);
        }
    }
    float v[3] = {0.0f, 0.0f, 0.0f};
    for (int c = 0; c < a.channelCount; ++c) {
        auto acc = a.channels[c]->grid().getAccessor();
        if (!trilinear) {
            v[c] = acc.getValue(nanovdb::Coord(k0[0], k0[1], k0[2]));
            continue;
        }
        auto at = [&](int x, int y, int z) {
            return acc.getValue(
                nanovdb::Coord(x ? k1[0] : k0[0], y ? k1[1] : k0[1], z ? k1[2] : k0[2]));
        };
        const float x00 = lerp(at(0, 0, 0), at(1, 0, 0), w[0]);
        const float x10 = lerp(at(0, 1, 0), at(1, 1, 0), w[0]);
        const float x01 = lerp(at(0, 0, 1), at(1, 0, 1), w[0]);
        const float x11 = lerp(at(0, 1, 1), at(1, 1, 1), w[0]);
        v[c] = lerp(lerp(x00, x10, w[1]), lerp(x01, x11, w[1]), w[2]);
    }
    if (a.channelCount == 1) return Rgb(v[0]);
    return Rgb(v[0], v[1], v[2]);
}

std::vector<std::shared_ptr<const VdbGrid>> loadVdbAlbedoChannels(const std::string& path,
                                                                  const std::string& gridName) {
    return VdbGrid::loadChannels(path, gridName, "albedo", 1.0f);
}

}  // namespace ub
