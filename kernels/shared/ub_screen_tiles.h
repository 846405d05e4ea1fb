/* Screen tiles for the camera rays of bb1d (photon beams) and pb2d (photon points).
 *
 * bb1d's items are segments of photon beams: a whole beam where its box lies in front of the
 * eye, else the beam's BVH parts (src/estimators/screen_tiles.cpp); "part" below is either.
 *
 * A query beam whose line passes through a pinhole camera's eye (the camera subpath's first
 * segment, at any part of it) meets a photon-beam part (a photon point) only if its direction,
 * projected to the image as the camera projects a point, falls where the part's box (the
 * photon's cube) projects. The host bins the parts and the photons by the image tiles their
 * boxes cover (src/estimators/screen_tiles.cpp), and such a query reads its tile's list
 * instead of walking the BVH: on the bunny and
 * mirrorballs these queries were a fifth to a quarter of the query beams and 40% of the nodes
 * bb1d's walk visited (docs/performance.md, session 39).
 *
 * Why a tile holds every part a query of it can pair with (each step a bound, not an
 * estimate):
 *  - a query qualifies (ub_screen_tile_of) when its line is within `tolerance` of the eye
 *    (|(o - eye) x d| <= tolerance), its origin is not behind the eye along d by more than
 *    tolerance, and its direction projects inside the image;
 *  - a point X = o + t d (t >= 0) of the query is then within tolerance of the point X0 =
 *    eye + s d (s >= -tolerance) of the exact line through the eye;
 *  - a pair needs X within r of the part's segment, so X0 lies within r + tolerance of it, in
 *    the part's box: the segment grown by r + 2 tolerance along itself and along two axes
 *    across it (an oriented box; the second tolerance is for rounding); for pb2d, X within r
 *    of the photon, and the box is the cube of half-width r + 2 tolerance around it;
 *  - if every corner of the box is in front of the eye (depth > tolerance), X0 is too, so
 *    s > 0 and X0 projects where d does; the box is convex and projection keeps segments
 *    straight in front of the eye, so X0 projects into the convex hull of the corners'
 *    projections: in each row of tiles, the host lists the part in the tiles that the hull's
 *    span across the row's band covers (band and span widened by 1/64 pixel against
 *    rounding);
 *  - a box with every corner behind the eye by more than tolerance holds no such X0 and is
 *    left out; any other part (a box across the eye's plane, or whose hull's spans cover more
 *    tiles than the host allows) goes into the list every tile reads, number tilesX * tilesY.
 * Each tile's list is a run of blocks of four, as the BVH leaves hold them (ub_beam_keys4,
 * kernels/shared/ub_bvh.h; ub_photon_keys4, ub_upbp_records.h), with the items' indices
 * beside them; unused lanes have empty ranges (t0 = t1 = +infinity) or no medium, which the
 * filters reject. Items are listed in ascending index, so the host twin and the kernel find
 * the same candidates in the same order.
 */
#ifndef UB_SCREEN_TILES_H
#define UB_SCREEN_TILES_H

#include "ub_vec3.h"

typedef struct {
    float eye[3];
    float tolerance; /* world distance: see the banner */
    float right[3];
    float imagePlaneDist; /* as src/scene/camera.h: raster = dot(v, right) * dist / depth ... */
    float up[3];
    float width; /* raster size, pixels */
    float forward[3];
    float height;
    ub_uint tileSize; /* pixels */
    ub_uint tilesX, tilesY;
    ub_uint enabled; /* 0: no query qualifies (no pinhole camera, or no tiles built) */
} ub_screen_tiles;

/* The raster position of the point eye + v, as Camera::worldToRaster computes it
 * (src/scene/camera.cpp), for v in front of the eye (depth > 0, not checked). */
UB_INLINE void ub_screen_raster(ub_screen_tiles s, ub_float3 v, UB_PRIVATE float* x,
                                UB_PRIVATE float* y) {
    float scale = s.imagePlaneDist / ub_f3_dot(v, ub_f3_from(s.forward));
    *x = ub_f3_dot(v, ub_f3_from(s.right)) * scale + 0.5f * s.width;
    *y = 0.5f * s.height - ub_f3_dot(v, ub_f3_from(s.up)) * scale;
}

/* The tile whose list holds every part a query beam (origin o, unit direction d) can pair
 * with, or -1 when the query does not qualify (it then walks the BVH). */
UB_INLINE int ub_screen_tile_of(ub_screen_tiles s, ub_float3 o, ub_float3 d) {
    if (!s.enabled) return -1;
    ub_float3 v = ub_f3_sub(o, ub_f3_from(s.eye));
    if (ub_f3_dot(v, d) < -s.tolerance) return -1;
    ub_float3 c = ub_f3_cross(v, d);
    if (!(ub_f3_dot(c, c) <= s.tolerance * s.tolerance)) return -1;
    if (!(ub_f3_dot(d, ub_f3_from(s.forward)) > 1e-3f)) return -1;
    float x, y;
    ub_screen_raster(s, d, &x, &y);
    if (!(x >= 0.0f && x < s.width && y >= 0.0f && y < s.height)) return -1;
    ub_uint tx = (ub_uint)x / s.tileSize, ty = (ub_uint)y / s.tileSize;
    if (tx >= s.tilesX) tx = s.tilesX - 1u;
    if (ty >= s.tilesY) ty = s.tilesY - 1u;
    return (int)(ty * s.tilesX + tx);
}

#ifndef __OPENCL_C_VERSION__
#include <cstddef>
static_assert(sizeof(ub_screen_tiles) == 80, "ub_screen_tiles layout");
static_assert(offsetof(ub_screen_tiles, tileSize) == 64, "ub_screen_tiles layout");
#endif

#endif /* UB_SCREEN_TILES_H */
