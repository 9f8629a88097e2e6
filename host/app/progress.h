// Progress on stderr: spp done, elapsed, ETA and the half-buffer error estimate. Style Bar: one
// line redrawn with a carriage return (a terminal); Lines: one plain line per iteration (a log,
// no control characters); None: nothing. With a minimum interval, an update within it of the
// last one drawn is left out (the last iteration's never is): under mpirun, which stops reading
// the ranks' output when it is interrupted, a rank printing hundreds of lines a second would
// fill the pipe and block in the write before the stop signal reaches it.
#pragma once

#include <chrono>
#include <cstdio>
#include <optional>
#include <string>

namespace spw {

class ProgressBar {
  public:
    enum class Style { None, Bar, Lines };
    explicit ProgressBar(Style style, double minIntervalSeconds = 0.0)
        : style_(style), minInterval_(minIntervalSeconds),
          start_(std::chrono::steady_clock::now()) {}
    void update(int done, int total, int sppDone, int sppTotal, std::optional<double> relMse);
    void finish();

  private:
    Style style_;
    double minInterval_;
    std::optional<double> lastDrawn_; // elapsed seconds at the last update drawn
    bool drawn_ = false;
    std::chrono::steady_clock::time_point start_;
};

} // namespace spw
