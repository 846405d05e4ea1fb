// Progress display of a render on stderr.
//  * On a terminal (isatty): one line redrawn in place (at most 10 times a second),
//      [##########----------]  12/100 it   3.2 s elapsed   ETA 24.1 s
//    (for time-limited renders the bar shows elapsed / limit).
//  * Otherwise (log files, CI): a plain line at most every `intervalSeconds`,
//      unibeam: iteration 12/100, 3.2 s elapsed, ETA 24.1 s
//    and always one for the last iteration.
#pragma once

#include <cstdio>
#include <string>

#include "render/progressive.h"

namespace ub {

class ProgressBar {
  public:
    /// interactive: redraw in place (use isatty(fileno(out))).
    ProgressBar(std::FILE* out, bool interactive, double intervalSeconds = 2.0);
    void update(const ProgressInfo& info);
    /// Ends the display (newline after an in-place bar, last plain line if not yet shown).
    void finish();

  private:
    std::FILE* out_;
    bool interactive_;
    double interval_;
    double lastPrinted_ = -1e30;
    bool drawn_ = false;
    bool lastShown_ = true;
    ProgressInfo last_;
};

/// "3.2 s", "4 min 05 s", "1 h 02 min".
std::string formatSeconds(double seconds);

}  // namespace ub
