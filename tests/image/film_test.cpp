// The film's guard: a NaN or Inf sample is counted and dropped, never added, so one bad path
// cannot blacken or whiten a pixel (the CLI reports the count on stderr at the end).
#include "host/image/film.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>

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
        film.beginIteration();
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

// The whole render's sums start at 64 bits and gain their high words the first time a sum could
// pass 2^63: 24 iterations of a sample at 2^61 (radiance 2^21 at the scale 2^40) sum to 1.5 x
// 2^65 per channel, and the image is still exactly 2^21, as are a checkpoint's state of the
// film and a film restored from it, which goes on summing. A negative sum (a filter's negative
// lobe) sign-extends.
TEST(Film, SumsWidenPast64BitsWithoutLosingAnything) {
    Film film(2, 1, Filter{}, 1.0f);
    ASSERT_EQ(film.fixedPointScale(), std::ldexp(1.0, 40));
    const float big = std::ldexp(1.0f, 21);
    for (int it = 0; it < 24; ++it) {
        if (it > 0) film.beginIteration();
        film.addSample(vec2(0.5f), uint(it));
        film.addSample(vec2(1.5f), uint(it));
        film.splat(vec2(0.5f), uint(it), vec3(big, 1.0f, 0.5f), 1u);
        film.splat(vec2(1.5f), uint(it), vec3(0.25f), 2u);
        film.endIteration();
        EXPECT_EQ(film.lastIterationImage()[0], big) << it;
    }
    EXPECT_EQ(film.saturatedSamples(), 0u);
    const std::vector<float> img = film.image();
    EXPECT_EQ(img[0], big);
    EXPECT_EQ(img[1], 1.0f);
    EXPECT_EQ(img[2], 0.5f);
    EXPECT_EQ(img[3], 0.25f);
    const Film::State state = film.state();
    // Half 0 took the even iterations' samples (sample index 0, iteration it: half it mod 2).
    EXPECT_EQ(state.sums[0], Film::Fixed(12) << 61);
    EXPECT_EQ(Film::imageOf(state), img);
    Film resumed(2, 1, Filter{}, 1.0f);
    resumed.restore(state);
    EXPECT_EQ(resumed.image(), img);
    resumed.addSample(vec2(0.5f), 24u);
    resumed.splat(vec2(0.5f), 24u, vec3(big), 1u);
    resumed.endIteration();
    EXPECT_EQ(resumed.image()[0], big);
    EXPECT_EQ(resumed.state().sums[0], Film::Fixed(13) << 61);

    Film negative(1, 1, Filter{}, 1.0f);
    for (int it = 0; it < 8; ++it) {
        if (it > 0) negative.beginIteration();
        negative.addSample(vec2(0.5f), 0u);
        negative.splat(vec2(0.5f), 0u, vec3(-big, big, 1.0f), 1u);
        negative.endIteration();
    }
    EXPECT_EQ(negative.image(), (std::vector<float>{-big, big, 1.0f}));
    EXPECT_EQ(negative.state().sums[0], -(Film::Fixed(8) << 61));
}

// An iteration ends only after it began: a loop that forgets beginIteration() would add the
// same sums twice.
TEST(Film, AnIterationEndsOnceItBegan) {
    Film film(1, 1, Filter{}, 1.0f);
    film.endIteration();
    EXPECT_THROW(film.endIteration(), std::logic_error);
    film.beginIteration();
    EXPECT_THROW(film.lastIterationImage(), std::logic_error);
}

// The usual film keeps its brightest emitter's sample at 2^40 (a box filter, up to 64 samples
// per iteration), so images do not change with the guard above.
TEST(Film, UsualFilmsKeepTheBrightestSampleAt2To40) {
    for (int spi : {1, 4, 16, 64}) {
        const Film film(8, 8, Filter{}, 17.0f, spi);
        EXPECT_EQ(film.fixedPointScale() * 32.0, std::ldexp(1.0, 40)) << spi; // 17 rounds up to 2^5
    }
}

// Distributed rendering's split (Film::setShare): three films' shares cover every tile exactly
// once, evenly (within one tile), and their accumulators, added, are one film's: the same image
// and counts, bit for bit, with the non-finite samples counted once.
TEST(Film, SharesCoverEveryTileOnceAndAddUpToOneFilm) {
    const int width = 41, height = 17, shares = 3; // 6 x 3 tiles, the last ones partial
    Film whole(width, height, Filter{FilterType::Gaussian, 1.5f}, 4.0f);
    std::vector<std::unique_ptr<Film>> parts;
    for (int s = 0; s < shares; ++s) {
        parts.push_back(
            std::make_unique<Film>(width, height, Filter{FilterType::Gaussian, 1.5f}, 4.0f));
        parts.back()->setShare(s, shares);
    }
    std::vector<int> tiles(size_t(shares), 0);
    for (int y = 0; y < height; y += Film::kAdaptiveTile)
        for (int x = 0; x < width; x += Film::kAdaptiveTile) {
            int owners = 0;
            for (int s = 0; s < shares; ++s)
                if (parts[size_t(s)]->sampling(x, y)) {
                    ++owners;
                    ++tiles[size_t(s)];
                }
            EXPECT_EQ(owners, 1) << "tile at " << x << ", " << y;
        }
    for (int s = 0; s < shares; ++s)
        EXPECT_EQ(tiles[size_t(s)], 6) << "18 tiles in 3 even shares";

    // Each pixel's sample goes to the film whose share holds it; all of them to `whole`.
    std::vector<std::int64_t> sum;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            for (int s = 0; s < shares; ++s) {
                Film& f = *parts[size_t(s)];
                if (!f.sampling(x, y)) continue;
                const vec2 p(float(x) + 0.3f, float(y) + 0.6f);
                const vec3 v(float(x % 7) * 0.1f, float(y % 5) * 0.2f, 0.7f);
                const uint key = uint(y * width + x);
                for (Film* film : {&f, &whole}) {
                    film->addSample(p, 0);
                    film->splat(p, 0, v, key);
                    if (x == 3 && y == 4) film->splat(p, 0, vec3(NAN, 0.0f, 0.0f), key);
                }
            }
    for (int s = 0; s < shares; ++s) {
        const std::vector<std::int64_t> a = parts[size_t(s)]->iterationAccumulators();
        if (sum.empty()) sum.assign(a.size(), 0);
        for (size_t i = 0; i < a.size(); ++i)
            sum[i] += a[i];
    }
    parts[0]->setIterationAccumulators(sum);
    parts[0]->endIteration();
    whole.endIteration();
    EXPECT_EQ(parts[0]->image(), whole.image());
    EXPECT_EQ(parts[0]->sampleCounts(), whole.sampleCounts());
    EXPECT_EQ(parts[0]->nonFiniteSamples(), 1u);
}

} // namespace
} // namespace spw
