// The path tracer's stated rules, on every backend, from ray counts with closed forms: Russian
// roulette from bounce `min depth` on, no shadow rays in a scene without emitters, and the
// Dielectric's ior range (both ends render finite and passive).
#include "host/loaders/scene_loader.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdarg>

namespace spw::test {
namespace {

struct Counts {
    double camera, bounce, shadow;
    std::vector<float> image;
};

Counts countRays(const Scene& scene, const std::string& backend) {
    RenderConfig cfg;
    cfg.backend = parseBackend(backend);
    auto r = render(scene, cfg);
    return {double(r->stats.cameraRays.load()), double(r->stats.bounceRays.load()),
            double(r->stats.shadowRays.load()), r->film->image()};
}

std::string enclosureYaml(double albedo, int minDepth, double threshold,
                          const std::string& extra = "") {
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  "image: {width: 32, height: 32, sample base: 2, iterations: 4}\n"
                  "settings: {min depth: %d, max depth: 1000, threshold: %.17g}\n"
                  "camera: {look at: {eye: [0, 0, 0], target: [0.3, 0.2, -1]}, fov: 100}\n"
                  "object: {filename: cube.obj, shader: 0}\n"
                  "shader: {type: Lambert, reflectance: %.17g}\n",
                  minDepth, threshold, albedo);
    return buf + extra;
}

// Inside a closed Lambert enclosure of albedo a every path continues until Russian roulette
// ends it. With threshold 1, the first bounce at or past min depth m survives with probability
// a^(m+1) (its throughput) and each later one with probability a, so a path traces
// N = m + X bounce rays, X = 0 with probability 1 - p, else 1 + Geometric(a), p = a^(m+1):
// E[N] = m + p / (1 - a), Var[N] = p (1 + a) / (1 - a)^2 - (p / (1 - a))^2. Asserted within 4
// standard errors for m = 0, 3 and 7 (a roulette starting one bounce early or late is off by
// about 10 to 40 of them).
TEST(PathRules, RussianRouletteStartsAtMinDepth) {
    TempDir dir;
    dir.write("cube.obj", insideCubeObj());
    const double a = 0.6;
    for (int m : {0, 3, 7}) {
        const Scene scene = loadScene(dir.write("e.yaml", enclosureYaml(a, m, 1.0)));
        const double p = std::pow(a, m + 1), mean = m + p / (1 - a);
        const double var = p * (1 + a) / ((1 - a) * (1 - a)) - (p / (1 - a)) * (p / (1 - a));
        for (const std::string& backend : backendsUnderTest()) {
            const Counts c = countRays(scene, backend);
            const double n = c.bounce / c.camera, se = std::sqrt(var / c.camera);
            std::printf(
                "%s, min depth %d: %.4f bounce rays a path, expected %.4f +- %.4f (z %+.2f)\n",
                backend.c_str(), m, n, mean, se, (n - mean) / se);
            EXPECT_NEAR(n, mean, 4 * se) << backend << ", min depth " << m;
        }
    }
}

// No emitter, no shadow ray (and a black image); one light, and every surface hit casts one.
TEST(PathRules, NoShadowRaysWithoutEmitters) {
    TempDir dir;
    dir.write("cube.obj", insideCubeObj());
    const Scene dark = loadScene(dir.write("d.yaml", enclosureYaml(0.5, 3, 0.1)));
    const Scene lit =
        loadScene(dir.write("l.yaml", enclosureYaml(0.5, 3, 0.1,
                                                    "light: {type: Quad, translation: [0, 0.9, 0], "
                                                    "rotation: [90, 0, 0], scale: [0.5, 0.5]}\n")));
    for (const std::string& backend : backendsUnderTest()) {
        const Counts d = countRays(dark, backend);
        EXPECT_EQ(d.shadow, 0.0) << backend;
        EXPECT_GT(d.bounce, 0.0) << backend;
        EXPECT_EQ(mean(d.image), 0.0) << backend;
        const Counts l = countRays(lit, backend);
        EXPECT_GT(l.shadow, 0.5 * (l.camera + l.bounce)) << backend;
    }
}

// The Dielectric's ior lies in [1.01, 10] (the loader rejects the rest: the LoaderError cases
// IorBelowRange and IorAboveRange): a smooth and a rough glass plane at both ends, in the white
// furnace, render finite, non-negative and passive (mean <= 1 within 4 standard errors).
TEST(PathRules, DielectricAtBothEndsOfItsIorRange) {
    TempDir dir;
    dir.write("enclosure.obj", insideCubeObj());
    dir.write("plane.obj", floorObj(0.5f));
    for (double ior : {1.01, 10.0})
        for (double alpha : {0.0, 0.3}) {
            char shader[128];
            std::snprintf(shader, sizeof shader, "{type: Dielectric, ior: %g, alpha: %g}", ior,
                          alpha);
            const Scene scene = loadScene(dir.write(
                "g.yaml",
                std::string(
                    "image: {width: 16, height: 16, sample base: 2, iterations: 16}\n"
                    "settings: {max depth: 64, min depth: 3, threshold: 0.1}\n"
                    "camera: {look at: {eye: [0.3, 0.7, 0.5], target: [0, 0, 0]}, fov: 50}\n"
                    "shaders:\n  - {type: Emissive, emission: [1, 1, 1]}\n  - ") +
                    shader +
                    "\nobjects:\n  - {filename: enclosure.obj, shader: 0}\n  - {filename: "
                    "plane.obj, shader: 1}\n"));
            for (const std::string& backend : backendsUnderTest()) {
                RenderConfig cfg;
                cfg.backend = parseBackend(backend);
                PixelStats s;
                auto r = render(scene, cfg,
                                [&](int, int, const Film& f) { s.add(f.lastIterationImage()); });
                const MeanError m = s.imageMean();
                std::printf("%s, ior %g, alpha %g: mean %.4f +- %.4f\n", backend.c_str(), ior,
                            alpha, m.mean, m.stderror);
                EXPECT_EQ(r->stats.nonFiniteSamples, 0u) << backend << ", ior " << ior;
                for (float v : r->film->image())
                    ASSERT_TRUE(std::isfinite(v) && v >= 0.0f) << backend << ", ior " << ior;
                EXPECT_LE(m.mean, 1.0 + 4 * m.stderror)
                    << backend << ", ior " << ior << ", alpha " << alpha;
                EXPECT_GT(m.mean, 0.0) << backend;
            }
        }
}

} // namespace
} // namespace spw::test
