#include "host/image/film.h"

#include "host/image/compare.h"
#include "shared/rng.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace spw {
namespace {

float filterWeight1D(FilterType type, float d, float radius) {
    d = std::fabs(d);
    if (d >= radius) return 0.0f;
    if (type == FilterType::Tent) return 1.0f - d / radius;
    float sigma = radius * 0.5f; // Gaussian, shifted to reach 0 at the radius
    float k = -0.5f / (sigma * sigma);
    return std::exp(k * d * d) - std::exp(k * radius * radius);
}

// The stochastic rounding's key: the caller's (path and bounce within the iteration) mixed with
// the render-wide sample index, so that every iteration rounds with fresh random numbers. Without
// the sample index a pixel whose value repeats each iteration (a tiny light seen through the
// Grid sampler) would be rounded the same way every time: a bias of up to one fixed-point step.
uint roundingKey(uint key, uint sampleIndex) {
    return pcg4d(uvec4(key, sampleIndex, 0xF11Du, 0x2545F491u)).x;
}

} // namespace

Film::Film(int width, int height, const Filter& filter, float brightestRadiance,
           int samplesPerIteration)
    : width_(width), height_(height), samplesPerIteration_(uint(samplesPerIteration)),
      filter_(filter), acc_(new PixelSums[size_t(width) * height]),
      sum_(size_t(width) * height * 8, 0), lastIteration_(size_t(width) * height * 3, 0.0f),
      iterationSamples_(new std::atomic<std::uint32_t>[size_t(width) * height]),
      samples_(size_t(width) * height, 0u), tilesX_((width + kAdaptiveTile - 1) / kAdaptiveTile),
      tilesY_((height + kAdaptiveTile - 1) / kAdaptiveTile) {
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
    beginIteration();
}

void Film::beginIteration() {
    nonFiniteBefore_ = nonFinite_.load();
    saturatedBefore_ = saturated_.load();
    for (size_t i = 0; i < size_t(width_) * height_; ++i) {
        for (std::atomic<std::int64_t>& v : acc_[i].v)
            v.store(0, std::memory_order_relaxed);
        iterationSamples_[i].store(0, std::memory_order_relaxed);
    }
}

void Film::setAdaptive(double threshold, int minSamples) {
    adaptiveThreshold_ = threshold;
    adaptiveMinSamples_ = minSamples;
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

void Film::decideAdaptiveTiles() {
    if (!(adaptiveThreshold_ > 0.0)) {
        active_.clear();
        activeTiles_ = 1;
        return;
    }
    active_.assign(size_t(tilesX_) * size_t(tilesY_), 1);
    activeTiles_ = active_.size();
    const double limit = adaptiveThreshold_ * adaptiveThreshold_; // on the mean square
    for (int ty = 0; ty < tilesY_; ++ty)
        for (int tx = 0; tx < tilesX_; ++tx) {
            double total = 0.0;
            size_t values = 0;
            bool ready = true;
            for (int y = ty * kAdaptiveTile; y < std::min(height_, (ty + 1) * kAdaptiveTile); ++y)
                for (int x = tx * kAdaptiveTile; x < std::min(width_, (tx + 1) * kAdaptiveTile);
                     ++x) {
                    const size_t i = size_t(y) * size_t(width_) + size_t(x);
                    if (samples_[i] < std::uint32_t(adaptiveMinSamples_) ||
                        !addHalfBufferRelMse(i, total, values))
                        ready = false;
                }
            if (ready && values > 0 && total / double(values) < limit) {
                active_[size_t(ty) * size_t(tilesX_) + size_t(tx)] = 0;
                --activeTiles_;
            }
        }
}

void Film::setShare(int index, int shares) {
    share_ = index;
    shares_ = shares;
    decideTiles();
}

std::vector<std::int64_t> Film::iterationAccumulators() const {
    const size_t n = size_t(width_) * height_;
    std::vector<std::int64_t> out(n * 9 + 2);
    for (size_t i = 0; i < n; ++i) {
        for (int k = 0; k < 8; ++k)
            out[i * 9 + size_t(k)] = acc_[i].v[k].load(std::memory_order_relaxed);
        out[i * 9 + 8] = iterationSamples_[i].load(std::memory_order_relaxed);
    }
    out[n * 9] = std::int64_t(nonFinite_.load() - nonFiniteBefore_);
    out[n * 9 + 1] = std::int64_t(saturated_.load() - saturatedBefore_);
    return out;
}

void Film::setIterationAccumulators(const std::vector<std::int64_t>& values) {
    const size_t n = size_t(width_) * height_;
    if (values.size() != n * 9 + 2)
        throw std::invalid_argument("iteration accumulators of another film size");
    for (size_t i = 0; i < n; ++i) {
        for (int k = 0; k < 8; ++k)
            acc_[i].v[k].store(values[i * 9 + size_t(k)], std::memory_order_relaxed);
        iterationSamples_[i].store(std::uint32_t(values[i * 9 + 8]), std::memory_order_relaxed);
    }
    nonFinite_ = nonFiniteBefore_ + std::uint64_t(values[n * 9]);
    saturated_ = saturatedBefore_ + std::uint64_t(values[n * 9 + 1]);
}

std::uint64_t Film::samplesTaken() const {
    std::uint64_t n = 0;
    for (std::uint32_t s : samples_)
        n += s;
    return n;
}

void Film::add(int px, int py, int half, vec3 value, float weight, uint key) {
    std::atomic<std::int64_t>* a = &acc_[size_t(py) * width_ + size_t(px)].v[half * 4];
    uvec4 h = pcg4d(uvec4(key, uint(py * width_ + px), 0x5157u, 0x9E3779B9u));
    const double in[4] = {value.x * scale_, value.y * scale_, value.z * scale_,
                          weight * weightScale_};
    const uint rnd[4] = {h.x, h.y, h.z, h.w};
    for (int c = 0; c < 4; ++c) {
        double v = in[c];
        if (std::fabs(v) > maxAdd_) {
            saturated_.fetch_add(1, std::memory_order_relaxed);
            v = std::copysign(maxAdd_, v);
        }
        double fl = std::floor(v);
        // Round up with probability frac(v): E[rounded] = v exactly.
        std::int64_t q = std::int64_t(fl) + (double(uintToUnit(rnd[c])) < v - fl ? 1 : 0);
        if (q != 0) a[c].fetch_add(q, std::memory_order_relaxed);
    }
}

void Film::splat(vec2 filmPos, uint sampleIndex, vec3 radiance, uint key) {
    if (!std::isfinite(radiance.x) || !std::isfinite(radiance.y) || !std::isfinite(radiance.z)) {
        nonFinite_.fetch_add(1, std::memory_order_relaxed);
        return;
    }
    if (radiance.x == 0.0f && radiance.y == 0.0f && radiance.z == 0.0f) return;
    filtered(filmPos, halfOf(sampleIndex), radiance, 0.0f, roundingKey(key, sampleIndex));
}

void Film::addSample(vec2 filmPos, uint sampleIndex) {
    const int px = std::min(int(filmPos.x), width_ - 1), py = std::min(int(filmPos.y), height_ - 1);
    iterationSamples_[size_t(py) * size_t(width_) + size_t(px)].fetch_add(
        1, std::memory_order_relaxed);
    filtered(filmPos, halfOf(sampleIndex), vec3(0.0f), 1.0f, roundingKey(0u, sampleIndex));
}

void Film::prefetch(vec2 filmPos) const {
    if (filter_.type == FilterType::Box) {
        const int px = std::clamp(int(filmPos.x), 0, width_ - 1);
        const int py = std::clamp(int(filmPos.y), 0, height_ - 1);
        __builtin_prefetch(&acc_[size_t(py) * width_ + size_t(px)], 1);
        return;
    }
    // Every pixel of the footprint (a line each): a wide filter's splat waits on all of them.
    const float r = std::min(filter_.radius, 2.0f); // beyond 4 x 4, prefetching the centre will do
    const int x0 = std::max(0, int(std::ceil(filmPos.x - 0.5f - r)));
    const int x1 = std::min(width_ - 1, int(std::floor(filmPos.x - 0.5f + r)));
    const int y0 = std::max(0, int(std::ceil(filmPos.y - 0.5f - r)));
    const int y1 = std::min(height_ - 1, int(std::floor(filmPos.y - 0.5f + r)));
    for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x)
            __builtin_prefetch(&acc_[size_t(y) * width_ + size_t(x)], 1);
}

int Film::halfOf(uint sampleIndex) const {
    return int((sampleIndex / samplesPerIteration_ + sampleIndex % samplesPerIteration_) & 1u);
}

void Film::filtered(vec2 filmPos, int half, vec3 radiance, float weight, uint key) {
    if (filter_.type == FilterType::Box) {
        int px = std::min(int(filmPos.x), width_ - 1), py = std::min(int(filmPos.y), height_ - 1);
        add(px, py, half, radiance, weight, key);
        return;
    }
    float r = filter_.radius;
    int x0 = std::max(0, int(std::ceil(filmPos.x - 0.5f - r)));
    int x1 = std::min(width_ - 1, int(std::floor(filmPos.x - 0.5f + r)));
    int y0 = std::max(0, int(std::ceil(filmPos.y - 0.5f - r)));
    int y1 = std::min(height_ - 1, int(std::floor(filmPos.y - 0.5f + r)));
    // The filter is separable: each column's weight once, not once per row (a Gaussian's two
    // exp() calls each). The products are the same floats as before, so the film is too.
    constexpr int kMaxReach = 2 * int(kMaxFilterRadius) + 2; // the widest footprint
    float wx[kMaxReach];
    for (int x = x0; x <= x1; ++x)
        wx[x - x0] = filterWeight1D(filter_.type, float(x) + 0.5f - filmPos.x, r);
    for (int y = y0; y <= y1; ++y) {
        float wy = filterWeight1D(filter_.type, float(y) + 0.5f - filmPos.y, r);
        if (wy <= 0.0f) continue;
        for (int x = x0; x <= x1; ++x) {
            float w = wy * wx[x - x0];
            if (w > 0.0f) add(x, y, half, radiance * w, weight * w, key);
        }
    }
}

void Film::endIteration() {
    const size_t n = size_t(width_) * height_;
    for (size_t i = 0; i < n; ++i) {
        std::int64_t it[4] = {0, 0, 0, 0};
        for (int h = 0; h < 2; ++h)
            for (int c = 0; c < 4; ++c) {
                const std::int64_t v = acc_[i].v[h * 4 + c].load(std::memory_order_relaxed);
                sum_[i * 8 + size_t(h) * 4 + size_t(c)] += v;
                it[c] += v;
            }
        const double weight = double(it[3]) / weightScale_;
        for (int c = 0; c < 3; ++c)
            lastIteration_[i * 3 + c] = it[3] > 0 ? float(double(it[c]) / scale_ / weight) : 0.0f;
        samples_[i] += iterationSamples_[i].load(std::memory_order_relaxed);
    }
    beginIteration();
    decideTiles();
}

Film::State Film::state() const {
    return {sum_,
            samples_,
            nonFinite_.load(),
            saturated_.load(),
            std::ilogb(scale_),
            std::ilogb(weightScale_)};
}

void Film::restore(const State& state) {
    if (state.sums.size() != sum_.size() || state.samples.size() != samples_.size())
        throw std::invalid_argument("a film state of another size");
    if (state.scaleExponent != std::ilogb(scale_) ||
        state.weightExponent != std::ilogb(weightScale_))
        throw std::invalid_argument("a film state of another fixed-point scale");
    sum_ = state.sums;
    samples_ = state.samples;
    nonFinite_ = state.nonFinite;
    saturated_ = state.saturated;
    beginIteration();
    decideTiles();
}

namespace {
// A pixel's eight sums in radiance and weight units.
void toUnits(const Film::Fixed* sums, double scale, double weightScale, double* s) {
    for (int k = 0; k < 8; ++k)
        s[k] = double(sums[k]) / (k % 4 == 3 ? weightScale : scale);
}

std::vector<float> imageFromSums(const Film::Fixed* sums, size_t pixels, double scale,
                                 double weightScale) {
    std::vector<float> out(pixels * 3, 0.0f);
    for (size_t i = 0; i < pixels; ++i) {
        double s[8];
        toUnits(sums + i * 8, scale, weightScale, s);
        double w = s[3] + s[7];
        if (w > 0)
            for (int c = 0; c < 3; ++c)
                out[i * 3 + c] = float((s[c] + s[4 + c]) / w);
    }
    return out;
}
} // namespace

void Film::pixelSums(size_t pixel, double* s) const {
    toUnits(&sum_[pixel * 8], scale_, weightScale_, s);
}

bool Film::addHalfBufferRelMse(size_t pixel, double& total, size_t& count) const {
    double s[8];
    pixelSums(pixel, s);
    if (!(s[3] > 0 && s[7] > 0)) return false;
    for (int c = 0; c < 3; ++c) {
        const double a = s[c] / s[3], b = s[4 + c] / s[7], m = (s[c] + s[4 + c]) / (s[3] + s[7]);
        total += (a - b) * (a - b) / 4.0 / (m * m + kRelMseEpsilon);
        ++count;
    }
    return true;
}

std::vector<float> Film::image() const {
    return imageFromSums(sum_.data(), size_t(width_) * height_, scale_, weightScale_);
}

std::vector<float> Film::imageOf(const State& state) {
    return imageFromSums(state.sums.data(), state.sums.size() / 8,
                         std::ldexp(1.0, state.scaleExponent),
                         std::ldexp(1.0, state.weightExponent));
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

std::optional<double> Film::halfBufferRelMseEstimate() const {
    const size_t n = size_t(width_) * height_;
    double total = 0;
    size_t count = 0;
    for (size_t i = 0; i < n; ++i)
        addHalfBufferRelMse(i, total, count);
    if (count == 0) return std::nullopt;
    return total / double(count);
}

} // namespace spw
