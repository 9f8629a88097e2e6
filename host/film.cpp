#include "host/film.h"

#include "shared/rng.h"

#include <cmath>

namespace spw {
namespace {

constexpr double kMaxFixed = 4.6e18; // below 2^62: the sum of two saturated adds cannot wrap

float filterWeight1D(FilterType type, float d, float radius) {
    d = std::fabs(d);
    if (d >= radius) return 0.0f;
    if (type == FilterType::Tent) return 1.0f - d / radius;
    float sigma = radius * 0.5f; // Gaussian, shifted to reach 0 at the radius
    float k = -0.5f / (sigma * sigma);
    return std::exp(k * d * d) - std::exp(k * radius * radius);
}

} // namespace

Film::Film(int width, int height, const Filter& filter, float brightestRadiance)
    : width_(width), height_(height), filter_(filter),
      acc_(new std::atomic<std::int64_t>[size_t(width) * height * 4]),
      sum_(size_t(width) * height * 4, 0.0), lastIteration_(size_t(width) * height * 3, 0.0f) {
    int e = brightestRadiance > 0.0f ? int(std::ceil(std::log2(brightestRadiance))) : 0;
    e = std::max(-60, std::min(60, e));
    scale_ = std::ldexp(1.0, 40 - e);
    weightScale_ = std::ldexp(1.0, 40);
    beginIteration();
}

void Film::beginIteration() {
    for (size_t i = 0; i < size_t(width_) * height_ * 4; ++i) acc_[i].store(0, std::memory_order_relaxed);
}

void Film::add(int px, int py, vec3 value, float weight, uint key) {
    std::atomic<std::int64_t>* a = &acc_[(size_t(py) * width_ + px) * 4];
    uvec4 h = pcg4d(uvec4(key, uint(py * width_ + px), 0x5157u, 0x9E3779B9u));
    const double in[4] = {value.x * scale_, value.y * scale_, value.z * scale_, weight * weightScale_};
    const uint rnd[4] = {h.x, h.y, h.z, h.w};
    for (int c = 0; c < 4; ++c) {
        double v = in[c];
        if (std::fabs(v) > kMaxFixed) {
            saturated_.fetch_add(1, std::memory_order_relaxed);
            v = std::copysign(kMaxFixed, v);
        }
        double fl = std::floor(v);
        // Round up with probability frac(v): E[rounded] = v exactly.
        std::int64_t q = std::int64_t(fl) + (double(uintToUnit(rnd[c])) < v - fl ? 1 : 0);
        if (q != 0) a[c].fetch_add(q, std::memory_order_relaxed);
    }
}

void Film::splat(vec2 filmPos, vec3 radiance, uint key) {
    if (!std::isfinite(radiance.x) || !std::isfinite(radiance.y) || !std::isfinite(radiance.z)) {
        nonFinite_.fetch_add(1, std::memory_order_relaxed);
        return;
    }
    if (radiance.x == 0.0f && radiance.y == 0.0f && radiance.z == 0.0f) return;
    filtered(filmPos, radiance, 0.0f, key);
}

void Film::addSample(vec2 filmPos) { filtered(filmPos, vec3(0.0f), 1.0f, 0u); }

void Film::filtered(vec2 filmPos, vec3 radiance, float weight, uint key) {
    if (filter_.type == FilterType::Box) {
        int px = std::min(int(filmPos.x), width_ - 1), py = std::min(int(filmPos.y), height_ - 1);
        add(px, py, radiance, weight, key);
        return;
    }
    float r = filter_.radius;
    int x0 = std::max(0, int(std::ceil(filmPos.x - 0.5f - r)));
    int x1 = std::min(width_ - 1, int(std::floor(filmPos.x - 0.5f + r)));
    int y0 = std::max(0, int(std::ceil(filmPos.y - 0.5f - r)));
    int y1 = std::min(height_ - 1, int(std::floor(filmPos.y - 0.5f + r)));
    for (int y = y0; y <= y1; ++y) {
        float wy = filterWeight1D(filter_.type, float(y) + 0.5f - filmPos.y, r);
        if (wy <= 0.0f) continue;
        for (int x = x0; x <= x1; ++x) {
            float w = wy * filterWeight1D(filter_.type, float(x) + 0.5f - filmPos.x, r);
            if (w > 0.0f) add(x, y, radiance * w, weight * w, key);
        }
    }
}

void Film::endIteration() {
    const size_t n = size_t(width_) * height_;
    for (size_t i = 0; i < n; ++i) {
        double v[4];
        for (int c = 0; c < 4; ++c) v[c] = double(acc_[i * 4 + c].load(std::memory_order_relaxed));
        v[0] /= scale_;
        v[1] /= scale_;
        v[2] /= scale_;
        v[3] /= weightScale_;
        for (int c = 0; c < 4; ++c) sum_[i * 4 + c] += v[c];
        for (int c = 0; c < 3; ++c) lastIteration_[i * 3 + c] = v[3] > 0 ? float(v[c] / v[3]) : 0.0f;
    }
    beginIteration();
}

std::vector<float> Film::image() const {
    const size_t n = size_t(width_) * height_;
    std::vector<float> out(n * 3, 0.0f);
    for (size_t i = 0; i < n; ++i) {
        double w = sum_[i * 4 + 3];
        if (w > 0)
            for (int c = 0; c < 3; ++c) out[i * 3 + c] = float(sum_[i * 4 + c] / w);
    }
    return out;
}

} // namespace spw
