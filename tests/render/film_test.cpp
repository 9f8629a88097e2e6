// The film's guard: a NaN or Inf sample is counted and dropped, never added, so one bad path
// cannot blacken or whiten a pixel (the CLI reports the count on stderr at the end).
#include "host/film.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace spw {
namespace {

TEST(Film, NonFiniteSamplesAreCountedAndDropped) {
    Film film(2, 1, Filter{}, 1.0f);
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    film.addSample(vec2(0.5f, 0.5f), 0);
    film.addSample(vec2(1.5f, 0.5f), 0);
    film.splat(vec2(0.5f, 0.5f), 0, vec3(0.25f, 0.5f, 1.0f), 1u);
    film.splat(vec2(0.5f, 0.5f), 0, vec3(nan, 0.0f, 0.0f), 2u);
    film.splat(vec2(0.5f, 0.5f), 0, vec3(0.0f, inf, 0.0f), 3u);
    film.splat(vec2(1.5f, 0.5f), 0, vec3(0.0f, 0.0f, -inf), 4u);
    film.endIteration();
    EXPECT_EQ(film.nonFiniteSamples(), 3u);
    const std::vector<float> img = film.image();
    EXPECT_FLOAT_EQ(img[0], 0.25f);
    EXPECT_FLOAT_EQ(img[1], 0.5f);
    EXPECT_FLOAT_EQ(img[2], 1.0f);
    for (int c = 3; c < 6; ++c) EXPECT_EQ(img[size_t(c)], 0.0f) << "the second pixel saw only a non-finite sample";
}

// The stochastic rounding to the fixed-point grid is unbiased over iterations even for a value
// that repeats exactly each time (it draws fresh random numbers per sample index): the mean of
// many iterations of a value between two grid steps lands between them, not on one.
TEST(Film, RoundingIsUnbiasedAcrossIterations) {
    Film film(1, 1, Filter{}, 1.0f);
    const double step = 1.0 / film.fixedPointScale();
    const float value = float(step * 0.3); // 0.3 of one fixed-point step
    const int iterations = 4000;
    for (int it = 0; it < iterations; ++it) {
        film.addSample(vec2(0.5f), uint(it));
        film.splat(vec2(0.5f), uint(it), vec3(value), 7u); // same path key every iteration
        film.endIteration();
    }
    const double mean = film.image()[0];
    // Binomial: 0.3 steps on average, standard error step * sqrt(0.21 / n).
    EXPECT_NEAR(mean, value, 4.0 * step * std::sqrt(0.21 / iterations)) << "step " << step;
}

} // namespace
} // namespace spw
