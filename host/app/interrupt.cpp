#include "host/app/interrupt.h"

#include <csignal>

namespace spw {
namespace {

std::atomic<int> gSignal{0};
static_assert(std::atomic<int>::is_always_lock_free, "the handler needs a lock-free flag");

// SIGHUP too: a terminal or ssh connection that goes away is a stop, not a reason to lose the
// finished iterations.
constexpr int kSignals[] = {SIGINT, SIGTERM, SIGHUP};
constexpr int kSignalCount = int(sizeof(kSignals) / sizeof(kSignals[0]));
struct sigaction gPrevious[kSignalCount];

extern "C" void onSignal(int sig) {
    int none = 0;
    if (gSignal.compare_exchange_strong(none, sig)) return; // the first: stop gracefully
    // The second: die now, as the user asked twice.
    std::signal(sig, SIG_DFL);
    std::raise(sig);
}

} // namespace

InterruptGuard::InterruptGuard() {
    gSignal.store(0);
    struct sigaction action = {};
    action.sa_handler = onSignal;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESTART;
    for (int i = 0; i < kSignalCount; ++i)
        sigaction(kSignals[i], &action, &gPrevious[i]);
}

InterruptGuard::~InterruptGuard() {
    for (int i = 0; i < kSignalCount; ++i)
        sigaction(kSignals[i], &gPrevious[i], nullptr);
}

const std::atomic<int>* InterruptGuard::flag() const {
    return &gSignal;
}

void InterruptGuard::requestStop(int code) {
    int none = 0;
    gSignal.compare_exchange_strong(none, code);
}

int InterruptGuard::signal() const {
    return gSignal.load();
}

} // namespace spw
