// The film read out: its image (whole, by rows, of the last iteration, of a saved state), the
// exact state a checkpoint keeps and restores (Film::State: the 128-bit sums, the fine levels and
// the sample counts), and the iteration's sums that distributed rendering adds over the ranks.
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
            // As Film::pixelSums: the home sums, then the levels coarsest first, in home units.
            for (int k = 0; k < 8; ++k)
                s[k] = double(state.sums[i * 8 + size_t(k)]);
            for (const State::Level& level : state.levels) {
                const double unit = std::ldexp(1.0, -state.levelBits * level.level);
                for (int half = 0; half < 2; ++half)
                    for (int c = 0; c < 3; ++c)
                        s[half * 4 + c] += double(level.sums[i * 6 + size_t(half * 3 + c)]) * unit;
            }
            for (int k = 0; k < 8; ++k)
                s[k] /= k % 4 == 3 ? weightScale : scale;
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
            double fine[8] = {};
            if (lastLevels_) addLevelSums(*lastLevels_, i, fine);
            const double weight = double(it[3]) / weightScale_;
            for (int c = 0; c < 3; ++c)
                out[i * 3 + c] =
                    it[3] > 0 ? float((double(it[c]) + fine[c] + fine[4 + c]) / scale_ / weight)
                              : 0.0f;
        }
    });
    return out;
}

void Film::addLevelSums(const FilmLevels& levels, size_t i, double* s) const {
    if (levels.levels() == 0) return;
    const auto [tile, slot] = levelSlot(i);
    for (int level = 1; level <= levels.levels(); ++level) {
        if (!levels.holds(level, tile)) continue;
        const double unit = std::ldexp(1.0, -levelBits_ * level);
        for (int half = 0; half < 2; ++half)
            for (int c = 0; c < 3; ++c)
                s[half * 4 + c] +=
                    double(levels.at(level, tile, slot + size_t(half) * 3 + size_t(c))) * unit;
    }
}

std::vector<std::int64_t> Film::levelTilesReached() {
    finishSamples(); // which routes the sample sums' small contributions
    const size_t tiles = size_t(tilesX_) * size_t(tilesY_);
    std::vector<std::int64_t> reached(size_t(levelCount_) * tiles, 0);
    for (int level = 1; level <= levelCount_; ++level)
        for (size_t t = 0; t < tiles; ++t)
            reached[size_t(level - 1) * tiles + t] = iterLevels_.holds(level, t) ? 1 : 0;
    return reached;
}

std::vector<std::int64_t> Film::iterationAccumulators(const std::vector<std::int64_t>& tiles) {
    const std::vector<std::int64_t> own = tiles.empty() ? levelTilesReached() : tiles;
    finishSamples();
    const size_t n = size_t(width_) * height_;
    std::vector<std::int64_t> out(n * 8 + 2);
    for (size_t i = 0; i < n; ++i)
        for (int k = 0; k < 8; ++k)
            out[i * 8 + size_t(k)] = acc_[i].v[k].load(std::memory_order_relaxed);
    out[n * 8] = std::int64_t(nonFinite_.load() - nonFiniteBefore_);
    out[n * 8 + 1] = std::int64_t(saturated_.load() - saturatedBefore_);
    // An iteration's level sums fit 64 bits (film_levels.h), as its home sums do.
    const size_t count = size_t(tilesX_) * size_t(tilesY_);
    for (size_t j = 0; j < own.size(); ++j)
        if (own[j] != 0)
            for (size_t s = 0; s < FilmLevels::kSlots; ++s)
                out.push_back(std::int64_t(iterLevels_.at(int(j / count) + 1, j % count, s)));
    return out;
}

void Film::setIterationAccumulators(const std::vector<std::int64_t>& values,
                                    const std::vector<std::int64_t>& tiles) {
    const std::vector<std::int64_t> own = tiles.empty() ? levelTilesReached() : tiles;
    const size_t n = size_t(width_) * height_, count = size_t(tilesX_) * size_t(tilesY_);
    const size_t reached =
        size_t(std::count_if(own.begin(), own.end(), [](std::int64_t f) { return f != 0; }));
    if (own.size() != size_t(levelCount_) * count ||
        values.size() != n * 8 + 2 + reached * FilmLevels::kSlots)
        throw std::invalid_argument("iteration accumulators of another film size");
    for (size_t i = 0; i < n; ++i)
        for (int k = 0; k < 8; ++k)
            acc_[i].v[k].store(values[i * 8 + size_t(k)], std::memory_order_relaxed);
    accZero_ = false;
    nonFinite_ = nonFiniteBefore_ + std::uint64_t(values[n * 8]);
    saturated_ = saturatedBefore_ + std::uint64_t(values[n * 8 + 1]);
    size_t at = n * 8 + 2;
    for (size_t j = 0; j < own.size(); ++j)
        if (own[j] != 0)
            for (size_t s = 0; s < FilmLevels::kSlots; ++s)
                iterLevels_.set(int(j / count) + 1, j % count, s, values[at++]);
}

Film::State Film::state() const {
    State s{std::vector<Fixed>(pixels() * 8),
            sampleCounts(),
            nonFinite_.load(),
            saturated_.load(),
            std::ilogb(scale_),
            std::ilogb(weightScale_),
            levelBits_,
            {}};
    forPixels(pixels(), [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i)
            for (int k = 0; k < 8; ++k)
                s.sums[i * 8 + size_t(k)] = sumAt(i, k);
    });
    for (int level = 1; level <= renderLevels_.levels(); ++level) {
        if (!renderLevels_.holdsLevel(level)) continue;
        State::Level& l = s.levels.emplace_back(State::Level{level, {}});
        l.sums.resize(pixels() * 6);
        forPixels(pixels(), [&](size_t begin, size_t end) {
            for (size_t i = begin; i < end; ++i) {
                const auto [tile, slot] = levelSlot(i);
                for (size_t k = 0; k < 6; ++k)
                    l.sums[i * 6 + k] = renderLevels_.at(level, tile, slot + k);
            }
        });
    }
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
        state.weightExponent != std::ilogb(weightScale_) || state.levelBits != levelBits_)
        throw std::invalid_argument("a film state of another fixed-point scale");
    for (const State::Level& level : state.levels)
        if (level.level < 1 || level.level > levelCount_ || level.sums.size() != pixels() * 6)
            throw std::invalid_argument("a film state of other fine levels");
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
    renderLevels_ = FilmLevels(levelCount_, size_t(tilesX_) * size_t(tilesY_));
    for (const State::Level& level : state.levels)
        for (size_t i = 0; i < pixels(); ++i) {
            const auto [tile, slot] = levelSlot(i);
            for (size_t k = 0; k < 6; ++k)
                renderLevels_.set(level.level, tile, slot + k, level.sums[i * 6 + k]);
        }
    tileSamples_ = std::move(tiles);
    nonFinite_ = state.nonFinite;
    saturated_ = state.saturated;
    discardIteration();
    decideTiles();
}

} // namespace spw
