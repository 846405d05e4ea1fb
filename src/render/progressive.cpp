#include "render/progressive.h"

#include <algorithm>
#include <chrono>
#include <csignal>
#include <stdexcept>
#include <vector>

#include "core/memory_budget.h"
#include "render/film.h"

namespace ub {

namespace {

std::atomic<bool> gStop{false};
volatile std::sig_atomic_t gLastSignal = 0;

extern "C" void onStopSignal(int sig) {
    // Only async-signal-safe work here: a lock-free atomic store and signal().
    gLastSignal = sig;
    gStop.store(true, std::memory_order_relaxed);
    std::signal(sig, SIG_DFL);  // a second signal terminates at once
}

}  // namespace

std::atomic<bool>& stopRequested() {
    return gStop;
}

int lastStopSignal() {
    return int(gLastSignal);
}

void installStopSignalHandlers() {
    static_assert(std::atomic<bool>::is_always_lock_free, "stop flag must be lock-free");
    std::signal(SIGINT, onStopSignal);
    std::signal(SIGTERM, onStopSignal);
}

ProgressiveResult renderProgressive(Integrator& integrator, int width, int height,
                                    const ProgressiveOptions& options) {
    if (options.iterations <= 0 && options.timeLimitSeconds <= 0)
        throw std::invalid_argument("renderProgressive: give an iteration count or a time limit");
    const std::atomic<bool>& stop = options.stop ? *options.stop : gStop;
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };

    Film film(width, height);
    Image iterationImage(width, height);
    const std::vector<std::string> layerNames = integrator.layerNames();
    std::vector<Film> layerFilms(layerNames.size(), Film(width, height));
    ProgressiveResult result;
    // Welford's running mean and sum of squared deviations, per pixel and channel.
    std::vector<double> wMean, wM2;
    if (options.computeVariance) {
        wMean.assign(size_t(width) * height * 3, 0.0);
        wM2.assign(size_t(width) * height * 3, 0.0);
    }
    const ProgressiveState* resume = options.resume;
    double secondsBefore = 0;
    int firstIteration = 0;
    if (resume) {
        if (resume->layers.size() != layerFilms.size() ||
            resume->hasVariance != options.computeVariance)
            throw std::invalid_argument(
                "renderProgressive: the checkpoint's layers or variance do not match the render");
        for (size_t l = 0; l < layerFilms.size(); ++l) {
            if (resume->layerNames[l] != layerNames[l])
                throw std::invalid_argument("renderProgressive: checkpoint layer '" +
                                            resume->layerNames[l] + "' is not '" + layerNames[l] +
                                            "'");
            layerFilms[l].restore(resume->iterations, resume->layers[l], resume->layerRejected[l]);
        }
        film.restore(resume->iterations, resume->film, resume->filmRejected);
        if (options.computeVariance) {
            wMean = resume->varianceMean;
            wM2 = resume->varianceM2;
        }
        secondsBefore = resume->seconds;
        firstIteration = resume->iterations;
    }
    auto totalSeconds = [&] { return secondsBefore + elapsed(); };
    // The integrator's rejection counts, plus those of the checkpoint resumed from.
    auto rejectedSoFar = [&] {
        RejectionCounts counts = integrator.rejectedContributions();
        if (resume)
            for (const auto& entry : resume->rejected) {
                // (not a structured binding: C++17 lambdas cannot capture those; clang rejects)
                const std::string& name = entry.first;
                auto it = std::find_if(counts.begin(), counts.end(),
                                       [&](const auto& c) { return c.first == name; });
                if (it == counts.end())
                    counts.emplace_back(name, entry.second);
                else
                    it->second += entry.second;
            }
        return counts;
    };
    auto makeState = [&] {
        ProgressiveState st;
        st.iterations = film.iterations();
        st.seconds = totalSeconds();
        st.film = film.sums();
        st.filmRejected = film.rejected();
        st.layerNames = layerNames;
        for (const Film& f : layerFilms) {
            st.layers.push_back(f.sums());
            st.layerRejected.push_back(f.rejected());
        }
        st.hasVariance = options.computeVariance;
        st.varianceMean = wMean;
        st.varianceM2 = wM2;
        st.rejected = rejectedSoFar();
        return st;
    };
    double lastCheckpoint = 0;
    for (int it = firstIteration;; ++it) {
        if (options.iterations > 0 && it >= options.iterations) break;
        if (it > 0) {
            if (options.timeLimitSeconds > 0 && totalSeconds() >= options.timeLimitSeconds) break;
            if (stop.load(std::memory_order_relaxed)) {
                result.interrupted = true;
                break;
            }
        }
        try {
            integrator.renderIteration(it, iterationImage);
        } catch (const ResourceError& e) {
            if (film.iterations() == 0) throw;
            result.stopError = e.what();
            result.interrupted = true;
            break;
        }
        film.addIteration(iterationImage);
        if (const std::vector<Image>* layers = integrator.iterationLayers())
            for (size_t l = 0; l < layerFilms.size() && l < layers->size(); ++l)
                layerFilms[l].addIteration((*layers)[l]);
        if (options.computeVariance) {
            for (size_t i = 0; i < iterationImage.pixels.size(); ++i)
                for (int c = 0; c < 3; ++c) {
                    // What the film adds: nothing for a pixel it rejects.
                    const double x = isValidContribution(iterationImage.pixels[i])
                                         ? double(iterationImage.pixels[i][c])
                                         : 0.0;
                    double& mean = wMean[i * 3 + c];
                    const double delta = x - mean;
                    mean += delta / double(it + 1);
                    wM2[i * 3 + c] += delta * (x - mean);
                }
        }

        if (options.progress) {
            ProgressInfo info;
            info.iteration = it + 1;
            info.targetIterations = std::max(0, options.iterations);
            info.elapsedSeconds = totalSeconds();
            info.timeLimitSeconds = std::max(0.0, options.timeLimitSeconds);
            double perIteration = info.elapsedSeconds / info.iteration;
            double eta = -1;
            if (options.iterations > 0) eta = perIteration * (options.iterations - info.iteration);
            if (options.timeLimitSeconds > 0) {
                double etaTime = std::max(0.0, options.timeLimitSeconds - info.elapsedSeconds);
                eta = eta < 0 ? etaTime : std::min(eta, etaTime);
            }
            info.etaSeconds = eta;
            options.progress(info);
        }
        if (options.checkpoint && options.checkpointEverySeconds > 0 &&
            elapsed() - lastCheckpoint >= options.checkpointEverySeconds) {
            options.checkpoint(makeState());
            lastCheckpoint = elapsed();
        }
    }
    if (options.checkpoint) options.checkpoint(makeState());
    result.rejected = rejectedSoFar();
    uint64_t filmRejected = film.rejected();
    for (const Film& f : layerFilms) filmRejected += f.rejected();
    result.rejected.emplace_back("film", filmRejected);
    result.iterations = film.iterations();
    result.seconds = totalSeconds();
    result.image = film.average();
    for (size_t l = 0; l < layerFilms.size(); ++l)
        result.layers.emplace_back(layerNames[l], layerFilms[l].average());
    if (options.computeVariance && result.iterations >= 2) {
        result.variance = Image(width, height);
        for (size_t i = 0; i < result.variance.pixels.size(); ++i)
            for (int c = 0; c < 3; ++c)
                result.variance.pixels[i][c] = float(wM2[i * 3 + c] / (result.iterations - 1));
    }
    return result;
}

}  // namespace ub
