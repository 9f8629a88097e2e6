// Point and directional lights and the environment against closed forms, on the reference and cpu
// backends (the vulkan backend is compared with cpu in tests/vk/vulkan_test.cpp): the white
// furnace, the inverse-square law, the environment map's sampling density, and MIS with an
// environment.
#include "host/image/image_io.h"
#include "host/loaders/scene_loader.h"
#include "host/scene/camera.h"
#include "host/scene_view/lights.h"
#include "shared/path.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>

namespace spw::test {
namespace {

// The box [-1,1]^3 with its faces pointing out: a convex object.
std::string outsideCubeObj() {
    return "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\n"
           "v -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
           "f 4 3 2 1\nf 6 7 8 5\nf 5 8 4 1\nf 3 7 6 2\nf 2 6 5 1\nf 8 7 3 4\n";
}

// How many of pixel (x, y)'s four corners see the cube [-1,1]^3 (the camera at (0, 0, 4) looking
// down -Z, horizontal field of view `fov` degrees, square image of `size` pixels).
int cornersOnCube(int x, int y, int size, double fov) {
    const double t = std::tan(fov * kPi / 360.0);
    int hits = 0;
    for (int c = 0; c < 4; ++c) {
        const double fx = x + (c & 1), fy = y + (c >> 1);
        const glm::dvec3 d((2.0 * fx / size - 1.0) * t, (1.0 - 2.0 * fy / size) * t, -1.0);
        const glm::dvec3 o(0.0, 0.0, 6.0);
        double t0 = 0.0, t1 = 1e30;
        for (int a = 0; a < 3; ++a) {
            const double lo = (-1.0 - o[a]) / d[a], hi = (1.0 - o[a]) / d[a];
            t0 = std::max(t0, std::min(lo, hi));
            t1 = std::min(t1, std::max(lo, hi));
        }
        hits += t0 < t1 ? 1 : 0;
    }
    return hits;
}

// Whether neither pixel (x, y) nor any neighbour has a corner on the cube: the pixel is sky.
bool whollySky(int x, int y, int size, double fov) {
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            const int nx = std::clamp(x + dx, 0, size - 1), ny = std::clamp(y + dy, 0, size - 1);
            if (cornersOnCube(nx, ny, size, fov) > 0) return false;
        }
    return true;
}

std::vector<BackendKind> hostBackends() {
    return {BackendKind::Reference, BackendKind::Cpu};
}

// A convex Lambert object of albedo a under a uniform environment of radiance L reflects a L
// everywhere (every reflected ray escapes), and the background is L. A constant environment
// and a map of one value alike (the map is sampled by its CDFs, the constant uniformly).
TEST(EnvironmentLight, WhiteFurnaceConvexLambertIsAlbedoTimesRadiance) {
    TempDir dir;
    dir.write("cube.obj", outsideCubeObj());
    ImageRGB flat{8, 4, std::vector<float>(8 * 4 * 3, 0.5f)};
    writeImage(dir.path() + "/flat.exr", flat);
    const int size = 24;
    for (const std::string light :
         {"{type: Environment, colour: [2, 2, 2]}", "{type: Environment, string: flat.exr, "
                                                    "intensity: 4}"}) {
        const Scene scene = loadScene(dir.write(
            "furnace.yaml", "image: {width: 24, height: 24, sample base: 1, iterations: 64}\n"
                            "settings: {max depth: 4}\n"
                            "camera: {look at: {eye: [0, 0, 6], target: [0, 0, 0]}, fov: 40}\n"
                            "object: {filename: cube.obj, shader: 0}\n"
                            "shader: {type: Lambert, reflectance: 0.6}\n"
                            "light: " +
                                light + "\n"));
        for (BackendKind b : hostBackends()) {
            RenderConfig cfg;
            cfg.backend = b;
            PixelStats ps;
            auto result = render(
                scene, cfg, [&](int, int, const Film& film) { ps.add(film.lastIterationImage()); });
            const std::vector<float> img = result->film->image();
            int onCube = 0, background = 0;
            double worstZ = 0, sumZ = 0;
            for (int y = 0; y < size; ++y)
                for (int x = 0; x < size; ++x) {
                    const size_t i = size_t(y * size + x);
                    if (cornersOnCube(x, y, size, 40.0) == 4) { // wholly on the cube
                        const double z = (ps.mean(i) - 1.2) / std::max(ps.stderror(i), 1e-9);
                        worstZ = std::max(worstZ, std::fabs(z));
                        sumZ += z;
                        ++onCube;
                    } else if (whollySky(x, y, size, 40.0)) { // camera rays see L, exactly
                        for (int c = 0; c < 3; ++c)
                            EXPECT_NEAR(img[i * 3 + size_t(c)], 2.0, 1e-5)
                                << "pixel " << x << ", " << y;
                        ++background;
                    }
                }
            std::printf("%s, %s: %d cube pixels, worst |z| %.2f, mean z %+.3f; %d background\n",
                        backendName(b), light.c_str(), onCube, worstZ, sumZ / onCube, background);
            ASSERT_GT(onCube, 30);
            EXPECT_GT(background, 100);
            EXPECT_LT(worstZ, 5.0);
            EXPECT_LT(std::fabs(sumZ / onCube), 4.0 / std::sqrt(double(onCube)));
            EXPECT_EQ(result->stats.nonFiniteSamples, 0u);
        }
    }
}

// The floor of floorUnderLight rendered on each host backend against a closed form: the radiance
// `expected(p)` at the floor point each pixel centre sees, times the light's colour [1, 0.5,
// 0.25], within 1e-5 relative in every pixel and channel.
// Relative to each pixel's value, or to 1 % of the brightest where a pixel is darker (a spot's
// falloff to 0, where float rounding of the cosine is a larger share).
void expectFloorRadiance(const Scene& scene, const std::function<double(vec3)>& expected,
                         double tolerance = 1e-5) {
    double peak = 0;
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x)
            peak = std::max(peak, expected(floorPointAtPixelCentre(scene, x, y)));
    for (BackendKind b : hostBackends()) {
        RenderConfig cfg;
        cfg.backend = b;
        const std::vector<float> img = render(scene, cfg)->film->image();
        double worst = 0;
        for (int y = 0; y < 16; ++y)
            for (int x = 0; x < 16; ++x) {
                const double e = expected(floorPointAtPixelCentre(scene, x, y));
                for (int c = 0; c < 3; ++c) {
                    const double scale = c == 0 ? 1.0 : c == 1 ? 0.5 : 0.25;
                    const double want = e * scale;
                    const double got = img[size_t(y * 16 + x) * 3 + size_t(c)];
                    worst = std::max(worst,
                                     std::fabs(got - want) / std::max(want, 1e-2 * peak * scale));
                }
            }
        std::printf("%s: worst relative difference %.2e\n", backendName(b), worst);
        EXPECT_LT(worst, tolerance) << backendName(b);
    }
}

// A Lambert floor of albedo 0.5 under a point light of intensity I: every pixel is
// 0.5 / pi x I cos(theta) / r^2 at its centre (the Grid sampler). No randomness is left (a
// delta light, one bounce): the render equals the closed form up to float rounding.
TEST(PointLight, RadianceIsAlbedoOverPiTimesIntensityCosOverRSquared) {
    TempDir dir;
    const Scene scene = floorUnderLight(
        dir, 4, "max depth: 1",
        "{type: Point, position: [0.5, 0.7, -0.2], intensity: 3, colour: [1, 0.5, 0.25]}");
    const vec3 light(0.5f, 0.7f, -0.2f);
    expectFloorRadiance(scene, [&](vec3 p) {
        const vec3 d = light - p;
        const double r2 = double(glm::dot(d, d));
        return 0.5 / kPi * 3.0 * double(d.y) / std::sqrt(r2) / r2;
    });
}

// A spot light above the floor, tilted, its cone edge crossing the floor: inside the inner cone
// the point light's closed form, between the cones glTF's falloff t^2, outside it black (the
// floor's albedo 0.5; vulkan: tests/vk/vulkan_test.cpp's every-kind scene).
TEST(SpotLight, RadianceIsThePointLightsTimesGltfsConeFalloff) {
    TempDir dir;
    const Scene scene = floorUnderLight(dir, 4, "max depth: 1",
                                        "{type: Spot, position: [0.5, 0.7, -0.2], direction: "
                                        "[0.3, -1, 0.2], intensity: 3, colour: [1, 0.5, 0.25], "
                                        "inner angle: 14, outer angle: 35}");
    const vec3 light(0.5f, 0.7f, -0.2f);
    const glm::dvec3 axis = glm::normalize(glm::dvec3(0.3, -1, 0.2));
    const double cosInner = std::cos(14.0 * M_PI / 180.0), cosOuter = std::cos(35.0 * M_PI / 180.0);
    int dark = 0, falling = 0, full = 0;
    auto closedForm = [&](vec3 p) {
        const vec3 d = light - p;
        const double r2 = double(glm::dot(d, d));
        const double cosAxis = -glm::dot(glm::dvec3(d), axis) / std::sqrt(r2);
        const double t = std::clamp((cosAxis - cosOuter) / (cosInner - cosOuter), 0.0, 1.0);
        return 0.5 / kPi * 3.0 * t * t * double(d.y) / std::sqrt(r2) / r2;
    };
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) {
            const vec3 p = floorPointAtPixelCentre(scene, x, y);
            const vec3 d = light - p;
            const double c = -glm::dot(glm::dvec3(d), axis) / double(glm::length(d));
            (c <= cosOuter ? dark : c >= cosInner ? full : falling) += 1;
        }
    EXPECT_GT(dark, 10); // the test reaches every part of the cone
    EXPECT_GT(falling, 10);
    EXPECT_GT(full, 10);
    // The falloff's slope, 1 / (cos inner - cos outer) = 5.7, amplifies the cosine's float
    // rounding: 2e-5 measured where the point light's form holds to 2e-6.
    expectFloorRadiance(scene, closedForm, 1e-4);
}

// A directional light of irradiance E arriving along unit d lights the floor (albedo 0.5) with
// 0.5/pi E cos(theta) everywhere, cos(theta) = -d.y: one value for every pixel, on every
// backend (vulkan: tests/vk/vulkan_test.cpp's every-kind scene).
TEST(DirectionalLight, RadianceIsAlbedoOverPiTimesIrradianceCos) {
    TempDir dir;
    const Scene scene = floorUnderLight(
        dir, 4, "max depth: 1",
        "{type: Directional, direction: [0.3, -2, 0.6], intensity: 3, colour: [1, 0.5, 0.25]}");
    const double cosTheta = 2.0 / std::sqrt(0.09 + 4.0 + 0.36);
    expectFloorRadiance(scene, [&](vec3) { return 0.5 / kPi * 3.0 * cosTheta; });
}

// A directional light shares next-event estimation with a quad light by power (pi r^2 E
// against pi L A), and neither biases the other: outside the quad's shadow (the sun shines
// straight down, so the shadow is the quad's own footprint), the floor under both is the floor
// under the quad plus the sun's closed form, within the noise of the quad light's sampling.
TEST(DirectionalLight, AddsToAQuadLightWithoutBias) {
    TempDir dir;
    const std::string sun = "{type: Directional, direction: [0, -1, 0], intensity: 0.5}";
    auto litMean = [&](const std::string& lights) {
        const Scene scene = floorUnderLight(dir, 64, "max depth: 1", lights);
        RenderConfig cfg;
        cfg.backend = BackendKind::Cpu;
        const std::vector<float> img = render(scene, cfg)->film->image();
        double sum = 0;
        int n = 0;
        for (int y = 0; y < 16; ++y)
            for (int x = 0; x < 16; ++x) {
                const vec3 p = floorPointAtPixelCentre(scene, x, y);
                if (std::fabs(p.x) < 0.7f && std::fabs(p.z) < 0.45f) continue; // the shadow
                for (int c = 0; c < 3; ++c, ++n)
                    sum += double(img[size_t(y * 16 + x) * 3 + size_t(c)]);
            }
        EXPECT_GT(n, 100);
        return sum / double(n);
    };
    const double quad = litMean(kQuadOverFloor);
    const double both = litMean("[" + std::string(kQuadOverFloor) + ", " + sun + "]");
    const double sunAlone = 0.5 / kPi * 0.5;
    std::printf("quad %.5f, both %.5f, sun alone %.5f\n", quad, both, sunAlone);
    EXPECT_NEAR(both, quad + sunAlone, 0.01 * (quad + sunAlone));
}

// A map with a bright texel, a black band and a gradient.
Scene mapScene(int w, int h) {
    Scene scene;
    Environment env;
    env.path = "test map";
    env.width = w;
    env.height = h;
    env.rgb.resize(size_t(w * h * 3));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c)
                env.rgb[size_t((y * w + x) * 3 + c)] =
                    y == 2 ? 0.0f : (x == 5 && y == 1 ? 200.0f : 0.1f + 0.05f * float(x + c));
    scene.environment = env;
    return scene;
}

// Directions drawn by environmentSample() land in texels as often as their share of
// luminance x sin(theta) says (chi-square over the texels; none in black ones), and
// environmentPdf() is that density in solid angle: it integrates to 1 over the sphere. A light
// sample's radiance and density, taken from the texel it was drawn in, are the lookup's at its
// direction bit for bit wherever the direction lies in that texel, which is all but a few in a
// hundred thousand.
TEST(EnvironmentLight, MapSamplingPassesChiSquareAgainstItsPdf) {
    const int w = 16, h = 8;
    const Scene scene = mapScene(w, h);
    const SceneLights lights(scene);
    const SceneView view = lights.view();
    RenderParams rp{};
    rp.envWidth = lights.environmentWidth();
    rp.envHeight = lights.environmentHeight();
    ASSERT_EQ(rp.envWidth, uint(w));
    // The orientation: straight up is row 0, -Z the centre of the middle row.
    EXPECT_EQ(environmentTexel(view, rp, glm::normalize(vec3(0.001f, 1, -0.01f))), uvec2(w / 2, 0));
    EXPECT_EQ(environmentTexel(view, rp, glm::normalize(vec3(0.01f, -0.01f, -1))),
              uvec2(w / 2, h / 2));
    EXPECT_EQ(environmentTexel(view, rp, glm::normalize(vec3(-0.01f, -0.2f, -1))),
              uvec2(w / 2 - 1, h / 2));
    EXPECT_EQ(environmentTexel(view, rp, glm::normalize(vec3(0.01f, -1, 0.02f))),
              uvec2(w - 2, h - 1));
    EXPECT_EQ(environmentTexel(view, rp, glm::normalize(vec3(-0.01f, 0.1f, 1))),
              uvec2(0, h / 2 - 1));

    std::vector<double> p(size_t(w * h));
    double total = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const float* t = &scene.environment->rgb[size_t((y * w + x) * 3)];
            p[size_t(y * w + x)] =
                double(luminance(vec3(t[0], t[1], t[2]))) * std::sin(kPi * (y + 0.5) / h);
            total += p[size_t(y * w + x)];
        }
    const int n = 400000;
    std::vector<int> counts(size_t(w * h), 0);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    double worstPdf = 0;
    int across = 0; // directions rounded across their texel's edge
    Emitter e{};
    e.pickPdf = 0.5f;
    for (int i = 0; i < n; ++i) {
        const vec2 u(unit(rng), unit(rng));
        uvec2 drawn;
        const vec3 d = environmentSample(view, rp, u, drawn);
        ASSERT_NEAR(glm::length(d), 1.0f, 1e-5f);
        const uvec2 t = environmentTexel(view, rp, d);
        ++counts[t.y * uint(w) + t.x];
        const LightSample ls = environment_lightSample(view, rp, e, SurfaceHit{}, u);
        ASSERT_EQ(ls.wi, d);
        across += drawn != t;
        if (drawn == t) {
            float pdf;
            ASSERT_EQ(ls.radiance, environmentLookUp(view, rp, e, d, true, pdf));
            ASSERT_EQ(ls.pdf, e.pickPdf * pdf);
            ASSERT_EQ(pdf, environmentPdf(view, rp, d));
        }
        // The density at d: the texel's probability over its solid angle at d's sin(theta)
        // (none at a pole, where float rounds the direction to straight up or down).
        const double sinTheta = std::sqrt(std::max(0.0, 1.0 - double(d.y) * d.y));
        if (sinTheta == 0.0) continue;
        const double expected =
            p[t.y * uint(w) + t.x] / total * w * h / (2.0 * kPi * kPi * sinTheta);
        worstPdf = std::max(worstPdf, std::fabs(environmentPdf(view, rp, d) / expected - 1.0));
    }
    EXPECT_LT(worstPdf, 1e-4);
    EXPECT_LE(across, n / 20000);
    double chi2 = 0;
    int bins = 0;
    for (size_t t = 0; t < counts.size(); ++t) {
        const double expected = n * p[t] / total;
        if (p[t] == 0.0) {
            EXPECT_EQ(counts[t], 0) << "texel " << t << " is black";
            continue;
        }
        chi2 += (counts[t] - expected) * (counts[t] - expected) / expected;
        ++bins;
    }
    // bins - 1 degrees of freedom: a 4.5-sigma bound.
    const double dof = bins - 1;
    std::printf("chi-square %.1f over %d texels (dof %.0f)\n", chi2, bins, dof);
    EXPECT_LT(chi2, dof + 4.5 * std::sqrt(2.0 * dof));

    // The pdf integrates to one: E[pdf(d) 4 pi] over uniform directions.
    double sum = 0, sum2 = 0;
    const int m = 200000;
    for (int i = 0; i < m; ++i) {
        const float z = 1.0f - 2.0f * unit(rng), phi = 2.0f * float(kPi) * unit(rng);
        const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
        const double v =
            double(environmentPdf(view, rp, vec3(r * std::cos(phi), z, r * std::sin(phi)))) * 4.0 *
            kPi;
        sum += v;
        sum2 += v * v;
    }
    const double mean = sum / m, se = std::sqrt((sum2 / m - mean * mean) / m);
    EXPECT_NEAR(mean, 1.0, 4.0 * se);
}

// A glossy metal floor under a sky with a small, bright sun: light sampling wastes samples on
// sky the narrow lobe does not reflect, BSDF sampling rarely finds the sun, and MIS is better
// than either. All three agree on the image (within their standard errors).
TEST(EnvironmentLight, MisHasLowerVarianceThanEitherStrategyOnAGlossyObject) {
    TempDir dir;
    dir.write("floor.obj", floorObj(2.0f));
    ImageRGB sky{32, 16, std::vector<float>(32 * 16 * 3, 1.0f)};
    for (int c = 0; c < 3; ++c)
        sky.rgb[size_t((3 * 32 + 20) * 3 + c)] = 3000.0f; // the sun, 1/512 of the map
    writeImage(dir.path() + "/sky.exr", sky);
    const Scene scene = loadScene(dir.write(
        "glossy.yaml", "image: {width: 16, height: 16, sample base: 1, iterations: 200}\n"
                       "settings: {max depth: 1}\n"
                       "camera: {look at: {eye: [0, 1, 1.5], target: [0, 0, -0.5]}, fov: 70}\n"
                       "object: {filename: floor.obj, shader: 0}\n"
                       "shader: {type: Conductor, colour: [0.9, 0.9, 0.9], alpha: 0.05}\n"
                       "light: {type: Environment, string: sky.exr}\n"));
    PixelStats stats[3];
    for (uint s : {kStrategyMis, kStrategyLight, kStrategyBsdf}) {
        RenderConfig cfg;
        cfg.backend = BackendKind::Reference;
        cfg.strategy = s;
        render(scene, cfg,
               [&](int, int, const Film& film) { stats[s].add(film.lastIterationImage()); });
        const MeanError m = stats[s].imageMean();
        std::printf("strategy %u: mean %.4f +- %.4f, mean pixel variance %.4f\n", s, m.mean,
                    m.stderror, stats[s].averageVariance());
    }
    const MeanError mis = stats[kStrategyMis].imageMean();
    for (uint s : {kStrategyLight, kStrategyBsdf}) {
        const MeanError m = stats[s].imageMean();
        EXPECT_NEAR(m.mean, mis.mean, 4.0 * std::hypot(m.stderror, mis.stderror)) << s;
        EXPECT_LT(stats[kStrategyMis].averageVariance(), 0.8 * stats[s].averageVariance()) << s;
    }
}

} // namespace
} // namespace spw::test

namespace spw::test {
namespace {

// The emitter pick (a branch-free binary search) is the first CDF entry above u, as
// std::upper_bound finds it, for every count, with emitters of zero power (repeated entries)
// and u on the entries themselves.
TEST(Lights, EmitterPickIsTheFirstCdfEntryAboveU) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    for (uint count = 1; count <= 40; ++count) {
        std::vector<float> cdf(count);
        float sum = 0.0f;
        for (float& c : cdf)
            c = sum += unit(rng) < 0.2f ? 0.0f : unit(rng);
        for (float& c : cdf)
            c /= sum;
        cdf.back() = 1.0f;
        SceneView view;
        view.emitterCdf = cdf.data();
        std::vector<float> us = {0.0f, kOneMinusEpsilon};
        for (float c : cdf)
            if (c < 1.0f) us.push_back(c);
        for (int i = 0; i < 200; ++i)
            us.push_back(unit(rng));
        for (float u : us)
            ASSERT_EQ(pickEmitter(view, count, u),
                      uint(std::upper_bound(cdf.begin(), cdf.end(), u) - cdf.begin()))
                << count << " emitters, u " << u;
    }
}

} // namespace
} // namespace spw::test
