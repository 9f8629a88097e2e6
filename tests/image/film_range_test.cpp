// The film's dynamic range (host/image/film_levels.h): every contribution keeps float precision
// relative to its pixel whatever the brightest emitter is, across the whole range of radiance the
// loader accepts, deterministically; and the scenes where one very bright light used to zero
// the rest of the image render their closed forms on every backend.
#include "host/image/film.h"
#include "host/loaders/scene_loader.h"
#include "host/render/render.h"
#include "host/scene/scene.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace spw::test {
namespace {

// Pixel i's contributions span the loader's range below the brightest emitter: from the
// smallest normal float (2^-126) up to 2^8 times the brightest emitter (a path's throughput can
// pass 1; far beyond it the film clamps, and counts, as it always did), a value 2^e with a
// random mantissa for each pixel's e, and two more 2^-60 and 2^-100 of it. For every brightest
// emitter from the smallest to the largest the loader allows (kMaxRadiance), each filter kind
// and a few samples per iteration: each pixel reads its exact mean to within 2^-23, float
// precision of the pixel's own value (the film's 2^-24 and the image's float rounding); and
// the sums are the same bit for bit when the contributions arrive in another order.
TEST(FilmRange, EveryContributionKeepsFloatPrecisionRelativeToItsPixel) {
    const int width = 40, height = 9;
    struct Contribution {
        int pixel;
        vec3 value;
    };
    for (float brightest : {1e-30f, 1.0f, 17.0f, float(kMaxRadiance)})
        for (const Filter& filter : {Filter{}, Filter{FilterType::Gaussian, 1.5f}})
            for (int spi : {1, 16}) {
                std::mt19937 rng(11);
                std::uniform_real_distribution<float> mantissa(1.0f, 2.0f);
                const int top = int(std::ceil(std::log2(double(brightest)))) + 7;
                std::vector<Contribution> parts;
                for (int i = 0; i < width * height; ++i) {
                    const int e = -126 + i * (top + 126) / (width * height);
                    for (int spread : {0, -60, -100}) {
                        const int f = std::max(-126, e + spread);
                        parts.push_back(
                            {i, vec3(std::ldexp(mantissa(rng), f), std::ldexp(mantissa(rng), e),
                                     std::ldexp(mantissa(rng), (f + e) / 2))});
                    }
                }
                auto run = [&](bool reversed) {
                    Film film(width, height, filter, brightest, spi);
                    for (int i = 0; i < width * height; ++i)
                        film.addSample(uint(i * spi),
                                       vec2(float(i % width) + 0.5f, float(i / width) + 0.5f), 0);
                    // The pixels last first; a path's own contributions in its order (the
                    // bounce order every backend keeps).
                    for (size_t n = 0; n < parts.size(); ++n) {
                        const size_t k = reversed ? (parts.size() / 3 - 1 - n / 3) * 3 + n % 3 : n;
                        const Contribution& c = parts[k];
                        const vec2 at(float(c.pixel % width) + 0.5f, float(c.pixel / width) + 0.5f);
                        const uint path = uint(c.pixel * spi);
                        film.splat(path, at, 0, c.value, filmKey(path, uint(k % 3), false));
                    }
                    film.endIteration();
                    EXPECT_EQ(film.saturatedSamples(), 0u);
                    return film.state();
                };
                const Film::State state = run(false);
                const std::vector<float> img = Film::imageOf(state);
                std::vector<double> exact(size_t(width * height) * 3, 0.0);
                if (filter.type == FilterType::Box)
                    for (const Contribution& c : parts)
                        for (int ch = 0; ch < 3; ++ch)
                            exact[size_t(c.pixel) * 3 + size_t(ch)] += double(c.value[ch]);
                double worst = 0;
                for (size_t i = 0; i < exact.size(); ++i) {
                    if (filter.type != FilterType::Box) continue; // closed form below
                    worst = std::max(worst, std::fabs(img[i] - exact[i]) / exact[i]);
                }
                EXPECT_LE(worst, 0x1p-23) << brightest << " spi " << spi;
                if (filter.type != FilterType::Box) {
                    // Each pixel's value is a weighted mean of its neighbours' sums: never below
                    // the smallest, never above the largest of them, and never 0.
                    for (size_t i = 0; i < img.size(); ++i)
                        EXPECT_GT(img[i], 0.0f) << brightest << " pixel " << i / 3;
                }
                const Film::State reversed = run(true);
                EXPECT_EQ(reversed.sums, state.sums) << brightest;
                ASSERT_EQ(reversed.levels.size(), state.levels.size()) << brightest;
                for (size_t l = 0; l < state.levels.size(); ++l)
                    EXPECT_EQ(reversed.levels[l].sums, state.levels[l].sums) << brightest;
            }
}

// A checkpoint's state keeps the fine levels: a film restored from it reads the same image bit
// for bit and goes on summing, and two halves of a render added (a merge) are the whole.
TEST(FilmRange, TheFineLevelsSurviveAStateAndItsSum) {
    auto film = [] { return std::make_unique<Film>(9, 9, Filter{}, 1e20f); };
    auto iteration = [](Film& f, uint index, bool begin) {
        if (begin) f.beginIteration();
        for (uint i = 0; i < 81; ++i) {
            const vec2 at(float(i % 9) + 0.5f, float(i / 9) + 0.5f);
            f.addSample(i, at, index);
            f.splat(i, at, index, vec3(1e20f * float(i == 40), 0.07f, 1e-30f), 3u);
        }
        f.endIteration();
    };
    const auto whole = film();
    for (uint it = 0; it < 4; ++it)
        iteration(*whole, it, it > 0);
    const std::vector<float> img = whole->image();
    EXPECT_FLOAT_EQ(img[40 * 3], 1e20f);
    for (size_t i = 0; i < 81; ++i) {
        EXPECT_FLOAT_EQ(img[i * 3 + 1], 0.07f) << "green beside a 1e20 pixel, pixel " << i;
        EXPECT_FLOAT_EQ(img[i * 3 + 2], 1e-30f) << i;
    }
    const Film::State state = whole->state();
    ASSERT_FALSE(state.levels.empty());
    EXPECT_EQ(Film::imageOf(state), img);

    const auto first = film(), resumed = film();
    for (uint it = 0; it < 2; ++it)
        iteration(*first, it, it > 0);
    resumed->restore(first->state());
    for (uint it = 2; it < 4; ++it)
        iteration(*resumed, it, true);
    EXPECT_EQ(resumed->image(), img);
}

// The scenes: a Lambert floor under a light that is bright beyond every other radiance
// in the scene, where the film's home grid (set from the brightest emitter) once rounded the
// whole image to 0 and a few spikes. Each pixel is its closed form, 0.5 / pi times the
// irradiance, on every backend.
void expectFloorWithin(const Scene& scene, const std::function<double(vec3)>& expected,
                       double tolerance) {
    for (const std::string& backend : backendsUnderTest()) {
        RenderConfig cfg;
        cfg.backend = parseBackend(backend);
        const std::vector<float> img = render(scene, cfg)->film->image();
        double worst = 0;
        for (int y = 0; y < 16; ++y)
            for (int x = 0; x < 16; ++x) {
                const double want = expected(floorPointAtPixelCentre(scene, x, y));
                const double got = img[size_t(y * 16 + x) * 3];
                worst = std::max(worst, std::fabs(got - want) / want);
            }
        std::printf("  %s: worst relative difference %.2e\n", backend.c_str(), worst);
        EXPECT_LT(worst, tolerance) << backend;
    }
}

double pointLight(vec3 p, vec3 light, double intensity) {
    const glm::dvec3 d = glm::dvec3(light) - glm::dvec3(p);
    const double r2 = glm::dot(d, d);
    return 0.5 / kPi * intensity * d.y / std::sqrt(r2) / r2;
}

TEST(FilmRange, APointLightOfTheBrightestRadianceFarAwayLightsAsANearOne) {
    TempDir dir;
    // 1e20 W/sr 1e9 above: the floor's irradiance is about 100, as under a light of 100 W/sr
    // one unit above.
    const Scene scene = floorUnderLight(
        dir, 2, "max depth: 1", "{type: Point, position: [0.2, 1e9, 0.1], intensity: 1e20}");
    expectFloorWithin(
        scene, [](vec3 p) { return pointLight(p, vec3(0.2f, 1e9f, 0.1f), 1e20); }, 1e-5);
}

TEST(FilmRange, ATinyQuadLightOfTheBrightestRadianceLightsTheFloor) {
    TempDir dir;
    // 1e-9 wide, radiance 1e20, one unit above: power 1e20 x 1e-18 x pi, the floor's radiance
    // about 15.9 under it. At that size the quad is a point of intensity L x area x cos (its
    // corners are within 1e-9 of its centre: a relative 1e-18 in the irradiance).
    const Scene scene = floorUnderLight(dir, 2, "max depth: 1",
                                        "{type: Quad, translation: [0.2, 1, 0.1], rotation: [90, "
                                        "0, 0], scale: [1e-9, 1e-9], intensity: 1e20}");
    expectFloorWithin(
        scene,
        [](vec3 p) {
            const glm::dvec3 d = glm::dvec3(0.2, 1.0, 0.1) - glm::dvec3(p);
            return pointLight(p, vec3(0.2f, 1.0f, 0.1f), 1e20 * 1e-18) * d.y / glm::length(d);
        },
        1e-4);
}

// A lamp over the floor, and 1e20 W/sr a billion units below it, which no floor point sees (the
// floor faces up). The light tree picks lights by the shading point alone, not its normal, so
// the far light takes most of the shadow rays, and the lamp's few carry its light divided by its
// small pick probability: the image is noisy, but its mean is the lamp's closed form within its
// standard error (it read 0, but for one pixel in a thousand, when the film's grid was the far
// light's).
TEST(FilmRange, ABrightLightThatCannotReachTheFloorLeavesTheRestOfTheImage) {
    TempDir dir;
    dir.write("floor.obj", floorObj(4.0f));
    const Scene scene = loadScene(
        dir.write("two.yaml", "image: {width: 16, height: 16, sample base: 1, iterations: 256}\n"
                              "settings: {max depth: 1}\n"
                              "camera: {look at: {eye: [0.2, 0.6, 0.1], target: [0.2, 0, 0.1], "
                              "up: [0, 0, -1]}, fov: 90}\n"
                              "sampler: {type: Grid}\n"
                              "object: {filename: floor.obj, shader: 0}\n"
                              "shader: {type: Lambert, reflectance: 0.5}\n"
                              "lights:\n"
                              "  - {type: Point, position: [0.5, 0.7, -0.2], intensity: 0.3}\n"
                              "  - {type: Point, position: [0.2, -1e9, 0.1], intensity: 1e20}\n"));
    double expected = 0;
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x)
            expected +=
                pointLight(floorPointAtPixelCentre(scene, x, y), vec3(0.5f, 0.7f, -0.2f), 0.3) /
                256.0;
    for (const std::string& backend : backendsUnderTest()) {
        RenderConfig cfg;
        cfg.backend = parseBackend(backend);
        PixelStats stats;
        render(scene, cfg,
               [&](int, int, const Film& film) { stats.add(film.lastIterationImage()); });
        const MeanError m = stats.imageMean();
        std::printf("  %s: image mean %.5f +- %.5f, closed form %.5f\n", backend.c_str(), m.mean,
                    m.stderror, expected);
        EXPECT_LT(std::fabs(m.mean - expected), 4.0 * m.stderror) << backend;
        EXPECT_LT(m.stderror, 0.1 * expected) << backend;
    }
}

} // namespace
} // namespace spw::test
