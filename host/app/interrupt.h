// Ctrl-C keeps the work. While an InterruptGuard lives, the first SIGINT, SIGTERM or SIGHUP (the
// terminal or ssh connection gone) only sets a flag (RenderConfig::stop): the render stops at the
// next batch or tile boundary, discards the iteration in progress, and the CLI writes the image
// of every completed iteration, then exits 130, 143 or 129 as a shell expects. A second signal ends
// the process at once by the signal's default action; every file Spillway writes is anonymous until
// committed (output_file.h) and the spill file has no name at all (batch_queue.h), so no temporary
// file survives either way.
#pragma once

#include <atomic>

namespace spw {

class InterruptGuard {
  public:
    InterruptGuard();  // installs the handlers
    ~InterruptGuard(); // restores the previous ones
    InterruptGuard(const InterruptGuard&) = delete;
    InterruptGuard& operator=(const InterruptGuard&) = delete;

    // The flag: the number of the first signal received, 0 until then.
    const std::atomic<int>* flag() const;
    int signal() const;
    // Stops the render as a first signal would, with `code` (kStopByWindow) as the flag's
    // value; no-op once something else stopped it.
    void requestStop(int code);
};

} // namespace spw
