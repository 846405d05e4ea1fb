/* The voxel steps of regular tracking through a grid (3D-DDA, Amanatides and Woo 1987) that
 * the host's walk (scene/medium.cpp forEachPiece, which also serves chromatic grids and
 * visitors) and the kernels' (ub_grid_medium.h ub_grid_walk) share inside a leaf, so that
 * both compute the same boundaries with the same operations (tests/medium_test.cpp compares
 * their pieces bit for bit). Cell space: voxel v covers [v, v + 1) on each axis. */
#ifndef UB_GRID_DDA_H
#define UB_GRID_DDA_H

#include "ub_defs.h"

/* Where the line P + t D leaves voxel v along one axis (step: the sign of D there, not 0;
 * invD = 1 / D). */
UB_INLINE float ub_dda_exit(int v, int step, float P, float invD) {
    return ((float)(step > 0 ? v + 1 : v) - P) * invD;
}

/* The axis whose boundary tb[a] comes first, strictly before tExit and before the axes
 * ahead of it (ties go to the lower axis), and *tNext, that boundary (or tExit, with -1). */
UB_INLINE int ub_dda_nearest(UB_PRIVATE const float* tb, float tExit, UB_PRIVATE float* tNext) {
    int axis = -1;
    *tNext = tExit;
    UB_UNROLL
    for (int a = 0; a < 3; ++a) {
        const int nearer = tb[a] < *tNext;
        axis = nearer ? a : axis;
        *tNext = nearer ? tb[a] : *tNext;
    }
    return axis;
}

#endif /* UB_GRID_DDA_H */
