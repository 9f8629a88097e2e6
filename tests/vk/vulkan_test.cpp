// The vulkan backend on whatever device the loader offers (lavapipe in CI): it must exist (no
// silent skip), pass the Khronos validation layer without a single message, render the cpu
// backend's image up to float rounding (the shading math is the same source), build only the
// pipelines a scene needs, and fail or fall back cleanly when no driver is visible.
#include "embree_backend/embree_scene.h"
#include "host/cpu/cpu_shading.h"
#include "host/image/image_io.h"
#include "host/loaders/scene_loader.h"
#include "host/pipeline/slotted_engine.h"
#include "host/scene/camera.h"
#include "host/scene/surface_models.h"
#include "host/textures/textures.h"
#include "host/vk/check.h"
#include "host/vk/context.h"
#include "host/vk/spirv.h"
#include "host/vk/vulkan_shading.h"
#include "shared/sampling.h"
#include "test_util.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <set>
#include <sys/wait.h>
#include <thread>

namespace spw::test {
namespace {

// Lavapipe: one worker thread per core (its default can oversubscribe small machines). Set
// before any instance exists; every test runs in its own process under ctest.
class LavapipeThreads : public ::testing::Environment {
  public:
    void SetUp() override {
        setenv("LP_NUM_THREADS",
               std::to_string(std::max(1u, std::thread::hardware_concurrency())).c_str(), 0);
    }
};
[[maybe_unused]] ::testing::Environment* const kLavapipeThreads =
    ::testing::AddGlobalTestEnvironment(new LavapipeThreads);

Scene smallCornell(int size) {
    Scene scene = loadScene(sourceDir() + "/scenes/cornell-box.yaml");
    scene.image.width = scene.image.height = size;
    return scene;
}

// The closed enclosure of the sorted pipeline's tests: Lambert albedo 0.8 emitting 1 on every
// face, so the radiance everywhere is 1 / (1 - 0.8) = 5.
Scene enclosure(const TempDir& dir) {
    dir.write("cube.obj", insideCubeObj());
    return loadScene(dir.write(
        "e.yaml", "image: {width: 16, height: 16, sample base: 1, iterations: 1}\n"
                  "settings: {max depth: 300}\n"
                  "camera: {look at: {eye: [0, 0, 0], target: [0.3, 0.2, -1]}, fov: 100}\n"
                  "object: {filename: cube.obj, shader: 0}\n"
                  "shader: {type: Lambert, reflectance: 0.8, emission: [1, 1, 1]}\n"));
}

RenderConfig validatedVulkan(int spp) {
    RenderConfig cfg;
    cfg.backend = BackendKind::Vulkan;
    cfg.vulkan.validation = true;
    cfg.spp = spp;
    return cfg;
}

// Renders with validation on and fails the test on any message the layer printed, counted
// after the render returned (the instance, and the layer's leak checks, are gone by then).
// With `iterations`, each iteration's image is appended to it.
std::unique_ptr<RenderResult>
renderValidated(const Scene& scene, const RenderConfig& cfg,
                std::vector<std::vector<float>>* iterations = nullptr) {
    const std::uint64_t before = vk::validationMessageCount();
    auto result = render(scene, cfg, [&](int, int, const Film& film) {
        if (iterations) iterations->push_back(film.lastIterationImage());
    });
    EXPECT_EQ(vk::validationMessageCount() - before, 0u)
        << "the validation layer reported messages (see stderr)";
    EXPECT_EQ(result->stats.backend, "vulkan");
    EXPECT_TRUE(result->stats.extra["vulkan"]["validation"].get<bool>());
    return result;
}

// How far two renders of the same paths are apart, value by value (every channel of every
// pixel): relative difference |a - b| / max(|a|, |b|, 1e-3).
struct Difference {
    size_t values = 0;
    size_t unequal = 0;  // not bit-identical
    size_t diverged = 0; // beyond kDiverged
    double p999 = 0;     // 99.9th percentile
    double maxRel = 0;
};

// A value this far off is not rounding along its paths but a path that went elsewhere.
constexpr double kDiverged = 1e-3;

Difference difference(const std::vector<float>& a, const std::vector<float>& b) {
    Difference d;
    d.values = a.size();
    std::vector<double> rel(a.size());
    for (size_t i = 0; i < a.size(); ++i) {
        const double x = a[i], y = b[i];
        rel[i] = std::fabs(x - y) / std::max({std::fabs(x), std::fabs(y), 1e-3});
        d.unequal += std::memcmp(&a[i], &b[i], sizeof(float)) != 0;
        d.diverged += rel[i] > kDiverged;
        d.maxRel = std::max(d.maxRel, rel[i]);
    }
    std::sort(rel.begin(), rel.end());
    d.p999 = rel.empty() ? 0.0 : rel[rel.size() * 999 / 1000];
    return d;
}

// Vulkan and cpu run shared/path.h's shadeSurface() on the same hits with the same random
// numbers; only the compilers' float rounding differs (lavapipe's LLVM evaluates cos/sin, sqrt,
// pow and divisions its own way, as GLSL allows, flushes denormals and may fuse multiply-adds).
// One shading step then differs by a few float epsilons (VulkanVsCpu.*HitByHit measure it) and
// a value by what those add up to along its paths. Now and then a rounding flips a branch (a
// Russian-roulette or stochastic-rounding threshold, a total internal reflection) and that path
// goes elsewhere: its pixel differs by a whole sample. Asserted, with figures measured on
// lavapipe (Mesa 22.3.6, LLVM 15) in the comments of the tests:
//  * rounding: the 99.9th percentile of the relative differences within `rounding`, about 10x
//    what was measured;
//  * divergence: at most 1 value in 1000 beyond kDiverged (a wrong kernel diverges most of the
//    values it touches; measured: none at this size, 1e-5 of the values on the 256^2 box);
//  * no bias: the per-iteration (paired) difference has mean zero within 4 of its own standard
//    errors, which are far below either render's noise (see expectNoPairedDifference), allowing
//    `rounding` x the image mean per pixel for consistent rounding.
void expectSameUpToRounding(const char* what, const std::vector<std::vector<float>>& vulkan,
                            const std::vector<std::vector<float>>& cpu, int width, int height,
                            double rounding) {
    ASSERT_EQ(vulkan.size(), cpu.size());
    std::vector<float> v(vulkan[0].size(), 0.0f), c(cpu[0].size(), 0.0f);
    for (size_t k = 0; k < vulkan.size(); ++k)
        for (size_t i = 0; i < v.size(); ++i)
            v[i] += vulkan[k][i] / float(vulkan.size()), c[i] += cpu[k][i] / float(cpu.size());
    const Difference d = difference(v, c);
    std::printf("%s: %zu of %zu values differ at all; relative difference: 99.9th percentile %.2e, "
                "max %.2e; "
                "%zu beyond %.0e (paths that diverged)\n",
                what, d.unequal, d.values, d.p999, d.maxRel, d.diverged, kDiverged);
    EXPECT_LE(d.p999, rounding) << what;
    EXPECT_LE(double(d.diverged), 1e-3 * double(d.values)) << what;
    expectNoPairedDifference(pairedDifference(vulkan, cpu), width, height, what,
                             rounding * mean(c));
}

// Renders `scene` on vulkan (under validation) and on cpu with the same settings (`configure`
// changes both) and asserts that they agree up to `rounding` (expectSameUpToRounding). Returns
// the vulkan render.
std::unique_ptr<RenderResult>
expectVulkanMatchesCpu(const Scene& scene, int spp, const char* what, double rounding,
                       const std::function<void(RenderConfig&)>& configure = nullptr) {
    RenderConfig vkCfg = validatedVulkan(spp);
    if (configure) configure(vkCfg);
    RenderConfig cpuCfg = vkCfg;
    cpuCfg.backend = BackendKind::Cpu;
    std::vector<std::vector<float>> v, c;
    auto result = renderValidated(scene, vkCfg, &v);
    render(scene, cpuCfg,
           [&](int, int, const Film& film) { c.push_back(film.lastIterationImage()); });
    expectSameUpToRounding(what, v, c, scene.image.width, scene.image.height, rounding);
    return result;
}

// --- the device ----------------------------------------------------------------------------

// CI installs mesa-vulkan-drivers: lavapipe is always there. No device is a failure, not a skip.
TEST(VulkanDevice, AUsableDeviceExists) {
    std::vector<vk::DeviceInfo> devices;
    ASSERT_NO_THROW(devices = vk::listDevices()) << "no Vulkan driver: install mesa-vulkan-drivers";
    ASSERT_FALSE(devices.empty());
    bool usable = false;
    for (const vk::DeviceInfo& d : devices) {
        std::printf("device %u: %s (%s), Vulkan %s, %s\n", d.index, d.name.c_str(),
                    d.driver.c_str(), d.api.c_str(), d.usable ? "usable" : d.whyNot.c_str());
        usable = usable || d.usable;
        EXPECT_FALSE(d.driver.empty());
    }
    EXPECT_TRUE(usable);
}

// The zero-message assertions mean something only if the layer is live: provoke one error (a
// buffer with no usage bits, VUID-VkBufferCreateInfo-usage-requiredbitmask) and see it counted.
TEST(VulkanDevice, ValidationLayerIsLiveAndCounted) {
    VulkanConfig cfg;
    cfg.validation = true;
    vk::Context context(cfg);
    ASSERT_TRUE(context.validation());
    const std::uint64_t before = vk::validationMessageCount();
    auto info = vk::zeroed<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
    info.size = 256;
    info.usage = 0;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    VkBuffer buffer = VK_NULL_HANDLE;
    if (vkCreateBuffer(context.device(), &info, nullptr, &buffer) == VK_SUCCESS)
        vkDestroyBuffer(context.device(), buffer, nullptr);
    EXPECT_GE(vk::validationMessageCount() - before, 1u);
    EXPECT_GE(context.validationMessages(), 1u);
}

// Every Vulkan render in the suite runs validated, not only the ones that ask for it: the test
// helpers set SPILLWAY_VK_VALIDATION=1 for the whole process (and the spillway processes it
// starts), and fail any test during which the layer reported a message (tests/test_util.cpp).
// Not in the sanitized build, where only the Vulkan* tests ask for it.
TEST(VulkanDevice, EveryRenderInTheSuiteRunsUnderTheValidationLayer) {
    RenderConfig cfg;
    cfg.backend = BackendKind::Vulkan;
    cfg.spp = 1;
    ASSERT_FALSE(cfg.vulkan.validation);
    auto result = render(smallCornell(8), cfg);
    EXPECT_EQ(result->stats.extra["vulkan"]["validation"].get<bool>(), !kAddressSanitizer);
}

// --- vulkan against cpu --------------------------------------------------------------------

// Measured: 99.9th percentile 1.3e-6, max 2.1e-6, nothing diverged.
TEST(VulkanVsCpu, CornellBoxAgreesUpToFloatRounding) {
    auto result = expectVulkanMatchesCpu(smallCornell(32), 16, "Cornell box", 1e-5);
    // The scene's models: its Lambert walls and blocks, and the quad light's Null shader.
    EXPECT_EQ(result->stats.extra["vulkan"]["pipelines"], nlohmann::json({"null", "lambert"}));
    EXPECT_EQ(result->stats.extra["vulkan"]["specialization"]["emitters"], true);
    EXPECT_EQ(result->stats.extra["vulkan"]["specialization"]["textures"], false);
    EXPECT_EQ(result->stats.extra["shading"], "sorted");
}

// The Sobol sampler's bit manipulations (shared/rng.h) compile to the same numbers in GLSL.
TEST(VulkanVsCpu, SobolSamplerAgreesUpToFloatRounding) {
    Scene scene = smallCornell(32);
    scene.sampler = SamplerType::Sobol;
    auto result = expectVulkanMatchesCpu(scene, 8, "Cornell box, Sobol", 1e-5);
    EXPECT_EQ(result->stats.extra["sampler"], "Sobol");
    EXPECT_EQ(result->stats.extra["vulkan"]["specialization"]["sampler"], "sobol");
}

// The sampling strategy is a specialisation constant of the kernels (the others' code dropped):
// light sampling alone and BSDF sampling alone against cpu, which reads it from RenderParams.
TEST(VulkanVsCpu, EachSamplingStrategyAgreesUpToFloatRounding) {
    Scene scene = smallCornell(24);
    for (const auto& [strategy, name] :
         {std::pair{kStrategyLight, "light"}, std::pair{kStrategyBsdf, "bsdf"}}) {
        const uint chosen = strategy; // C++17 lambdas cannot capture a structured binding
        auto result = expectVulkanMatchesCpu(scene, 8, name, 1e-5,
                                             [&](RenderConfig& c) { c.strategy = chosen; });
        EXPECT_EQ(result->stats.extra["vulkan"]["specialization"]["strategy"], name);
        EXPECT_GT(mean(result->film->image()), 0.01) << name;
    }
}

// Scenes lit only by point lights, only by an environment map, and by both: the kernels' branches
// (shared/path.h's sampleEmitter) against cpu, and the environment map's buffer bound and read.
TEST(VulkanVsCpu, EveryEmitterKindAgreesUpToFloatRounding) {
    TempDir dir;
    dir.write("floor.obj", floorObj(2.0f));
    dir.write("cube.obj", insideCubeObj());
    ImageRGB sky{16, 8, std::vector<float>(16 * 8 * 3, 0.2f)};
    for (size_t i = 0; i < sky.rgb.size(); ++i)
        sky.rgb[i] += 0.1f * float(i % 7);
    writeImage(dir.file("sky.exr"), sky);
    const std::string common =
        "image: {width: 24, height: 24}\n"
        "camera: {look at: {eye: [0, 1, 2.5], target: [0, 0, 0]}, fov: 60}\n"
        "shaders:\n  - {type: Lambert, reflectance: 0.7}\n"
        "  - {type: Conductor, colour: [0.9, 0.6, 0.3], alpha: 0.2}\n"
        "objects:\n  - {filename: floor.obj, shader: 1}\n"
        "  - {filename: cube.obj, shader: 0, scale: 0.3, translation: [0.3, 0.3, 0]}\n";
    // One kind of emitter lets the kernels drop the other kinds' light sampling (the
    // specialisation's emitter_kinds); both kinds together keep both.
    const std::string point = "  - {type: Point, position: [0.5, 1.5, 0.5], intensity: 2}\n"
                              "  - {type: Point, position: [-1, 0.5, 1], intensity: 1, "
                              "colour: [0.2, 0.4, 1]}\n";
    const std::string environment = "  - {type: Environment, string: sky.exr}\n";
    const std::string sun = "  - {type: Directional, direction: [0.4, -1, -0.3], intensity: 1.5}\n";
    const std::string spot =
        "  - {type: Spot, position: [0.2, 1.5, 0.4], direction: [0, -1, -0.2], "
        "intensity: 3, inner angle: 15, outer angle: 40}\n";
    for (const auto& [lights, kinds] :
         {std::pair{point, nlohmann::json({"point"})}, std::pair{spot, nlohmann::json({"spot"})},
          std::pair{environment, nlohmann::json({"environment"})},
          std::pair{sun, nlohmann::json({"directional"})},
          std::pair{point + environment + sun,
                    nlohmann::json({"point", "environment", "directional"})}}) {
        const Scene scene = loadScene(dir.write("lights.yaml", common + "lights:\n" + lights));
        auto result = expectVulkanMatchesCpu(scene, 16, lights.c_str(), 1e-4);
        EXPECT_GT(mean(result->film->image()), 0.01) << lights;
        EXPECT_EQ(result->stats.extra["vulkan"]["specialization"]["emitter_kinds"], kinds);
    }
}

// Paths of up to 300 bounces: rounding adds up along them. Measured: 99.9th percentile 4.5e-5.
TEST(VulkanVsCpu, ClosedEnclosureAgreesUpToFloatRounding) {
    TempDir dir;
    auto result = expectVulkanMatchesCpu(enclosure(dir), 32, "closed enclosure", 5e-4);
    // And against the closed form Le / (1 - a) = 5.
    const MeanError m = meanAndError(result->film->image());
    EXPECT_NEAR(m.mean, 5.0, 4.0 * m.stderror);
    EXPECT_EQ(result->stats.nonFiniteSamples, 0u);
}

// --- one shading step, hit by hit -----------------------------------------------------------

// Every registered model in one scene: Lambert walls, a rough and a polished Conductor, a rough
// and a smooth Dielectric, and the quad light's Null.
// The Cornell box's camera, meshes and quad light at 16 x 16, with `shaders` (YAML list items)
// and `objects`: each a mesh of scenes/cornell-box/ and its keys, "white.obj, shader: 0".
Scene boxWith(const TempDir& dir, const std::string& shaders,
              const std::vector<std::string>& objects) {
    std::string yaml = "image: {width: 16, height: 16}\n"
                       "camera: {look at: {eye: [278, 273, -800], target: [278, 273, 0]}, "
                       "fov: 39.3}\n"
                       "shaders:\n" +
                       shaders + "objects:\n";
    for (const std::string& o : objects)
        yaml += "  - {filename: " + sourceDir() + "/scenes/cornell-box/" + o + "}\n";
    yaml += "light: {type: Quad, translation: [278, 548.7, 279.5], rotation: [90, 0, 0], "
            "scale: [130, 105], intensity: 1, colour: [17, 12, 4]}\n";
    return loadScene(dir.write("box.yaml", yaml));
}

Scene everyModelScene(const TempDir& dir) {
    return boxWith(dir,
                   "  - {type: Lambert, colour: [0.725, 0.71, 0.68]}\n"
                   "  - {type: Conductor, colour: [0.95, 0.64, 0.54], alpha: 0.3}\n"
                   "  - {type: Conductor, colour: [0.9, 0.9, 0.9]}\n"
                   "  - {type: Dielectric, ior: 1.5, alpha: 0.2}\n"
                   "  - {type: Dielectric, ior: 1.33}\n"
                   "  - {type: MetallicRoughness, colour: [0.8, 0.6, 0.3], metallic: 0.4, "
                   "roughness: 0.35}\n",
                   {"white.obj, shader: 0", "red.obj, shader: 1", "green.obj, shader: 2",
                    "blocks.obj, shader: 3", "blocks.obj, shader: 4", "blocks.obj, shader: 5"});
}

// |a - b| over the vector's size, in float epsilons (2^-23): a direction or a position rounded
// differently by one ulp in its largest component scores about 1.
double relativeEps(vec3 a, vec3 b) {
    const double scale =
        std::max({double(std::fabs(a.x)), double(std::fabs(a.y)), double(std::fabs(a.z)),
                  double(std::fabs(b.x)), double(std::fabs(b.y)), double(std::fabs(b.z)), 1e-30});
    const double d = std::max(
        {std::fabs(double(a.x) - b.x), std::fabs(double(a.y) - b.y), std::fabs(double(a.z) - b.z)});
    return d / scale / 0x1p-23;
}
double relativeEps(float a, float b) {
    return relativeEps(vec3(a, 0.0f, 0.0f), vec3(b, 0.0f, 0.0f));
}

struct PerHit {
    size_t hits = 0, identical = 0, flagMismatches = 0;
    double maxEps[8] =
        {}; // emitted, shadow origin, dir, tmax, contribution, next origin, dir, beta
};

// Shades the same synthetic hits (random triangle, point, incoming direction, throughput,
// bounce) with the cpu engine and the Vulkan one, and compares the ShadeResults field by field.
PerHit shadeSameHits(ShadingMode mode) {
    TempDir dir;
    Scene scene = everyModelScene(dir);
    SceneLights lights(scene);
    EmbreeScene embree(scene);
    HitSetup hitSetup(scene, lights);
    TextureResolver textures(scene, scene.settings.textureCacheMiB);
    CameraModel camera(scene, 1);
    RenderStats stats;
    RenderConfig cfg;
    cfg.backend = BackendKind::Vulkan;
    cfg.vulkan.validation = true;
    cfg.pipeline.shading = mode;
    cfg.pipeline.fuseStages = false; // the cpu engine with a slot to feed (--stages separate)
    RenderParams params{};
    params.seed = 7;
    params.samplesPerIteration = 4;
    params.minDepth = 2;
    params.maxDepth = 12;
    params.threshold = scene.settings.threshold;
    params.strategy = kStrategyMis;
    params.emitterCount = uint(lights.emitters().size());
    RenderContext ctx{scene, cfg, lights, embree, hitSetup, textures, camera, params, 2, stats};

    const std::uint64_t before = vk::validationMessageCount();
    PerHit out;
    {
        vk::Context context(cfg.vulkan);
        std::unique_ptr<ShadingEngine> gpu = makeVulkanShading(ctx, cfg.pipeline, context);
        std::unique_ptr<ShadingEngine> cpu = makeCpuShading(ctx);
        gpu->beginIteration(3);
        cpu->beginIteration(3);

        std::mt19937 rng(1234);
        std::uniform_real_distribution<float> unit(0.0f, 1.0f);
        const size_t n = 20000;
        std::vector<ShadeInput> inputs(n);
        for (size_t i = 0; i < n; ++i) {
            const uint mesh = uint(rng() % scene.meshes.size());
            const uint prim = uint(rng() % scene.meshes[mesh].triangles.size());
            float u = unit(rng), v = unit(rng);
            if (u + v > 1.0f) u = 1.0f - u, v = 1.0f - v;
            ShadeInput& in = inputs[i];
            hitSetup.setUpHit(HitRecord{mesh, prim, u, v, 10.0f + 1000.0f * unit(rng)},
                              vec3(0.0f, 0.0f, 1.0f), 0u, textures, true, in.hit);
            vec3 d = glm::normalize(vec3(unit(rng) - 0.5f, unit(rng) - 0.5f, unit(rng) - 0.5f));
            if (rng() % 8 != 0 && glm::dot(d, in.hit.ng) > 0.0f)
                d = -d; // mostly the front, some backs
            in.rayDir = d;
            in.path = PathState{};
            in.path.beta = vec3(0.05f + unit(rng), 0.05f + unit(rng), 0.05f + unit(rng));
            in.path.prevPdf = quantizePdf(0.01f + 4.0f * unit(rng));
            in.path.pathId = uint(rng() % (64 * 64 * 4));
            in.path.bounce = uint(rng() % 12);
            in.path.flags = rng() % 5 == 0 ? kPathSpecular : 0u;
            in.path.cone = uint(rng() & 0xFFFFu);
        }
        // One range per shader (sorted shading), or all at once (megakernel).
        std::stable_sort(
            inputs.begin(), inputs.end(),
            [](const ShadeInput& a, const ShadeInput& b) { return a.hit.shader < b.hit.shader; });
        std::vector<ShadeRange> ranges;
        for (size_t b = 0; b < n;) {
            size_t e = b + 1;
            while (e < n && inputs[e].hit.shader == inputs[b].hit.shader)
                ++e;
            ranges.push_back({scene.shaders[inputs[b].hit.shader].params.model, b, e - b});
            b = e;
        }
        if (mode == ShadingMode::Megakernel) ranges = {{kMixedModels, 0, n}};

        // The engines' slots, fed the same inputs directly.
        auto& gpuSlots = dynamic_cast<SlottedEngine&>(*gpu);
        auto& cpuSlots = dynamic_cast<SlottedEngine&>(*cpu);
        ShadeSlot g = gpuSlots.reserve(0, n), c = cpuSlots.reserve(0, n);
        std::copy(inputs.begin(), inputs.end(), g.inputs);
        std::copy(inputs.begin(), inputs.end(), c.inputs);
        gpuSlots.submit(0, ranges);
        cpuSlots.submit(0, ranges);
        gpuSlots.wait(0);
        cpuSlots.wait(0);

        out.hits = n;
        for (size_t i = 0; i < n; ++i) {
            const ShadeResult& a = g.results[i];
            const ShadeResult& b = c.results[i];
            if (std::memcmp(&a, &b, sizeof a) == 0) {
                ++out.identical;
                continue;
            }
            if (a.flags != b.flags || a.next.bounce != b.next.bounce ||
                a.next.pathId != b.next.pathId || a.next.flags != b.next.flags ||
                ((a.flags & kShadeContinue) && a.next.cone != b.next.cone)) {
                ++out.flagMismatches;
                continue;
            }
            const double e[8] = {
                relativeEps(a.emitted, b.emitted),
                (a.flags & kShadeShadow) ? relativeEps(a.shadowOrigin, b.shadowOrigin) : 0.0,
                (a.flags & kShadeShadow) ? relativeEps(a.shadowDir, b.shadowDir) : 0.0,
                (a.flags & kShadeShadow) ? relativeEps(a.shadowTmax, b.shadowTmax) : 0.0,
                (a.flags & kShadeShadow) ? relativeEps(a.shadowContribution, b.shadowContribution)
                                         : 0.0,
                (a.flags & kShadeContinue) ? relativeEps(a.nextOrigin, b.nextOrigin) : 0.0,
                (a.flags & kShadeContinue) ? relativeEps(a.nextDir, b.nextDir) : 0.0,
                (a.flags & kShadeContinue) ? relativeEps(a.next.beta, b.next.beta) : 0.0};
            for (int k = 0; k < 8; ++k)
                out.maxEps[k] = std::max(out.maxEps[k], e[k]);
        }
    }
    EXPECT_EQ(vk::validationMessageCount() - before, 0u)
        << "the validation layer reported messages (see stderr)";
    std::printf("%s: %zu hits, %zu bit-identical, %zu with other flags; worst differences in float "
                "epsilons: "
                "emitted %.1f, shadow origin %.1f, dir %.1f, tmax %.1f, contribution %.1f, next "
                "origin %.1f, "
                "dir %.1f, throughput %.1f\n",
                mode == ShadingMode::Sorted ? "per-model kernels" : "megakernel", out.hits,
                out.identical, out.flagMismatches, out.maxEps[0], out.maxEps[1], out.maxEps[2],
                out.maxEps[3], out.maxEps[4], out.maxEps[5], out.maxEps[6], out.maxEps[7]);
    return out;
}

// The bound for one shading step: the same source compiled twice differs by float rounding
// only. Measured on lavapipe over 20000 hits of every model: 55% of the results bit-identical,
// no decision different (which rays exist, bounce, flags), and in float epsilons relative to
// the vector's size: emission, shadow-ray origin, direction and length exact; shadow
// contribution 2.8; continuation origin exact, direction 22 (the cosine-hemisphere and GGX
// samples' cos/sin); throughput 170 (the rough Conductor's GGX weight: sqrt, divisions and
// the Smith term). Asserted: decisions agree for all but 0.1% of hits, and every float within
// 1024 epsilons (1.2e-4 relative).
constexpr double kMaxEps = 1024.0;

void expectPerHitBound(const PerHit& r) {
    EXPECT_LE(double(r.flagMismatches), 0.001 * double(r.hits));
    for (double e : r.maxEps)
        EXPECT_LE(e, kMaxEps);
    EXPECT_GT(r.identical, 0u);
}

TEST(VulkanVsCpu, EveryModelsKernelMatchesTheCpuHitByHit) {
    expectPerHitBound(shadeSameHits(ShadingMode::Sorted));
}

TEST(VulkanVsCpu, MegakernelMatchesTheCpuHitByHit) {
    expectPerHitBound(shadeSameHits(ShadingMode::Megakernel));
}

// --- leave out what the scene does not need ------------------------------------------------

TEST(VulkanPipelines, OneSurfaceModelCreatesExactlyOnePipeline) {
    TempDir dir;
    Scene scene = enclosure(dir);
    auto v = renderValidated(scene, validatedVulkan(1));
    EXPECT_EQ(v->stats.extra["vulkan"]["pipelines"], nlohmann::json({"lambert"}));
}

// Shaders of two models listed alternately: the hit sort ranks the shaders by model, so that each
// model's hits are one range and one dispatch per batch (at most one per pipeline per submit;
// sorted by shader index, the three Lambert shaders would be three ranges split by the two
// Conductors). The image is still the cpu backend's.
TEST(VulkanPipelines, EachSurfaceModelIsOneDispatchPerBatch) {
    TempDir dir;
    const Scene scene =
        boxWith(dir,
                "  - {type: Lambert, colour: [0.725, 0.71, 0.68]}\n"
                "  - {type: Conductor, colour: [0.95, 0.64, 0.54], alpha: 0.3}\n"
                "  - {type: Lambert, colour: [0.63, 0.065, 0.05]}\n"
                "  - {type: Conductor, colour: [0.9, 0.9, 0.9], alpha: 0.1}\n"
                "  - {type: Lambert, colour: [0.14, 0.45, 0.091]}\n",
                {"white.obj, shader: 0", "red.obj, shader: 2", "green.obj, shader: 4",
                 "blocks.obj, shader: 1", "blocks.obj, shader: 3, translation: [0, 0, -200]"});
    auto v = expectVulkanMatchesCpu(scene, 4, "alternating models", 1e-5);
    const nlohmann::json& vs = v->stats.extra["vulkan"];
    const size_t pipelines = vs["pipelines"].size();
    EXPECT_GE(pipelines, 2u);
    EXPECT_LE(vs["dispatches"].get<std::uint64_t>(),
              vs["submits"].get<std::uint64_t>() * pipelines);
}

// No emitter: the kernels are specialised without emission and next-event estimation, and the
// image is black on both backends, exactly.
TEST(VulkanPipelines, NoEmittersSpecialisesNextEventEstimationAway) {
    TempDir dir;
    dir.write("cube.obj", insideCubeObj());
    Scene scene = loadScene(
        dir.write("dark.yaml", "image: {width: 8, height: 8}\n"
                               "camera: {look at: {eye: [0, 0, 0], target: [0, 0, -1]}, fov: 90}\n"
                               "object: {filename: cube.obj, shader: 0}\n"
                               "shader: {type: Lambert}\n"));
    auto v = renderValidated(scene, validatedVulkan(2));
    EXPECT_EQ(v->stats.extra["vulkan"]["specialization"]["emitters"], false);
    EXPECT_EQ(v->stats.extra["vulkan"]["specialization"]["emitter_kinds"], nlohmann::json::array());
    EXPECT_EQ(v->stats.extra["vulkan"]["pipelines"], nlohmann::json({"lambert"}));
    EXPECT_EQ(mean(v->film->image()), 0.0);
}

// --- the ablation and the buffer paths -----------------------------------------------------

// --shading megakernel: unsorted hits, one uber-shader. Same math, so the same image as the cpu
// backend's; only the megakernel pipeline is built.
TEST(VulkanMegakernel, MatchesCpuAndBuildsOnlyTheUberShader) {
    Scene scene = smallCornell(24);
    auto v = expectVulkanMatchesCpu(
        scene, 8, "megakernel Cornell box", 3e-5, // measured 3.5e-6
        [](RenderConfig& c) { c.pipeline.shading = ShadingMode::Megakernel; });
    EXPECT_EQ(v->stats.extra["vulkan"]["pipelines"], nlohmann::json({"megakernel"}));
    EXPECT_EQ(v->stats.extra["shading"], "megakernel");
    EXPECT_EQ(v->stats.extra["hit_sort"], false);
}

// Staging copies (what a discrete GPU without resizable BAR takes), 2D dispatches (more
// workgroups than one dimension allows) and ranges split across binding windows (buffers larger
// than maxStorageBufferRange), forced on with tiny limits, tiny batches (more submits per
// iteration than the timestamp pool holds) and the stages after shading run separately: the
// image is bit for bit the one of the plain path, as each hit's arithmetic is unchanged and the
// film does not depend on batching or on the order of its splats.
TEST(VulkanBuffers, StagingTwoDimensionalAndWindowedDispatchesGiveTheSameImage) {
    Scene scene = smallCornell(24);
    scene.settings.binExponent = 12;
    RenderConfig plain = validatedVulkan(4);
    auto a = renderValidated(scene, plain);
    RenderConfig odd = plain;
    odd.vulkan.forceStaging = true;
    odd.vulkan.maxGroupsX = 3;             // 192 hits per row of workgroups
    odd.vulkan.maxBindingBytes = 64 << 10; // windows of ~585 records
    auto b = renderValidated(scene, odd);
    const std::vector<float> ia = a->film->image(), ib = b->film->image();
    EXPECT_EQ(ia.size(), ib.size());
    EXPECT_EQ(std::memcmp(ia.data(), ib.data(), ia.size() * sizeof(float)), 0);
    const nlohmann::json& vs = b->stats.extra["vulkan"];
    EXPECT_EQ(vs["memory"]["inputs"], "staged");
    EXPECT_EQ(vs["memory"]["results"], "staged");
    EXPECT_GT(vs["dispatches_2d"].get<int>(), 0);
    EXPECT_GT(vs["binding_windows_used"].get<int>(), 1);
    EXPECT_EQ(a->stats.extra["vulkan"]["memory"]["inputs"], "mapped in place");
    for (const char* stage : {"upload", "dispatch", "download"})
        EXPECT_GT(b->stats.stages.get(stage), 0.0) << stage;

    Scene tiny = scene;
    tiny.settings.binExponent = 4; // 16-ray batches
    auto c = renderValidated(tiny, plain);
    const std::vector<float> ic = c->film->image();
    EXPECT_EQ(std::memcmp(ia.data(), ic.data(), ia.size() * sizeof(float)), 0);
    EXPECT_GT(c->stats.extra["vulkan"]["submits"].get<int>(), 512);

    // The stages after shading, each over the whole batch instead of chunk by chunk.
    RenderConfig separate = plain;
    separate.pipeline.fuseStages = false;
    auto d = renderValidated(scene, separate);
    const std::vector<float> id = d->film->image();
    EXPECT_EQ(std::memcmp(ia.data(), id.data(), ia.size() * sizeof(float)), 0);
    EXPECT_EQ(d->stats.extra["stages"], "separate");
    EXPECT_EQ(a->stats.extra["stages"], "fused after shading");
    EXPECT_EQ(a->stats.shadowRays, d->stats.shadowRays);
    EXPECT_GT(a->stats.shadowRays, 0u);
}

// --- the registry --------------------------------------------------------------------------

TEST(SurfaceModels, EveryRegisteredModelHasItsKernel) {
    std::set<std::string> registered;
    for (size_t i = 0; i < kSurfaceModelCount; ++i) {
        const SurfaceModelInfo& m = kSurfaceModels[i];
        EXPECT_EQ(m.model, uint(i)) << m.name << ": registry order must follow the kModel* values";
        EXPECT_NE(vk::findSpirvKernel(m.kernel), nullptr)
            << "shaders/" << m.kernel << ".comp is not embedded";
        registered.insert(m.kernel);
    }
    ASSERT_NE(vk::findSpirvKernel(kMegakernel), nullptr);
    registered.insert(kMegakernel);
    for (size_t i = 0; i < vk::kSpirvKernelCount; ++i) {
        EXPECT_TRUE(registered.count(vk::kSpirvKernels[i].name))
            << vk::kSpirvKernels[i].name << " is not registered";
        EXPECT_EQ(vk::kSpirvKernels[i].words[0], 0x07230203u)
            << "not SPIR-V: " << vk::kSpirvKernels[i].name;
    }
}

// --- the command line ----------------------------------------------------------------------

// Runs the binary with extra environment variables, output and status captured.
CommandResult runWithEnv(const std::string& env, const std::string& args) {
    return runShell("env " + env + " " + binary() + " " + args);
}

bool contains(const std::string& s, const std::string& part) {
    return s.find(part) != std::string::npos;
}

std::string tinyScene(const TempDir& dir) {
    return dir.write(
        "tiny.yaml",
        "image: {width: 8, height: 8}\n"
        "camera: {look at: {eye: [278, 273, -800], target: [278, 273, 0]}, fov: 39.3}\n"
        "shader: {type: Lambert}\n"
        "object: {filename: " +
            sourceDir() +
            "/scenes/cornell-box/blocks.obj, shader: 0}\n"
            "light: {type: Quad, translation: [278, 548.7, 279.5], rotation: [90, 0, 0], scale: "
            "[130, 105]}\n");
}

TEST(VulkanCli, NoDriverVisibleVulkanExitsOneAndAutoRendersOnCpu) {
    TempDir dir;
    const std::string scene = tinyScene(dir);
    const std::string noDriver = "VK_DRIVER_FILES=" + dir.file("no-such-icd.json");

    CommandResult v = runWithEnv(noDriver, "render " + scene + " --quiet --backend vulkan -o " +
                                               dir.file("v.exr"));
    EXPECT_EQ(v.status, 1) << v.output;
    const std::string why =
        "VK_DRIVER_FILES names '" + dir.file("no-such-icd.json") + "', which does not exist";
    EXPECT_TRUE(contains(v.output, "--backend vulkan: " + why)) << v.output;
    EXPECT_FALSE(std::filesystem::exists(dir.file("v.exr")));

    CommandResult a = runWithEnv(noDriver, "render " + scene + " --quiet -o " + dir.file("a.exr") +
                                               " --stats " + dir.file("a.json"));
    ASSERT_EQ(a.status, 0) << a.output;
    EXPECT_TRUE(contains(a.output, "spillway: no Vulkan device (" + why + "); rendering on cpu\n"))
        << a.output;
    nlohmann::json stats = nlohmann::json::parse(std::ifstream(dir.file("a.json")));
    EXPECT_EQ(stats["backend"], "cpu");
    EXPECT_FALSE(stats.contains("vulkan"));

    CommandResult d = runWithEnv(noDriver, "devices");
    EXPECT_EQ(d.status, 1) << d.output;
    EXPECT_TRUE(contains(d.output, "no Vulkan")) << d.output;
    // It still says what --backend auto does, and why.
    EXPECT_TRUE(contains(d.output, "--backend auto takes cpu: no Vulkan device (" + why))
        << d.output;

    // cpu never touches Vulkan: no fallback line.
    CommandResult c =
        runWithEnv(noDriver, "render " + scene + " --quiet --backend cpu -o " + dir.file("c.exr"));
    EXPECT_EQ(c.status, 0) << c.output;
    EXPECT_FALSE(contains(c.output, "Vulkan")) << c.output;

    // A manifest cut short (which the loader reports as VK_ERROR_OUT_OF_HOST_MEMORY), under the
    // older variable: the same fallback, naming it.
    const std::string cut =
        dir.write("cut.json", "{\"file_format_version\": \"1.0.0\", \"ICD\": {");
    const std::string env = "VK_ICD_FILENAMES=" + cut;
    CommandResult t = runWithEnv(env, "render " + scene + " --quiet -o " + dir.file("t.exr"));
    EXPECT_EQ(t.status, 0) << t.output;
    EXPECT_TRUE(contains(t.output, "spillway: no Vulkan device (VK_ICD_FILENAMES names '" + cut +
                                       "', which is not a Vulkan driver manifest"))
        << t.output;
    CommandResult tv =
        runWithEnv(env, "render " + scene + " --quiet --backend vulkan -o " + dir.file("tv.exr"));
    EXPECT_EQ(tv.status, 1) << tv.output;
    EXPECT_TRUE(contains(tv.output, "--backend vulkan: VK_ICD_FILENAMES names '" + cut))
        << tv.output;
}

// The loader's own log (VK_LOADER_DEBUG=all) shows whether an instance was made: it searches for
// layers and drivers only then. cpu and reference must never make one, nor auto on a machine
// without a GPU device file.
TEST(VulkanCli, CpuAndReferenceNeverInitialiseVulkanNorAutoWithoutAGpu) {
    TempDir dir;
    const std::string scene = tinyScene(dir);
    for (const char* backend : {"cpu", "reference", "auto"}) {
        CommandResult r =
            runWithEnv("VK_LOADER_DEBUG=all", "render " + scene + " --quiet --backend " + backend +
                                                  " -o " + dir.file("x.exr"));
        ASSERT_EQ(r.status, 0) << backend << "\n" << r.output;
        const bool initialised = contains(r.output, "DRIVER:") || contains(r.output, "LAYER:");
        // auto starts the loader only where a GPU's device file says there may be a GPU.
        const bool probes = std::string(backend) == "auto" && !vk::gpuDeviceFiles().empty();
        EXPECT_EQ(initialised, probes) << backend << "\n" << r.output.substr(0, 2000);
    }
}

TEST(VulkanCli, DevicesAndDeviceSelectionUnderValidation) {
    TempDir dir;
    const std::string scene = tinyScene(dir);
    const std::string validated = "SPILLWAY_VK_VALIDATION=1";
    CommandResult list = runWithEnv(validated, "devices");
    ASSERT_EQ(list.status, 0) << list.output;
    EXPECT_TRUE(contains(list.output, "0: ")) << list.output;
    EXPECT_TRUE(contains(list.output, "driver: ")) << list.output;
    std::vector<vk::DeviceInfo> devices = vk::listDevices();
    ASSERT_FALSE(devices.empty());
    const vk::DeviceInfo& first = *std::find_if(devices.begin(), devices.end(),
                                                [](const vk::DeviceInfo& d) { return d.usable; });

    // --backend vulkan takes the first usable device; by index and by part of the name too (the
    // default backend, auto, then takes the device named).
    const std::string byName = first.name.substr(0, first.name.find(' '));
    for (const std::string& choice :
         {std::string("--backend vulkan"), "--device " + std::to_string(first.index),
          "--device " + byName}) {
        CommandResult r =
            runWithEnv(validated, "render " + scene + " --quiet " + choice + " -o " +
                                      dir.file("x.exr") + " --stats " + dir.file("x.json"));
        ASSERT_EQ(r.status, 0) << choice << "\n" << r.output;
        EXPECT_FALSE(contains(r.output, "vulkan validation")) << r.output;
        nlohmann::json stats = nlohmann::json::parse(std::ifstream(dir.file("x.json")));
        EXPECT_EQ(stats["backend"], "vulkan") << choice;
        EXPECT_EQ(stats["device"], first.name) << choice;
        EXPECT_EQ(stats["vulkan"]["validation_messages"], 0);
        for (const char* stage : {"upload", "dispatch", "download"})
            EXPECT_TRUE(stats["stage_seconds"].contains(stage)) << stage;
    }

    CommandResult bad =
        runWithEnv(validated, "render " + scene + " --quiet --device 99 -o " + dir.file("y.exr"));
    EXPECT_EQ(bad.status, 1) << bad.output;
    EXPECT_TRUE(contains(bad.output, "--device 99: no such Vulkan device")) << bad.output;
    EXPECT_TRUE(contains(bad.output, first.name)) << bad.output;

    CommandResult usage = runWithEnv(
        validated, "render " + scene + " --quiet --shading sideways -o " + dir.file("z.exr"));
    EXPECT_EQ(usage.status, 2) << usage.output;
    EXPECT_TRUE(contains(usage.output, "sideways")) << usage.output;
}

vk::DeviceInfo fakeDevice(uint32_t index, const char* type, bool usable = true) {
    vk::DeviceInfo d;
    d.index = index;
    d.name = std::string(type) + " " + std::to_string(index);
    d.type = type;
    d.usable = usable;
    return d;
}

// A GPU is reached through a device file (DRM's nodes, NVIDIA's, WSL's, Qualcomm's, Arm's); where
// there is none, --backend auto knows without the loader that there is no GPU.
TEST(VulkanCli, AGpuIsFoundByItsDeviceFile) {
    TempDir dir;
    const std::string root = dir.file("dev");
    std::filesystem::create_directories(root + "/dri");
    for (const char* other : {"null", "nvidia-uvm", "nvidia-modeset", "dri/by-path", "tty0"})
        dir.write("dev/" + std::string(other), "");
    EXPECT_TRUE(vk::gpuDeviceFiles(root).empty());
    EXPECT_TRUE(vk::gpuDeviceFiles(dir.file("no-such-dev")).empty());
    for (const char* gpu :
         {"dri/renderD128", "dri/card0", "nvidia0", "nvidiactl", "dxg", "kgsl-3d0", "mali0"}) {
        TempDir one;
        std::filesystem::create_directories(one.file("dev/dri"));
        one.write("dev/" + std::string(gpu), "");
        EXPECT_EQ(vk::gpuDeviceFiles(one.file("dev")),
                  std::vector<std::string>{one.file("dev/" + std::string(gpu))})
            << gpu;
    }
}

// auto: a real GPU (discrete first, then integrated), never a software device unless the
// driver variables ask for one, and the cpu backend otherwise.
TEST(VulkanCli, AutoTakesARealGpuElseCpuAndLavapipeOnlyWhenAskedFor) {
    using vk::chooseAutoDevice;
    const std::vector<vk::DeviceInfo> lavapipeOnly = {fakeDevice(0, "cpu")};
    EXPECT_EQ(chooseAutoDevice(lavapipeOnly, false).device, -1);
    EXPECT_TRUE(contains(chooseAutoDevice(lavapipeOnly, false).why, "cpu: no usable GPU"));
    EXPECT_EQ(chooseAutoDevice(lavapipeOnly, true).device, 0);
    const std::vector<vk::DeviceInfo> mixed = {
        fakeDevice(0, "cpu"), fakeDevice(1, "integrated gpu"), fakeDevice(2, "discrete gpu", false),
        fakeDevice(3, "discrete gpu")};
    EXPECT_EQ(chooseAutoDevice(mixed, false).device, 3);
    EXPECT_EQ(chooseAutoDevice(mixed, true).device, 3);
    EXPECT_EQ(chooseAutoDevice({mixed[0], mixed[1], mixed[2]}, false).device, 1);
    EXPECT_EQ(chooseAutoDevice({fakeDevice(0, "discrete gpu", false)}, false).device, -1);
    EXPECT_EQ(chooseAutoDevice({}, true).device, -1);

    // This machine, as a new user runs it: no driver variables.
    TempDir dir;
    const std::string scene = tinyScene(dir);
    const std::string plain = "-u VK_DRIVER_FILES -u VK_ICD_FILENAMES -u VK_ADD_DRIVER_FILES";
    // Without a GPU's device file the loader is not started at all (autoChoiceWithoutLoader).
    const vk::AutoChoice expected =
        vk::gpuDeviceFiles().empty()
            ? vk::AutoChoice{-1, "cpu: no GPU on this machine (no device file in /dev/dri, no "
                                 "/dev/nvidia*, /dev/dxg or another GPU's), so no Vulkan driver "
                                 "can reach one; a software device such as lavapipe shades more "
                                 "slowly than the cpu backend on the same cores; --backend vulkan "
                                 "takes it"}
            : chooseAutoDevice(vk::listDevices(), false);
    CommandResult r = runWithEnv(plain, "render " + scene + " --quiet -o " + dir.file("a.exr") +
                                            " --stats " + dir.file("a.json"));
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(r.output, "");
    nlohmann::json stats = nlohmann::json::parse(std::ifstream(dir.file("a.json")));
    EXPECT_EQ(stats["backend"], expected.device >= 0 ? "vulkan" : "cpu");
    EXPECT_EQ(stats["backend_auto"], expected.why);
    CommandResult d = runWithEnv(plain, "devices");
    EXPECT_EQ(d.status, 0) << d.output;
    EXPECT_TRUE(contains(d.output, "--backend auto takes " + expected.why)) << d.output;

    // The driver variables naming lavapipe: auto takes it.
    const std::string lvp = "/usr/share/vulkan/icd.d/lvp_icd.x86_64.json";
    if (!std::filesystem::exists(lvp)) return;
    r = runWithEnv("VK_DRIVER_FILES=" + lvp, "render " + scene + " --quiet -o " +
                                                 dir.file("b.exr") + " --stats " +
                                                 dir.file("b.json"));
    ASSERT_EQ(r.status, 0) << r.output;
    stats = nlohmann::json::parse(std::ifstream(dir.file("b.json")));
    EXPECT_EQ(stats["backend"], "vulkan");
    EXPECT_TRUE(contains(stats["device"].get<std::string>(), "llvmpipe")) << stats["device"];
}

} // namespace
} // namespace spw::test
