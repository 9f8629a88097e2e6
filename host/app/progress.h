// A one-line progress bar on stderr (iterations, spp, elapsed, ETA), drawn only on a terminal.
#pragma once

#include <chrono>
#include <cstdio>
#include <string>

namespace spw {

class ProgressBar {
  public:
    explicit ProgressBar(bool enabled)
        : enabled_(enabled), start_(std::chrono::steady_clock::now()) {}
    void update(int done, int total, int sppDone, int sppTotal);
    void finish();

  private:
    bool enabled_;
    bool drawn_ = false;
    std::chrono::steady_clock::time_point start_;
};

} // namespace spw
