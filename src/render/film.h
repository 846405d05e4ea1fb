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
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "core/image.h"

namespace ub {

class Film {
  public:
    Film() = default;
    Film(int width, int height) { reset(width, height); }
    void reset(int width, int height);

    /// Adds one iteration's image (must have the film's size).
    void addIteration(const Image& iteration);
    /// Average of the iterations added so far (black if none).
    Image average() const;
    int iterations() const { return iterations_; }
    int width() const { return width_; }
    int height() const { return height_; }

  private:
    int width_ = 0, height_ = 0;
    int iterations_ = 0;
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

    class Chunk {
      public:
        /// Adds value to the pixel containing raster position (x right, y down); positions
        /// outside the image are ignored.
        void add(const Vec2& raster, const Rgb& value) {
            if (!(raster.x >= 0 && raster.y >= 0)) return;  // also rejects NaN
            int x = int(raster.x), y = int(raster.y);
            if (x >= width_ || y >= height_) return;
            splats_.push_back({uint32_t(y) * uint32_t(width_) + uint32_t(x), value});
        }
        /// Adds value to pixel (x, y) (must be inside the image).
        void addPixel(int x, int y, const Rgb& value) {
            splats_.push_back({uint32_t(y) * uint32_t(width_) + uint32_t(x), value});
        }
        size_t size() const { return splats_.size(); }

      private:
        friend class SplatBuffer;
        int width_ = 0, height_ = 0;
        std::vector<Splat> splats_;
    };

    SplatBuffer() = default;
    SplatBuffer(int width, int height) { reset(width, height); }
    void reset(int width, int height);
    /// Empties every chunk (keeps the allocations).
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

  private:
    int width_ = 0, height_ = 0;
    std::vector<Chunk> chunks_;
};

}  // namespace ub
