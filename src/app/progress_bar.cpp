#include "app/progress_bar.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace ub {

std::string formatSeconds(double s) {
    char buf[64];
    if (s < 0) return "?";
    if (s < 60) {
        std::snprintf(buf, sizeof(buf), "%.1f s", s);
    } else if (s < 3600) {
        int m = int(s / 60);
        std::snprintf(buf, sizeof(buf), "%d min %02d s", m, int(s - 60 * m));
    } else {
        int h = int(s / 3600);
        std::snprintf(buf, sizeof(buf), "%d h %02d min", h, int((s - 3600 * h) / 60));
    }
    return buf;
}

ProgressBar::ProgressBar(std::FILE* out, bool interactive, double intervalSeconds)
    : out_(out), interactive_(interactive), interval_(intervalSeconds) {}

void ProgressBar::update(const ProgressInfo& info) {
    last_ = info;
    std::string its = std::to_string(info.iteration);
    if (info.targetIterations > 0) its += "/" + std::to_string(info.targetIterations);
    std::string eta = info.etaSeconds >= 0 ? formatSeconds(info.etaSeconds) : "?";
    if (interactive_) {
        // Redraw at most 10 times a second; finish() draws the final state.
        lastShown_ = false;
        if (drawn_ && info.elapsedSeconds - lastPrinted_ < 0.1) return;
        lastPrinted_ = info.elapsedSeconds;
        lastShown_ = true;
        double fraction = 0;
        if (info.targetIterations > 0) fraction = double(info.iteration) / info.targetIterations;
        if (info.timeLimitSeconds > 0)
            fraction = std::max(fraction, info.elapsedSeconds / info.timeLimitSeconds);
        fraction = std::clamp(fraction, 0.0, 1.0);
        const int width = 30;
        int filled = int(std::lround(fraction * width));
        std::string bar(size_t(filled), '#');
        bar += std::string(size_t(width - filled), '-');
        std::fprintf(out_, "\r[%s] %s it  %s elapsed  ETA %s\x1b[K", bar.c_str(), its.c_str(),
                     formatSeconds(info.elapsedSeconds).c_str(), eta.c_str());
        std::fflush(out_);
        drawn_ = true;
        return;
    }
    lastShown_ = false;
    if (info.elapsedSeconds - lastPrinted_ < interval_) return;
    std::fprintf(out_, "unibeam: iteration %s, %s elapsed, ETA %s\n", its.c_str(),
                 formatSeconds(info.elapsedSeconds).c_str(), eta.c_str());
    std::fflush(out_);
    lastPrinted_ = info.elapsedSeconds;
    lastShown_ = true;
}

void ProgressBar::finish() {
    if (interactive_) {
        if (!lastShown_) {
            drawn_ = false;
            update(last_);
        }
        if (drawn_) std::fputc('\n', out_);
    } else if (!lastShown_) {
        lastPrinted_ = -1e30;
        update(last_);
    }
    std::fflush(out_);
}

}  // namespace ub
