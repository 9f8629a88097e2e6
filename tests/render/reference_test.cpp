// The reference backend against closed forms: every assertion compares with an analytic value
// within a standard error computed from the render's own samples. Every render here runs the
// reference backend (the library's RenderConfig defaults to cpu).
#include "host/loaders/scene_loader.h"
#include "host/scene/camera.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

namespace spw::test {
namespace {

RenderConfig referenceConfig() {
    RenderConfig cfg;
    cfg.backend = BackendKind::Reference;
    return cfg;
}

std::unique_ptr<RenderResult> renderWithStats(const Scene& scene, const RenderConfig& cfg,
                                              PixelStats* stats) {
    return render(scene, cfg, [&](int, int, const Film& film) {
        if (stats) stats->add(film.lastIterationImage());
    });
}

std::string enclosureScene(TempDir& dir, double albedo, int maxDepth) {
    dir.write("cube.obj", insideCubeObj());
    char buf[1024];
    std::snprintf(buf, sizeof buf,
                  "image: {width: 24, height: 24, sample base: 2, iterations: 8}\n"
                  "settings: {max depth: %d, min depth: 3, threshold: 0.1}\n"
                  "camera: {look at: {eye: [0, 0, 0], target: [0.3, 0.2, -1]}, fov: 100}\n"
                  "object: {type: Polygon, filename: cube.obj, shader: 0}\n"
                  "shader: {type: Lambert, reflectance: %.17g, emission: [1, 1, 1]}\n",
                  maxDepth, albedo);
    return dir.write("enclosure.yaml", buf);
}

class ClosedEnclosure : public ::testing::TestWithParam<double> {};

// Inside a closed cube whose every face is Lambert with albedo a and emission Le, the radiance
// everywhere is Le / (1 - a) (a geometric series over bounces).
TEST_P(ClosedEnclosure, MeanMatchesLeOverOneMinusAlbedo) {
    const double a = GetParam();
    TempDir dir;
    Scene scene = loadScene(enclosureScene(dir, a, 400));
    auto result = render(scene, referenceConfig());
    MeanError m = meanAndError(result->film->image());
    const double expected = 1.0 / (1.0 - a);
    std::printf("albedo %.3f: mean %.5f, expected %.5f, standard error %.5f\n", a, m.mean, expected,
                m.stderror);
    EXPECT_GT(m.stderror, 0.0);
    EXPECT_NEAR(m.mean, expected, 4.0 * m.stderror) << "standard error " << m.stderror;
    EXPECT_EQ(result->stats.nonFiniteSamples, 0u);
}

INSTANTIATE_TEST_SUITE_P(Albedo, ClosedEnclosure, ::testing::Values(0.5, 0.9));

// Irradiance at x from a uniformly emitting polygon (Lambert's formula): E = L/2 sum_i theta_i
// (n . unit(v_i x v_{i+1})), v_i the corners relative to x.
double polygonIrradiance(vec3 x, vec3 n, const std::vector<vec3>& corners, double L) {
    double sum = 0;
    for (size_t i = 0; i < corners.size(); ++i) {
        glm::dvec3 a = glm::normalize(glm::dvec3(corners[i] - x));
        glm::dvec3 b = glm::normalize(glm::dvec3(corners[(i + 1) % corners.size()] - x));
        double theta = std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0));
        glm::dvec3 g = glm::normalize(glm::cross(a, b));
        sum += theta * glm::dot(glm::dvec3(n), g);
    }
    return 0.5 * L * std::fabs(sum);
}

// A Lambert floor under one quad light, direct light only: every pixel is albedo/pi * E(x).
TEST(QuadLight, PixelsMatchPolygonIrradiance) {
    TempDir dir;
    const Scene scene = floorUnderLight(dir, 256, "max depth: 1", kQuadOverFloor);
    PixelStats ps;
    auto result = renderWithStats(scene, referenceConfig(), &ps);
    const std::vector<vec3> corners = {
        {-0.5f, 1, -0.25f}, {0.5f, 1, -0.25f}, {0.5f, 1, 0.25f}, {-0.5f, 1, 0.25f}};
    double worstZ = 0, sumZ = 0;
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) {
            const vec3 p = floorPointAtPixelCentre(scene, x, y);
            double expected = 0.5 / kPi * polygonIrradiance(p, vec3(0, 1, 0), corners, 3.0);
            size_t i = size_t(y * 16 + x);
            double z = (ps.mean(i) - expected) / std::max(ps.stderror(i), 1e-12);
            worstZ = std::max(worstZ, std::fabs(z));
            sumZ += z;
        }
    std::printf("worst |z| %.2f, mean z %.3f\n", worstZ, sumZ / 256.0);
    // 256 pixels: |z| < 5 for each, and their mean z within 4 / sqrt(256) of 0.
    EXPECT_LT(worstZ, 5.0);
    EXPECT_LT(std::fabs(sumZ / 256.0), 4.0 / 16.0);
}

// Direct light on a floor from a tiny bright light and a large dim wall emitter standing on it:
// light sampling is best for the former, BSDF sampling for the parts of the floor next to the
// wall. Every strategy against the closed form (each light's polygon irradiance at each pixel
// centre, or the wall's radiance where the camera sees it) over the image, within 4 of its own
// standard errors, which must be below 5 % of the mean (BSDF sampling, which finds the tiny
// light by chance, renders 20x the samples for that); MIS also per floor pixel (|z| < 5, mean z
// within 4 / sqrt(pixels)): the other two are heavy-tailed there (light sampling at the wall's
// foot, BSDF sampling under the tiny light), so their per-pixel errors are not to be trusted.
// And MIS has the lowest variance of the three.
TEST(Mis, StrategiesAgreeWithTheClosedFormAndMisHasLowestVariance) {
    TempDir dir;
    dir.write("floor.obj", floorObj(1.0f));
    const std::string yaml =
        "settings: {max depth: 1}\n"
        "camera: {look at: {eye: [0, 0.8, -0.2], target: [0, 0, -0.2], up: [0, 0, -1]}, fov: 100}\n"
        "sampler: {type: Grid}\n"
        "object: {filename: floor.obj, shader: 0}\n"
        "shader: {type: Lambert, reflectance: 0.8}\n"
        "lights:\n"
        "  - {type: Quad, translation: [0, 1, 0], rotation: [90, 0, 0], scale: [0.04, 0.04], "
        "intensity: 600}\n"
        "  - {type: Quad, translation: [0, 1, -1], scale: [2, 2], intensity: 0.4}\n";
    const Scene scene = loadScene(dir.write(
        "mis.yaml", "image: {width: 16, height: 16, sample base: 1, iterations: 800}\n" + yaml));
    const Scene longer = loadScene(dir.write(
        "bsdf.yaml", "image: {width: 16, height: 16, sample base: 1, iterations: 16000}\n" + yaml));

    // The closed form at each pixel centre (the Grid sampler puts every sample there).
    const std::vector<vec3> tiny = {
        {-0.02f, 1, -0.02f}, {0.02f, 1, -0.02f}, {0.02f, 1, 0.02f}, {-0.02f, 1, 0.02f}};
    const std::vector<vec3> wall = {{-1, 0, -1}, {1, 0, -1}, {1, 2, -1}, {-1, 2, -1}};
    CameraModel cam(scene, 1);
    std::vector<double> expected(256);
    std::vector<bool> seesWall(256, false);
    double expectedMean = 0;
    int wallPixels = 0;
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) {
            const CameraRay r = cam.generate(uint(x), uint(y), 0, 0, 0);
            const vec3 o = vec3(scene.origin) + r.origin; // the world is camera-relative
            const float tWall = (-1.0f - o.z) / r.dir.z, tFloor = -o.y / r.dir.y;
            const vec3 q = o + r.dir * tWall, p = o + r.dir * tFloor;
            double e = 0.0;
            if (tWall > 0 && tWall < tFloor && std::fabs(q.x) <= 1 && q.y >= 0 && q.y <= 2) {
                e = 0.4, ++wallPixels, seesWall[size_t(y * 16 + x)] = true;
            } else if (std::fabs(p.x) <= 1 && std::fabs(p.z) <= 1) {
                e = 0.8 / kPi *
                    (polygonIrradiance(p, vec3(0, 1, 0), tiny, 600.0) +
                     polygonIrradiance(p, vec3(0, 1, 0), wall, 0.4));
            }
            expected[size_t(y * 16 + x)] = e;
            expectedMean += e / 256.0;
        }
    EXPECT_GT(wallPixels, 0);
    EXPECT_LT(wallPixels, 64);

    PixelStats stats[3];
    for (uint s : {kStrategyMis, kStrategyLight, kStrategyBsdf}) {
        RenderConfig cfg = referenceConfig();
        cfg.strategy = s;
        renderWithStats(s == kStrategyBsdf ? longer : scene, cfg, &stats[s]);
        const MeanError m = stats[s].imageMean();
        std::printf("strategy %u: mean %.5f +- %.5f (closed form %.5f, z %+.2f), mean pixel "
                    "variance %.5f\n",
                    s, m.mean, m.stderror, expectedMean, (m.mean - expectedMean) / m.stderror,
                    stats[s].averageVariance());
        EXPECT_NEAR(m.mean, expectedMean, 4.0 * m.stderror) << "strategy " << s;
        EXPECT_LT(m.stderror, 0.05 * expectedMean) << "too few samples to test strategy " << s;
        if (s != kStrategyMis) continue;
        double worstZ = 0, sumZ = 0;
        for (size_t i = 0; i < 256; ++i) {
            if (seesWall[i]) { // emission seen directly: no noise at all
                EXPECT_NEAR(stats[s].mean(i), 0.4, 1e-6) << "strategy " << s << ", pixel " << i;
                continue;
            }
            const double z =
                (stats[s].mean(i) - expected[i]) / std::max(stats[s].stderror(i), 1e-9);
            worstZ = std::max(worstZ, std::fabs(z));
            sumZ += z;
        }
        const double floorPixels = 256.0 - wallPixels, meanZ = sumZ / floorPixels;
        std::printf("  per floor pixel: worst |z| %.2f, mean z %+.3f\n", worstZ, meanZ);
        EXPECT_LT(worstZ, 5.0) << "strategy " << s;
        EXPECT_LT(std::fabs(meanZ), 4.0 / std::sqrt(floorPixels)) << "strategy " << s;
    }
    // Per-iteration variance, the BSDF strategy's from its longer render (the same estimator).
    for (uint s : {kStrategyLight, kStrategyBsdf})
        EXPECT_LT(stats[kStrategyMis].averageVariance(), stats[s].averageVariance())
            << "strategy " << s;
}

std::vector<float> renderCornell(int threads) {
    Scene scene = loadScene(sourceDir() + "/scenes/cornell-box.yaml");
    scene.image.width = scene.image.height = 48;
    RenderConfig cfg = referenceConfig();
    cfg.threads = threads;
    cfg.spp = 8;
    return render(scene, cfg)->film->image();
}

TEST(Determinism, ReferenceImageIsTheSameBitForBitWithOneAndTwoThreads) {
    std::vector<float> one = renderCornell(1), two = renderCornell(2);
    ASSERT_EQ(one.size(), two.size());
    EXPECT_EQ(std::memcmp(one.data(), two.data(), one.size() * sizeof(float)), 0);
    EXPECT_GT(mean(one), 0.01);
}

// max depth 0: only emitters seen directly; the floor under a light stays black.
TEST(MaxDepth, ZeroShowsOnlyEmitters) {
    TempDir dir;
    dir.write("floor.obj", floorObj(4.0f));
    Scene scene = loadScene(dir.write(
        "d0.yaml",
        "image: {width: 8, height: 8}\n"
        "settings: {max depth: 0}\n"
        "camera: {look at: {eye: [0, 2, 0], target: [0, 0, 0], up: [0, 0, -1]}, fov: 60}\n"
        "object: {filename: floor.obj, shader: 0}\n"
        "shader: {type: Lambert}\n"
        "light: {type: Quad, translation: [0, 3, 0], rotation: [90, 0, 0], intensity: 5}\n"));
    EXPECT_EQ(mean(render(scene, referenceConfig())->film->image()), 0.0);
    // The same floor emitting itself is seen at exactly its radiance.
    Scene lit = loadScene(dir.write(
        "d0e.yaml",
        "image: {width: 8, height: 8}\n"
        "settings: {max depth: 0}\n"
        "camera: {look at: {eye: [0, 2, 0], target: [0, 0, 0], up: [0, 0, -1]}, fov: 60}\n"
        "object: {filename: floor.obj, shader: 0}\n"
        "shader: {type: Emissive, emission: [0.25, 0.5, 2]}\n"));
    std::vector<float> img = render(lit, referenceConfig())->film->image();
    for (size_t i = 0; i < img.size(); i += 3) {
        ASSERT_FLOAT_EQ(img[i], 0.25f);
        ASSERT_FLOAT_EQ(img[i + 1], 0.5f);
        ASSERT_FLOAT_EQ(img[i + 2], 2.0f);
    }
}

} // namespace
} // namespace spw::test
