// The film read out: its image (whole, by rows, of the last iteration, of a saved state) and the
// exact state a checkpoint keeps and restores (Film::State: the 128-bit sums and sample counts).
#include "host/image/film.h"

#include "host/image/pixel_ranges.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace spw {

namespace {
// Pixels first .. first + count - 1 of the image whose pixel i's eight sums, in radiance and
// weight units, sums(i, s) gives, into out (3 floats a pixel).
template <typename Sums>
void imageFromSums(const Sums& sums, size_t first, size_t count, float* out) {
    forPixels(count, [&](size_t begin, size_t end) {
        for (size_t j = begin; j < end; ++j) {
            double s[8];
            sums(first + j, s);
            const double w = s[3] + s[7];
            for (int c = 0; c < 3; ++c)
                out[j * 3 + c] = w > 0 ? float((s[c] + s[4 + c]) / w) : 0.0f;
        }
    });
}
} // namespace

std::vector<float> Film::image() const {
    std::vector<float> out(pixels() * 3);
    imageRows(0, height_, out.data());
    return out;
}

void Film::imageRows(int y0, int y1, float* rgb) const {
    imageFromSums([&](size_t i, double* s) { pixelSums(i, s); }, size_t(y0) * size_t(width_),
                  size_t(y1 - y0) * size_t(width_), rgb);
}

std::vector<float> Film::imageOf(const State& state) {
    const double scale = std::ldexp(1.0, state.scaleExponent),
                 weightScale = std::ldexp(1.0, state.weightExponent);
    std::vector<float> out(state.sums.size() / 8 * 3);
    imageFromSums(
        [&](size_t i, double* s) {
            for (int k = 0; k < 8; ++k)
                s[k] = double(state.sums[i * 8 + size_t(k)]) / (k % 4 == 3 ? weightScale : scale);
        },
        0, state.sums.size() / 8, out.data());
    return out;
}

std::vector<float> Film::lastIterationImage() const {
    if (!lastIteration_)
        throw std::logic_error("Film::lastIterationImage outside endIteration .. beginIteration");
    std::vector<float> out(pixels() * 3, 0.0f);
    forPixels(pixels(), [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i) {
            std::int64_t it[4] = {0, 0, 0, 0};
            for (int k = 0; k < 8; ++k)
                it[k % 4] += lastIteration_[i].v[k].load(std::memory_order_relaxed);
            const double weight = double(it[3]) / weightScale_;
            for (int c = 0; c < 3; ++c)
                out[i * 3 + c] = it[3] > 0 ? float(double(it[c]) / scale_ / weight) : 0.0f;
        }
    });
    return out;
}

Film::State Film::state() const {
    State s{std::vector<Fixed>(pixels() * 8),
            sampleCounts(),
            nonFinite_.load(),
            saturated_.load(),
            std::ilogb(scale_),
            std::ilogb(weightScale_)};
    forPixels(pixels(), [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i)
            for (int k = 0; k < 8; ++k)
                s.sums[i * 8 + size_t(k)] = sumAt(i, k);
    });
    return s;
}

void Film::restore(const State& state) {
    if (state.sums.size() != pixels() * 8 || state.samples.size() != pixels())
        throw std::invalid_argument("a film state of another size");
    std::vector<std::uint32_t> tiles(tileSamples_.size(), 0u);
    for (size_t i = 0; i < pixels(); ++i) {
        const size_t t = tileOf(i);
        if (i % size_t(width_) % kAdaptiveTile == 0 && i / size_t(width_) % kAdaptiveTile == 0)
            tiles[t] = state.samples[i];
        else if (state.samples[i] != tiles[t])
            throw std::invalid_argument("a film state whose sample counts differ within a tile");
    }
    if (state.scaleExponent != std::ilogb(scale_) ||
        state.weightExponent != std::ilogb(weightScale_))
        throw std::invalid_argument("a film state of another fixed-point scale");
    const auto fits = [](Fixed v) { return v == Fixed(std::int64_t(v)); };
    errorOfDecision_.reset(); // decideTiles() below may make it again
    sumLo_ = zeroedSums(pixels());
    sumHi_.reset();
    if (!std::all_of(state.sums.begin(), state.sums.end(), fits)) widenSums();
    forPixels(pixels(), [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i)
            for (int k = 0; k < 8; ++k) {
                const Fixed v = state.sums[i * 8 + size_t(k)];
                sumLo_[i].v[k].store(std::int64_t(std::uint64_t(v)), std::memory_order_relaxed);
                if (sumHi_) sumHi_[i * 8 + size_t(k)] = std::int64_t(v >> 64);
            }
    });
    sumBound_ = std::uint64_t(1) << 62; // unknown: at most the clamp
    tileSamples_ = std::move(tiles);
    nonFinite_ = state.nonFinite;
    saturated_ = state.saturated;
    discardIteration();
    decideTiles();
}

} // namespace spw
