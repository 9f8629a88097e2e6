#include "host/image/compare.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <stdexcept>

namespace spw {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

void checkSizes(const ImageRGB& a, const ImageRGB& b) {
    if (a.width != b.width || a.height != b.height)
        throw std::invalid_argument("image sizes differ: " + std::to_string(a.width) + "x" +
                                    std::to_string(a.height) + " against " +
                                    std::to_string(b.width) + "x" + std::to_string(b.height));
    const std::size_t values = std::size_t(a.width) * std::size_t(a.height) * 3;
    if (a.rgb.size() != values || b.rgb.size() != values)
        throw std::invalid_argument("image data do not match the stated size");
}

bool finitePixel(const float* p) {
    return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
}

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return s;
}

// ---- metric names -----------------------------------------------------------------------------

struct MetricName {
    const char* name;
    double ImageMetrics::*field;
    bool lowerBound; // psnr: larger is better
};
constexpr MetricName kMetrics[] = {
    {"mse", &ImageMetrics::mse, false},       {"rmse", &ImageMetrics::rmse, false},
    {"relmse", &ImageMetrics::relMse, false}, {"mae", &ImageMetrics::mae, false},
    {"maxabs", &ImageMetrics::maxAbs, false}, {"psnr", &ImageMetrics::psnr, true},
};

const MetricName& findMetric(const std::string& name) {
    const std::string key = lower(name);
    for (const MetricName& m : kMetrics)
        if (key == m.name) return m;
    throw std::invalid_argument("unknown metric '" + name +
                                "' (mse, rmse, relmse, mae, maxabs, psnr)");
}

// ---- heatmap drawing --------------------------------------------------------------------------

// Matplotlib's viridis at t = 0, 1/8, ..., 1 (sRGB bytes; viridisLite's nine-colour palette).
constexpr unsigned char kViridis[9][3] = {
    {0x44, 0x01, 0x54}, {0x47, 0x2D, 0x7B}, {0x3B, 0x52, 0x8B},
    {0x2C, 0x72, 0x8E}, {0x21, 0x90, 0x8C}, {0x27, 0xAD, 0x81},
    {0x5D, 0xC8, 0x63}, {0xAA, 0xDC, 0x32}, {0xFD, 0xE7, 0x25},
};

// A 3x5 pixel font for the bar labels: each glyph is five rows of three bits, MSB on the left.
struct Glyph {
    char c;
    unsigned char rows[5];
};
constexpr Glyph kFont[] = {
    {'0', {7, 5, 5, 5, 7}}, {'1', {2, 6, 2, 2, 7}}, {'2', {7, 1, 7, 4, 7}}, {'3', {7, 1, 7, 1, 7}},
    {'4', {5, 5, 7, 1, 1}}, {'5', {7, 4, 7, 1, 7}}, {'6', {7, 4, 7, 5, 7}}, {'7', {7, 1, 1, 1, 1}},
    {'8', {7, 5, 7, 5, 7}}, {'9', {7, 5, 7, 1, 7}}, {'.', {0, 0, 0, 0, 2}}, {'-', {0, 0, 7, 0, 0}},
    {'+', {0, 2, 7, 2, 0}}, {'e', {2, 5, 7, 4, 3}},
};

class Canvas {
  public:
    Canvas(int width, int height, unsigned char grey)
        : width_(width), height_(height), px_(std::size_t(width) * height * 3, grey) {}
    int width() const { return width_; }
    int height() const { return height_; }
    const unsigned char* data() const { return px_.data(); }

    void fill(int x0, int y0, int x1, int y1, std::array<unsigned char, 3> c) {
        x0 = std::max(x0, 0), y0 = std::max(y0, 0);
        x1 = std::min(x1, width_), y1 = std::min(y1, height_);
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x)
                std::copy(c.begin(), c.end(), &px_[(std::size_t(y) * width_ + x) * 3]);
    }
    // Text with its top-left corner at (x, y), each font pixel `scale` pixels wide.
    void text(int x, int y, const std::string& s, int scale, std::array<unsigned char, 3> c) {
        for (char ch : s) {
            for (const Glyph& g : kFont)
                if (g.c == ch)
                    for (int r = 0; r < 5; ++r)
                        for (int k = 0; k < 3; ++k)
                            if (g.rows[r] & (4 >> k))
                                fill(x + k * scale, y + r * scale, x + (k + 1) * scale,
                                     y + (r + 1) * scale, c);
            x += advance(scale);
        }
    }
    static int advance(int scale) { return 4 * scale; }
    static int textWidth(const std::string& s, int scale) {
        return s.empty() ? 0 : int(s.size()) * advance(scale) - scale;
    }

  private:
    int width_, height_;
    std::vector<unsigned char> px_;
};

std::string shortNumber(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.2g", v);
    return buf;
}

} // namespace

ImageMetrics compareImages(const ImageRGB& a, const ImageRGB& b) {
    checkSizes(a, b);
    ImageMetrics m;
    m.width = a.width;
    m.height = a.height;
    m.pixels = std::size_t(a.width) * std::size_t(a.height);
    double sum2 = 0, sumRel = 0, sumAbs = 0;
    std::array<double, 3> sumA{}, sumB{};
    for (std::size_t i = 0; i < m.pixels; ++i) {
        const float* pa = &a.rgb[3 * i];
        const float* pb = &b.rgb[3 * i];
        const bool fa = finitePixel(pa), fb = finitePixel(pb);
        m.nonFiniteA += !fa;
        m.nonFiniteB += !fb;
        if (!fa || !fb) continue;
        ++m.comparedPixels;
        for (int c = 0; c < 3; ++c) {
            const double va = pa[c], vb = pb[c], d = va - vb;
            sum2 += d * d;
            sumRel += d * d / (vb * vb + kRelMseEpsilon);
            sumAbs += std::abs(d);
            if (std::abs(d) > m.maxAbs || m.maxAbsX < 0) {
                m.maxAbs = std::abs(d);
                m.maxAbsX = int(i % std::size_t(a.width));
                m.maxAbsY = int(i / std::size_t(a.width));
            }
            sumA[c] += va;
            sumB[c] += vb;
        }
    }
    if (m.comparedPixels == 0) {
        m.mse = m.rmse = m.relMse = m.mae = m.maxAbs = m.psnr = kNaN;
        m.meanA = m.meanB = {kNaN, kNaN, kNaN};
        return m;
    }
    const double n = double(m.comparedPixels);
    m.mse = sum2 / (3 * n);
    m.rmse = std::sqrt(m.mse);
    m.relMse = sumRel / (3 * n);
    m.mae = sumAbs / (3 * n);
    m.psnr = m.mse > 0 ? -10.0 * std::log10(m.mse) : kInf;
    for (int c = 0; c < 3; ++c)
        m.meanA[c] = sumA[c] / n, m.meanB[c] = sumB[c] / n;
    return m;
}

nlohmann::json toJson(const ImageMetrics& m) {
    auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
    auto triple = [&](const std::array<double, 3>& v) {
        return nlohmann::json::array({num(v[0]), num(v[1]), num(v[2])});
    };
    return {{"width", m.width},
            {"height", m.height},
            {"pixels", m.pixels},
            {"compared_pixels", m.comparedPixels},
            {"nonfinite_a", m.nonFiniteA},
            {"nonfinite_b", m.nonFiniteB},
            {"mse", num(m.mse)},
            {"rmse", num(m.rmse)},
            {"relmse", num(m.relMse)},
            {"mae", num(m.mae)},
            {"maxabs", num(m.maxAbs)},
            {"maxabs_pixel", nlohmann::json::array({m.maxAbsX, m.maxAbsY})},
            {"psnr", num(m.psnr)},
            {"psnr_peak", 1.0},
            {"mean_a", triple(m.meanA)},
            {"mean_b", triple(m.meanB)}};
}

Threshold parseThreshold(const std::string& text) {
    const std::size_t eq = text.find('=');
    if (eq == std::string::npos) throw std::invalid_argument("'" + text + "' is not METRIC=VALUE");
    Threshold t;
    t.metric = findMetric(text.substr(0, eq)).name;
    const std::string v = text.substr(eq + 1);
    std::size_t used = 0;
    try {
        t.bound = std::stod(v, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (v.empty() || used != v.size() || std::isnan(t.bound))
        throw std::invalid_argument("the bound of " + t.metric + " must be a number, not '" + v +
                                    "'");
    if (!findMetric(t.metric).lowerBound && !(t.bound >= 0.0))
        throw std::invalid_argument("the bound of " + t.metric + " must be 0 or more, not " + v);
    return t;
}

double metricValue(const ImageMetrics& metrics, const std::string& metric) {
    return metrics.*findMetric(metric).field;
}

bool isLowerBound(const std::string& metric) {
    return findMetric(metric).lowerBound;
}

bool meetsThreshold(const ImageMetrics& metrics, const Threshold& threshold) {
    const MetricName& m = findMetric(threshold.metric);
    const double v = metrics.*m.field;
    if (std::isnan(v)) return false;
    return m.lowerBound ? v >= threshold.bound : v <= threshold.bound;
}

std::vector<double> relativeErrorPerPixel(const ImageRGB& a, const ImageRGB& b) {
    checkSizes(a, b);
    std::vector<double> err(std::size_t(a.width) * std::size_t(a.height), kNaN);
    for (std::size_t i = 0; i < err.size(); ++i) {
        const float* pa = &a.rgb[3 * i];
        const float* pb = &b.rgb[3 * i];
        if (!finitePixel(pa) || !finitePixel(pb)) continue;
        double s = 0;
        for (int c = 0; c < 3; ++c) {
            const double d = double(pa[c]) - double(pb[c]);
            s += d * d / (double(pb[c]) * pb[c] + kRelMseEpsilon);
        }
        err[i] = s / 3.0;
    }
    return err;
}

std::array<unsigned char, 3> viridis(double t) {
    t = std::isnan(t) ? 0.0 : std::clamp(t, 0.0, 1.0) * 8.0;
    const int k = std::min(int(t), 7);
    const double f = t - k;
    std::array<unsigned char, 3> c;
    for (int i = 0; i < 3; ++i)
        c[i] =
            (unsigned char)std::lround(kViridis[k][i] + f * (kViridis[k + 1][i] - kViridis[k][i]));
    return c;
}

HeatmapInfo writeHeatmap(const std::string& path, const ImageRGB& a, const ImageRGB& b) {
    const std::vector<double> err = relativeErrorPerPixel(a, b);

    // The bar's range: the largest error, down to the smallest non-zero one (six decades at most).
    HeatmapInfo info;
    double low = kInf;
    for (double e : err)
        if (std::isfinite(e)) {
            info.high = std::max(info.high, e);
            if (e > 0) low = std::min(low, e);
        }
    if (info.high > 0) {
        info.low = std::max(low, info.high * 1e-6);
        if (info.low >= info.high) info.low = info.high / 10; // one value: a decade below it
    }
    const double logLow = info.high > 0 ? std::log10(info.low) : 0.0;
    const double logSpan = info.high > 0 ? std::log10(info.high) - logLow : 1.0;
    auto colour = [&](double e) -> std::array<unsigned char, 3> {
        if (!std::isfinite(e)) return {255, 0, 0};
        if (!(e > info.low)) return viridis(0.0);
        return viridis((std::log10(e) - logLow) / logSpan);
    };

    // Layout: the image enlarged by a whole factor to at least 256 pixels wide (at most 16x),
    // centred on a canvas at least 256 wide; below it the bar, its ticks and its labels.
    const int scale = a.width >= 256 ? 1 : std::min(16, (256 + a.width - 1) / a.width);
    const int imageW = a.width * scale, imageH = a.height * scale;
    const int canvasW = std::max(imageW, 256);
    const int fs = std::max(2, canvasW / 300); // font pixel size
    const int gap = 3 * fs, barH = 5 * fs, tickH = 2 * fs, textH = 5 * fs;
    const int barTop = imageH + gap, tickTop = barTop + barH, textTop = tickTop + tickH + fs;
    Canvas canvas(canvasW, textTop + textH + 2 * fs, 24);
    const int offsetX = (canvasW - imageW) / 2;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x)
            canvas.fill(offsetX + x * scale, y * scale, offsetX + (x + 1) * scale, (y + 1) * scale,
                        colour(err[std::size_t(y) * a.width + x]));

    const int margin = std::max(8, canvasW / 32);
    const int barX0 = margin, barX1 = canvasW - margin, barW = barX1 - barX0;
    for (int x = barX0; x < barX1; ++x)
        canvas.fill(x, barTop, x + 1, tickTop, viridis((x - barX0 + 0.5) / barW));

    // Labels: both ends first, then every decade inside that does not collide with one drawn.
    const std::array<unsigned char, 3> white{235, 235, 235};
    std::vector<std::pair<int, int>> taken; // x extents of drawn labels
    auto label = [&](double frac, const std::string& s, bool tick) {
        const int x = barX0 + int(std::lround(frac * (barW - 1)));
        const int w = Canvas::textWidth(s, fs);
        const int left = std::clamp(x - w / 2, fs, std::max(fs, canvasW - w - fs));
        const int tickX = x - fs / 4;
        if (tick) canvas.fill(tickX, tickTop, tickX + std::max(1, fs / 2), tickTop + tickH, white);
        for (auto [l, r] : taken)
            if (left < r + 2 * fs && l < left + w + 2 * fs) return;
        taken.emplace_back(left, left + w);
        canvas.text(left, textTop, s, fs, white);
    };
    if (info.high > 0) {
        label(0.0, shortNumber(info.low), true);
        label(1.0, shortNumber(info.high), true);
        for (int d = int(std::ceil(logLow)); d <= int(std::floor(logLow + logSpan)); ++d)
            label((d - logLow) / logSpan, "1e" + std::to_string(d), true);
    } else {
        label(0.0, "0", true);
    }

    char desc[320];
    std::snprintf(desc, sizeof desc,
                  "Spillway compare heatmap: per-pixel relative error, channel mean of "
                  "(a-b)^2/(b^2+0.01); viridis on a log10 scale from %.6g to %.6g; "
                  "red = non-finite pixel",
                  info.low, info.high);
    writeImage8(path, canvas.width(), canvas.height(), canvas.data(), "Spillway compare", desc);
    info.width = canvas.width();
    info.height = canvas.height();
    return info;
}

} // namespace spw
