#include "host/app/progress.h"

namespace spw {
namespace {
std::string clock(double s) {
    char buf[32];
    int m = int(s / 60);
    std::snprintf(buf, sizeof buf, "%d:%04.1f", m, s - 60.0 * m);
    return buf;
}
} // namespace

void ProgressBar::update(int done, int total, int sppDone, int sppTotal) {
    if (!enabled_) return;
    double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    double eta = done > 0 ? elapsed * (total - done) / done : 0.0;
    const int width = 30;
    int filled = total > 0 ? done * width / total : width;
    std::string bar(size_t(filled), '#');
    bar.resize(width, '.');
    std::fprintf(stderr, "\r[%s] iteration %d/%d  %d/%d spp  %s elapsed  ETA %s ", bar.c_str(),
                 done, total, sppDone, sppTotal, clock(elapsed).c_str(), clock(eta).c_str());
    std::fflush(stderr);
    drawn_ = true;
}

void ProgressBar::finish() {
    if (drawn_) std::fputc('\n', stderr);
    drawn_ = false;
}

} // namespace spw
