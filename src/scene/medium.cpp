// Regular tracking through homogeneous and NanoVDB grid media (see medium.h).
#include "scene/medium.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "kernels/shared/ub_grid_dda.h"
#include "kernels/shared/ub_medium_homogeneous.h"
#include "scene/albedo_grid.h"
#include "scene/medium_trilinear.h"

namespace ub {

namespace {

bool isFiniteNonNegative(const Rgb& c) {
    return isFinite(c) && c.x >= 0 && c.y >= 0 && c.z >= 0;
}

void checkG(float g) {
    if (!(std::fabs(g) < 1.0f))
        throw std::invalid_argument("medium: HG g must lie in (-1, 1), got " + std::to_string(g));
}

/// Leaf nodes of the default NanoVDB float tree are 8^3 voxels; a voxel whose block has no
/// leaf has the value of the enclosing tile (or the background) over the whole block.
constexpr int kLeafDim = 8;

enum class LeafWalk { kLeft, kEnded, kStopped };

/// forEachPiece's walk through the voxels of one leaf of a grey grid, from voxel v at t, until
/// it leaves the leaf (kLeft: v and *t are the next voxel and where it starts), reaches tExit
/// or the grid's box (kEnded), or a visit returns false (kStopped). In a leaf every step of
/// forEachPiece's general loop is one voxel, and its other axes' voxel indices are clamped
/// to themselves, so only the crossed axis changes: this loop reads the leaf's values by
/// offset instead of probing the accessor, and recomputes only the crossed axis's boundary
/// parameter, with the general loop's operations. Same pieces, bit for bit: tests/
/// medium_test.cpp compares them with the kernels' walk (kernels/shared/ub_grid_medium.h, which
/// has the same loop) and with brute-force boundaries. Measured in docs/performance.md
/// (session 43).
template <typename Leaf, typename Visit>
LeafWalk walkLeaf(const Leaf& leaf, const Vec3& P, const float invD[3], const int step[3],
                  const int lo[3], const int hi[3], float tExit, float densityScale,
                  const Rgb& albedo, int v[3], float* t, Visit& visit) {
    constexpr float kNever = std::numeric_limits<float>::infinity();
    int leafLo[3];
    float tb[3];
    for (int a = 0; a < 3; ++a) {
        leafLo[a] = v[a] & ~(kLeafDim - 1);
        tb[a] = step[a] == 0 ? kNever : ub_dda_exit(v[a], step[a], P[a], invD[a]);
    }
    for (;;) {
        const uint32_t offset = uint32_t((v[0] & (kLeafDim - 1)) << 6 |
                                         (v[1] & (kLeafDim - 1)) << 3 | (v[2] & (kLeafDim - 1)));
        const float density = leaf.getValue(offset);
        float tNext;
        const int axis = ub_dda_nearest(tb, tExit, &tNext);  // the general loop's choice
        tNext = std::max(tNext, *t);
        if (tNext > *t) {
            const Rgb sigmaT = Rgb(density) * densityScale;
            if (!visit(*t, tNext, sigmaT, albedo * sigmaT)) return LeafWalk::kStopped;
        }
        if (axis < 0) return LeafWalk::kEnded;
        *t = tNext;
        v[axis] += step[axis];
        if (v[axis] < lo[axis] || v[axis] >= hi[axis]) return LeafWalk::kEnded;
        if ((v[axis] & ~(kLeafDim - 1)) != leafLo[axis]) return LeafWalk::kLeft;
        tb[axis] = ub_dda_exit(v[axis], step[axis], P[axis], invD[axis]);
    }
}

/// Calls visit(ta, tb, sigmaT, sigmaS) for consecutive pieces [ta, tb) of constant
/// coefficients covering [0, tMax] in order, until visit returns false. Zero-length pieces
/// are skipped. Returns false if a visit stopped the walk.
template <typename Visit>
bool forEachPiece(const Medium& m, const Vec3& origin, const Vec3& dir, float tMax, Visit&& visit) {
    if (!(tMax > 0.0f)) return true;
    if (m.type == MediumType::kHomogeneous) return visit(0.0f, tMax, m.sigmaA + m.sigmaS, m.sigmaS);

    // Channel grids: one (grey) or three (chromatic), sharing the index transform.
    const bool rgb = m.chromatic();
    const VdbGrid& vdb = *m.grid;
    Rgb bgT(m.densityScale * vdb.background());
    if (rgb) {
        bgT.y = m.densityScale * m.gridG->background();
        bgT.z = m.densityScale * m.gridB->background();
    }
    const Rgb bgS = m.albedo * bgT;

    // Cell space: t is shared with world space because the direction is not renormalised.
    const Vec3 P = m.worldToCell.point(origin);
    const Vec3 D = m.worldToCell.vector(dir);
    const int lo[3] = {m.activeLo[0], m.activeLo[1], m.activeLo[2]};
    const int hi[3] = {m.activeHi[0] + 1, m.activeHi[1] + 1, m.activeHi[2] + 1};  // exclusive

    // Slab test against the cell box [lo, hi).
    float tEnter = 0.0f, tExit = tMax;
    float invD[3];
    int step[3];
    for (int a = 0; a < 3; ++a) {
        step[a] = D[a] > 0 ? 1 : (D[a] < 0 ? -1 : 0);
        if (step[a] == 0) {
            invD[a] = 0.0f;
            if (P[a] < float(lo[a]) || P[a] >= float(hi[a])) tExit = -1.0f;  // misses the box
            continue;
        }
        invD[a] = 1.0f / D[a];
        float t0 = (float(lo[a]) - P[a]) * invD[a], t1 = (float(hi[a]) - P[a]) * invD[a];
        if (t0 > t1) std::swap(t0, t1);
        tEnter = std::max(tEnter, t0);
        tExit = std::min(tExit, t1);
    }
    if (!(tEnter < tExit)) return visit(0.0f, tMax, bgT, bgS);
    if (tEnter > 0.0f && !visit(0.0f, tEnter, bgT, bgS)) return false;

    // 3D-DDA (Amanatides & Woo 1987) over voxels inside leaves and over whole 8^3 blocks
    // elsewhere. v is the current voxel; the block containing it is [blockLo, blockLo + dim).
    auto acc = vdb.grid().getAccessor();
    auto accG = m.channelGrid(1).grid().getAccessor();
    auto accB = m.channelGrid(2).grid().getAccessor();
    int v[3];
    const float tStart = tEnter;
    for (int a = 0; a < 3; ++a)
        v[a] = std::clamp(int(std::floor(P[a] + D[a] * tStart)), lo[a], hi[a] - 1);
    float t = tEnter;
    for (;;) {
        const nanovdb::Coord ijk(v[0], v[1], v[2]);
        const auto* leaf = acc.probeLeaf(ijk);
        if (leaf && !rgb) {
            const LeafWalk w = walkLeaf(*leaf, P, invD, step, lo, hi, tExit, m.densityScale,
                                        m.albedo, v, &t, visit);
            if (w == LeafWalk::kStopped) return false;
            if (w == LeafWalk::kEnded) break;
            continue;  // v is the first voxel past the leaf
        }
        Rgb density(leaf ? leaf->getValue(ijk) : acc.getValue(ijk));
        bool inLeaf = leaf != nullptr;
        if (rgb) {  // a voxel step wherever any channel has a leaf; elsewhere all are constant
            const auto* leafG = accG.probeLeaf(ijk);
            const auto* leafB = accB.probeLeaf(ijk);
            density.y = leafG ? leafG->getValue(ijk) : accG.getValue(ijk);
            density.z = leafB ? leafB->getValue(ijk) : accB.getValue(ijk);
            inLeaf = inLeaf || leafG || leafB;
        }
        const int dim = inLeaf ? 1 : kLeafDim;
        int blockLo[3];
        for (int a = 0; a < 3; ++a) blockLo[a] = inLeaf ? v[a] : (v[a] & ~(kLeafDim - 1));

        float tNext = tExit;
        int axis = -1;
        for (int a = 0; a < 3; ++a) {
            if (step[a] == 0) continue;
            const int boundary = step[a] > 0 ? blockLo[a] + dim : blockLo[a];
            const float tb = (float(boundary) - P[a]) * invD[a];
            if (tb < tNext) {
                tNext = tb;
                axis = a;
            }
        }
        tNext = std::max(tNext, t);
        if (tNext > t) {
            const Rgb sigmaT = density * m.densityScale;
            if (!visit(t, tNext, sigmaT, m.albedo * sigmaT)) return false;
        }
        if (axis < 0) break;  // reached tExit inside this block
        t = tNext;
        for (int b = 0; b < 3; ++b) {
            if (b == axis) continue;
            v[b] = std::clamp(int(std::floor(P[b] + D[b] * t)), blockLo[b], blockLo[b] + dim - 1);
        }
        v[axis] = step[axis] > 0 ? blockLo[axis] + dim : blockLo[axis] - 1;
        if (v[axis] < lo[axis] || v[axis] >= hi[axis]) break;
    }
    if (tExit < tMax) return visit(tExit, tMax, bgT, bgS);
    return true;
}

}  // namespace

Medium Medium::homogeneous(const Rgb& sigmaA, const Rgb& sigmaS, float g, const Rgb& Le) {
    if (!isFiniteNonNegative(sigmaA) || !isFiniteNonNegative(sigmaS) || !isFiniteNonNegative(Le))
        throw std::invalid_argument(
            "homogeneous medium: sigma_a, sigma_s and Le must be finite "
            "and >= 0");
    checkG(g);
    Medium m;
    m.type = MediumType::kHomogeneous;
    m.sigmaA = sigmaA;
    m.sigmaS = sigmaS;
    m.Le = Le;
    m.g = g;
    return m;
}

namespace {

/// World bounds of the cell box [lo, hi + 1) (inclusive voxel bounds).
Bounds3 cellBoxBounds(const Transform& cellToWorld, const int lo[3], const int hi[3]) {
    Bounds3 b;
    for (int c = 0; c < 8; ++c) {
        Vec3 corner(float(c & 1 ? hi[0] + 1 : lo[0]), float(c & 2 ? hi[1] + 1 : lo[1]),
                    float(c & 4 ? hi[2] + 1 : lo[2]));
        b.extend(cellToWorld.point(corner));
    }
    return b;
}

bool sameTransform(const Transform& a, const Transform& b) {
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c)
            if (a.m[r][c] != b.m[r][c]) return false;
    return true;
}

}  // namespace

Medium Medium::heterogeneous(std::shared_ptr<const VdbGrid> grid, float densityScale,
                             const Rgb& albedo, float g, const Transform& localToWorld) {
    if (!grid) throw std::invalid_argument("grid medium: no grid");
    if (!(densityScale >= 0.0f) || !std::isfinite(densityScale))
        throw std::invalid_argument("grid medium: density scale must be finite and >= 0");
    if (!isFiniteNonNegative(albedo) || maxComponent(albedo) > 1.0f)
        throw std::invalid_argument("grid medium: albedo must lie in [0, 1]");
    checkG(g);
    Transform cellToWorld = localToWorld * grid->indexToLocal() * Transform::translate(Vec3(-0.5f));
    if (!(std::fabs(cellToWorld.determinant3()) > 0.0f))
        throw std::invalid_argument("grid medium: singular transform");
    Medium m;
    m.type = MediumType::kGrid;
    m.grid = std::move(grid);
    m.densityScale = densityScale;
    m.albedo = albedo;
    m.g = g;
    m.localToWorld = localToWorld;
    m.worldToCell = cellToWorld.inverse();
    const nanovdb::CoordBBox& bb = m.grid->indexBounds();
    for (int a = 0; a < 3; ++a) {
        m.domainLo[a] = m.activeLo[a] = bb.min()[a];
        m.domainHi[a] = m.activeHi[a] = bb.max()[a];
    }
    m.worldBounds = cellBoxBounds(cellToWorld, m.activeLo, m.activeHi);
    return m;
}

Medium Medium::heterogeneous(std::shared_ptr<const VdbGrid> grid, float densityScale,
                             const Rgb& albedo, float g, const Transform& localToWorld,
                             const GridMediumOptions& options) {
    std::shared_ptr<const VdbGrid> channels[3] = {grid, grid, grid};
    return heterogeneousRgb(channels, densityScale, albedo, g, localToWorld, options);
}

Medium Medium::heterogeneousRgb(const std::shared_ptr<const VdbGrid> channels[3],
                                float densityScale, const Rgb& albedo, float g,
                                const Transform& localToWorld, const GridMediumOptions& options) {
    for (int c = 0; c < 3; ++c)
        if (!channels[c]) throw std::invalid_argument("grid medium: no grid");
    Medium m = heterogeneous(channels[0], densityScale, albedo, g, localToWorld);
    m.filter = options.filter;
    if (channels[1] != channels[0] || channels[2] != channels[0]) {
        for (int c = 1; c < 3; ++c)
            if (!sameTransform(channels[c]->indexToLocal(), channels[0]->indexToLocal()))
                throw std::invalid_argument(
                    "grid medium: the sigma_t channels have different voxel transforms");
        m.gridG = channels[1];
        m.gridB = channels[2];
        for (int c = 1; c < 3; ++c) {
            const nanovdb::CoordBBox& bb = channels[c]->indexBounds();
            for (int a = 0; a < 3; ++a) {
                m.activeLo[a] = std::min(m.activeLo[a], bb.min()[a]);
                m.activeHi[a] = std::max(m.activeHi[a], bb.max()[a]);
            }
        }
        for (int a = 0; a < 3; ++a) {
            m.domainLo[a] = m.activeLo[a];
            m.domainHi[a] = m.activeHi[a];
        }
        m.worldBounds = cellBoxBounds(m.worldToCell.inverse(), m.activeLo, m.activeHi);
    }
    const bool given = options.domainLo[0] <= options.domainHi[0] ||
                       options.domainLo[1] <= options.domainHi[1] ||
                       options.domainLo[2] <= options.domainHi[2];
    if (given) {
        for (int a = 0; a < 3; ++a) {
            if (options.domainLo[a] > options.domainHi[a])
                throw std::invalid_argument("grid medium: empty domain");
            m.domainLo[a] = options.domainLo[a];
            m.domainHi[a] = options.domainHi[a];
        }
        m.worldBounds = cellBoxBounds(m.worldToCell.inverse(), m.domainLo, m.domainHi);
    }
    return m;
}

MediumCoefficients mediumCoefficientsAt(const Medium& m, const Vec3& p) {
    MediumCoefficients c;
    if (m.type == MediumType::kGrid && m.filter == GridFilter::kTrilinear) {
        c.sigmaT = trilinearDensityRgbAt(m, p) * m.densityScale;
        c.sigmaS = mediumAlbedoAt(m, p) * c.sigmaT;
        c.sigmaA = c.sigmaT - c.sigmaS;
        c.Le = Rgb(0.0f);
        return c;
    }
    if (m.type == MediumType::kHomogeneous) {
        c.sigmaA = m.sigmaA;
        c.sigmaS = m.sigmaS;
        c.sigmaT = m.sigmaA + m.sigmaS;
        c.Le = m.Le;
        return c;
    }
    const Vec3 q = m.worldToCell.point(p);
    const int ijkv[3] = {int(std::floor(q.x)), int(std::floor(q.y)), int(std::floor(q.z))};
    bool inside = true;
    for (int a = 0; a < 3; ++a)
        inside = inside && ijkv[a] >= m.activeLo[a] && ijkv[a] <= m.activeHi[a];
    const nanovdb::Coord ijk(ijkv[0], ijkv[1], ijkv[2]);
    Rgb density;
    for (int ch = 0; ch < (m.chromatic() ? 3 : 1); ++ch) {
        const VdbGrid& grid = m.channelGrid(ch);
        density[ch] = inside ? grid.grid().getAccessor().getValue(ijk) : grid.background();
    }
    if (!m.chromatic()) density = Rgb(density.x);
    c.sigmaT = density * m.densityScale;
    c.sigmaS = mediumAlbedoAt(m, p) * c.sigmaT;
    c.sigmaA = c.sigmaT - c.sigmaS;
    c.Le = Rgb(0.0f);
    return c;
}

bool gridPieces(const Medium& m, const Vec3& origin, const Vec3& dir, float length,
                const std::function<void(float, float, float)>& visit) {
    if (m.type != MediumType::kGrid || m.filter == GridFilter::kTrilinear || m.chromatic())
        return false;
    forEachPiece(m, origin, dir, length, [&](float ta, float tb, const Rgb& sigmaT, const Rgb&) {
        visit(ta, tb, sigmaT.x);  // grid extinction is grey (density x scale)
        return true;
    });
    return true;
}

Rgb transmittance(const Medium& m, const Vec3& origin, const Vec3& dir, float length) {
    if (m.type == MediumType::kGrid && m.filter == GridFilter::kTrilinear)
        return trilinearTransmittance(m, origin, dir, length);
    Rgb tau(0.0f);
    forEachPiece(m, origin, dir, length, [&](float ta, float tb, const Rgb& sigmaT, const Rgb&) {
        tau += sigmaT * (tb - ta);
        return true;
    });
    return expNeg(tau);
}

MediumSegment evalMediumSegment(const Medium& m, const Vec3& origin, const Vec3& dir,
                                float length) {
    if (m.type == MediumType::kGrid && m.filter == GridFilter::kTrilinear)
        return trilinearSegment(m, origin, dir, length);
    MediumSegment seg;
    seg.length = length;
    Rgb tau(0.0f);
    bool first = true;
    forEachPiece(m, origin, dir, length,
                 [&](float ta, float tb, const Rgb& sigmaT, const Rgb& sigmaS) {
                     if (first) seg.sigmaT0 = sigmaT;
                     first = false;
                     seg.sigmaT1 = sigmaT;
                     seg.sigmaS1 = sigmaS;
                     tau += sigmaT * (tb - ta);
                     return true;
                 });
    if (first) {  // zero-length segment: both ends are the origin
        MediumCoefficients c = mediumCoefficientsAt(m, origin);
        seg.sigmaT0 = seg.sigmaT1 = c.sigmaT;
        seg.sigmaS1 = c.sigmaS;
    } else if (m.albedoGrid) {  // the pieces carry the constant albedo: use the grid's at x1
        seg.sigmaS1 = albedoGridAt(*m.albedoGrid, origin + dir * length) * seg.sigmaT1;
    }
    seg.transmittance = expNeg(tau);
    return seg;
}

/// -ln(1 - u), an Exp(1) optical depth by inversion. logf of 1 - u rather than log1pf of -u
/// (about three times as fast, 6% of a pp3d iteration in perf): for the generator's u =
/// k 2^-24, 1 - u is exact, so the two agree to logf's rounding.
static float opticalDepthTarget(float u) {
    return -std::log(1.0f - u);
}

/// The colour channel whose extinction free-flight sampling inverts (spectral MIS).
static int flightChannel(float u) {
    return std::min(2, int(u * 3.0f));
}

float homogeneousFlightDistance(const Medium& m, float uChannel, float uDistance) {
    // sampleFreeFlight's inversion below for the single piece [0, tMax) of a homogeneous
    // medium: 0 + (tauTarget - 0) / sigmaT[c], evaluated with the same operations.
    const int c = flightChannel(uChannel);
    const float tauTarget = opticalDepthTarget(uDistance);
    const Rgb sigmaT = m.sigmaA + m.sigmaS;
    if (!(sigmaT[c] > 0.0f)) return kInf;
    return 0.0f + (tauTarget - 0.0f) / sigmaT[c];
}

FreeFlightSample sampleFreeFlight(const Medium& m, const Vec3& origin, const Vec3& dir, float tMax,
                                  float uChannel, float uDistance) {
    if (m.type == MediumType::kGrid && m.filter == GridFilter::kTrilinear)
        return trilinearFreeFlight(m, origin, dir, tMax, uChannel, uDistance);
    const int c = flightChannel(uChannel);
    // Target optical depth in channel c: tau ~ Exp(1) by inversion.
    const float tauTarget = opticalDepthTarget(uDistance);
    FreeFlightSample s;
    MediumSegment& seg = s.segment;
    Rgb tau(0.0f);
    bool first = true;
    forEachPiece(m, origin, dir, tMax,
                 [&](float ta, float tb, const Rgb& sigmaT, const Rgb& sigmaS) {
                     if (first) seg.sigmaT0 = sigmaT;
                     first = false;
                     seg.sigmaT1 = sigmaT;
                     seg.sigmaS1 = sigmaS;
                     const float len = tb - ta;
                     if (sigmaT[c] > 0.0f && tau[c] + sigmaT[c] * len >= tauTarget) {
                         // Invert the piecewise-linear optical depth inside this piece.
                         float t = ta + (tauTarget - tau[c]) / sigmaT[c];
                         t = std::clamp(t, ta, tb);
                         tau += sigmaT * (t - ta);
                         s.t = t;
                         s.scattered = t < tMax;
                         return false;
                     }
                     tau += sigmaT * len;
                     return true;
                 });
    if (!s.scattered) s.t = tMax;
    if (first) {
        MediumCoefficients co = mediumCoefficientsAt(m, origin);
        seg.sigmaT0 = seg.sigmaT1 = co.sigmaT;
        seg.sigmaS1 = co.sigmaS;
    } else if (m.albedoGrid) {  // sigma_s at the collision (or the end): the grid's albedo
        seg.sigmaS1 = albedoGridAt(*m.albedoGrid, origin + dir * s.t) * seg.sigmaT1;
    }
    seg.transmittance = expNeg(tau);
    seg.length = s.t;
    s.pdf = s.scattered ? seg.pdfScatterFwdL() : seg.probPass();
    if (s.pdf > 0.0f)
        s.weight =
            s.scattered ? seg.transmittance * seg.sigmaS1 / s.pdf : seg.transmittance / s.pdf;
    return s;
}

Rgb expNeg(const Rgb& tau) {
    float t[3];
    ub_exp_neg3(tau.x, tau.y, tau.z, t);
    return {t[0], t[1], t[2]};
}

}  // namespace ub
