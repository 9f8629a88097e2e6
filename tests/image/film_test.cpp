// The film's guard: a NaN or Inf sample is counted and dropped, never added, so one bad path
// cannot blacken or whiten a pixel (the CLI reports the count on stderr at the end).
#include "host/image/film.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <random>

namespace spw {
namespace {

TEST(Film, NonFiniteSamplesAreCountedAndDropped) {
    Film film(2, 1, Filter{}, 1.0f);
    const float nan = std::numeric_limits<float>::quiet_NaN(),
                inf = std::numeric_limits<float>::infinity();
    film.addSample(0, vec2(0.5f, 0.5f), 0);
    film.addSample(1, vec2(1.5f, 0.5f), 0);
    film.splat(0, vec2(0.5f, 0.5f), 0, vec3(0.25f, 0.5f, 1.0f), 1u);
    film.splat(0, vec2(0.5f, 0.5f), 0, vec3(nan, 0.0f, 0.0f), 2u);
    film.splat(0, vec2(0.5f, 0.5f), 0, vec3(0.0f, inf, 0.0f), 3u);
    film.splat(1, vec2(1.5f, 0.5f), 0, vec3(0.0f, 0.0f, -inf), 4u);
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
        film.addSample(0, vec2(0.5f), uint(it));
        film.splat(0, vec2(0.5f), uint(it), vec3(value), 7u); // same path key every iteration
        film.endIteration();
    }
    const double mean = film.image()[0];
    // Binomial: 0.3 steps on average, standard error step * sqrt(0.21 / n).
    EXPECT_NEAR(mean, value, 4.0 * step * std::sqrt(0.21 / iterations)) << "step " << step;
}

// No accumulator wraps, whatever the samples per iteration and the filter's reach: the film
// clamps each add at 2^62 / N (N = samples per iteration x pixels a sample reaches) and scales
// so that samples up to 2^16 times the brightest emitter stay below the clamp. Through a
// Gaussian of radius 16 with 4096 samples per iteration, 2^22 contributions 8x the brightest
// emitter, 1024 into each of the 4096 samples, sum 2^63.4 in each half buffer at a fixed scale
// of 2^40 (a wrap to garbage, as it was); here each sample sums exactly 8192, and so does the
// image.
TEST(Film, NoAccumulatorWrapsAtTheMostSamplesAFilterGathers) {
    const uint samples = 4096;
    Film film(1, 1, Filter{FilterType::Gaussian, 16.0f}, 1.0f, int(samples));
    ASSERT_TRUE(film.sumsSamples());
    for (uint i = 0; i < samples; ++i)
        film.addSample(i, vec2(0.5f), i);
    for (int k = 0; k < 1024; ++k)
        for (uint i = 0; i < samples; ++i)
            film.splat(i, vec2(0.5f), i, vec3(8.0f), uint(k) * samples + i);
    film.endIteration();
    EXPECT_EQ(film.saturatedSamples(), 0u);
    for (float v : film.image())
        EXPECT_NEAR(v, 8192.0f, 8192.0f * 1e-6f);
}

// A wide filter sums each sample's contributions and filters the sum once: every pixel's
// value is the closed form sum_k w_k S_k / sum_k w_k over the samples k that reach it, with
// S_k the sum of sample k's contributions and w_k the Gaussian at the pixel's centre, whatever
// the order in which the samples' contributions arrive.
TEST(Film, WideFiltersFilterEachSampleSumOnce) {
    const int width = 6, height = 5;
    const Filter gaussian{FilterType::Gaussian, 1.5f};
    struct Sample {
        vec2 pos;
        vec3 parts[3]; // its contributions, in path order
    };
    std::vector<Sample> samples;
    for (int i = 0; i < width * height; ++i) {
        const float x = float(i % width), y = float(i / width);
        samples.push_back({vec2(x + 0.1f + 0.03f * float(i % 7), y + 0.9f - 0.05f * float(i % 5)),
                           {vec3(0.1f * float(i % 3), 0.5f, 0.25f), vec3(0.0f),
                            vec3(2.0f, 0.125f * float(i % 4), 1.0f)}});
    }
    auto render = [&](bool interleaved) {
        Film film(width, height, gaussian, 4.0f);
        EXPECT_TRUE(film.sumsSamples());
        for (uint i = 0; i < samples.size(); ++i)
            film.addSample(i, samples[i].pos, 0);
        // The paths one after another, or bounce by bounce across the paths, the last first.
        const uint n = uint(samples.size());
        for (uint k = 0; k < 3 * n; ++k) {
            const uint i = interleaved ? n - 1 - k % n : k / 3, c = interleaved ? k / n : k % 3;
            film.splat(i, vec2(-1.0f), 0, samples[i].parts[c], filmKey(i, c, false));
        }
        film.endIteration();
        return film.state();
    };
    const Film::State a = render(false), b = render(true);
    EXPECT_EQ(a.sums, b.sums) << "sample sums are exact: no order shows";
    const std::vector<float> img = Film::imageOf(a);
    auto weight = [](double d) {
        const double sigma = 0.75, k = -0.5 / (sigma * sigma);
        return std::fabs(d) >= 1.5 ? 0.0 : std::exp(k * d * d) - std::exp(k * 1.5 * 1.5);
    };
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            double num[3] = {0, 0, 0}, den = 0;
            for (const Sample& s : samples) {
                const double w = weight(x + 0.5 - s.pos.x) * weight(y + 0.5 - s.pos.y);
                const vec3 sum = s.parts[0] + s.parts[1] + s.parts[2];
                den += w;
                num[0] += w * sum.x;
                num[1] += w * sum.y;
                num[2] += w * sum.z;
            }
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(img[size_t(y * width + x) * 3 + size_t(c)], num[c] / den,
                            1e-6 * (num[c] / den) + 1e-9)
                    << x << ", " << y << " channel " << c;
        }
}

// A sample's own sum cannot wrap (it is a double), and its add to a pixel saturates at the clamp
// of one film add, is counted, and gives the same film whatever the other paths do meanwhile.
// 1000 contributions at 2^60 times the brightest emitter fill one sample's sum; each of its
// three channels is clamped; its neighbour's ordinary contribution is untouched.
TEST(Film, ASampleSumSaturatesAtTheClampAndIsCounted) {
    auto render = [](bool neighbourFirst) {
        Film film(2, 1, Filter{FilterType::Tent, 1.0f}, 1.0f);
        film.addSample(0, vec2(0.5f), 0);
        film.addSample(1, vec2(1.5f, 0.5f), 0);
        if (neighbourFirst) film.splat(1, vec2(-1.0f), 0, vec3(0.5f), 1u);
        for (uint k = 0; k < 1000; ++k)
            film.splat(0, vec2(-1.0f), 0, vec3(std::ldexp(1.0f, 60)), 64u * k);
        if (!neighbourFirst) film.splat(1, vec2(-1.0f), 0, vec3(0.5f), 1u);
        film.endIteration();
        return std::make_pair(film.image(), film.saturatedSamples());
    };
    const auto [img, saturated] = render(false);
    EXPECT_EQ(render(true).first, img);
    EXPECT_EQ(saturated, 3u) << "every clamped add is counted";
    // The clamp: 2^62 over 9 adds (a Tent of radius 1 reaches 3 x 3 pixels), rounded down to a
    // power of 2, at the scale 2^40: 2^18 in radiance.
    for (int c = 0; c < 3; ++c)
        EXPECT_EQ(img[size_t(c)], std::ldexp(1.0f, 18)) << c;
    EXPECT_FLOAT_EQ(img[3], 0.5f) << "the Tent of radius 1 keeps the samples apart";
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
        film.addSample(0, vec2(0.5f), uint(it));
        film.addSample(1, vec2(1.5f), uint(it));
        film.splat(0, vec2(0.5f), uint(it), vec3(big, 1.0f, 0.5f), 1u);
        film.splat(1, vec2(1.5f), uint(it), vec3(0.25f), 2u);
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
    resumed.addSample(0, vec2(0.5f), 24u);
    resumed.splat(0, vec2(0.5f), 24u, vec3(big), 1u);
    resumed.endIteration();
    EXPECT_EQ(resumed.image()[0], big);
    EXPECT_EQ(resumed.state().sums[0], Film::Fixed(13) << 61);

    Film negative(1, 1, Filter{}, 1.0f);
    for (int it = 0; it < 8; ++it) {
        if (it > 0) negative.beginIteration();
        negative.addSample(0, vec2(0.5f), 0u);
        negative.splat(0, vec2(0.5f), 0u, vec3(-big, big, 1.0f), 1u);
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
                // Blue far below the home grid's precision: the fine levels are added too.
                const vec3 v(float(x % 7) * 0.1f, float(y % 5) * 0.2f, 1e-30f);
                const uint key = uint(y * width + x);
                for (Film* film : {&f, &whole}) {
                    film->addSample(key, p, 0);
                    film->splat(key, p, 0, v, key);
                    if (x == 3 && y == 4) film->splat(key, p, 0, vec3(NAN, 0.0f, 0.0f), key);
                }
            }
    // As RankSync::reduce adds them: the level tiles any share reached, then every sum.
    std::vector<std::int64_t> reached;
    for (int s = 0; s < shares; ++s) {
        const std::vector<std::int64_t> r = parts[size_t(s)]->levelTilesReached();
        if (reached.empty()) reached.assign(r.size(), 0);
        for (size_t i = 0; i < r.size(); ++i)
            reached[i] += r[i];
    }
    for (int s = 0; s < shares; ++s) {
        const std::vector<std::int64_t> a = parts[size_t(s)]->iterationAccumulators(reached);
        if (sum.empty()) sum.assign(a.size(), 0);
        ASSERT_EQ(a.size(), sum.size());
        for (size_t i = 0; i < a.size(); ++i)
            sum[i] += a[i];
    }
    parts[0]->setIterationAccumulators(sum, reached);
    parts[0]->endIteration();
    whole.endIteration();
    EXPECT_EQ(parts[0]->image(), whole.image());
    const std::vector<float> img = whole.image();
    for (size_t i = 2; i < img.size(); i += 3)
        ASSERT_NEAR(img[i], 1e-30f, 1e-36f)
            << "blue, all of it in the fine levels, pixel " << i / 3;
    EXPECT_EQ(parts[0]->sampleCounts(), whole.sampleCounts());
    EXPECT_EQ(parts[0]->nonFiniteSamples(), 1u);
}

// Adaptive sampling toward a target computes the error estimate in the pass its decision makes
// over the terms, and the stop reads that: after every iteration it is what the film's state
// gives computed afresh, bit for bit (a film without adaptive sampling, restored to the state).
TEST(Film, TheAdaptiveDecisionsEstimateIsTheEstimateAfresh) {
    const int w = 24, h = 20; // 3 x 3 tiles, the last row and column partial
    Film film(w, h, Filter{}, 1e3f, 4);
    film.setAdaptiveTarget(1e-3);
    std::mt19937 rng(5);
    std::exponential_distribution<float> radiance(2.0f);
    uint key = 1;
    for (int it = 0; it < 6; ++it) {
        if (it > 0) film.beginIteration();
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                for (uint s = 0; s < 4; ++s) {
                    const uint path = uint(y * w + x) * 4 + s, index = uint(it) * 4 + s;
                    const vec2 at(float(x) + 0.5f, float(y) + 0.5f);
                    film.addSample(path, at, index);
                    // Brighter and noisier to the right: tiles that rest and tiles that sample.
                    film.splat(path, at, index, vec3(radiance(rng) * float(1 + x)), key++);
                }
        film.endIteration();
        Film fresh(w, h, Filter{}, 1e3f, 4);
        fresh.restore(film.state());
        const Film::ErrorEstimate a = film.halfBufferError(), b = fresh.halfBufferError();
        SCOPED_TRACE(it);
        ASSERT_TRUE(a.relMse.has_value());
        EXPECT_EQ(a.relMse, b.relMse);
        EXPECT_EQ(a.standardError, b.standardError);
    }
}

// The stop judges the subject: pixels whose halves agree to float precision (a flat background,
// black or a constant environment) are left out of the subject's estimate. A 32 x 32 film whose
// centre 8 x 8 is noisy and whose rest reads a constant (and, in a second film, black): the
// subject's estimate is the mean of the centre's terms alone, the whole image's the same terms
// over every pixel, so the one is the other over the subject's share of the frame (1/16); and
// toward a target, the flat tiles rest while the subject's samples on.
TEST(Film, TheSubjectIsThePixelsThatHoldNoise) {
    const int w = 32, h = 32;
    for (float background : {0.5f, 0.0f}) {
        SCOPED_TRACE(background);
        Film film(w, h, Filter{}, 8.0f, 4);
        film.setAdaptiveTarget(1e-6);
        std::mt19937 rng(11);
        std::exponential_distribution<float> radiance(1.0f);
        uint key = 1;
        auto subject = [](int x, int y) { return x >= 12 && x < 20 && y >= 12 && y < 20; };
        for (int it = 0; it < 4; ++it) {
            if (it > 0) film.beginIteration();
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    if (!film.sampling(x, y)) continue;
                    for (uint s = 0; s < 4; ++s) {
                        const uint path = uint(y * w + x) * 4 + s, index = uint(it) * 4 + s;
                        const vec2 at(float(x) + 0.5f, float(y) + 0.5f);
                        film.addSample(path, at, index);
                        const float v = subject(x, y) ? radiance(rng) : background;
                        film.splat(path, at, index, vec3(v), key++);
                    }
                }
            film.endIteration();
        }
        const Film::ErrorEstimate e = film.halfBufferError();
        ASSERT_TRUE(e.relMse && e.subjectRelMse);
        EXPECT_DOUBLE_EQ(e.subjectFraction, 64.0 / 1024.0);
        EXPECT_NEAR(*e.relMse, *e.subjectRelMse * e.subjectFraction, *e.relMse * 1e-9);
        EXPECT_GT(*e.subjectRelMse, 1e-3); // 16 exponential samples: far from converged
        EXPECT_EQ(film.subjectRelMseEstimate(), e.subjectRelMse);
        std::vector<float> terms(size_t(w) * h * 3);
        film.errorRows(0, h, terms.data());
        double sum = 0.0;
        for (int y = 12; y < 20; ++y)
            for (int x = 12; x < 20; ++x)
                for (int c = 0; c < 3; ++c)
                    sum += terms[(size_t(y) * w + x) * 3 + c];
        EXPECT_NEAR(*e.subjectRelMse, sum / (64.0 * 3.0), *e.subjectRelMse * 1e-6);
        for (int ty = 0; ty < h / Film::kAdaptiveTile; ++ty)
            for (int tx = 0; tx < w / Film::kAdaptiveTile; ++tx) {
                const int x = tx * Film::kAdaptiveTile, y = ty * Film::kAdaptiveTile;
                // The centre's 8 x 8 falls on the four middle tiles.
                const bool noisy = tx >= 1 && tx <= 2 && ty >= 1 && ty <= 2;
                EXPECT_EQ(film.sampling(x, y), noisy) << tx << ", " << ty;
            }
    }
    // An image that is all flat has no subject: the stop reads the whole image's estimate.
    Film flat(16, 16, Filter{}, 1.0f, 4);
    uint key = 1;
    for (int it = 0; it < 2; ++it) {
        if (it > 0) flat.beginIteration();
        for (uint p = 0; p < 16 * 16; ++p)
            for (uint s = 0; s < 4; ++s) {
                const vec2 at(float(p % 16) + 0.5f, float(p / 16) + 0.5f);
                flat.addSample(p * 4 + s, at, uint(it) * 4 + s);
                flat.splat(p * 4 + s, at, uint(it) * 4 + s, vec3(0.25f), key++);
            }
        flat.endIteration();
    }
    const Film::ErrorEstimate f = flat.halfBufferError();
    EXPECT_FALSE(f.subjectRelMse.has_value());
    ASSERT_TRUE(f.relMse.has_value());
    EXPECT_EQ(flat.subjectRelMseEstimate(), f.relMse);
    EXPECT_LT(*f.relMse, Film::kFlatTerm);
}

} // namespace
} // namespace spw
