// Film: where iterations of a progressive render accumulate.
//
// Film sums the per-iteration images of a progressive render (one sample per
// pixel each) in double precision and returns their average. Iterations are
// added one at a time in iteration order, so the result for a given seed does
// not depend on the number of threads.
//
// SplatBuffer: deterministic splatting for light-tracing techniques (lt, bpt,
// vcm, ...), whose light subpaths hit arbitrary pixels. Adding to a shared
// image from several threads would make the floating-point summation order,
// and so the image, depend on scheduling. Instead:
//   * the light subpaths of an iteration, indexed 0..pathCount-1, are split
//     into a FIXED number of chunks (kChunkCount, independent of the thread
//     count), chunk c holding the contiguous index range returned by
//     chunkRange(c, pathCount);
//   * each chunk is traced by one task, in index order, and records its splats
//     (pixel, value) in its own buffer, in the order they are made;
//   * resolve() adds the chunk buffers to the image in chunk order 0, 1, 2, ...
// Every pixel therefore receives its splats in the same order whatever the
// number of threads and the scheduling, and the image is bit-identical.
// Buffers are splat lists (not full images) so memory grows with the number
// of splats, not with kChunkCount x resolution; they keep their capacity
// between iterations.
//
// Typical use in an integrator:
//     splats.clear();
//     splats.forEachChunk(pathCount, [&](SplatBuffer::Chunk& chunk, size_t begin, size_t end) {
//         for (size_t i = begin; i < end; ++i) { ... chunk.add(raster, value); ... }
//     });
//     splats.resolve(image);   // image += splats, in a fixed order
//
// With a reconstruction filter other than the box (scene/pixel_filter.h), a splat is recorded
// with its raster position and resolve() spreads it over the pixels of the filter's footprint,
// each weighted by the normalised filter fhat of that pixel (PixelFilter::splatWeight).
//
// Both are guarded (render/contribution_guard.h): a splat that is NaN, infinite or negative is
// dropped and counted by its chunk (rejectedCount(), the chunks' counts summed), and
// Film::addIteration drops and counts every such pixel of an iteration (rejected()).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <utility>
#include <vector>

#include "core/image.h"
#include "render/contribution_guard.h"
#include "scene/pixel_filter.h"

namespace ub {

class Film {
  public:
    Film() = default;
    Film(int width, int height) { reset(width, height); }
    void reset(int width, int height);

    /// Adds one iteration's image (must have the film's size). A pixel with a NaN, infinite
    /// or negative channel adds nothing and is counted in rejected().
    void addIteration(const Image& iteration);
    /// Pixels of the added iterations rejected by the guard.
    uint64_t rejected() const { return rejected_; }
    /// Average of the iterations added so far (black if none).
    Image average() const;
    int iterations() const { return iterations_; }
    /// The sums (3 per pixel, double) and the rejection count, for checkpoints.
    const std::vector<double>& sums() const { return sum_; }
    /// Continues from a checkpoint: `iterations` iterations whose sums are `sums`.
    void restore(int iterations, const std::vector<double>& sums, uint64_t rejected) {
        if (sums.size() != sum_.size())
            throw std::logic_error("Film::restore: the sums do not have the film's size");
        iterations_ = iterations;
        sum_ = sums;
        rejected_ = rejected;
    }
    int width() const { return width_; }
    int height() const { return height_; }

  private:
    int width_ = 0, height_ = 0;
    int iterations_ = 0;
    uint64_t rejected_ = 0;
    std::vector<double> sum_;  ///< 3 per pixel
};

class SplatBuffer {
  public:
    /// Number of chunks: fixed, so results never depend on the thread count. 64 chunks
    /// keep 2-64 threads busy with little imbalance.
    static constexpr int kChunkCount = 64;

    struct Splat {
        uint32_t pixel;  ///< y * width + x
        Rgb value;
    };
    /// A splat of a filtered film: its raster position, spread over the footprint in resolve().
    struct FilteredSplat {
        Vec2 raster;
        Rgb value;
    };

    class Chunk {
      public:
        /// Adds value to the pixel containing raster position (x right, y down), or with a
        /// filter to the pixels of its footprint; positions outside the image are ignored. A
        /// NaN, infinite or negative value is dropped and counted (rejected()).
        void add(const Vec2& raster, const Rgb& value) {
            if (!(raster.x >= 0 && raster.y >= 0)) return;  // also rejects NaN
            int x = int(raster.x), y = int(raster.y);
            if (x >= width_ || y >= height_) return;
            if (filter_.isBox()) {
                addPixel(x, y, value);
                return;
            }
            Rgb v = value;
            const uint32_t pixel = uint32_t(y) * uint32_t(width_) + uint32_t(x);
            if (guard_.filter(pixel, &v, &rejected_)) filtered_.push_back({raster, v});
        }
        /// Adds value to pixel (x, y) (must be inside the image); guarded like add().
        void addPixel(int x, int y, Rgb value) {
            const uint32_t pixel = uint32_t(y) * uint32_t(width_) + uint32_t(x);
            if (guard_.filter(pixel, &value, &rejected_)) splats_.push_back({pixel, value});
        }
        size_t size() const { return splats_.size() + filtered_.size(); }
        /// Splats rejected by the guard since the last clear().
        uint64_t rejected() const { return rejected_; }

      private:
        friend class SplatBuffer;
        int width_ = 0, height_ = 0;
        uint64_t rejected_ = 0;
        ContributionGuard guard_;
        PixelFilter filter_;
        std::vector<Splat> splats_;
        std::vector<FilteredSplat> filtered_;
    };

    SplatBuffer() = default;
    SplatBuffer(int width, int height) { reset(width, height); }
    /// guard: the technique's guard (fault injection in tests; default: none); filter: the
    /// scene's reconstruction filter.
    void reset(int width, int height, const ContributionGuard& guard = ContributionGuard(),
               const PixelFilter& filter = PixelFilter());
    /// Empties every chunk (keeps the allocations) and zeroes the rejection counts.
    void clear();

    /// Index range [begin, end) of the paths that chunk `chunk` traces.
    static std::pair<size_t, size_t> chunkRange(int chunk, size_t pathCount);
    /// Runs body(chunk, begin, end) for every chunk, in parallel (TBB); each chunk is run
    /// by exactly one task. body must only write to its own chunk.
    void forEachChunk(size_t pathCount, const std::function<void(Chunk&, size_t, size_t)>& body);
    Chunk& chunk(int c) { return chunks_[size_t(c)]; }

    /// image += every splat, chunk 0 first, each chunk in recording order.
    void resolve(Image& image) const;
    /// Total number of splats recorded since clear().
    size_t splatCount() const;
    /// Splats rejected by the guard since clear() (the chunks' counts, summed).
    uint64_t rejectedCount() const;

  private:
    int width_ = 0, height_ = 0;
    PixelFilter filter_;
    std::vector<Chunk> chunks_;
};

}  // namespace ub
