// The light tree (shared/light_tree.h, host/scene_view/light_tree.cpp): its picks land on each
// emitter as often as the probability it reports, that probability is the one MIS recomputes
// from a ray's origin, every emitter that can light a point can be picked there, and many
// lights sampled through it light a floor as their closed forms add up (point lights: the
// inverse-square law; quad lights with MIS: Lambert's polygon formula), on every host backend.
#include "host/loaders/scene_loader.h"
#include "host/scene_view/lights.h"
#include "shared/path.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace spw::test {
namespace {

enum class Lights { Mixed, Punctual, QuadGrid };

// `count` lights above the floor of floorUnderLight, powers over 3 orders of magnitude:
// Mixed: quads facing down, points and spots in turn, at heights from 0.05 to 2; Punctual:
// points and spots; QuadGrid: quads facing down at one height, each in a cell of its own of a
// grid 0.5 apart (none shadows another on the floor).
std::string manyLights(int count, Lights kind, uint seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::string lights = "[";
    char buf[256];
    for (int i = 0; i < count; ++i) {
        float x = -2.0f + 4.0f * unit(rng), z = -2.0f + 4.0f * unit(rng);
        float y = 0.05f + 2.0f * unit(rng) * unit(rng);
        const float power = std::pow(10.0f, 3.0f * unit(rng) - 1.0f);
        const int type = kind == Lights::QuadGrid ? 0 : kind == Lights::Mixed ? i % 3 : 1 + i % 2;
        if (kind == Lights::QuadGrid) {
            x = -2.25f + 0.5f * float(i % 10);
            z = -2.25f + 0.5f * float(i / 10);
            y = 0.8f;
        }
        if (type == 0)
            std::snprintf(buf, sizeof buf,
                          "{type: Quad, translation: [%g, %g, %g], rotation: [90, 0, 0], "
                          "scale: [%g, %g], intensity: %g}",
                          x, y, z, 0.1f + 0.38f * unit(rng), 0.1f + 0.38f * unit(rng), power);
        else if (type == 1)
            std::snprintf(buf, sizeof buf, "{type: Point, position: [%g, %g, %g], intensity: %g}",
                          x, y, z, 0.1f * power);
        else
            std::snprintf(buf, sizeof buf,
                          "{type: Spot, position: [%g, %g, %g], direction: [%g, -1, %g], "
                          "intensity: %g, inner angle: 20, outer angle: 50}",
                          x, y, z, unit(rng) - 0.5f, unit(rng) - 0.5f, 0.1f * power);
        lights += std::string(i ? ", " : "") + buf;
    }
    return lights + "]";
}

RenderParams treeParams(const SceneLights& lights) {
    RenderParams rp{};
    rp.emitterCount = lights.sampledEmitters();
    rp.treeEmitters = lights.treeEmitters();
    rp.environment = lights.environment();
    return rp;
}

// At points above, on and below the lights: the probabilities over every emitter add to at most
// 1, the rest being picks that find no light, each pick reports the probability lightPickPdf
// recomputes, and 200000 picks land on each emitter within 5 standard deviations of that
// probability.
TEST(LightTree, PicksLandAsOftenAsTheProbabilityMisRecomputes) {
    TempDir dir;
    const Scene scene = floorUnderLight(dir, 1, "max depth: 1", manyLights(60, Lights::Mixed, 3));
    const SceneLights lights(scene);
    const SceneView view = lights.view();
    const RenderParams rp = treeParams(lights);
    ASSERT_EQ(rp.treeEmitters, rp.emitterCount); // every light has a place
    ASSERT_GT(rp.treeEmitters, 60u);
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    const vec3 points[] = {vec3(0.2f, 0.0f, 0.1f), vec3(-1.9f, 0.01f, 1.7f), vec3(0.0f, 1.0f, 0.0f),
                           vec3(3.0f, 2.5f, -3.0f), vec3(0.5f, -1.0f, 0.5f)};
    for (vec3 p : points) {
        p -= vec3(scene.origin); // the scene's data is relative to the camera
        std::vector<double> pmf(rp.emitterCount);
        double total = 0.0;
        for (uint e = 0; e < rp.emitterCount; ++e)
            total += pmf[e] = double(lightPickPdf(view, rp, e, p));
        // Below 1 where a node's bound lets p see it but neither child's does: those picks
        // find no light (kNoEmitter), which is where the rest goes.
        ASSERT_LE(total, 1.0 + 1e-4) << "at " << p.x << " " << p.y << " " << p.z;
        ASSERT_GT(total, 0.9);
        pmf.push_back(std::max(0.0, 1.0 - total));
        const int n = 200000;
        std::vector<int> counts(rp.emitterCount + 1, 0);
        for (int i = 0; i < n; ++i) {
            float reported;
            const uint e = pickLight(view, rp, p, unit(rng), reported);
            if (e == kNoEmitter) {
                ASSERT_EQ(reported, 0.0f);
                ++counts.back();
                continue;
            }
            ASSERT_LT(e, rp.emitterCount);
            ASSERT_NEAR(reported, pmf[e], 1e-5 * pmf[e]);
            ++counts[e];
        }
        for (size_t e = 0; e < counts.size(); ++e) {
            const double expected = n * pmf[e];
            EXPECT_LE(std::fabs(counts[e] - expected), 5.0 * std::sqrt(expected) + 2.0)
                << "emitter " << e << " at " << p.x << " " << p.y << " " << p.z;
        }
    }
}

// A one-sided triangle light can be picked wherever its front faces, however far and however
// weak against the others; well above every light (all face down) nothing can be, and the pick
// says so (kNoEmitter, probability 0) rather than picking a light that cannot reach.
TEST(LightTree, EveryLightThatCanReachAPointCanBePickedThere) {
    TempDir dir;
    const Scene scene =
        floorUnderLight(dir, 1, "max depth: 1", manyLights(80, Lights::QuadGrid, 9));
    const SceneLights lights(scene);
    const SceneView view = lights.view();
    const RenderParams rp = treeParams(lights);
    ASSERT_EQ(rp.treeEmitters, 160u);
    std::mt19937 rng(2);
    std::uniform_real_distribution<float> unit(-6.0f, 6.0f);
    int checked = 0;
    for (int i = 0; i < 300; ++i) {
        const vec3 p(unit(rng), 0.3f * unit(rng), unit(rng));
        for (uint e = 0; e < rp.emitterCount; ++e) {
            const Emitter& em = lights.emitters()[e];
            const vec3 centre = em.p0 + (em.e1 + em.e2) / 3.0f;
            if (glm::dot(em.normal, p - centre) > 1e-3f) {
                EXPECT_GT(lightPickPdf(view, rp, e, p), 0.0f) << "emitter " << e;
                ++checked;
            }
        }
    }
    EXPECT_GT(checked, 10000);
    float pmf = 1.0f;
    EXPECT_EQ(pickLight(view, rp, vec3(0.0f, 3.0f, 0.0f), 0.5f, pmf), kNoEmitter);
    EXPECT_EQ(pmf, 0.0f);
}

// No tree where it would pick as the CDF does: one point light, or one quad light (its two
// triangles have the same bounds); two quad lights, or a quad and a point, have one.
TEST(LightTree, OnlyScenesWhereItPicksDifferentlyHaveOne) {
    TempDir dir;
    auto treeEmitters = [&](const std::string& lights) {
        return SceneLights(floorUnderLight(dir, 1, "", lights)).treeEmitters();
    };
    const std::string quad = kQuadOverFloor;
    const std::string point = "{type: Point, position: [0, 1, 0], intensity: 1}";
    const std::string second = "{type: Quad, translation: [1, 1, 0], rotation: [90, 0, 0], "
                               "scale: [0.5, 0.5], intensity: 3}";
    EXPECT_EQ(treeEmitters(point), 0u);
    EXPECT_EQ(treeEmitters(quad), 0u);
    EXPECT_EQ(treeEmitters("[" + quad + ", " + second + "]"), 4u);
    EXPECT_EQ(treeEmitters("[" + quad + ", " + point + "]"), 3u);
}

// Lambert's formula: the irradiance at p (normal +Y) from a polygon of radiance L facing it,
// L / 2 x the sum over its edges of the angle each subtends times the cosine of its plane's
// normal with +Y.
double polygonIrradiance(vec3 p, const std::vector<glm::dvec3>& corners, double radiance) {
    double sum = 0.0;
    for (size_t i = 0; i < corners.size(); ++i) {
        const glm::dvec3 a = glm::normalize(corners[i] - glm::dvec3(p));
        const glm::dvec3 b = glm::normalize(corners[(i + 1) % corners.size()] - glm::dvec3(p));
        const glm::dvec3 c = glm::cross(a, b);
        sum += std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0)) * c.y / glm::length(c);
    }
    return 0.5 * radiance * std::fabs(sum);
}

// Each pixel's mean over the iterations against the closed form, on every host backend: no
// 8x8 block and not the image beyond 4.5 and 4 standard errors.
void expectFloorMean(const Scene& scene, const std::function<double(vec3)>& expected) {
    for (BackendKind b : {BackendKind::Reference, BackendKind::Cpu}) {
        RenderConfig cfg;
        cfg.backend = b;
        PixelStats stats;
        for (const std::vector<float>& img : iterationImages(scene, cfg))
            stats.add(img);
        double sum = 0.0, variance = 0.0;
        auto difference = [&](size_t i) {
            return stats.mean(i) -
                   expected(floorPointAtPixelCentre(scene, int(i % 16), int(i / 16)));
        };
        for (size_t i = 0; i < stats.pixels(); ++i) {
            sum += difference(i);
            variance += stats.meanVariance(i);
        }
        const double z = sum / std::sqrt(variance);
        const double block =
            worstBlockZ(16, 16, difference, [&](size_t i) { return stats.meanVariance(i); });
        std::printf("%s: image z %.2f, worst block z %.2f\n", backendName(b), z, block);
        EXPECT_LT(std::fabs(z), 4.0) << backendName(b);
        EXPECT_LT(block, 4.5) << backendName(b);
    }
}

// 30 point and spot lights picked through the tree: the floor is the sum of their closed forms
// (the spots' glTF falloff), the noise only the tree's choice among them.
TEST(LightTree, PointLightsPickedThroughItAddUpToTheirClosedForms) {
    TempDir dir;
    const std::string list = manyLights(30, Lights::Punctual, 21);
    const Scene scene = floorUnderLight(dir, 256, "max depth: 1", list);
    expectFloorMean(scene, [&](vec3 p) {
        double sum = 0.0;
        for (const PunctualLight& l : scene.punctualLights) {
            const glm::dvec3 d = glm::dvec3(l.position) + glm::dvec3(scene.origin) - glm::dvec3(p);
            const double r = glm::length(d);
            double falloff = 1.0;
            if (l.kind == kEmitterSpot) {
                const double c = -glm::dot(d / r, glm::dvec3(l.direction));
                const double t = std::clamp(
                    (c - double(l.cosOuter)) / double(l.cosInner - l.cosOuter), 0.0, 1.0);
                falloff = t * t;
            }
            sum += 0.5 / kPi * double(luminance(l.intensity)) * falloff * std::max(d.y, 0.0) /
                   (r * r * r);
        }
        return sum;
    });
}

// 40 quad lights, found by light sampling through the tree and by BSDF sampling, weighed by
// MIS with the tree's probability from the ray's origin: the floor is the sum of Lambert's
// formula over them (none shadows another at the pixel centres' points: all face down and the
// floor sees their fronts).
TEST(LightTree, QuadLightsWithMisAddUpToLambertsFormula) {
    TempDir dir;
    const std::string list = manyLights(40, Lights::QuadGrid, 17);
    const Scene scene = floorUnderLight(dir, 1024, "max depth: 1", list);
    const SceneLights lights(scene);
    expectFloorMean(scene, [&](vec3 p) {
        double sum = 0.0;
        for (const Emitter& e : lights.emitters()) {
            const glm::dvec3 a = glm::dvec3(e.p0) + glm::dvec3(scene.origin);
            const glm::dvec3 b = a + glm::dvec3(e.e1), c = a + glm::dvec3(e.e2);
            sum += polygonIrradiance(p, {a, b, c}, double(luminance(e.radiance)));
        }
        return 0.5 / kPi * sum;
    });
}

} // namespace
} // namespace spw::test
