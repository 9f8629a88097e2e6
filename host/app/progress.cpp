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

void ProgressBar::update(int done, int total, int sppDone, int sppTotal,
                         std::optional<double> relMse) {
    if (style_ == Style::None) return;
    double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    if (lastDrawn_ && elapsed - *lastDrawn_ < minInterval_ && done < total) return;
    lastDrawn_ = elapsed;
    double eta = done > 0 ? elapsed * (total - done) / done : 0.0;
    char error[32] = "-";
    if (relMse) std::snprintf(error, sizeof error, "%.3g", *relMse);
    if (style_ == Style::Lines) {
        std::fprintf(stderr,
                     "spillway: iteration %d/%d, %d/%d spp, %s elapsed, ETA %s, relMSE %s\n", done,
                     total, sppDone, sppTotal, clock(elapsed).c_str(), clock(eta).c_str(), error);
        std::fflush(stderr);
        return;
    }
    const int width = 30;
    int filled = total > 0 ? done * width / total : width;
    std::string bar(size_t(filled), '#');
    bar.resize(width, '.');
    std::fprintf(stderr, "\r[%s] %d/%d spp  %s elapsed  ETA %s  relMSE %s ", bar.c_str(), sppDone,
                 sppTotal, clock(elapsed).c_str(), clock(eta).c_str(), error);
    std::fflush(stderr);
    drawn_ = true;
}

void ProgressBar::finish() {
    if (drawn_) std::fputc('\n', stderr);
    drawn_ = false;
}

} // namespace spw
