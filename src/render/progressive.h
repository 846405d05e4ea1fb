// Progressive rendering loop: runs iterations of an Integrator (one sample per
// pixel each) into a Film until an iteration count or a time limit is
// reached, or a stop is requested.
//
// Stopping rules:
//  * iterations > 0: exactly that many iterations (unless stopped earlier);
//  * timeLimitSeconds > 0: iterations are started while the elapsed time is
//    below the limit, so the render ends after the iteration during which the
//    limit was reached (it may overrun by up to one iteration; at least one
//    iteration is always rendered);
//  * both given: whichever comes first;
//  * stop flag: checked between iterations. A request finishes the current
//    iteration and returns what has been accumulated (at least one iteration).
//
// installStopSignalHandlers() makes SIGINT and SIGTERM set stopRequested();
// a second SIGINT/SIGTERM restores the default action, so pressing Ctrl-C
// twice kills the program at once.
#pragma once

#include <atomic>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "core/image.h"
#include "render/checkpoint.h"
#include "render/integrator.h"

namespace ub {

struct ProgressInfo {
    int iteration = 0;         ///< iterations finished
    int targetIterations = 0;  ///< 0 if the render is time-limited only
    double elapsedSeconds = 0;
    double timeLimitSeconds = 0;  ///< 0 if none
    /// Estimated seconds left (from the mean iteration time), < 0 if unknown.
    double etaSeconds = -1;
};

struct ProgressiveOptions {
    int iterations = 0;           ///< > 0: number of iterations
    double timeLimitSeconds = 0;  ///< > 0: wall-clock limit
    /// Called after every iteration, on the calling thread.
    std::function<void(const ProgressInfo&)> progress;
    /// Stop flag polled between iterations (nullptr: use the global one set by the
    /// signal handlers, see stopRequested()).
    const std::atomic<bool>* stop = nullptr;
    /// Also estimate the per-pixel variance of one iteration (ProgressiveResult::variance).
    bool computeVariance = false;
    /// Continue from this state (render/checkpoint.h): its iterations count towards
    /// `iterations`, its seconds towards `timeLimitSeconds`. Must match the render (size,
    /// layers, variance), else std::invalid_argument.
    const ProgressiveState* resume = nullptr;
    /// Called with the accumulated state every checkpointEverySeconds (> 0) after an
    /// iteration, and once at the end; on the calling thread.
    double checkpointEverySeconds = 0;
    std::function<void(const ProgressiveState&)> checkpoint;
};

struct ProgressiveResult {
    Image image;  ///< average of the rendered iterations
    /// With computeVariance and >= 2 iterations: per-pixel, per-channel unbiased sample
    /// variance of the iteration images, sum (x_i - mean)^2 / (n - 1) (Welford's update in
    /// double precision). The variance of `image` is variance / iterations.
    Image variance;
    /// The integrator's per-technique layers (Integrator::layerNames), averaged like image.
    std::vector<std::pair<std::string, Image>> layers;
    /// Contributions dropped by the guard (render/contribution_guard.h): the integrator's
    /// techniques (Integrator::rejectedContributions), then "film", the pixels of iteration
    /// images (beauty and layers) the films dropped.
    RejectionCounts rejected;
    int iterations = 0;
    double seconds = 0;        ///< wall-clock time of the iterations
    bool interrupted = false;  ///< stopped by the stop flag before the target was reached
    /// Non-empty: an iteration after the first ran out of a resource (ResourceError: the
    /// memory budget, an OpenCL device; the first iteration's error propagates); the result
    /// holds the finished iterations.
    std::string stopError;
};

/// Renders width x height iterations of `integrator`. Throws std::invalid_argument if
/// neither an iteration count nor a time limit is given.
ProgressiveResult renderProgressive(Integrator& integrator, int width, int height,
                                    const ProgressiveOptions& options);

/// The process-wide stop flag (set by the signal handlers).
std::atomic<bool>& stopRequested();
/// Installs SIGINT/SIGTERM handlers that set stopRequested() (see the header comment).
void installStopSignalHandlers();
/// Signal number that set the stop flag last (0 if none).
int lastStopSignal();

}  // namespace ub
