// A check shared by the tests of work skipped where it cannot add to the image
// (render/vcm_camera.cpp: camera vertices at the length limit without vertex connection).
#pragma once

#include <gtest/gtest.h>

#include <cstdio>

#include "tests/support/render_stats.h"

namespace ub::test {

/// `tested` (the skipping integrator) agrees with `reference` (an unbiased one, same settings)
/// within 5 standard errors per channel, and `without` (the reference without the paths the
/// skip must keep) lies below the reference by more than `margin` times that bound, so that a
/// skip dropping those paths would fail. Prints the three means after `label`.
inline void expectSkipKeepsPaths(const char* label, const ImageMeans& reference,
                                 const ImageMeans& tested, const ImageMeans& without,
                                 double margin) {
    for (int c = 0; c < 3; ++c) {
        const double bound = reference.fiveSigmaTo(tested, c);
        std::printf(
            "[ skip     ] %s, channel %d: reference %.5f (%.5f), tested %.5f (%.5f), "
            "without the kept paths %.5f\n",
            label, c, reference.mean[c], reference.stdErr[c], tested.mean[c], tested.stdErr[c],
            without.mean[c]);
        EXPECT_NEAR(tested.mean[c], reference.mean[c], bound) << label << ", channel " << c;
        EXPECT_GT(reference.mean[c] - without.mean[c], margin * bound)
            << label << ", channel " << c;
    }
}

}  // namespace ub::test
