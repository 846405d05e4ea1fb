// The contribution guard: no NaN, infinity or negative value ever reaches an image.
//
// One bad sample (a NaN from 0/0 in a pdf, an infinity from a vanishing pdf, a negative value
// from a rounding error in a MIS weight) would spoil its pixel for the rest of a progressive
// render. Every integrator therefore passes each contribution it adds to an image through a
// ContributionGuard, with one check per contribution (isValidContribution); an invalid one is
// dropped (the image gets nothing) and counted for its technique. A contribution is what one
// technique adds to one pixel in one step:
//   * pt, vpt and the camera pass of the bidirectional engine: a pixel's camera-path estimate
//     of an iteration (technique: the -a algorithm; upbp: its first layer, "bpt" or
//     "emitted");
//   * light tracing (lt, bpt, vcm, vlt, vbpt, upbp): one splat (SplatBuffer::Chunk::add);
//   * upbp's surface merging ("surf") per pixel and iteration, and its volumetric estimators
//     ("pp3d", "pb2d", "bp2d", "bb1d") per query point or query beam;
// and the Film checks every pixel of every iteration once more (technique "film": a pixel
// whose valid contributions summed to an infinity).
//
// Counts are integers summed per chunk, row or query in a fixed order, so they do not depend
// on the thread count. The render command prints them and writes them into the EXR header
// (docs/cli.md, "Rejected contributions").
//
// Fault injection (tests only): ContributionFault makes one technique's contributions invalid
// for some pixels, so that the tests can check the guard end to end. It is set through
// RenderOptions::testFault, which the command-line program never sets.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "core/vec.h"

namespace ub {

/// True if every channel of v is finite and >= 0 (a NaN fails every comparison; -0 passes).
inline bool isValidContribution(const Rgb& v) {
    constexpr float kMax = std::numeric_limits<float>::max();
    return v.x >= 0.0f && v.x <= kMax && v.y >= 0.0f && v.y <= kMax && v.z >= 0.0f && v.z <= kMax;
}

/// Test-only fault injection (see the header comment).
struct ContributionFault {
    std::string technique;  ///< the technique whose contributions are faulted ("": none)
    uint32_t every = 0;     ///< fault the contributions to pixels with index % every == 0
    float value = std::numeric_limits<float>::quiet_NaN();  ///< faulted channel value
};

/// Per-technique counts of rejected contributions, in the integrator's technique order.
using RejectionCounts = std::vector<std::pair<std::string, uint64_t>>;

/// Guards the contributions of one technique.
class ContributionGuard {
  public:
    ContributionGuard() = default;
    /// A guard for `technique`, faulting it if fault.technique names it (tests only).
    ContributionGuard(const std::string& technique, const ContributionFault& fault) {
        if (fault.every > 0 && fault.technique == technique) {
            faultEvery_ = fault.every;
            faultValue_ = fault.value;
        }
    }
    /// Checks *value, a contribution to pixel index `pixel` (y * width + x): true if it may be
    /// added; otherwise sets it to black and increments *rejected. (With a fault for this
    /// technique, *value is first replaced by the fault's value at the faulted pixels.)
    bool filter(uint32_t pixel, Rgb* value, uint64_t* rejected) const {
        if (faultEvery_ != 0 && pixel % faultEvery_ == 0) *value = Rgb(faultValue_);
        if (isValidContribution(*value)) return true;
        *value = Rgb(0.0f);
        ++*rejected;
        return false;
    }
    /// The same without changing the value.
    bool accept(uint32_t pixel, Rgb value, uint64_t* rejected) const {
        return filter(pixel, &value, rejected);
    }

  private:
    uint32_t faultEvery_ = 0;
    float faultValue_ = 0.0f;
};

/// "pt 0, film 0": the counts in order.
std::string formatRejections(const RejectionCounts& counts);
/// EXR header attributes: "unibeam.rejected.<technique>" = count, one per technique.
std::vector<std::pair<std::string, std::string>> rejectionAttributes(const RejectionCounts& counts);

/// Renders one value per pixel in parallel over rows: out(x, y) = trace(x, y) after the
/// guard, rejections counted per row (rowRejected, resized here) and added to *rejected in row
/// order, so the count does not depend on the thread count (pt, vpt).
template <class Image, class Trace>
void renderGuardedRows(int width, int height, const ContributionGuard& guard,
                       std::vector<uint64_t>& rowRejected, uint64_t* rejected, Image& out,
                       Trace&& trace) {
    rowRejected.assign(size_t(height), 0);
    tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& r) {
        for (int y = r.begin(); y != r.end(); ++y)
            for (int x = 0; x < width; ++x) {
                Rgb v = trace(x, y);
                guard.filter(uint32_t(y) * uint32_t(width) + uint32_t(x), &v,
                             &rowRejected[size_t(y)]);
                out.at(x, y) = v;
            }
    });
    for (uint64_t n : rowRejected) *rejected += n;
}

}  // namespace ub
