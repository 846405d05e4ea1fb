// Participating media as flat data with a type tag (no virtual calls per
// sample): homogeneous, or heterogeneous with density from a NanoVDB grid.
//
// Coefficients are per unit world length, RGB. sigma_t = sigma_a + sigma_s.
//  * Homogeneous: sigma_a, sigma_s, optional emitted radiance Le (the source
//    term of the RTE is sigma_a * Le, as in pbrt-v4), HG g.
//  * Grid: sigma_t(x) = densityScale * density(x) (grey), or per channel
//    sigma_t,c(x) = densityScale * density_c(x) with one grid per channel
//    (chromatic extinction, Mitsuba's 3-channel sigma_t volumes), sigma_s(x) =
//    albedo(x) * sigma_t(x), HG g, no emission. albedo(x) is the constant RGB
//    `albedo`, or an optional albedo grid (scene/albedo_grid.h, Mitsuba's
//    heterogeneous medium with a volume albedo) looked up only where a collision
//    is made (mediumAlbedoAt below): tracking, transmittance and every distance
//    pdf depend on sigma_t alone. density(x) is piecewise constant per voxel
//    (see scene/vdb_grid.h for the cell convention); the grid's own transform
//    maps index to grid-local space and `localToWorld` places it in the scene.
//
// Regular tracking (Novak et al. 2018, "Monte Carlo Methods for Volumetric
// Light Transport Simulation", Sec. 4.1): a segment is cut into pieces of
// constant sigma_t by a 3D-DDA through the voxels (Amanatides & Woo 1987,
// "A Fast Voxel Traversal Algorithm for Ray Tracing"), skipping the 8^3
// blocks that hold no leaf node in one step. The optical depth is then
// piecewise linear in t, so transmittance T = exp(-sum_i sigma_t,i * len_i) is
// exact and free-flight sampling inverts it exactly.
// Why our own DDA and not nanovdb::HDDA (nanovdb/util/HDDA.h): HDDA treats
// voxel ijk as the box [ijk, ijk + 1) of index space, whereas the value of a
// voxel belongs to the cell centred on ijk (what nearest-neighbour lookup and
// OpenVDB's cell-centred convention use); we walk in "cell space" = index
// space + 1/2, so the pieces of a walk and a point lookup always agree. And
// nanovdb/CNanoVDB.h, which the OpenCL kernels will use, has no HDDA: this
// walk needs only "value at ijk" and "does ijk lie in a leaf node" (the
// latter is where CNanoVDB's read accessor descends to, and caches, a leaf),
// so it ports to kernels without a DDA library.
//
// Free-flight (distance) sampling with RGB coefficients (spectral MIS; Novak
// et al. 2018, Sec. 5.1): pick channel c uniformly, sample t with density
// sigma_t,c(t) T_c(t) on [0, tMax) or pass the segment with probability
// T_c(tMax). The pdf of the combined technique is the average over channels:
//   pdfScatterL(t) = (1/3) sum_c sigma_t,c(t) T_c(0, t)     (per unit length)
//   probPass       = (1/3) sum_c T_c(0, tMax)               (a probability)
// and the throughput weights are T sigma_s / pdfScatterL and T / probPass,
// which makes every channel's estimate unbiased. Chromatic grids use the same
// combination: each piece of regular tracking has an RGB sigma_t (the walk
// descends into a voxel wherever any channel has a leaf), so tracking stays
// exact and the pdfs are those above.
//
// Directions: `dir` is a unit world-space direction; t is distance along it.
// For bidirectional MIS both directions of a segment x0 -> x1 are needed: the
// reverse density (sampling from x1 towards x0 and stopping at x0) uses
// sigma_t at x0; the pass probability is the same both ways (T is symmetric).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>

#include "core/vec.h"
#include "scene/vdb_grid.h"

namespace ub {

struct AlbedoGrid;
/// Albedo of an albedo grid at world point p (scene/albedo_grid.cpp).
Rgb albedoGridAt(const AlbedoGrid& a, const Vec3& p);

enum class MediumType : uint32_t {
    kHomogeneous = 0,
    kGrid = 1,
};

/// How a grid medium's density varies inside the grid (an explicit choice, never a silent
/// switch; docs/mitsuba.md explains when to use which).
enum class GridFilter : uint32_t {
    /// Piecewise constant per voxel (the default): regular tracking, exact.
    kNearest = 0,
    /// Trilinear interpolation between voxel centres, clamped to the edge voxels of the
    /// domain and zero outside the domain's cell box (Mitsuba 3's gridvolume default,
    /// filter_type="trilinear", wrap_mode="clamp"). Along a ray inside one dual cell the
    /// density is a cubic polynomial in t, so the optical depth is integrated exactly and
    /// free-flight sampling inverts it by a safeguarded Newton iteration
    /// (scene/medium_trilinear.h).
    kTrilinear = 1,
};

struct GridMediumOptions {
    GridFilter filter = GridFilter::kNearest;
    /// Inclusive voxel index range of the grid's domain (kTrilinear: lookups clamp to it and
    /// the density is 0 outside its cells). lo > hi (the default) means the grid's active
    /// index bounds. Grids converted from dense files should pass their full extent, since
    /// zero voxels at the border are not active.
    int domainLo[3] = {0, 0, 0}, domainHi[3] = {-1, -1, -1};
};

struct Medium {
    MediumType type = MediumType::kHomogeneous;
    float g = 0.0f;  ///< Henyey-Greenstein mean cosine, |g| < 1 (kernels/shared/ub_phase.h)

    // Homogeneous.
    Rgb sigmaA{0.0f}, sigmaS{0.0f};
    Rgb Le{0.0f};  ///< emitted radiance (source term sigma_a * Le)

    // Grid.
    std::shared_ptr<const VdbGrid> grid;  ///< the density; channel R of a chromatic medium
    /// Chromatic extinction: the density of channels G and B (null: grey, `grid` for all).
    std::shared_ptr<const VdbGrid> gridG, gridB;
    float densityScale = 1.0f;  ///< sigma_t = densityScale * density
    Rgb albedo{1.0f};           ///< sigma_s / sigma_t, each channel in [0, 1]
    /// Spatially varying albedo replacing `albedo` where set (null: the constant albedo).
    std::shared_ptr<const AlbedoGrid> albedoGrid;
    Transform localToWorld;  ///< grid-local space -> world
    // Derived by heterogeneous(); do not set by hand.
    Transform worldToCell;  ///< world -> cell space (index space + 1/2: voxel v covers [v, v+1))
    Bounds3 worldBounds;    ///< world bounds of the grid's active voxels (background outside)
    GridFilter filter = GridFilter::kNearest;
    int domainLo[3] = {0, 0, 0}, domainHi[3] = {-1, -1, -1};  ///< set by heterogeneous()
    /// Union of the channels' active voxel bounds, inclusive (set by heterogeneous()):
    /// background outside.
    int activeLo[3] = {0, 0, 0}, activeHi[3] = {-1, -1, -1};

    /// Whether sigma_t differs between channels as a function of position (3 grids).
    bool chromatic() const { return gridG != nullptr; }
    /// The density grid of channel c (0, 1, 2).
    const VdbGrid& channelGrid(int c) const {
        return c == 1 && gridG ? *gridG : (c == 2 && gridB ? *gridB : *grid);
    }

    /// Throws std::invalid_argument on negative or non-finite coefficients or |g| >= 1.
    static Medium homogeneous(const Rgb& sigmaA, const Rgb& sigmaS, float g,
                              const Rgb& Le = Rgb(0.0f));
    /// Throws std::invalid_argument on a null grid, densityScale < 0, albedo outside [0, 1],
    /// |g| >= 1 or a singular transform.
    static Medium heterogeneous(std::shared_ptr<const VdbGrid> grid, float densityScale,
                                const Rgb& albedo, float g,
                                const Transform& localToWorld = Transform());
    /// Same with a density filter and domain (GridMediumOptions). Throws std::invalid_argument
    /// also on an empty domain.
    static Medium heterogeneous(std::shared_ptr<const VdbGrid> grid, float densityScale,
                                const Rgb& albedo, float g, const Transform& localToWorld,
                                const GridMediumOptions& options);
    /// Chromatic extinction: one density grid per channel (R, G, B), all with the same index
    /// transform (a grey medium when the three are the same grid). Throws
    /// std::invalid_argument also on a null channel or differing transforms.
    static Medium heterogeneousRgb(const std::shared_ptr<const VdbGrid> channels[3],
                                   float densityScale, const Rgb& albedo, float g,
                                   const Transform& localToWorld,
                                   const GridMediumOptions& options = GridMediumOptions());

    bool hasEmission() const { return !isBlack(Le) && !isBlack(sigmaA); }
};

/// Single-scattering albedo of a grid medium at world point p: the albedo grid's value, else
/// the constant albedo (one branch, so media without an albedo grid pay nothing).
inline Rgb mediumAlbedoAt(const Medium& m, const Vec3& p) {
    return m.albedoGrid ? albedoGridAt(*m.albedoGrid, p) : m.albedo;
}

/// Coefficients at one point (grid: the voxel containing it, background outside).
struct MediumCoefficients {
    Rgb sigmaT, sigmaS, sigmaA;
    Rgb Le;  ///< emitted radiance (0 for grids)
};
MediumCoefficients mediumCoefficientsAt(const Medium& m, const Vec3& p);

/// Transmittance and end-point extinction of the segment x0 = origin,
/// x1 = origin + length * dir, with the pdfs of both sampling directions.
struct MediumSegment {
    float length = 0.0f;
    Rgb transmittance{1.0f};  ///< T(x0, x1) = T(x1, x0)
    Rgb sigmaT0{0.0f};        ///< extinction at x0 (of the first piece of the segment)
    Rgb sigmaT1{0.0f};        ///< extinction at x1 (of the last piece)
    Rgb sigmaS1{0.0f};        ///< scattering coefficient at x1

    /// Density (per unit length) that free-flight sampling from x0 along dir stops at x1.
    float pdfScatterFwdL() const { return average(sigmaT1 * transmittance); }
    /// Density (per unit length) that free-flight sampling from x1 along -dir stops at x0.
    float pdfScatterRevL() const { return average(sigmaT0 * transmittance); }
    /// Probability that free-flight sampling passes the whole segment (either direction).
    float probPass() const { return average(transmittance); }
};

/// Evaluates the segment by regular tracking (exact for the piecewise-constant grid).
MediumSegment evalMediumSegment(const Medium& m, const Vec3& origin, const Vec3& dir, float length);
/// exp(-tau) per channel, one exponential for a grey depth (ub_exp_neg3,
/// kernels/shared/ub_medium_homogeneous.h): the transmittance of every medium kind.
Rgb expNeg(const Rgb& tau);
/// The pieces of constant extinction of a grid medium along [0, length] of a ray, in order
/// (regular tracking, the walk evalMediumSegment makes): visit(ta, tb, sigmaT) per piece.
/// Returns false, visiting nothing, for media that are not piecewise constant along rays
/// or not grey (homogeneous media, where one closed form serves every length, trilinear
/// grids and chromatic grids).
bool gridPieces(const Medium& m, const Vec3& origin, const Vec3& dir, float length,
                const std::function<void(float, float, float)>& visit);
/// Transmittance only (the cheaper query, for shadow rays and photon beams).
Rgb transmittance(const Medium& m, const Vec3& origin, const Vec3& dir, float length);

/// Result of free-flight sampling along [0, tMax).
struct FreeFlightSample {
    bool scattered = false;  ///< true: interaction at t < tMax; false: passed (t = tMax)
    float t = 0.0f;
    MediumSegment segment;  ///< from origin to origin + t * dir (pdfs of both directions)
    float pdf = 0.0f;       ///< segment.pdfScatterFwdL() if scattered, else segment.probPass()
    /// Throughput weight: T * sigma_s / pdf if scattered, T / pdf if passed; black if the
    /// pdf underflowed to 0. (Emission at a sampled point: T * sigma_a * Le / pdf.)
    Rgb weight{0.0f};
};

/// uChannel picks the colour channel, uDistance the distance; both uniform in [0, 1).
FreeFlightSample sampleFreeFlight(const Medium& m, const Vec3& origin, const Vec3& dir, float tMax,
                                  float uChannel, float uDistance);

/// The distance sampleFreeFlight draws in a homogeneous medium from (uChannel, uDistance) when
/// the segment is long enough to hold it, the same float (kInf if sigma_t is 0 in the chosen
/// channel). The distance does not depend on the segment: Scene::traceMedia uses it to cut a
/// ray where sampling will stop (MediumTrace::truncated).
float homogeneousFlightDistance(const Medium& m, float uChannel, float uDistance);

}  // namespace ub
