// Screen tiles: binning of photon-beam parts (see screen_tiles.h and, for why the lists are
// complete, kernels/shared/ub_screen_tiles.h).
#include "estimators/screen_tiles.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>

#include "scene/camera.h"

namespace ub {

namespace {
std::atomic<bool> tilesAllowed{true};

/// Where a part goes: a rectangle of tiles, the list every tile reads, or nowhere.
struct Placement {
    enum Kind : uint8_t { kTiles, kEverywhere, kNone } kind = kNone;
    uint16_t x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // inclusive
};
}  // namespace

void setScreenTilesForTests(bool allowed) {
    tilesAllowed = allowed;
}
bool screenTilesAllowed() {
    return tilesAllowed;
}

void buildScreenTiles(const Camera& camera, float sceneRadius,
                      const std::vector<ub_beam_part>& parts, float r,
                      const std::function<void(size_t)>& reserve, ScreenTiles* out) {
    *out = ScreenTiles();
    out->start.assign(2, 0u);
    auto padBlock = [&] {
        ub_beam_keys4 k{};
        for (int j = 0; j < 4; ++j) k.t0[j] = k.t1[j] = INFINITY;  // rejected by the filter
        return k;
    };
    auto finishEmpty = [&] {
        out->params.enabled = 0;
        out->start.assign(2, 0u);
        out->lines.assign(1, padBlock());
        out->parts.assign(4, 0u);
    };
    const int width = camera.width(), height = camera.height();
    if (!tilesAllowed || !camera.isPinhole() || parts.empty() || width <= 0 || height <= 0 ||
        parts.size() >= (size_t(1) << 31))
        return finishEmpty();
    // About 4096 tiles (4 x 4 pixels at 256 x 256): on the bunny and mirrorballs, 4-pixel tiles
    // hold 100-200 parts a query against 150-400 for 8 pixels, and 240-340 part lines and 60-90
    // nodes for the BVH walk (docs/performance.md, session 39).
    const int tile = std::max(4, int(std::ceil(std::sqrt(double(width) * height / 4096.0))));
    ub_screen_tiles& s = out->params;
    const Vec3 eye = camera.position();
    const Vec3 axes[3] = {camera.right(), camera.up(), camera.forward()};
    for (int c = 0; c < 3; ++c) {
        s.eye[c] = eye[c];
        s.right[c] = axes[0][c];
        s.up[c] = axes[1][c];
        s.forward[c] = axes[2][c];
    }
    s.imagePlaneDist = camera.imagePlaneDist();
    s.width = float(width);
    s.height = float(height);
    s.tileSize = uint32_t(tile);
    s.tilesX = uint32_t((width + tile - 1) / tile);
    s.tilesY = uint32_t((height + tile - 1) / tile);
    if (s.tilesX > 65535 || s.tilesY > 65535) return finishEmpty();  // Placement's 16 bits
    // About a hundred times the rounding of a camera ray's points (a few ulp of their
    // coordinates): a query off the eye's lines by more walks the BVH.
    float extent = std::fabs(eye.x) + std::fabs(eye.y) + std::fabs(eye.z) + 2.0f * sceneRadius;
    s.tolerance = 1e-5f * extent;
    const size_t tileCount = size_t(s.tilesX) * s.tilesY;
    // A part covering more than a quarter of the tiles costs each tile's queries one test in
    // the common list, at one entry.
    const size_t maxRect = std::max<size_t>(1, tileCount / 4);
    const float grow = r + 2.0f * s.tolerance, margin = 1.0f / 64.0f;

    std::vector<Placement> place(parts.size());
    tbb::parallel_for(size_t(0), parts.size(), [&](size_t i) {
        const ub_beam_part& p = parts[i];
        const Vec3 o(p.origin[0], p.origin[1], p.origin[2]), d(p.dir[0], p.dir[1], p.dir[2]);
        const Vec3 a = o + d * p.t0, b = o + d * p.t1;
        Vec3 lo(std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z));
        Vec3 hi(std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z));
        lo = lo - Vec3(grow);
        hi = hi + Vec3(grow);
        int front = 0, behind = 0;
        float xlo = INFINITY, ylo = INFINITY, xhi = -INFINITY, yhi = -INFINITY;
        for (int c = 0; c < 8; ++c) {
            const Vec3 corner((c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z);
            const Vec3 v = corner - eye;
            const float depth = dot(v, axes[2]);
            if (depth > s.tolerance) {
                ++front;
                float x, y;
                ub_screen_raster(s, ub_make_float3(v.x, v.y, v.z), &x, &y);
                xlo = std::min(xlo, x);
                xhi = std::max(xhi, x);
                ylo = std::min(ylo, y);
                yhi = std::max(yhi, y);
            } else if (depth < -s.tolerance) {
                ++behind;
            }
        }
        Placement& pl = place[i];
        if (behind == 8) return;  // kNone
        if (front < 8 || !std::isfinite(xlo + xhi + ylo + yhi)) {
            pl.kind = Placement::kEverywhere;
            return;
        }
        xlo -= margin, ylo -= margin, xhi += margin, yhi += margin;
        if (xhi < 0.0f || yhi < 0.0f || xlo >= s.width || ylo >= s.height) return;  // off image
        auto tileOf = [&](float v, uint32_t n) {
            return uint16_t(std::min<float>(float(n - 1), std::max(0.0f, std::floor(v / tile))));
        };
        pl.x0 = tileOf(xlo, s.tilesX), pl.x1 = tileOf(xhi, s.tilesX);
        pl.y0 = tileOf(ylo, s.tilesY), pl.y1 = tileOf(yhi, s.tilesY);
        const size_t rect = size_t(pl.x1 - pl.x0 + 1) * size_t(pl.y1 - pl.y0 + 1);
        pl.kind = rect > maxRect ? Placement::kEverywhere : Placement::kTiles;
    });
    // The parts of each tile row, ascending, so that rows fill their tiles in parallel.
    std::vector<uint32_t> rowStart(size_t(s.tilesY) + 1, 0u), common;
    size_t entries = 0;
    for (const Placement& pl : place) {
        if (pl.kind != Placement::kTiles) continue;
        for (uint32_t y = pl.y0; y <= pl.y1; ++y) ++rowStart[y + 1];
        entries += size_t(pl.x1 - pl.x0 + 1) * size_t(pl.y1 - pl.y0 + 1);
    }
    for (uint32_t i = 0; i < uint32_t(parts.size()); ++i)
        if (place[i].kind == Placement::kEverywhere) common.push_back(i);
    entries += common.size();
    if (entries > 16 * parts.size() + 4096) return finishEmpty();  // the BVH walk's memory
    for (size_t y = 0; y < s.tilesY; ++y) rowStart[y + 1] += rowStart[y];
    std::vector<uint32_t> rowParts(rowStart.back()), rowNext(rowStart.begin(), rowStart.end() - 1);
    for (uint32_t i = 0; i < uint32_t(parts.size()); ++i) {
        const Placement& pl = place[i];
        if (pl.kind == Placement::kTiles)
            for (uint32_t y = pl.y0; y <= pl.y1; ++y) rowParts[rowNext[y]++] = i;
    }
    // Counts per list, then block ranges (each list padded to whole blocks).
    std::vector<uint32_t> count(tileCount + 1, 0u);
    count[tileCount] = uint32_t(common.size());
    tbb::parallel_for(uint32_t(0), s.tilesY, [&](uint32_t y) {
        for (uint32_t k = rowStart[y]; k < rowStart[y + 1]; ++k) {
            const Placement& pl = place[rowParts[k]];
            for (uint32_t x = pl.x0; x <= pl.x1; ++x) ++count[y * s.tilesX + x];
        }
    });
    out->start.assign(tileCount + 2, 0u);
    for (size_t k = 0; k <= tileCount; ++k) out->start[k + 1] = out->start[k] + (count[k] + 3) / 4;
    const size_t blocks = std::max<size_t>(1, out->start[tileCount + 1]);
    reserve(out->start.size() * 4 + blocks * (sizeof(ub_beam_keys4) + 16));
    out->lines.assign(blocks, padBlock());
    out->parts.assign(blocks * 4, 0u);
    // Fill in ascending part index (the kernel and the host twin read the same order); a row's
    // tiles are its own, so rows fill in parallel.
    auto put = [&](uint32_t lane, uint32_t i) {
        ub_beam_keys4_set(&out->lines[lane / 4], int(lane % 4), parts[i]);
        out->parts[lane] = i;
    };
    tbb::parallel_for(uint32_t(0), s.tilesY, [&](uint32_t y) {
        std::vector<uint32_t> next(s.tilesX);
        for (uint32_t x = 0; x < s.tilesX; ++x) next[x] = out->start[y * s.tilesX + x] * 4;
        for (uint32_t k = rowStart[y]; k < rowStart[y + 1]; ++k) {
            const uint32_t i = rowParts[k];
            const Placement& pl = place[i];
            for (uint32_t x = pl.x0; x <= pl.x1; ++x) put(next[x]++, i);
        }
    });
    for (size_t k = 0; k < common.size(); ++k)
        put(uint32_t(out->start[tileCount] * 4 + k), common[k]);
    s.enabled = 1;
}

}  // namespace ub
