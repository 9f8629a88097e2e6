// The film's accumulation: iterations begun and ended, samples splatted into fixed-point sums
// (straight for a box filter, or through each sample's own sum and its footprint for wide ones),
// the sums widened to 128 bits before they could wrap, and the tiles still sampling. Its readout
// and checkpoint state: film_state.cpp; its error estimate and adaptive tiles: film_error.cpp.
#include "host/image/film.h"

#include "host/image/pixel_ranges.h"
#include "host/simd/film_rounding.h"
#include "shared/rng.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <sys/mman.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <new>
#include <stdexcept>

namespace spw {
namespace {

// The stochastic rounding's key: the caller's (path and bounce within the iteration) mixed with
// the render-wide sample index, so that every iteration rounds with fresh random numbers. Without
// the sample index a pixel whose value repeats each iteration (a tiny light seen through the
// Grid sampler) would be rounded the same way every time: a bias of up to one fixed-point step.
uint roundingKey(uint key, uint sampleIndex) {
    return pcg4d(uvec4(key, sampleIndex, 0xF11Du, 0x2545F491u)).x;
}

std::uint64_t magnitude(std::int64_t v) {
    return v < 0 ? std::uint64_t(0) - std::uint64_t(v) : std::uint64_t(v);
}

} // namespace

// The filter's 1D weight at distance d from the sample. The Gaussian's constant terms are the
// film's (gaussK_, gaussTail_): the same floats as computed in place, without an exp() each.
float Film::weight1D(float d) const {
    d = std::fabs(d);
    const float radius = filter_.radius;
    if (d >= radius) return 0.0f;
    if (filter_.type == FilterType::Tent) return 1.0f - d / radius;
    return std::exp(gaussK_ * d * d) - gaussTail_; // Gaussian, shifted to reach 0 at the radius
}

Film::Film(int width, int height, const Filter& filter, float brightestRadiance,
           int samplesPerIteration, Halves halves)
    : width_(width), height_(height), samplesPerIteration_(uint(samplesPerIteration)),
      halves_(halves), filter_(filter), tilesX_((width + kAdaptiveTile - 1) / kAdaptiveTile),
      tilesY_((height + kAdaptiveTile - 1) / kAdaptiveTile),
      tileSamples_(size_t(tilesX_) * size_t(tilesY_), 0u) {
    if (!(filter.radius > 0.0f && filter.radius <= kMaxFilterRadius))
        throw std::invalid_argument("a pixel filter's radius lies in (0, 16]");
    // No clamp on e: the scale is a double, and every emission the loader accepts (up to
    // kMaxRadiance, down to the smallest float) keeps its brightest sample at 2^40.
    const int e =
        brightestRadiance > 0.0f ? int(std::ceil(std::log2(double(brightestRadiance)))) : 0;
    // N adds at most per accumulator and iteration: a sample reaches (floor(2r) + 1)^2 pixels.
    const double reach =
        filter.type == FilterType::Box ? 1.0 : std::floor(2.0 * double(filter.radius)) + 1.0;
    const int logAdds =
        int(std::ceil(std::log2(std::max(1.0, double(samplesPerIteration) * reach * reach))));
    maxAdd_ = std::ldexp(1.0, 62 - logAdds);
    const int top = std::min(40, 62 - logAdds - 16); // the brightest sample's exponent
    scale_ = std::ldexp(1.0, top - e);
    weightScale_ = std::ldexp(1.0, std::min(40, 62 - logAdds - 1));
    // The fine levels (film_levels.h): a step as wide as an iteration's adds leave room for (a
    // level's value is below 2^(24 + bits), and at most 2^logAdds of them land in one sum), at
    // most 32 bits; as many levels as reach 2^-149 in radiance, the smallest float, at 2^24 units.
    levelBits_ = std::clamp(38 - logAdds, 1, 32);
    levelCount_ = std::max(0, (24 + 149 - (top - e) + levelBits_ - 1) / levelBits_);
    for (int level = 0; level <= levelCount_; ++level)
        levelScale_.push_back(std::ldexp(1.0, levelBits_ * level));
    const float sigma = filter.radius * 0.5f;
    gaussK_ = -0.5f / (sigma * sigma);
    gaussTail_ = std::exp(gaussK_ * filter.radius * filter.radius);
    beginIteration();
}

void Film::FreeSums::operator()(PixelSums* p) const {
    std::free(p);
}

Film::Sums Film::zeroedSums(size_t pixels) {
    constexpr size_t kHugePage = size_t(2) << 20;
    const size_t bytes = (pixels * sizeof(PixelSums) + kHugePage - 1) / kHugePage * kHugePage;
    void* memory = std::aligned_alloc(kHugePage, bytes);
    if (!memory) throw std::bad_alloc();
    madvise(memory, bytes, MADV_HUGEPAGE); // a hint: without it, the same in 4 KiB pages
    Sums sums(static_cast<PixelSums*>(memory));
    forPixels(pixels, [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i) {
            PixelSums* p = new (&sums[i]) PixelSums;
            for (std::atomic<std::int64_t>& v : p->v)
                v.store(0, std::memory_order_relaxed);
        }
    });
    return sums;
}

void Film::beginIteration() {
    nonFiniteBefore_ = nonFinite_.load();
    saturatedBefore_ = saturated_.load();
    if (!acc_) {
        acc_ = zeroedSums(pixels());
    } else if (!accZero_) {
        forPixels(pixels(), [&](size_t begin, size_t end) {
            for (size_t i = begin; i < end; ++i)
                for (std::atomic<std::int64_t>& v : acc_[i].v)
                    v.store(0, std::memory_order_relaxed);
        });
    }
    accZero_ = true;
    open_ = true;
    lastIteration_ = nullptr;
    lastLevels_ = nullptr;
    if (iterLevels_.levels() == 0 && levelCount_ > 0)
        iterLevels_ = FilmLevels(levelCount_, size_t(tilesX_) * size_t(tilesY_));
    else
        iterLevels_.zero();
    if (sumsSamples() && !samples_) {
        // Zeroed once; finishSamples() zeroes each sum it reads, discardIteration() the rest.
        const size_t n = pixels() * samplesPerIteration_;
        samples_.reset(new SampleSum[n]);
        forPixels(n, [&](size_t begin, size_t end) {
            for (size_t i = begin; i < end; ++i)
                for (std::atomic<double>& v : samples_[i].rgb)
                    v.store(0.0, std::memory_order_relaxed);
        });
    }
    samplesPending_ = sumsSamples();
}

void Film::discardIteration() {
    accZero_ = false;
    if (samples_) {
        forPixels(pixels() * samplesPerIteration_, [&](size_t begin, size_t end) {
            for (size_t i = begin; i < end; ++i)
                for (std::atomic<double>& v : samples_[i].rgb)
                    v.store(0.0, std::memory_order_relaxed);
        });
    }
    beginIteration();
}

void Film::setAdaptive(double threshold, int minSamples) {
    adaptiveThreshold_ = threshold;
    adaptiveMinSamples_ = minSamples;
    decideTiles();
}

void Film::setAdaptiveTarget(double relMse) {
    adaptiveTarget_ = relMse;
    decideTiles();
}

void Film::decideTiles() {
    decideAdaptiveTiles();
    // This process's share: every shares_-th of the tiles still sampling.
    take_.clear();
    if (shares_ <= 1) {
        take_ = active_;
        return;
    }
    const size_t tiles = size_t(tilesX_) * size_t(tilesY_);
    take_.assign(tiles, 0);
    size_t k = 0;
    for (size_t t = 0; t < tiles; ++t)
        if (active_.empty() || active_[t]) take_[t] = k++ % size_t(shares_) == size_t(share_);
}

void Film::setShare(int index, int shares) {
    share_ = index;
    shares_ = shares;
    decideTiles();
}

size_t Film::tileOf(size_t pixel) const {
    const size_t x = pixel % size_t(width_), y = pixel / size_t(width_);
    return y / kAdaptiveTile * size_t(tilesX_) + x / kAdaptiveTile;
}

std::vector<std::uint32_t> Film::sampleCounts() const {
    std::vector<std::uint32_t> counts(pixels());
    for (size_t i = 0; i < counts.size(); ++i)
        counts[i] = tileSamples_[tileOf(i)];
    return counts;
}

std::uint64_t Film::samplesTaken() const {
    std::uint64_t n = 0;
    for (int ty = 0; ty < tilesY_; ++ty)
        for (int tx = 0; tx < tilesX_; ++tx) {
            const std::uint64_t w =
                std::uint64_t(std::min(kAdaptiveTile, width_ - tx * kAdaptiveTile));
            const std::uint64_t h =
                std::uint64_t(std::min(kAdaptiveTile, height_ - ty * kAdaptiveTile));
            n += w * h * tileSamples_[size_t(ty) * size_t(tilesX_) + size_t(tx)];
        }
    return n;
}

std::int64_t Film::quantize(double v, uint u) {
    if (std::fabs(v) > maxAdd_) {
        saturated_.fetch_add(1, std::memory_order_relaxed);
        v = std::copysign(maxAdd_, v);
    }
    const double fl = std::floor(v);
    // Round up with probability frac(v): E[rounded] = v exactly.
    return std::int64_t(fl) + (double(uintToUnit(u)) < v - fl ? 1 : 0);
}

void Film::add(int px, int py, int half, vec3 value, float weight, uint key) {
    std::atomic<std::int64_t>* a = &acc_[size_t(py) * width_ + size_t(px)].v[half * 4];
    uvec4 h = pcg4d(uvec4(key, uint(py * width_ + px), 0x5157u, 0x9E3779B9u));
    const double in[4] = {value.x * scale_, value.y * scale_, value.z * scale_,
                          weight * weightScale_};
    const uint rnd[4] = {h.x, h.y, h.z, h.w};
    const size_t pixel = size_t(py) * size_t(width_) + size_t(px);
    for (int c = 0; c < 4; ++c) {
        if (c < 3 && addFine(pixel, half, c, in[c], rnd[c])) continue;
        const std::int64_t q = quantize(in[c], rnd[c]);
        if (q != 0) a[c].fetch_add(q, std::memory_order_relaxed);
    }
}

bool Film::addFine(size_t pixel, int half, int c, double v, uint u) {
    const double m = std::fabs(v);
    if (!(m < kHomeFloor) || m == 0.0) return false;
    // The coarsest level at which v is 2^24 units or more: e + bits x level >= 24, e = v's
    // binary exponent (v is a normal double: a float times the scale and a weight).
    std::uint64_t bits;
    std::memcpy(&bits, &m, sizeof bits);
    const int e = int(bits >> 52) - 1023;
    const int level = (24 - e + levelBits_ - 1) / levelBits_;
    if (level > levelCount_) return true; // under the smallest float in radiance
    const double x = v * levelScale_[size_t(level)], fl = std::floor(x); // exact: a power of 2
    const std::int64_t q = std::int64_t(fl) + (double(uintToUnit(u)) < x - fl ? 1 : 0);
    const auto [tile, slot] = levelSlot(pixel);
    if (q != 0) iterLevels_.add(level, tile, slot + size_t(half) * 3 + size_t(c), q);
    return true;
}

void Film::splat(uint path, vec2 filmPos, uint sampleIndex, vec3 radiance, uint key) {
    if (!std::isfinite(radiance.x) || !std::isfinite(radiance.y) || !std::isfinite(radiance.z)) {
        nonFinite_.fetch_add(1, std::memory_order_relaxed);
        return;
    }
    if (radiance.x == 0.0f && radiance.y == 0.0f && radiance.z == 0.0f) return;
    if (sumsSamples())
        addToSample(path, radiance);
    else
        filtered(filmPos, halfOf(sampleIndex), radiance, 0.0f, roundingKey(key, sampleIndex));
}

void Film::roundLanes(FootprintLanes& lanes, size_t count, const int* halves, FootprintAdds& adds) {
    for (size_t k = 0; k < count; ++k) {
        double* channel[3] = {&lanes.r[k], &lanes.g[k], &lanes.b[k]};
        const double w = double(lanes.weight.v[k]); // as roundFootprint multiplies
        uvec4 h(0u);
        bool hashed = false;
        for (int c = 0; c < 3; ++c) {
            const double v = *channel[c] * w, m = std::fabs(v);
            if (!(m < kHomeFloor) || m == 0.0) continue;
            if (!hashed) // roundFootprint's random numbers
                h = pcg4d(uvec4(lanes.rgbKey.v[k], lanes.pixel.v[k], 0x5157u, 0x9E3779B9u));
            hashed = true;
            addFine(lanes.pixel.v[k], halves[k], c, v, c == 0 ? h.x : c == 1 ? h.y : h.z);
            *channel[c] = 0.0;
        }
    }
    const size_t end = simd::wholeVectors(count);
    for (size_t k = count; k < end; ++k) { // padding: no weight, nothing added
        lanes.pixel.v[k] = lanes.weightKey.v[k] = lanes.rgbKey.v[k] = 0u;
        lanes.weight.v[k] = 0.0f;
        lanes.r[k] = lanes.g[k] = lanes.b[k] = 0.0;
    }
    const size_t saturated = roundFootprint(lanes, end, weightScale_, maxAdd_, adds);
    if (saturated) saturated_.fetch_add(saturated, std::memory_order_relaxed);
}

void Film::splat(const Splat* splats, size_t n) {
    // Each lane is rounded as add() rounds (the Box filter: hashed with the pixel): the radiance
    // at weight 1, whose double product is the value itself; the weight's add is not used. A
    // wide filter's sample sums take the values as they come (addToSample).
    static_assert(kSplatBatch <= simd::kBlock, "a batch is one block of lanes");
    const bool sums = sumsSamples();
    FootprintLanes lanes{}; // (zeroed: GCC cannot see that roundLanes reads only what is set)
    std::atomic<std::int64_t>* target[simd::kBlock]; // the three sums the splat adds to
    int halves[simd::kBlock];
    size_t count = 0;
    for (size_t k = 0; k < n; ++k) {
        const Splat& s = splats[k];
        const vec3 v = s.value;
        if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) {
            nonFinite_.fetch_add(1, std::memory_order_relaxed);
            continue;
        }
        if (v.x == 0.0f && v.y == 0.0f && v.z == 0.0f) continue;
        if (sums) {
            addToSample(s.path, v);
            continue;
        }
        // filtered()'s pixel
        const int px = std::min(int(s.pos.x), width_ - 1);
        const int py = std::min(int(s.pos.y), height_ - 1);
        halves[count] = halfOf(s.sample);
        target[count] = &acc_[size_t(py) * width_ + size_t(px)].v[halves[count] * 4];
        lanes.pixel.v[count] = uint(py * width_ + px);
        lanes.rgbKey.v[count] = roundingKey(s.key, s.sample);
        lanes.weightKey.v[count] = 0u;
        lanes.weight.v[count] = 1.0f;
        lanes.r[count] = v.x * scale_, lanes.g[count] = v.y * scale_, lanes.b[count] = v.z * scale_;
        ++count;
    }
    if (count == 0) return;
    FootprintAdds adds;
    roundLanes(lanes, count, halves, adds);
    for (size_t k = 0; k < count; ++k) {
        const std::int64_t q[3] = {adds.r[k], adds.g[k], adds.b[k]};
        for (int c = 0; c < 3; ++c)
            if (q[c] != 0) target[k][c].fetch_add(q[c], std::memory_order_relaxed);
    }
}

void Film::addSample(uint path, vec2 filmPos, uint sampleIndex) {
    if (!sumsSamples()) {
        filtered(filmPos, halfOf(sampleIndex), vec3(0.0f), 1.0f, roundingKey(0u, sampleIndex));
        return;
    }
    SampleSum& s = samples_[path];
    s.x = filmPos.x;
    s.y = filmPos.y;
    sampleBase_.store(sampleIndex - sampleIndex % samplesPerIteration_, std::memory_order_relaxed);
}

void Film::addToSample(uint path, vec3 radiance) {
    std::atomic<double>* sum = samples_[path].rgb;
    const float in[3] = {radiance.x, radiance.y, radiance.z};
    for (int c = 0; c < 3; ++c)
        if (in[c] != 0.0f)
            sum[c].store(sum[c].load(std::memory_order_relaxed) + double(in[c]) * scale_,
                         std::memory_order_relaxed);
}

void Film::finishSamples() {
    if (!samplesPending_) return;
    samplesPending_ = false;
    // A band of rows at a time, in pixel order, so that neighbouring samples' footprints share
    // cache lines. A sample in row y reaches rows y - reach .. y + reach: bands 2 x reach rows
    // high, the even ones and then the odd ones, never write the same pixel at once, so each
    // add is a plain load and store rather than an atomic (a fifth of this pass's time).
    const int reach = int(std::ceil(filter_.radius + 0.5f));
    const int band = std::max(8, 2 * reach), bands = (height_ + band - 1) / band;
    for (int parity = 0; parity < 2; ++parity)
        tbb::parallel_for(0, (bands + 1 - parity) / 2, [&](int k) {
            const int y0 = (2 * k + parity) * band;
            filterSamples(y0, std::min(height_, y0 + band));
        });
}

namespace {
// The (pixel, sample) pairs of footprints waiting to be rounded (roundFootprint) and added.
struct FootprintBatch {
    FootprintLanes lanes;
    FootprintAdds adds;
    std::atomic<std::int64_t>* target[simd::kBlock]; // the pixel's half's four sums
    int halves[simd::kBlock];
    size_t count = 0;
};
} // namespace

// The sums of the samples of rows [y0, y1), each filtered into its footprint, and zeroed. A
// sample's weight is rounded with the key a sample's weight always had, so that the weight sums
// are the same as if each contribution were filtered on its own; its radiance sum with a key of
// its own path. The rounding is SIMD-wide, over the pixels of many samples' footprints at once.
void Film::filterSamples(int y0, int y1) {
    const uint spi = samplesPerIteration_, base = sampleBase_.load();
    // What depends on the sample's index alone: its half and its weight's rounding key.
    thread_local std::vector<int> halves;
    thread_local std::vector<uint> weightKeys;
    halves.resize(spi);
    weightKeys.resize(spi);
    for (uint s = 0; s < spi; ++s)
        halves[s] = halfOf(base + s), weightKeys[s] = roundingKey(0u, base + s);
    FootprintBatch batch;
    auto flush = [&] {
        roundLanes(batch.lanes, batch.count, batch.halves, batch.adds);
        // No other thread adds to these pixels now (finishSamples).
        auto addTo = [](std::atomic<std::int64_t>& v, std::int64_t q) {
            if (q != 0) v.store(v.load(std::memory_order_relaxed) + q, std::memory_order_relaxed);
        };
        for (size_t k = 0; k < batch.count; ++k) {
            std::atomic<std::int64_t>* a = batch.target[k];
            addTo(a[0], batch.adds.r[k]);
            addTo(a[1], batch.adds.g[k]);
            addTo(a[2], batch.adds.b[k]);
            addTo(a[3], batch.adds.w[k]);
        }
        batch.count = 0;
    };
    for (int y = y0; y < y1; ++y)
        for (int x = 0; x < width_; ++x) {
            if (!sampling(x, y)) continue;
            const size_t pixel = size_t(y) * size_t(width_) + size_t(x);
            for (uint s = 0; s < spi; ++s) {
                const size_t path = pixel * spi + s;
                SampleSum& sum = samples_[path];
                double rgb[3];
                for (int c = 0; c < 3; ++c) {
                    rgb[c] = sum.rgb[c].load(std::memory_order_relaxed);
                    sum.rgb[c].store(0.0, std::memory_order_relaxed);
                }
                const int half = halves[s];
                const uint weightKey = weightKeys[s];
                const uint rgbKey = roundingKey(uint(path) ^ 0x5A3D0000u, base + s);
                forFootprint(vec2(sum.x, sum.y), [&](int px, int py, float w) {
                    const uint at = uint(py * width_ + px);
                    FootprintLanes& l = batch.lanes;
                    const size_t k = batch.count++;
                    l.pixel.v[k] = at, l.weightKey.v[k] = weightKey, l.rgbKey.v[k] = rgbKey;
                    l.weight.v[k] = w;
                    l.r[k] = rgb[0], l.g[k] = rgb[1], l.b[k] = rgb[2];
                    batch.target[k] = &acc_[at].v[half * 4];
                    batch.halves[k] = half;
                    if (batch.count == simd::kBlock) flush();
                });
            }
        }
    flush();
}

template <typename Fn> void Film::forFootprint(vec2 filmPos, const Fn& fn) const {
    const float r = filter_.radius;
    const int x0 = std::max(0, int(std::ceil(filmPos.x - 0.5f - r)));
    const int x1 = std::min(width_ - 1, int(std::floor(filmPos.x - 0.5f + r)));
    const int y0 = std::max(0, int(std::ceil(filmPos.y - 0.5f - r)));
    const int y1 = std::min(height_ - 1, int(std::floor(filmPos.y - 0.5f + r)));
    // The filter is separable: each column's weight once, not once per row.
    constexpr int kMaxReach = 2 * int(kMaxFilterRadius) + 2; // the widest footprint
    float wx[kMaxReach];
    for (int x = x0; x <= x1; ++x)
        wx[x - x0] = weight1D(float(x) + 0.5f - filmPos.x);
    for (int y = y0; y <= y1; ++y) {
        const float wy = weight1D(float(y) + 0.5f - filmPos.y);
        if (wy <= 0.0f) continue;
        for (int x = x0; x <= x1; ++x) {
            const float w = wy * wx[x - x0];
            if (w > 0.0f) fn(x, y, w);
        }
    }
}

void Film::filtered(vec2 filmPos, int half, vec3 radiance, float weight, uint key) {
    if (filter_.type == FilterType::Box) {
        int px = std::min(int(filmPos.x), width_ - 1), py = std::min(int(filmPos.y), height_ - 1);
        add(px, py, half, radiance, weight, key);
        return;
    }
    forFootprint(filmPos,
                 [&](int x, int y, float w) { add(x, y, half, radiance * w, weight * w, key); });
}

void Film::prefetch(uint path, vec2 filmPos) const {
    if (sumsSamples()) {
        __builtin_prefetch(&samples_[path], 1);
        return;
    }
    const int px = std::clamp(int(filmPos.x), 0, width_ - 1);
    const int py = std::clamp(int(filmPos.y), 0, height_ - 1);
    __builtin_prefetch(&acc_[size_t(py) * width_ + size_t(px)], 1);
    // And the pixel's sums on the first fine level, where most small contributions land.
    const size_t tile = size_t(py / kAdaptiveTile) * size_t(tilesX_) + size_t(px / kAdaptiveTile);
    const size_t slot = size_t((py % kAdaptiveTile) * kAdaptiveTile + px % kAdaptiveTile) * 6;
    if (const void* fine = iterLevels_.address(1, tile, slot)) __builtin_prefetch(fine, 1);
}

int Film::halfOf(uint sampleIndex) const {
    if (halves_ == Halves::ByStream) return int(sampleIndex & 1u);
    return int((sampleIndex / samplesPerIteration_ + sampleIndex % samplesPerIteration_) & 1u);
}

// Converting a 64-bit integer to double is one instruction, a 128-bit one a library call: the
// film reads the low words alone while they are the whole sums.
void Film::pixelSums(size_t pixel, double* s) const {
    for (int k = 0; k < 8; ++k)
        s[k] = !sumLo_  ? 0.0
               : sumHi_ ? double(sumAt(pixel, k))
                        : double(sumLo_[pixel].v[k].load(std::memory_order_relaxed));
    addLevelSums(renderLevels_, pixel, s);
    for (int k = 0; k < 8; ++k)
        s[k] /= k % 4 == 3 ? weightScale_ : scale_;
}

Film::Fixed Film::sumAt(size_t i, int k) const {
    if (!sumLo_) return 0;
    const std::int64_t lo = sumLo_[i].v[k].load(std::memory_order_relaxed);
    if (!sumHi_) return lo;
    return Fixed(sumHi_[i * 8 + size_t(k)]) * (Fixed(1) << 64) + Fixed(std::uint64_t(lo));
}

void Film::widenSums() {
    sumHi_.reset(new std::int64_t[pixels() * 8]);
    forPixels(pixels(), [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i)
            for (int k = 0; k < 8; ++k)
                sumHi_[i * 8 + size_t(k)] =
                    sumLo_[i].v[k].load(std::memory_order_relaxed) < 0 ? -1 : 0;
    });
}

void Film::addIterationToSums() {
    // An iteration's sum is at most 2^62 in magnitude (the clamp): the sums can only pass 2^63
    // once the largest is over 2^62, and then each add is checked before any is made.
    if (!sumHi_ && sumBound_ >= (std::uint64_t(1) << 62)) {
        const bool overflows = tbb::parallel_reduce(
            tbb::blocked_range<size_t>(0, pixels(), 16384), false,
            [&](const tbb::blocked_range<size_t>& r, bool any) {
                for (size_t i = r.begin(); i < r.end() && !any; ++i)
                    for (int k = 0; k < 8; ++k) {
                        std::int64_t out;
                        any |= __builtin_add_overflow(
                            sumLo_[i].v[k].load(std::memory_order_relaxed),
                            acc_[i].v[k].load(std::memory_order_relaxed), &out);
                    }
                return any;
            },
            [](bool a, bool b) { return a || b; });
        if (overflows) widenSums();
    }
    sumBound_ = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, pixels(), 16384), std::uint64_t(0),
        [&](const tbb::blocked_range<size_t>& r, std::uint64_t bound) {
            for (size_t i = r.begin(); i < r.end(); ++i)
                for (int k = 0; k < 8; ++k) {
                    const std::int64_t v = acc_[i].v[k].load(std::memory_order_relaxed);
                    std::atomic<std::int64_t>& lo = sumLo_[i].v[k];
                    if (!sumHi_) {
                        const std::int64_t sum = lo.load(std::memory_order_relaxed) + v;
                        lo.store(sum, std::memory_order_relaxed);
                        bound = std::max(bound, magnitude(sum));
                        continue;
                    }
                    // GCC's >> of a negative __int128 is arithmetic (the high word's sign).
                    const Fixed sum = sumAt(i, k) + v;
                    lo.store(std::int64_t(std::uint64_t(sum)), std::memory_order_relaxed);
                    sumHi_[i * 8 + size_t(k)] = std::int64_t(sum >> 64);
                }
            return bound;
        },
        [](std::uint64_t a, std::uint64_t b) { return std::max(a, b); });
}

void Film::endIteration() {
    if (!open_) throw std::logic_error("Film::endIteration without beginIteration");
    errorOfDecision_.reset(); // the sums change; decideTiles() below may make it again
    finishSamples();
    if (!sumLo_) {
        // The first iteration is the whole render so far: its sums become the render's, and
        // the next iteration's are allocated when it begins.
        sumLo_ = std::move(acc_);
        sumBound_ = std::uint64_t(1) << 62; // unknown: at most the clamp
        lastIteration_ = sumLo_.get();
        renderLevels_ = std::move(iterLevels_);
        lastLevels_ = &renderLevels_;
    } else {
        addIterationToSums();
        lastIteration_ = acc_.get();
        renderLevels_.add(iterLevels_);
        lastLevels_ = &iterLevels_;
    }
    accZero_ = false;
    open_ = false;
    // Every pixel of a tile that was sampling took the iteration's samples (in some process's
    // share): the counts are the tiles'.
    for (size_t t = 0; t < tileSamples_.size(); ++t)
        if (active_.empty() || active_[t]) tileSamples_[t] += samplesPerIteration_;
    decideTiles();
}

} // namespace spw
