// Screen tiles: binning of photon-beam parts (see screen_tiles.h and, for why the lists are
// complete, kernels/shared/ub_screen_tiles.h).
#include "estimators/screen_tiles.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>

#include "core/vec.h"
#include "scene/camera.h"

namespace ub {

namespace {
std::atomic<bool> tilesAllowed{true};

/// Where a part goes: rows y0 .. y1 of tiles (each row's span from the corners), the list
/// every tile reads, or nowhere.
struct Placement {
    enum Kind : uint8_t { kTiles, kEverywhere, kNone } kind = kNone;
    uint32_t y0 = 0, y1 = 0;
    uint8_t n = 8;     ///< corners, then (makeHull) the hull's vertices
    float x[8], y[8];  ///< raster positions of the box's corners
};

/// Replaces the 8 corners of p by their convex hull, counter-clockwise in (x, y) (Andrew's
/// monotone chain; a hull of the projected box has 4 to 6 vertices).
void makeHull(Placement* p) {
    int order[8] = {0, 1, 2, 3, 4, 5, 6, 7};
    std::sort(order, order + 8, [&](int i, int j) {
        return p->x[i] < p->x[j] || (p->x[i] == p->x[j] && p->y[i] < p->y[j]);
    });
    auto cross = [&](int o, int a, int b) {
        return (p->x[a] - p->x[o]) * (p->y[b] - p->y[o]) -
               (p->y[a] - p->y[o]) * (p->x[b] - p->x[o]);
    };
    int hull[16], n = 0;
    for (int k = 0; k < 8; ++k) {  // lower hull
        while (n >= 2 && cross(hull[n - 2], hull[n - 1], order[k]) <= 0.0f) --n;
        hull[n++] = order[k];
    }
    for (int k = 6, lower = n + 1; k >= 0; --k) {  // upper hull
        while (n >= lower && cross(hull[n - 2], hull[n - 1], order[k]) <= 0.0f) --n;
        hull[n++] = order[k];
    }
    --n;  // the last point is the first
    float x[8], y[8];
    for (int k = 0; k < n; ++k) {
        x[k] = p->x[hull[k]];
        y[k] = p->y[hull[k]];
    }
    for (int k = 0; k < n; ++k) {
        p->x[k] = x[k];
        p->y[k] = y[k];
    }
    p->n = uint8_t(std::max(n, 1));
}

/// The raster x range of p's hull within the band y in [lo, hi]: its vertices in the band and
/// its edges' crossings of the band's two lines (empty, lo > hi, where it misses the band).
/// The hull is computed in float: a corner it drops as collinear lies on an edge it keeps, up
/// to rounding far below the margin the callers add.
void hullSpan(const Placement& p, float lo, float hi, float* xlo, float* xhi) {
    float a = INFINITY, b = -INFINITY;
    for (int i = 0; i < p.n; ++i) {
        const int j = i + 1 == p.n ? 0 : i + 1;
        if (p.y[i] >= lo && p.y[i] <= hi) {
            a = std::min(a, p.x[i]);
            b = std::max(b, p.x[i]);
        }
        for (float line : {lo, hi})
            if ((p.y[i] - line) * (p.y[j] - line) < 0.0f) {
                const float x = p.x[i] + (line - p.y[i]) * (p.x[j] - p.x[i]) / (p.y[j] - p.y[i]);
                a = std::min(a, x);
                b = std::max(b, x);
            }
    }
    *xlo = a;
    *xhi = b;
}
}  // namespace

void setScreenTilesForTests(bool allowed) {
    tilesAllowed = allowed;
}
bool screenTilesAllowed() {
    return tilesAllowed;
}

namespace {
/// About a hundred times the rounding of a camera ray's points (a few ulp of their
/// coordinates): a query off the eye's lines by more walks the BVH.
float screenTolerance(const Camera& camera, float sceneRadius) {
    const Vec3 eye = camera.position();
    return 1e-5f * (std::fabs(eye.x) + std::fabs(eye.y) + std::fabs(eye.z) + 2.0f * sceneRadius);
}

/// The lists of n items whose boxes' corners corners(i, grow, out) gives (a box holding every
/// point within grow of item i); out gets params, start and items (kNoItem in unused lanes).
void buildLists(const Camera& camera, float sceneRadius, size_t n, float r,
                const std::function<void(size_t, float, Vec3*)>& corners,
                const std::function<void(size_t)>& reserve, ScreenTiles* out) {
    *out = ScreenTiles();
    auto finishEmpty = [&] {
        out->params.enabled = 0;
        out->start.assign(2, 0u);
        out->items.assign(4, ScreenTiles::kNoItem);
    };
    const int width = camera.width(), height = camera.height();
    if (!tilesAllowed || !camera.isPinhole() || n == 0 || width <= 0 || height <= 0 ||
        n >= (size_t(1) << 31))
        return finishEmpty();
    // About 1024 tiles (8 x 8 pixels at 256 x 256). Measured on the bunny and mirrorballs
    // (bb1d, lookups plus estimates, docs/performance.md, session 39): 4096 and 16384 tiles
    // give fewer candidates a query but cost more to build, and were no faster.
    const int tile = std::max(2, int(std::ceil(std::sqrt(double(width) * height / 1024.0))));
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
    s.tolerance = screenTolerance(camera, sceneRadius);
    const size_t tileCount = size_t(s.tilesX) * s.tilesY;
    // An item covering more than a quarter of the tiles costs each tile's queries one test in
    // the common list, at one entry.
    const size_t maxRect = std::max<size_t>(1, tileCount / 4);
    const float grow = r + 2.0f * s.tolerance, margin = 1.0f / 64.0f;

    // The tiles of item pl in row y: its hull's span in the row's band, widened by the margin.
    auto rowTiles = [&](const Placement& pl, uint32_t y, uint32_t* x0, uint32_t* x1) {
        float a, b;
        hullSpan(pl, float(y * s.tileSize) - margin, float((y + 1) * s.tileSize) + margin, &a, &b);
        if (!(a <= b) || b + margin < 0.0f || a - margin >= s.width) return false;
        *x0 = uint32_t(std::max(0.0f, std::floor((a - margin) / tile)));
        *x1 = uint32_t(std::min<float>(float(s.tilesX - 1), std::floor((b + margin) / tile)));
        return *x0 <= *x1;
    };
    // Each item's box (corners) grown by r plus twice the tolerance holds every point within
    // r + tolerance of it.
    std::vector<Placement> place(n);
    tbb::parallel_for(size_t(0), n, [&](size_t i) {
        Vec3 box[8];
        corners(i, grow, box);
        Placement& pl = place[i];
        int front = 0, behind = 0;
        float ylo = INFINITY, yhi = -INFINITY, xlo = INFINITY, xhi = -INFINITY;
        for (int c = 0; c < 8; ++c) {
            const Vec3 v = box[c] - eye;
            const float depth = dot(v, axes[2]);
            if (depth > s.tolerance) {
                ++front;
                ub_screen_raster(s, ub_make_float3(v.x, v.y, v.z), &pl.x[c], &pl.y[c]);
                xlo = std::min(xlo, pl.x[c]);
                xhi = std::max(xhi, pl.x[c]);
                ylo = std::min(ylo, pl.y[c]);
                yhi = std::max(yhi, pl.y[c]);
            } else if (depth < -s.tolerance) {
                ++behind;
            }
        }
        if (behind == 8) return;  // kNone
        if (front < 8 || !std::isfinite(xlo + xhi + ylo + yhi)) {
            pl.kind = Placement::kEverywhere;
            return;
        }
        if (xhi + margin < 0.0f || yhi + margin < 0.0f || xlo - margin >= s.width ||
            ylo - margin >= s.height)
            return;  // off the image: no query reads it
        auto tileOf = [&](float v, uint32_t count) {
            return uint32_t(
                std::min<float>(float(count - 1), std::max(0.0f, std::floor(v / tile))));
        };
        pl.y0 = tileOf(ylo - margin, s.tilesY), pl.y1 = tileOf(yhi + margin, s.tilesY);
        const size_t rect =
            size_t(tileOf(xhi + margin, s.tilesX) - tileOf(xlo - margin, s.tilesX) + 1) *
            size_t(pl.y1 - pl.y0 + 1);
        pl.kind = Placement::kTiles;
        makeHull(&pl);
        if (rect > maxRect) {
            // A long thin item (a whole beam across the image) covers far fewer tiles than its
            // bounding rectangle: count the tiles of its rows.
            size_t covered = 0;
            for (uint32_t y = pl.y0; y <= pl.y1 && covered <= maxRect; ++y) {
                uint32_t x0, x1;
                if (rowTiles(pl, y, &x0, &x1)) covered += x1 - x0 + 1;
            }
            if (covered > maxRect) pl.kind = Placement::kEverywhere;
        }
    });
    // The parts of each tile row, ascending, so that rows fill their tiles in parallel.
    std::vector<uint32_t> rowStart(size_t(s.tilesY) + 1, 0u), common;
    for (const Placement& pl : place)
        if (pl.kind == Placement::kTiles)
            for (uint32_t y = pl.y0; y <= pl.y1; ++y) ++rowStart[y + 1];
    for (uint32_t i = 0; i < uint32_t(n); ++i)
        if (place[i].kind == Placement::kEverywhere) common.push_back(i);
    for (size_t y = 0; y < s.tilesY; ++y) rowStart[y + 1] += rowStart[y];
    std::vector<uint32_t> rowParts(rowStart.back()), rowNext(rowStart.begin(), rowStart.end() - 1);
    for (uint32_t i = 0; i < uint32_t(n); ++i) {
        const Placement& pl = place[i];
        if (pl.kind == Placement::kTiles)
            for (uint32_t y = pl.y0; y <= pl.y1; ++y) rowParts[rowNext[y]++] = i;
    }
    // Counts per list, then block ranges (each list padded to whole blocks). Each entry's
    // tiles in its row are kept for the fill (x0 > x1: none): computing the hull's span twice
    // was half of the lists' time (bb1d on the bunny and mirrorballs, docs/performance.md,
    // session 46).
    std::vector<uint32_t> count(tileCount + 1, 0u);
    count[tileCount] = uint32_t(common.size());
    std::vector<uint32_t> spanX0(rowParts.size()), spanX1(rowParts.size());
    tbb::parallel_for(uint32_t(0), s.tilesY, [&](uint32_t y) {
        for (uint32_t k = rowStart[y]; k < rowStart[y + 1]; ++k) {
            uint32_t x0 = 0, x1 = 0;
            if (!rowTiles(place[rowParts[k]], y, &x0, &x1)) {
                x0 = 1;  // no tile
                x1 = 0;
            }
            spanX0[k] = x0;
            spanX1[k] = x1;
            for (uint32_t x = x0; x <= x1; ++x) ++count[y * s.tilesX + x];
        }
    });
    size_t entries = 0;
    for (uint32_t c : count) entries += c;
    if (entries > 16 * n + 4096) return finishEmpty();  // the BVH walk's memory
    out->start.assign(tileCount + 2, 0u);
    for (size_t k = 0; k <= tileCount; ++k) out->start[k + 1] = out->start[k] + (count[k] + 3) / 4;
    const size_t blocks = std::max<size_t>(1, out->start[tileCount + 1]);
    reserve(out->start.size() * 4 + blocks * (sizeof(ub_beam_keys4) + 16));
    out->items.assign(blocks * 4, ScreenTiles::kNoItem);
    // Fill in ascending item index (the kernel and the host twin read the same order); a row's
    // tiles are its own, so rows fill in parallel.
    auto put = [&](uint32_t lane, uint32_t i) { out->items[lane] = i; };
    tbb::parallel_for(uint32_t(0), s.tilesY, [&](uint32_t y) {
        std::vector<uint32_t> next(s.tilesX);
        for (uint32_t x = 0; x < s.tilesX; ++x) next[x] = out->start[y * s.tilesX + x] * 4;
        for (uint32_t k = rowStart[y]; k < rowStart[y + 1]; ++k) {
            const uint32_t i = rowParts[k];
            if (spanX0[k] > spanX1[k]) continue;
            for (uint32_t x = spanX0[k]; x <= spanX1[k]; ++x) put(next[x]++, i);
        }
    });
    for (size_t k = 0; k < common.size(); ++k)
        put(uint32_t(out->start[tileCount] * 4 + k), common[k]);
    s.enabled = 1;
}

/// The blocks of keys beside out->items: set(&block, lane, item) for each lane, item kNoItem
/// for an unused one.
template <class Keys, class Set>
void fillBlocks(const ScreenTiles& tiles, std::vector<Keys>* blocks, Set set) {
    blocks->resize(tiles.items.size() / 4);
    tbb::parallel_for(size_t(0), blocks->size(), [&](size_t b) {
        for (int j = 0; j < 4; ++j) set(&(*blocks)[b], j, tiles.items[4 * b + size_t(j)]);
    });
}
}  // namespace

void buildScreenTiles(const Camera& camera, float sceneRadius, const std::vector<ub_beam>& beams,
                      const std::vector<ub_beam_part>& parts, float r,
                      const std::function<void(size_t)>& reserve, ScreenTiles* out) {
    // The items: a beam whose box (its segment grown by `grow` along itself and across, as
    // below) has every corner deeper than the tolerance in front of the eye is one item; a
    // corner is at most 3 grow shallower than the shallower end of the segment. The other
    // beams go by their parts, so that only their parts near the eye's plane join the list
    // every tile reads.
    const Vec3 eye = camera.position(), forward = camera.forward();
    const float tolerance = screenTolerance(camera, sceneRadius), grow = r + 2.0f * tolerance;
    std::vector<uint8_t> whole(beams.size());
    tbb::parallel_for(size_t(0), beams.size(), [&](size_t i) {
        const ub_beam& b = beams[i];
        const Vec3 o(b.origin[0], b.origin[1], b.origin[2]), d(b.dir[0], b.dir[1], b.dir[2]);
        const float d0 = dot(o - eye, forward), d1 = dot(o + d * b.length - eye, forward);
        whole[i] = std::min(d0, d1) > 4.0f * grow + 2.0f * tolerance ? 1 : 0;
    });
    std::vector<ub_beam_part> items;
    reserve((beams.size() + parts.size()) * sizeof(ub_beam_part));
    items.reserve(beams.size());
    for (uint32_t i = 0; i < beams.size(); ++i)
        if (whole[i]) items.push_back(ub_beam_part_of(beams[i], i, 0.0f, beams[i].length));
    for (const ub_beam_part& p : parts)
        if (!whole[p.beam]) items.push_back(p);
    // Each item's oriented box: its segment grown by `grow` along itself and along the two
    // other axes of a frame around it.
    buildLists(
        camera, sceneRadius, items.size(), r,
        [&](size_t i, float g, Vec3* box) {
            const ub_beam_part& p = items[i];
            const Vec3 o(p.origin[0], p.origin[1], p.origin[2]), d(p.dir[0], p.dir[1], p.dir[2]);
            const Frame f(d);
            const Vec3 ends[2] = {o + d * (p.t0 - g), o + d * (p.t1 + g)};
            for (int c = 0; c < 8; ++c)
                box[c] = ends[c & 1] + f.s * ((c & 2) ? g : -g) + f.t * ((c & 4) ? g : -g);
        },
        reserve, out);
    // The lanes' lines; unused lanes get empty ranges (t0 = t1 = +infinity), which the line
    // filter rejects.
    fillBlocks(*out, &out->lines, [&](ub_beam_keys4* k, int j, uint32_t i) {
        if (i != ScreenTiles::kNoItem) return ub_beam_keys4_set(k, j, items[i]);
        k->ox[j] = k->oy[j] = k->oz[j] = k->dx[j] = k->dy[j] = k->dz[j] = 0.0f;
        k->t0[j] = k->t1[j] = INFINITY;
    });
    // The kernels are given one record at least.
    if (items.empty()) items.push_back(ub_beam_part{});
    out->itemParts = std::move(items);
}

void buildPhotonScreenTiles(const Camera& camera, float sceneRadius,
                            const std::vector<ub_photon_point>& photons, float r,
                            const std::function<void(size_t)>& reserve, ScreenTiles* out) {
    // Each photon's cube of half-width `grow`.
    buildLists(
        camera, sceneRadius, photons.size(), r,
        [&](size_t i, float grow, Vec3* box) {
            const Vec3 p(photons[i].pos[0], photons[i].pos[1], photons[i].pos[2]);
            for (int c = 0; c < 8; ++c)
                box[c] = p + Vec3((c & 1) ? grow : -grow, (c & 2) ? grow : -grow,
                                  (c & 4) ? grow : -grow);
        },
        reserve, out);
    // The lanes' keys; unused lanes are in no medium, which the filter rejects.
    fillBlocks(*out, &out->photonKeys, [&](ub_photon_keys4* k, int j, uint32_t i) {
        if (i != ScreenTiles::kNoItem) return ub_photon_keys4_set(k, j, photons[i]);
        k->px[j] = k->py[j] = k->pz[j] = 0.0f;
        k->mediumId[j] = UB_NO_MEDIUM;
    });
}

}  // namespace ub
