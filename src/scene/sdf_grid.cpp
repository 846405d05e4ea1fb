// The sdfgrid shape (see sdf_grid.h for the method and its references).
#include "scene/sdf_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"

namespace ub {

namespace {

/// Solution accuracy of the root finder, in ray parameter units (Mitsuba's 1e-5).
constexpr float kSolveEpsilon = 1e-5f;
constexpr int kSolveMaxIterations = 50;

inline float maxAbs(const Vec3& p) {
    return std::max(std::fabs(p.x), std::max(std::fabs(p.y), std::fabs(p.z)));
}

inline float lerp(float a, float b, float w) {
    return a + (b - a) * w;
}
inline float bilerp(float f0, float f1, float f2, float f3, float u, float v) {
    return lerp(lerp(f0, f1, u), lerp(f2, f3, u), v);
}
/// Trilinear interpolant of corner values f (index x + 2y + 4z) at p in [0, 1]^3.
inline float trilerp(const float f[8], const Vec3& p) {
    return lerp(bilerp(f[0], f[1], f[2], f[3], p.x, p.y), bilerp(f[4], f[5], f[6], f[7], p.x, p.y),
                p.z);
}
/// Its gradient: each partial derivative a bilinear interpolant of four edge differences.
inline Vec3 trilerpGrad(const float f[8], const Vec3& p) {
    return {bilerp(f[1] - f[0], f[3] - f[2], f[5] - f[4], f[7] - f[6], p.y, p.z),
            bilerp(f[2] - f[0], f[3] - f[1], f[6] - f[4], f[7] - f[5], p.x, p.z),
            bilerp(f[4] - f[0], f[5] - f[1], f[6] - f[2], f[7] - f[3], p.x, p.y)};
}

/// Roots of a t^2 + b t + c (a linear equation when a = 0), smaller first.
bool solveQuadratic(float a, float b, float c, float* r0, float* r1) {
    if (a == 0.0f) {
        if (b == 0.0f) return false;
        *r0 = *r1 = -c / b;
        return true;
    }
    const double disc = double(b) * b - 4.0 * double(a) * c;
    if (disc < 0.0) return false;
    const double q = -0.5 * (b + std::copysign(std::sqrt(disc), double(b)));
    double x0 = q / a, x1 = q != 0.0 ? c / q : x0;
    if (x0 > x1) std::swap(x0, x1);
    *r0 = float(x0);
    *r1 = float(x1);
    return true;
}

/// First root in [0, tEnd] of the cubic c3 t^3 + c2 t^2 + c1 t + c0 whose values at the ends
/// are fBeg and fEnd: bracketed by the derivative's roots, then safeguarded Newton.
bool solveCubic(float tEnd, float fBeg, float fEnd, float c3, float c2, float c1, float c0,
                float* tOut) {
    const float d2 = 3.0f * c3, d1 = 2.0f * c2;
    auto eval = [&](float t) { return ((c3 * t + c2) * t + c1) * t + c0; };
    float tNear = 0.0f, tFar = tEnd, fNear = fBeg, fFar = fEnd;
    float r[2];
    if (solveQuadratic(d2, d1, c1, &r[0], &r[1]))
        for (float root : r) {
            if (!(tNear <= root && root <= tFar)) continue;
            const float fRoot = eval(root);
            if (fNear * fRoot <= 0.0f) {
                tFar = root;
                fFar = fRoot;
            } else {
                tNear = root;
                fNear = fRoot;
            }
        }
    if (!(fNear * fFar <= 0.0f)) return false;
    float t = tNear + (tFar - tNear) * (-fNear / (fFar - fNear));
    if (!(t >= tNear && t <= tFar)) t = 0.5f * (tNear + tFar);
    for (int i = 0; i <= kSolveMaxIterations; ++i) {
        const float ft = eval(t);
        if (ft * fNear <= 0.0f)
            tFar = t;
        else
            tNear = t;
        const float deriv = (d2 * t + d1) * t + c1;
        float next = t - ft / deriv;
        if (ft == 0.0f)
            next = t;
        else if (!(next > tNear && next < tFar))
            next = 0.5f * (tNear + tFar);
        const bool done = !(std::fabs(next - t) >= kSolveEpsilon);
        t = next;
        if (done) break;
    }
    *tOut = t;
    return std::isfinite(t);
}

}  // namespace

std::shared_ptr<const SdfGrid> SdfGrid::make(int nx, int ny, int nz, std::vector<float> values,
                                             const Transform& toWorld, bool smoothNormals,
                                             const std::string& label) {
    if (nx < 2 || ny < 2 || nz < 2)
        throw InputError(label, "sdfgrid: resolution " + std::to_string(nx) + " x " +
                                    std::to_string(ny) + " x " + std::to_string(nz) +
                                    " (expected at least 2 samples along each axis)");
    if (values.size() != size_t(nx) * size_t(ny) * size_t(nz))
        throw InputError(label, "sdfgrid: " + std::to_string(values.size()) +
                                    " values for the resolution (expected one channel)");
    for (float v : values)
        if (!std::isfinite(v)) throw InputError(label, "sdfgrid: non-finite distance values");
    if (!(std::fabs(toWorld.determinant3()) > 0.0f))
        throw InputError(label, "sdfgrid: singular to_world");
    auto g = std::make_shared<SdfGrid>();
    g->nx = nx;
    g->ny = ny;
    g->nz = nz;
    g->values = std::move(values);
    g->toWorld = toWorld;
    g->toObject = toWorld.inverse();
    g->smoothNormals = smoothNormals;
    g->label = label;
    const Vec3 h(1.0f / float(nx - 1), 1.0f / float(ny - 1), 1.0f / float(nz - 1));
    const Vec3 cell = toWorld.vector(h);
    for (int z = 0; z + 1 < nz; ++z)
        for (int y = 0; y + 1 < ny; ++y)
            for (int x = 0; x + 1 < nx; ++x) {
                const uint32_t base = uint32_t((size_t(z) * ny + y) * nx + x);
                float f[8];
                g->corners(base, f);
                bool nonNeg = false, nonPos = false;
                for (float v : f) {
                    nonNeg |= v >= 0.0f;
                    nonPos |= v <= 0.0f;
                }
                if (!(nonNeg && nonPos)) continue;
                // Tight box: corners on the surface and the edge crossings (Hansson-Söderlund
                // and Akenine-Möller 2023), in voxel coordinates.
                Bounds3 local;
                auto corner = [](int i) {
                    return Vec3(float(i & 1), float((i >> 1) & 1), float(i >> 2));
                };
                for (int i = 0; i < 8; ++i)
                    if (f[i] == 0.0f) local.extend(corner(i));
                for (int i = 0; i < 8; ++i)
                    for (int a = 0; a < 3; ++a) {
                        if (i & (1 << a)) continue;
                        const int j = i | (1 << a);
                        if (!(f[i] * f[j] <= 0.0f && f[i] != f[j])) continue;
                        Vec3 p = corner(i);
                        p[a] = f[i] / (f[i] - f[j]);
                        local.extend(p);
                    }
                if (local.empty()) continue;
                Bounds3 world;
                for (int i = 0; i < 8; ++i) {
                    const Vec3 q((i & 1) ? local.hi.x : local.lo.x,
                                 (i & 2) ? local.hi.y : local.lo.y,
                                 (i & 4) ? local.hi.z : local.lo.z);
                    world.extend(toWorld.point((q + Vec3(float(x), float(y), float(z))) * h));
                }
                // Padded so that rounding here and in the box tests never loses a hit.
                const Vec3 pad =
                    Vec3(std::fabs(cell.x), std::fabs(cell.y), std::fabs(cell.z)) * 1e-3f +
                    Vec3(8.0f * std::numeric_limits<float>::epsilon() *
                         std::max(maxAbs(world.lo), maxAbs(world.hi)));
                world.lo = world.lo - pad;
                world.hi = world.hi + pad;
                g->voxels.push_back(base);
                g->voxelBounds.push_back(world);
            }
    if (g->voxels.empty())
        throw InputError(label,
                         "sdfgrid: no voxel contains the surface (the distances never "
                         "change sign)");
    return g;
}

void SdfGrid::corners(uint32_t base, float f[8]) const {
    for (int i = 0; i < 8; ++i) {
        const size_t offset =
            size_t(i & 1) + size_t(nx) * (size_t((i >> 1) & 1) + size_t(ny) * size_t(i >> 2));
        f[i] = values[base + offset];
    }
}

bool SdfGrid::intersect(uint32_t prim, const Vec3& org, const Vec3& dir, float tMin, float tMax,
                        float* tHit) const {
    const uint32_t base = voxels[prim];
    const int vx = int(base % uint32_t(nx)), vy = int((base / uint32_t(nx)) % uint32_t(ny)),
              vz = int(base / (uint32_t(nx) * uint32_t(ny)));
    const Vec3 res(float(nx - 1), float(ny - 1), float(nz - 1));
    // Voxel coordinates: the voxel is [0, 1]^3; scaling keeps the ray parameter.
    const Vec3 o = toObject.point(org) * res - Vec3(float(vx), float(vy), float(vz));
    const Vec3 d = toObject.vector(dir) * res;
    float slabMin[3], slabMax[3];
    for (int a = 0; a < 3; ++a) {
        if (d[a] == 0.0f) {
            if (!(o[a] >= 0.0f && o[a] <= 1.0f)) return false;
            slabMin[a] = -kInf;
            slabMax[a] = kInf;
            continue;
        }
        const float t0 = (0.0f - o[a]) / d[a], t1 = (1.0f - o[a]) / d[a];
        slabMin[a] = std::min(t0, t1);
        slabMax[a] = std::max(t0, t1);
    }
    const float entry = std::max(std::max(slabMin[0], slabMin[1]), slabMin[2]);
    const float tEnd = std::min(std::min(slabMax[0], slabMax[1]), slabMax[2]);
    const float tBeg = std::max(entry, tMin);
    if (!(tBeg < tEnd) || !(tBeg < tMax)) return false;
    float f[8];
    corners(base, f);
    Vec3 pBeg = o + tBeg * d, pEnd = o + tEnd * d;
    // The crossed faces exactly on their planes, where neighbours interpolate the same values.
    for (int a = 0; a < 3; ++a) {
        if (slabMin[a] == tBeg) pBeg[a] = d[a] >= 0.0f ? 0.0f : 1.0f;
        if (slabMax[a] == tEnd) pEnd[a] = d[a] >= 0.0f ? 1.0f : 0.0f;
        pBeg[a] = std::clamp(pBeg[a], 0.0f, 1.0f);
        pEnd[a] = std::clamp(pEnd[a], 0.0f, 1.0f);
    }
    const float fBeg = trilerp(f, pBeg), fEnd = trilerp(f, pEnd);
    // The interpolant along the ray as a cubic in t - tBeg (Hansson-Söderlund et al. 2022,
    // Sec. 4): f = k0 + k1 x + k2 y + k4 z + k3 xy + k5 xz + k6 yz + k7 xyz.
    const float k0 = f[0], k1 = f[1] - f[0], k2 = f[2] - f[0], k3 = f[3] - f[2] - k1,
                k4 = f[4] - f[0], k5 = (f[5] - f[4]) - k1, k6 = (f[6] - f[4]) - k2,
                k7 = (f[7] - f[6] - (f[5] - f[4])) - k3;
    const float ox = pBeg.x, oy = pBeg.y, oz = pBeg.z, dx = d.x, dy = d.y, dz = d.z;
    const float m0 = ox * oy, m1 = dx * dy, m2 = ox * dy + oy * dx;
    const float m3 = k5 * oz + k1, m4 = k6 * oz + k2, m5 = k7 * oz + k3;
    const float c0 = (k4 * oz + k0) + ox * m3 + oy * m4 + m0 * m5;
    const float c1 = dx * m3 + dy * m4 + m2 * m5 + dz * (k4 + k5 * ox + k6 * oy + k7 * m0);
    const float c2 = m1 * m5 + dz * (k5 * dx + k6 * dy + k7 * m2);
    const float c3 = k7 * m1 * dz;
    float t = 0.0f;
    if (!solveCubic(tEnd - tBeg, fBeg, fEnd, c3, c2, c1, c0, &t)) return false;
    t += tBeg;
    if (!(t > tMin && t < tMax)) return false;
    *tHit = t;
    return true;
}

void SdfGrid::normals(uint32_t prim, const Vec3& p, Vec3* geometric, Vec3* shading) const {
    const uint32_t base = voxels[prim];
    const Vec3 voxel(float(base % uint32_t(nx)), float((base / uint32_t(nx)) % uint32_t(ny)),
                     float(base / (uint32_t(nx) * uint32_t(ny))));
    const Vec3 res(float(nx - 1), float(ny - 1), float(nz - 1));
    const Vec3 local = toObject.point(p);
    Vec3 w = local * res - voxel;
    for (int a = 0; a < 3; ++a) w[a] = std::clamp(w[a], 0.0f, 1.0f);
    float f[8];
    corners(base, f);
    const Vec3 grad = trilerpGrad(f, w) * res;
    // Object-space gradient to world: the inverse transpose of to_world, i.e. the transpose
    // of to_object's linear part.
    auto toWorldNormal = [&](const Vec3& n) {
        const auto& m = toObject.m;
        return normalize(Vec3(m[0][0] * n.x + m[1][0] * n.y + m[2][0] * n.z,
                              m[0][1] * n.x + m[1][1] * n.y + m[2][1] * n.z,
                              m[0][2] * n.x + m[1][2] * n.y + m[2][2] * n.z));
    };
    *geometric = toWorldNormal(grad);
    *shading = smoothNormals ? toWorldNormal(smoothNormal(local)) : *geometric;
    if (!isFinite(*shading) || lengthSqr(*shading) == 0.0f) *shading = *geometric;
}

// The blend of the gradients of the eight voxels around the grid vertex nearest to the point
// (Hansson-Söderlund et al. 2022, Sec. 5, as Mitsuba 3.9 evaluates it): each voxel's gradient
// is made of finite differences of the interpolant across the voxel along one axis, at the
// point's position along the other two; voxels outside the grid have weight zero.
Vec3 SdfGrid::smoothNormal(const Vec3& local) const {
    const int n[3] = {nx, ny, nz};
    const Vec3 res(float(nx - 1), float(ny - 1), float(nz - 1));
    const Vec3 sp = local * res;
    int v[3], cell[3];
    Vec3 uvw, w;
    for (int a = 0; a < 3; ++a) {
        v[a] = int(std::lround(sp[a])) - 1;
        uvw[a] = sp[a] - float(v[a]) - 0.5f;
        cell[a] = std::clamp(int(std::floor(sp[a])), 0, n[a] - 2);
        w[a] = sp[a] - float(cell[a]);
    }
    auto sample = [&](int q[3]) {
        const int x = std::clamp(q[0], 0, nx - 1), y = std::clamp(q[1], 0, ny - 1),
                  z = std::clamp(q[2], 0, nz - 1);
        return at(x, y, z);
    };
    // The interpolant on the sample plane q along axis a, at the point's other coordinates.
    auto plane = [&](int a, int q) {
        const int b = (a + 1) % 3, c = (a + 2) % 3;
        float f[4];
        for (int i = 0; i < 4; ++i) {
            int idx[3];
            idx[a] = q;
            idx[b] = cell[b] + (i & 1);
            idx[c] = cell[c] + (i >> 1);
            f[i] = sample(idx);
        }
        return bilerp(f[0], f[1], f[2], f[3], w[b], w[c]);
    };
    Vec3 d0, d1;
    for (int a = 0; a < 3; ++a) {
        const bool upper = cell[a] != v[a];
        const float g0 = plane(a, cell[a]), g1 = plane(a, cell[a] + 1),
                    gq = plane(a, cell[a] + (upper ? -1 : 2));
        const float dc = g1 - g0, dq = upper ? g0 - gq : gq - g1;
        d0[a] = (upper ? dq : dc) * res[a];
        d1[a] = (upper ? dc : dq) * res[a];
    }
    bool inside[3];
    for (int a = 0; a < 3; ++a) {
        inside[a] = v[a] >= 0;
        if (!inside[a]) uvw[a] = 1.0f;
    }
    Vec3 nrm[8];
    for (int i = 0; i < 8; ++i) {
        const bool hi[3] = {(i & 1) != 0, (i & 2) != 0, (i & 4) != 0};
        bool ok = true;
        Vec3 g;
        for (int a = 0; a < 3; ++a) {
            ok = ok && (hi[a] || inside[a]);
            g[a] = hi[a] ? d1[a] : d0[a];
        }
        const float len = length(g);
        nrm[i] = ok && len > 0.0f ? g / len : Vec3(0.0f);
    }
    auto mix = [](const Vec3& a, const Vec3& b, float t) { return a + (b - a) * t; };
    return mix(mix(mix(nrm[0], nrm[1], uvw.x), mix(nrm[2], nrm[3], uvw.x), uvw.y),
               mix(mix(nrm[4], nrm[5], uvw.x), mix(nrm[6], nrm[7], uvw.x), uvw.y), uvw.z);
}

}  // namespace ub
