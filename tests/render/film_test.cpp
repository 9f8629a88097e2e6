// The film's guard: a NaN or Inf sample is counted and dropped, never added, so one bad path
// cannot blacken or whiten a pixel (the CLI reports the count on stderr at the end).
#include "host/image/film.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace spw {
namespace {

TEST(Film, NonFiniteSamplesAreCountedAndDropped) {
    Film film(2, 1, Filter{}, 1.0f);
    const float nan = std::numeric_limits<float>::quiet_NaN(),
                inf = std::numeric_limits<float>::infinity();
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
    for (int c = 3; c < 6; ++c)
        EXPECT_EQ(img[size_t(c)], 0.0f) << "the second pixel saw only a non-finite sample";
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

// No accumulator wraps, whatever the samples per iteration and the filter's reach: the film
// clamps each add at 2^62 / N (N = samples per iteration x pixels a sample reaches) and scales
// so that samples up to 2^16 times the brightest emitter stay below the clamp. 2^22 samples
// 8x the brightest emitter, through a Gaussian of radius 16 with 4096 samples per iteration,
// summed 2^63.4 in each half buffer at a fixed scale of 2^40 (a wrap to garbage, as it was);
// here they average exactly 8.
TEST(Film, NoAccumulatorWrapsAtTheMostSamplesAFilterGathers) {
    Film film(1, 1, Filter{FilterType::Gaussian, 16.0f}, 1.0f, 4096);
    const int samples = 1 << 22;
    for (int i = 0; i < samples; ++i) {
        film.addSample(vec2(0.5f), uint(i));
        film.splat(vec2(0.5f), uint(i), vec3(8.0f), uint(i));
    }
    film.endIteration();
    EXPECT_EQ(film.saturatedSamples(), 0u);
    const std::vector<float> img = film.image();
    for (float v : img)
        EXPECT_NEAR(v, 8.0f, 8e-6f);
}

// The usual film keeps its brightest emitter's sample at 2^40 (a box filter, up to 64 samples
// per iteration), so images do not change with the guard above.
TEST(Film, UsualFilmsKeepTheBrightestSampleAt2To40) {
    for (int spi : {1, 4, 16, 64}) {
        const Film film(8, 8, Filter{}, 17.0f, spi);
        EXPECT_EQ(film.fixedPointScale() * 32.0, std::ldexp(1.0, 40)) << spi; // 17 rounds up to 2^5
    }
}

} // namespace
} // namespace spw
