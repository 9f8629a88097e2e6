// Progress on stderr: spp done, elapsed, ETA and the half-buffer error estimate. Style Bar: one
// line redrawn with a carriage return (a terminal); Lines: one plain line per iteration (a log,
// no control characters); None: nothing.
#pragma once

#include <chrono>
#include <cstdio>
#include <optional>
#include <string>

namespace spw {

class ProgressBar {
  public:
    enum class Style { None, Bar, Lines };
    explicit ProgressBar(Style style) : style_(style), start_(std::chrono::steady_clock::now()) {}
    void update(int done, int total, int sppDone, int sppTotal, std::optional<double> relMse);
    void finish();

  private:
    Style style_;
    bool drawn_ = false;
    std::chrono::steady_clock::time_point start_;
};

} // namespace spw
