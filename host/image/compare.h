// Image comparison, what `spillway compare A B` (host/app/compare_command.h) computes: error
// metrics of a test image A against a reference B, a false-colour heatmap of the per-pixel relative
// error, and pass/fail bounds.
//
// Metrics run over every channel value of every pixel where all six values (A's and B's RGB)
// are finite; a pixel with any NaN or infinity is counted in that image's non-finite count and
// left out. Over those N pixels (3N values), with d = a - b:
//   mse    = mean d^2            rmse = sqrt(mse)        mae = mean |d|
//   relmse = mean d^2 / (b^2 + 0.01)   (B is the reference; 0.01 keeps black pixels finite)
//   maxabs = max |d|
//   psnr   = 10 log10(1 / mse) dB: peak 1.0 on the linear values as stored (no tone mapping);
//            +infinity when mse = 0
// Per-channel means of A and B are over the same compared pixels. With no pixel compared every
// metric is NaN (null in JSON) and every threshold fails.
//
#pragma once

#include "host/image/image_io.h"

#include <nlohmann/json.hpp>

#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace spw {

struct ImageMetrics {
    int width = 0, height = 0;
    std::size_t pixels = 0;         // width * height
    std::size_t comparedPixels = 0; // pixels finite in both images
    std::size_t nonFiniteA = 0;     // pixels of A with a NaN or infinite channel
    std::size_t nonFiniteB = 0;
    double mse = 0, rmse = 0, relMse = 0, mae = 0, maxAbs = 0;
    double psnr = 0;                // dB, peak 1.0 (linear); +inf when mse == 0
    int maxAbsX = -1, maxAbsY = -1; // pixel holding maxAbs; -1 when none compared
    std::array<double, 3> meanA{}, meanB{};
};

// relMSE's denominator is b^2 + kRelMseEpsilon: it keeps black pixels finite. The film's
// half-buffer estimate (film.cpp) uses the same, so that the two are one measure.
constexpr double kRelMseEpsilon = 0.01;

// Metrics of `a` against the reference `b`. Throws std::invalid_argument when the sizes differ.
ImageMetrics compareImages(const ImageRGB& a, const ImageRGB& b);

// Keys: width, height, pixels, compared_pixels, nonfinite_a, nonfinite_b, mse, rmse, relmse,
// mae, maxabs, maxabs_pixel [x, y], psnr, psnr_peak, mean_a [r, g, b], mean_b [r, g, b].
// JSON has no infinity: psnr is null when mse == 0 (identical), as is any NaN metric.
nlohmann::json toJson(const ImageMetrics& metrics);

// A --threshold bound. Metrics: mse, rmse, relmse, mae, maxabs (upper bounds: fail above) and
// psnr (lower bound: fails below).
struct Threshold {
    std::string metric;
    double bound = 0;
};
// Parses "METRIC=VALUE" (metric case-insensitive); throws std::invalid_argument on an unknown
// metric or a value that is not a number.
Threshold parseThreshold(const std::string& text);
// The metric by its threshold name; throws std::invalid_argument on an unknown name.
double metricValue(const ImageMetrics& metrics, const std::string& metric);
// True for a metric whose threshold is a lower bound (psnr); throws like metricValue.
bool isLowerBound(const std::string& metric);
// True when the metric is within its bound; a NaN metric never is.
bool meetsThreshold(const ImageMetrics& metrics, const Threshold& threshold);

// Per pixel, the channel mean of (a - b)^2 / (b^2 + kRelMseEpsilon); NaN where either pixel is
// non-finite. Its mean over the finite pixels is relmse.
std::vector<double> relativeErrorPerPixel(const ImageRGB& a, const ImageRGB& b);

// Viridis (matplotlib's map, nine control points, linear in between), t clamped to [0, 1],
// as 8-bit sRGB.
std::array<unsigned char, 3> viridis(double t);

// What writeHeatmap drew: the error range the colour bar spans and the picture's size.
struct HeatmapInfo {
    double low = 0, high = 0; // relative error at the bar's left and right ends
    int width = 0, height = 0;
};
// Writes an 8-bit PNG: relativeErrorPerPixel on a log10 scale through viridis (images under
// 256 pixels wide are enlarged by whole pixels), non-finite pixels in red, and below it a
// colour bar with ticks at the decades and its end values written out. The bar spans the
// largest error down to the smallest non-zero one, at most six decades below; zero error is
// the bar's left colour. The range is also in the PNG's ImageDescription. Throws
// std::runtime_error naming the path when it cannot be written, std::invalid_argument when
// the sizes differ.
HeatmapInfo writeHeatmap(const std::string& path, const ImageRGB& a, const ImageRGB& b);

} // namespace spw
