#include "render/film.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <stdexcept>

namespace ub {

void Film::reset(int width, int height) {
    width_ = width;
    height_ = height;
    iterations_ = 0;
    rejected_ = 0;
    sum_.assign(size_t(width) * size_t(height) * 3, 0.0);
}

void Film::addIteration(const Image& iteration) {
    if (iteration.width != width_ || iteration.height != height_)
        throw std::logic_error("Film::addIteration: image size differs from the film size");
    // Each pixel is summed by one task, in iteration order: deterministic. The rejection count
    // is an integer sum, so it does not depend on the partition either.
    std::atomic<uint64_t> rejected{0};
    tbb::parallel_for(tbb::blocked_range<size_t>(0, iteration.pixels.size(), 4096),
                      [&](const tbb::blocked_range<size_t>& r) {
                          uint64_t bad = 0;
                          for (size_t i = r.begin(); i != r.end(); ++i) {
                              const Rgb& p = iteration.pixels[i];
                              if (!isValidContribution(p)) {
                                  ++bad;
                                  continue;
                              }
                              sum_[3 * i + 0] += p.x;
                              sum_[3 * i + 1] += p.y;
                              sum_[3 * i + 2] += p.z;
                          }
                          if (bad) rejected += bad;
                      });
    rejected_ += rejected.load();
    ++iterations_;
}

Image Film::average() const {
    Image img(width_, height_);
    if (iterations_ == 0) return img;
    double inv = 1.0 / iterations_;
    for (size_t i = 0; i < img.pixels.size(); ++i)
        img.pixels[i] = Rgb(float(sum_[3 * i] * inv), float(sum_[3 * i + 1] * inv),
                            float(sum_[3 * i + 2] * inv));
    return img;
}

void SplatBuffer::reset(int width, int height, const ContributionGuard& guard,
                        const PixelFilter& filter) {
    width_ = width;
    height_ = height;
    filter_ = filter;
    chunks_.assign(kChunkCount, Chunk());
    for (auto& c : chunks_) {
        c.width_ = width;
        c.height_ = height;
        c.guard_ = guard;
        c.filter_ = filter;
    }
}

void SplatBuffer::clear() {
    for (auto& c : chunks_) {
        c.splats_.clear();
        c.filtered_.clear();
        c.rejected_ = 0;
    }
}

std::pair<size_t, size_t> SplatBuffer::chunkRange(int chunk, size_t pathCount) {
    // Chunk c gets [c * n / K, (c + 1) * n / K): sizes differ by at most one.
    auto bound = [&](size_t c) { return size_t((unsigned __int128)(c)*pathCount / kChunkCount); };
    return {bound(size_t(chunk)), bound(size_t(chunk) + 1)};
}

void SplatBuffer::forEachChunk(size_t pathCount,
                               const std::function<void(Chunk&, size_t, size_t)>& body) {
    if (chunks_.size() != size_t(kChunkCount))
        throw std::logic_error("SplatBuffer::forEachChunk before reset()");
    tbb::parallel_for(0, kChunkCount, [&](int c) {
        auto [begin, end] = chunkRange(c, pathCount);
        body(chunks_[size_t(c)], begin, end);
    });
}

void SplatBuffer::resolve(Image& image) const {
    if (image.width != width_ || image.height != height_)
        throw std::logic_error("SplatBuffer::resolve: image size differs from the buffer size");
    for (const auto& c : chunks_) {
        for (const Splat& s : c.splats_) image.pixels[s.pixel] += s.value;
        for (const FilteredSplat& s : c.filtered_) {
            int x0, x1, y0, y1;
            filter_.footprint(s.raster, width_, height_, &x0, &x1, &y0, &y1);
            for (int y = y0; y <= y1; ++y)
                for (int x = x0; x <= x1; ++x) {
                    const float w = filter_.splatWeight(x, y, s.raster, width_, height_);
                    if (w > 0.0f)
                        image.pixels[size_t(y) * size_t(width_) + size_t(x)] += s.value * w;
                }
        }
    }
}

size_t SplatBuffer::splatCount() const {
    size_t n = 0;
    for (const auto& c : chunks_) n += c.size();
    return n;
}

uint64_t SplatBuffer::rejectedCount() const {
    uint64_t n = 0;
    for (const auto& c : chunks_) n += c.rejected_;
    return n;
}

}  // namespace ub
