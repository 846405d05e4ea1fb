// Mitsuba 3's `sdfgrid` shape: a signed distance function sampled on a grid of nx x ny x nz
// points spanning the object-space unit cube [0, 1]^3 (sample i at i / (n - 1) along each
// axis), trilinearly interpolated inside each voxel; the surface is its zero level set.
//
// Intersection (Hansson-Söderlund, Evans and Akenine-Möller, "Ray Tracing of Signed Distance
// Function Grids", JCGT 11(3), 2022): each voxel that the surface crosses is one Embree user
// primitive. Along a ray the trilinear interpolant is a cubic in t (their Sec. 4); its first
// root inside the voxel is bracketed by splitting at the roots of the derivative (Marmitt et
// al. 2004, "Fast and Accurate Ray-Voxel Intersection Techniques for Iso-Surface Ray
// Tracing") and refined by Newton steps safeguarded by bisection, to 1e-5 in the ray
// parameter, as Mitsuba does. The values where the ray enters and leaves the voxel are taken
// on the face planes exactly, so two neighbours agree on a shared face and no hit is lost
// between them.
//
// Normals: the geometric normal is the gradient of the voxel's interpolant; the shading
// normal is that one (`normals` = "analytic") or, by default ("smooth"), the blend of the
// eight voxel gradients around the nearest grid vertex (Hansson-Söderlund et al. 2022, Sec.
// 5), continuous across voxels, as Mitsuba 3.9's. The shape has no uv parameterisation (uv
// is 0, as in Mitsuba), cannot emit and cannot bound a medium (the loader refuses both).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/vec.h"

namespace ub {

struct SdfGrid {
    int nx = 0, ny = 0, nz = 0;  ///< samples per axis (>= 2)
    std::vector<float> values;   ///< x fastest, then y, then z
    Transform toWorld, toObject;
    bool smoothNormals = true;
    std::vector<uint32_t> voxels;      ///< sample index of each occupied voxel's lower corner
    std::vector<Bounds3> voxelBounds;  ///< their world-space boxes (padded)
    std::string label;                 ///< file, for messages

    /// Builds the grid: validates the resolution, finds the voxels the surface crosses (a
    /// corner >= 0 and a corner <= 0) and their tight boxes (corners on the surface and edge
    /// crossings, Hansson-Söderlund and Akenine-Möller 2023). Throws ub::InputError naming
    /// `label` for a resolution below 2, non-finite values or a grid without surface.
    static std::shared_ptr<const SdfGrid> make(int nx, int ny, int nz, std::vector<float> values,
                                               const Transform& toWorld, bool smoothNormals,
                                               const std::string& label);

    float at(int x, int y, int z) const {
        return values[(size_t(z) * size_t(ny) + size_t(y)) * size_t(nx) + size_t(x)];
    }

    /// Nearest hit of the world-space ray org + t dir with the surface in occupied voxel
    /// `prim`, t in (tMin, tMax): writes *t and returns true.
    bool intersect(uint32_t prim, const Vec3& org, const Vec3& dir, float tMin, float tMax,
                   float* t) const;

    /// World-space geometric normal (the interpolant's gradient in voxel `prim`) and shading
    /// normal at world point p, both unit and outward (towards positive distance).
    void normals(uint32_t prim, const Vec3& p, Vec3* geometric, Vec3* shading) const;

  private:
    void corners(uint32_t base, float f[8]) const;
    Vec3 smoothNormal(const Vec3& local) const;
};

}  // namespace ub
