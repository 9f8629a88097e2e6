// The film's error without a reference: the half buffers' per-pixel terms (A - B)^2 / 4 over
// d^2 + 0.01, with d resisting glints (termValue), computed in bands of rows; what reads them:
// the relMSE estimate and its standard error (--error-csv, --target-error), the error map, and
// adaptive sampling's tile decisions. docs/design.md, "Error without a reference".
#include "host/image/film.h"

#include "host/image/compare.h"
#include "host/image/pixel_ranges.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

namespace spw {

namespace {
// A pixel's values from its sums: m (the two halves together) and the halves' own, a and b, per
// channel, and whether both halves hold samples.
struct PixelValues {
    double m[3], a[3], b[3];
    bool both;
};

// The image's values, a pixel's, from row r0 on: pixels' neighbourhoods.
struct ValueRows {
    const PixelValues* values;
    int width, height, r0;
    const PixelValues& at(int x, int y) const {
        return values[size_t(y - r0) * size_t(width) + size_t(x)];
    }
    // The brightest value of each channel around (x, y) inside the image, the pixel left out.
    void brightest(int x, int y, double* out) const {
        out[0] = out[1] = out[2] = 0.0;
        for (int ny = std::max(0, y - 1); ny <= std::min(height - 1, y + 1); ++ny)
            for (int nx = std::max(0, x - 1); nx <= std::min(width - 1, x + 1); ++nx) {
                if (nx == x && ny == y) continue;
                const double* m = at(nx, ny).m;
                for (int c = 0; c < 3; ++c)
                    out[c] = std::max(out[c], m[c]);
            }
    }
    // The median of channel c over the 3 x 3 window around (x, y) inside the image, the pixel
    // included (the upper one of an even count).
    double median(int x, int y, int c) const {
        double window[9];
        int count = 0;
        for (int ny = std::max(0, y - 1); ny <= std::min(height - 1, y + 1); ++ny)
            for (int nx = std::max(0, x - 1); nx <= std::min(width - 1, x + 1); ++nx)
                window[count++] = at(nx, ny).m[c];
        std::nth_element(window, window + count / 2, window + count);
        return window[count / 2];
    }
};

// The value d in one channel's term (A - B)^2 / 4 / (d^2 + 0.01) of pixel (x, y), whose halves
// read a and b, m the two together, from `samples` samples.
//
// d is m, the pixel's own value, unless its samples spread more than anything around it shows:
// the per-sample standard deviation that the halves' difference gives, |a - b| sqrt(n / 4), and
// its brighter half both above the brightest value of its 3 x 3 neighbourhood. That is a spike
// no surface in view explains, a glint: a rare path of large value (a glossy bounce into a small
// light), whose one sample inflates m as much as the difference, so that with m as d the term
// reads at most about 1 where the pixel's true relative error is tens. Such a pixel takes d =
// min(m, max(min(a, b), the window's median)): its spike-free half, or its neighbourhood's level
// if that is higher. A pixel at an edge (a sliver of the light, a bright wall behind a dark one)
// has spikes that a neighbour shows as its steady value, and keeps m: its rare samples are a
// large part of its true value. What the rule cannot tell apart: a light smaller than a pixel or
// two, seen directly, that one half has hit and the other not yet, reads as a glint, and its
// term is far too high until both halves have hit it.
// docs/performance.md ("The denominator: glints") has the measurements behind the rule.
// `brightest`: the brightest value of the channel around the pixel, the pixel left out.
double termValue(const ValueRows& rows, int x, int y, int c, double samples, double brightest) {
    const PixelValues& v = rows.at(x, y);
    const double a = v.a[c], b = v.b[c];
    const double spread = std::fabs(a - b) * std::sqrt(samples / 4.0);
    if (!(spread > brightest && std::max(a, b) > brightest)) return v.m[c];
    return std::min(v.m[c], std::max(std::min(a, b), rows.median(x, y, c)));
}
} // namespace

void Film::halfBufferTermRows(int y0, int y1, double* terms) const {
    // The image's rows y0 - 1 .. y1 (those inside it): every pixel's neighbours.
    const int r0 = std::max(0, y0 - 1), r1 = std::min(height_, y1 + 1);
    const size_t w = size_t(width_);
    std::vector<PixelValues> values(size_t(r1 - r0) * w);
    forPixels(size_t(r1 - r0) * w, [&](size_t begin, size_t end) {
        for (size_t j = begin; j < end; ++j) {
            double s[8];
            pixelSums(size_t(r0) * w + j, s);
            PixelValues& v = values[j];
            const double weight = s[3] + s[7];
            v.both = s[3] > 0 && s[7] > 0;
            for (int c = 0; c < 3; ++c) {
                v.m[c] = weight > 0 ? (s[c] + s[4 + c]) / weight : 0.0;
                v.a[c] = v.both ? s[c] / s[3] : 0.0;
                v.b[c] = v.both ? s[4 + c] / s[7] : 0.0;
            }
        }
    });
    const ValueRows rows{values.data(), width_, height_, r0};
    forPixels(size_t(y1 - y0) * w, [&](size_t begin, size_t end) {
        for (size_t j = begin; j < end; ++j) {
            const size_t pixel = size_t(y0) * w + j;
            const int x = int(pixel % w), y = int(pixel / w);
            double* out = terms + j * 3;
            const PixelValues& v = rows.at(x, y);
            if (!v.both) {
                out[0] = out[1] = out[2] = kNoTerm;
                continue;
            }
            // The camera samples centred in the pixel. A wide filter's value averages more of
            // them, so the spread reads low there and the rule errs towards m.
            const double samples = double(tileSamples_[tileOf(pixel)]);
            double brightest[3];
            rows.brightest(x, y, brightest);
            for (int c = 0; c < 3; ++c) {
                const double a = v.a[c], b = v.b[c];
                const double d = termValue(rows, x, y, c, samples, brightest[c]);
                out[c] = (a - b) * (a - b) / 4.0 / (d * d + kRelMseEpsilon);
            }
        }
    });
}

template <typename Fn> void Film::forHalfBufferTerms(int y0, int y1, const Fn& fn) const {
    constexpr int kBand = 8 * kAdaptiveTile; // rows: whole tiles, a few MB of terms
    std::vector<double> terms;
    for (int b0 = y0; b0 < y1; b0 += kBand) {
        const int b1 = std::min(y1, b0 + kBand);
        terms.resize(size_t(b1 - b0) * size_t(width_) * 3);
        halfBufferTermRows(b0, b1, terms.data());
        fn(b0, b1, terms.data());
    }
}

void Film::errorRows(int y0, int y1, float* rgb) const {
    forHalfBufferTerms(y0, y1, [&](int b0, int b1, const double* terms) {
        float* out = rgb + size_t(b0 - y0) * size_t(width_) * 3;
        for (size_t i = 0; i < size_t(b1 - b0) * size_t(width_) * 3; ++i)
            out[i] = terms[i] == kNoTerm ? 0.0f : float(terms[i]);
    });
}

void Film::decideAdaptiveTiles() {
    errorOfDecision_.reset();
    if (!(adaptiveThreshold_ > 0.0) && !(adaptiveTarget_ > 0.0)) {
        active_.clear();
        activeTiles_ = 1;
        return;
    }
    const size_t tiles = size_t(tilesX_) * size_t(tilesY_);
    active_.assign(tiles, 1);
    activeTiles_ = tiles;
    // Each tile's mean half-buffer term over its values, and how many; not ready (-1) before its
    // minimum samples or while a pixel has no estimate. Toward a target, as the stop judges the
    // subject (halfBufferError), over the values of its pixels that hold noise: a tile of flat
    // pixels alone has nothing to reach (mean 0). The same terms give the image's estimate, which
    // the stop asks for next: one pass over them, not two.
    const bool subject = !(adaptiveThreshold_ > 0.0);
    std::vector<double> mean(tiles, -1.0);
    std::vector<size_t> count(tiles, 0);
    ErrorSums error;
    forHalfBufferTerms(0, height_, [&](int y0, int y1, const double* terms) {
        error.add(terms, size_t(y1 - y0) * size_t(width_));
        for (int ty = y0 / kAdaptiveTile; ty * kAdaptiveTile < y1; ++ty)
            for (int tx = 0; tx < tilesX_; ++tx) {
                const size_t tile = size_t(ty) * size_t(tilesX_) + size_t(tx);
                double total = 0.0;
                size_t values = 0;
                bool flat = false, ready = tileSamples_[tile] >= std::uint32_t(adaptiveMinSamples_);
                for (int y = ty * kAdaptiveTile; y < std::min(y1, (ty + 1) * kAdaptiveTile); ++y)
                    for (int x = tx * kAdaptiveTile; x < std::min(width_, (tx + 1) * kAdaptiveTile);
                         ++x) {
                        const double* t = terms + (size_t(y - y0) * size_t(width_) + size_t(x)) * 3;
                        if (t[0] == kNoTerm) {
                            ready = false;
                            continue;
                        }
                        if (subject && t[0] + t[1] + t[2] < kFlatTerm) {
                            flat = true;
                            continue;
                        }
                        for (int c = 0; c < 3; ++c) // one at a time, as the sum always was
                            total += t[c];
                        values += 3;
                    }
                if (ready && values > 0) mean[tile] = total / double(values);
                if (ready && values == 0 && flat) mean[tile] = 0.0;
                count[tile] = values;
            }
    });
    errorOfDecision_ = error.estimate();
    if (adaptiveThreshold_ > 0.0) {
        const double limit = adaptiveThreshold_ * adaptiveThreshold_; // on the mean square
        for (size_t t = 0; t < tiles; ++t)
            if (mean[t] >= 0.0 && mean[t] < limit) active_[t] = 0, --activeTiles_;
        return;
    }
    decideTargetTiles(mean, count);
}

void Film::decideTargetTiles(const std::vector<double>& mean, const std::vector<size_t>& count) {
    // A tile's noise sigma = sqrt(relMSE x samples) (its relMSE falls as sigma^2 / n). For a
    // given sample budget the image's relMSE (the mean over its values) is least with n_i
    // proportional to sigma_i; reaching the target E then takes n_i = k sigma_i with
    // k = sum(p_i sigma_i) / (P E), p_i a tile's values and P all of them. A tile that has its
    // n_i rests; the others sample. Tiles not ready sample, and count at the mean sigma.
    const size_t tiles = mean.size();
    std::vector<double> sigma(tiles, -1.0);
    double weighted = 0.0, weight = 0.0;
    for (size_t t = 0; t < tiles; ++t)
        if (mean[t] >= 0.0) {
            sigma[t] = std::sqrt(mean[t] * double(tileSamples_[t]));
            weighted += double(count[t]) * sigma[t];
            weight += double(count[t]);
        }
    if (!(weight > 0.0)) return;
    const double k = weighted / (weight * adaptiveTarget_);
    for (size_t t = 0; t < tiles; ++t)
        if (sigma[t] >= 0.0 && double(tileSamples_[t]) >= k * sigma[t])
            active_[t] = 0, --activeTiles_;
    // Every tile at its share while the estimate is still above the target (the estimates are
    // noisy): all sample on, as uniform sampling would. The stop is the target's.
    if (activeTiles_ == 0) {
        std::fill(active_.begin(), active_.end(), std::uint8_t(1));
        activeTiles_ = tiles;
    }
}

std::vector<float> Film::halfImage(int half) const {
    const size_t n = size_t(width_) * height_;
    std::vector<float> out(n * 3, 0.0f);
    for (size_t i = 0; i < n; ++i) {
        double all[8];
        pixelSums(i, all);
        const double* s = all + half * 4;
        if (s[3] > 0)
            for (int c = 0; c < 3; ++c)
                out[i * 3 + c] = float(s[c] / s[3]);
    }
    return out;
}

double Film::halfBufferRelMse() const {
    return halfBufferRelMseEstimate().value_or(0.0);
}

double Film::halfBufferRelMseStandardError() const {
    return halfBufferError().standardError;
}

std::optional<double> Film::halfBufferRelMseEstimate() const {
    return halfBufferError().relMse;
}

void Film::ErrorSums::add(const double* terms, size_t n) {
    for (size_t i = 0; i < n; ++i) {
        const double* t = terms + i * 3;
        if (t[0] == kNoTerm) continue;
        for (int c = 0; c < 3; ++c) // one at a time, in pixel order, as the sum always was
            total += t[c];
        const double p = t[0] + t[1] + t[2];
        squares += p * p;
        count += 3;
        if (p < kFlatTerm) continue;
        for (int c = 0; c < 3; ++c)
            subjectTotal += t[c];
        subjectSquares += p * p;
        subjectCount += 3;
    }
}

Film::ErrorEstimate Film::ErrorSums::estimate() const {
    // The standard error: a pixel's term sum P (its three channels, whose noise is mostly
    // shared) is a scaled chi-square of one degree of freedom where the halves' difference is
    // Gaussian: its variance is 2/3 of E[P^2], and P^2 estimates E[P^2] from the pixel alone.
    // Pixels are independent (up to the filter's reach), so the variances add.
    ErrorEstimate e;
    if (count == 0) return e;
    e.relMse = total / double(count);
    e.standardError = std::sqrt(2.0 / 3.0 * squares) / double(count);
    if (subjectCount > 0) {
        e.subjectRelMse = subjectTotal / double(subjectCount);
        e.subjectStandardError = std::sqrt(2.0 / 3.0 * subjectSquares) / double(subjectCount);
        e.subjectFraction = double(subjectCount) / double(count);
    }
    return e;
}

std::optional<double> Film::subjectRelMseEstimate() const {
    const ErrorEstimate e = halfBufferError();
    return e.subjectRelMse ? e.subjectRelMse : e.relMse;
}

Film::ErrorEstimate Film::halfBufferError() const {
    if (errorOfDecision_) return *errorOfDecision_;
    ErrorSums error;
    forHalfBufferTerms(0, height_, [&](int y0, int y1, const double* terms) {
        error.add(terms, size_t(y1 - y0) * size_t(width_));
    });
    return error.estimate();
}

} // namespace spw
