// A bound on the memory of one render's per-iteration records and lookups
// (--max-memory): light vertices, photon points and beams, query points and beams,
// their concatenated copies, and the lookup structures of the estimate pass.
//
// Every container counted here reserves its growth before it allocates (reserveFor /
// pushBudgeted), so the bound is checked before the memory is taken, and a render that
// would exceed it stops with a MemoryBudgetError naming what grew and which options make
// it smaller. Containers keep their capacity between iterations (they are cleared, not
// freed), so a reservation is held as long as the capacity is; lookups built and freed
// within an iteration hold theirs through a MemoryReservation.
#pragma once

#include <atomic>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

namespace ub {

/// A render ran out of a resource it was given: the memory budget, or an OpenCL device's
/// resources (cl/cl_runtime.h ClError). The CLI answers with exit status 2, after writing
/// the iterations that finished.
class ResourceError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

class MemoryBudgetError : public ResourceError {
  public:
    using ResourceError::ResourceError;
};

class MemoryBudget {
  public:
    explicit MemoryBudget(size_t limitBytes = 0) : limit_(limitBytes) {}
    /// 0: no limit.
    size_t limit() const { return limit_; }
    size_t used() const { return used_.load(std::memory_order_relaxed); }
    size_t peak() const { return peak_.load(std::memory_order_relaxed); }
    /// Takes `bytes` for `what` (e.g. "photon beams"), or throws MemoryBudgetError with
    /// `advice` (which options need less) when the limit would be exceeded. Thread-safe.
    void reserve(size_t bytes, const char* what, const char* advice);
    void release(size_t bytes) { used_.fetch_sub(bytes, std::memory_order_relaxed); }

  private:
    size_t limit_;
    std::atomic<size_t> used_{0}, peak_{0};
};

/// Bytes reserved while alive (lookups of one iteration).
class MemoryReservation {
  public:
    MemoryReservation(MemoryBudget* b, size_t bytes, const char* what, const char* advice)
        : budget_(b), bytes_(b ? bytes : 0) {
        if (budget_) budget_->reserve(bytes_, what, advice);
    }
    ~MemoryReservation() {
        if (budget_) budget_->release(bytes_);
    }
    MemoryReservation(const MemoryReservation&) = delete;
    MemoryReservation& operator=(const MemoryReservation&) = delete;

  private:
    MemoryBudget* budget_;
    size_t bytes_;
};

/// Makes room for n elements in v, reserving the capacity growth first.
template <class T>
void reserveFor(std::vector<T>& v, size_t n, MemoryBudget* b, const char* what,
                const char* advice) {
    if (n <= v.capacity()) return;
    const size_t cap = std::max(n, 2 * v.capacity());
    if (b) b->reserve((cap - v.capacity()) * sizeof(T), what, advice);
    v.reserve(cap);
}

/// v.push_back(x), reserving the capacity growth first.
template <class T>
void pushBudgeted(std::vector<T>& v, const T& x, MemoryBudget* b, const char* what,
                  const char* advice) {
    if (v.size() == v.capacity()) reserveFor(v, v.size() + 1, b, what, advice);
    v.push_back(x);
}

/// Parses a size: a number with an optional K, M, G or T suffix (powers of 1024; "B" or
/// "iB" may follow). Throws std::invalid_argument with what was expected.
size_t parseMemorySize(const std::string& text);

/// Half of the machine's physical memory (the --max-memory default).
size_t defaultMemoryBudget();

}  // namespace ub
