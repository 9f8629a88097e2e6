// When a render stops early, decided between iterations. In the order checked: the time limit,
// a stop asked for (a signal, or the preview window closing), every tile converged (adaptive
// sampling), and the target error reached: the relMSE estimate over the pixels that hold noise
// (the subject; a flat background is left out, Film::halfBufferError). Running out of iterations is
// the render loop's own end ("spp").
#pragma once

#include "host/backend/backend.h"
#include "host/image/film.h"
#include "host/render/ranks.h"

#include <optional>

namespace spw {

class StopRule {
  public:
    explicit StopRule(const RenderConfig& config) : config_(config) {}

    // What this process alone knows before iteration `ran` (counted from this run's start):
    // whether a stop was asked for, and whether its render time reached the time limit.
    bool stopAsked() const { return stopRequested(config_); }
    bool timeUp(int ran, double renderSeconds) const {
        return ran > 0 && config_.timeLimitSeconds && renderSeconds >= *config_.timeLimitSeconds;
    }

    // Why the render stops before its next iteration, given what the processes agreed, or
    // nullptr to go on; `filmHolds`: whether the film holds whole iterations (this run's, or a
    // checkpoint's: a render resumed after it stopped on its target stops again, at once). The
    // film's own decisions (adaptive, target error) are the same on every rank.
    const char* before(bool filmHolds, const Ranks::Agreement& agreed, const Film& film) const {
        if (agreed.timeUp) return "time limit";
        if (agreed.stop) return bySignal();
        if (filmHolds && !film.anySampling()) return "adaptive"; // every tile below threshold
        if (filmHolds && config_.targetError) {
            // The subject's error: the pixels that hold noise (Film::subjectRelMseEstimate).
            const std::optional<double> estimate = film.subjectRelMseEstimate();
            if (estimate && *estimate <= *config_.targetError) return "target error";
        }
        return nullptr;
    }

    // Why an iteration that did not complete stopped.
    const char* bySignal() const {
        const int code = config_.stop ? config_.stop->load() : 0;
        return code == kStopByWindow        ? "window"
               : code == kStopByLostDisplay ? "display lost"
                                            : "signal";
    }

  private:
    const RenderConfig& config_;
};

} // namespace spw
