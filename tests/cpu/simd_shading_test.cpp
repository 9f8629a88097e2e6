// The SIMD kernels (host/cpu/simd_shading.h) against shadeSurface(), hit by hit and bit by bit,
// on random hits that reach every branch: both sides of the surface, shading normals on the
// wrong side, emitters seen from behind and one- and two-sided, every strategy and sampler,
// paths before min depth, past it and at max depth, rough and smooth Conductors and Dielectrics
// (reflection, refraction, total internal reflection; tinted by the hit's albedo, and an
// absorbing medium behind one), MetallicRoughness from dielectric to
// metal (and with metallic and roughness per hit), and every model's hits mixed in runs
// that are not a multiple of the vector width.
#include "host/cpu/simd_shading.h"
#include "host/cpu/wide_models.h"
#include "host/loaders/scene_loader.h"
#include "host/render/render.h"
#include "host/scene/scene.h"
#include "host/scene/surface_models.h"
#include "host/scene_view/lights.h"
#include "host/simd/simd_target.h"
#include "test_util.h"

#include "shared/path.h"

#include <gtest/gtest.h>
#include <hwy/targets.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

namespace spw {
namespace {

struct Fixture {
    std::vector<ShaderParams> shaders;
    std::vector<Emitter> emitters;
    std::vector<float> cdf;
    SceneView view() const {
        SceneView v;
        v.shaders = shaders.data();
        v.emitters = emitters.data();
        v.emitterCdf = cdf.data();
        v.emitterCount = uint(cdf.size());
        return v;
    }
};

vec3 unitVector(std::mt19937& rng) {
    std::normal_distribution<float> g;
    return normalize(vec3(g(rng), g(rng), g(rng)));
}

// Emitter i of a fixture, its pickPdf unnormalised: kind 0 a triangle, 1 a point light, 2 a spot
// light, 3 a directional light, 4 the environment (constant).
Emitter randomEmitter(std::mt19937& rng, int i, int kind) {
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    Emitter e{};
    e.type = kEmitterTriangle;
    e.p0 = vec3(u(rng), 2.0f + u(rng), u(rng)) * 3.0f;
    e.e1 = vec3(u(rng) - 0.5f, 0.1f * u(rng), u(rng) - 0.5f) * 2.0f;
    e.e2 = vec3(u(rng) - 0.5f, 0.1f * u(rng), u(rng) - 0.5f) * 2.0f;
    e.normal = normalize(cross(e.e1, e.e2));
    e.area = 0.5f * length(cross(e.e1, e.e2));
    e.twoSided = i % 2 == 0 ? 1u : 0u;
    e.radiance = vec3(5.0f * u(rng), 4.0f, 3.0f * u(rng));
    e.pickPdf = 0.2f + u(rng);
    if (kind == 1 || kind == 2) { // a point light; a spot light shining down
        e.type = kind == 1 ? kEmitterPoint : kEmitterSpot;
        e.normal = normalize(vec3(u(rng) - 0.5f, -1.0f, u(rng) - 0.5f));
        e.e1 = vec3(0.5f, 0.9f, 0.0f); // cos outer, cos inner
    } else if (kind == 3) {            // a directional light shining down
        e.type = kEmitterDirectional;
        e.normal = normalize(vec3(u(rng) - 0.5f, -1.0f, u(rng) - 0.5f));
    } else if (kind == 4) {
        e.type = kEmitterEnvironment;
    }
    return e;
}

// `emitters` emitters: triangles; with everyKind, in turn a triangle, a point light, a spot
// light and a directional light, the last one the environment (constant), whose index the
// caller gives RenderParams::environment.
Fixture makeFixture(std::mt19937& rng, int emitters, bool everyKind = false) {
    Fixture f;
    struct Model {
        uint model;
        float alpha, ior;
        float metallic = 1.0f;
        uint flags = 0u;
        vec3 absorption{0.0f}; // Dielectric: the medium behind it absorbs
    };
    for (Model m :
         {Model{kModelLambert, 0.0f, 1.5f},
          Model{kModelLambert, 0.0f, 1.5f},
          Model{kModelConductor, 0.3f, 1.5f},
          Model{kModelLambert, 0.0f, 1.5f},
          Model{kModelNull, 0.0f, 1.5f},
          Model{kModelConductor, 0.0f, 1.5f},
          Model{kModelDielectric, 0.2f, 1.5f},
          Model{kModelConductor, 1e-3f, 1.5f},
          Model{kModelDielectric, 0.0f, 1.5f, 1.0f, 0u, vec3(0.7f, 0.1f, 0.0f)},
          Model{kModelCoatedMetallicRoughness, 0.3f, 1.5f, 0.5f},
          Model{kModelDielectric, 0.0f, 1.33f},
          Model{kModelMetallicRoughness, 0.3f, 1.5f, 0.5f},
          Model{kModelMetallicRoughness, 0.0f, 1.5f, 0.0f},
          Model{kModelMetallicRoughness, 0.6f, 1.5f, 1.0f},
          Model{kModelMetallicRoughness, 0.6f, 1.5f, 1.0f, kShaderHitParams},
          Model{kModelMetallicRoughness, 0.3f, 1.7f, 0.3f, kShaderSpecular},
          Model{kModelCoatedMetallicRoughness, 0.3f, 1.5f, 0.2f, kShaderSpecular},
          Model{kModelTransmissiveMetallicRoughness, 0.0f, 1.5f, 0.0f, 0u, vec3(0.5f, 0.1f, 0.0f)},
          Model{kModelTransmissiveMetallicRoughness, 0.2f, 1.3f},
          Model{kModelSheenMetallicRoughness, 0.3f, 1.5f, 0.2f}}) {
        ShaderParams sh{};
        sh.model = m.model;
        sh.colour = vec3(0.8f);
        sh.reflectance = 1.0f;
        sh.alpha = m.alpha;
        sh.ior = m.ior;
        sh.metallic = m.metallic;
        sh.flags = m.flags;
        sh.absorption = m.absorption;
        sh.coat = 0.7f;
        sh.coatAlpha = 0.01f;
        sh.specular = 0.6f; // read with kShaderSpecular only
        sh.specularColour = vec3(1.8f, 1.0f, 0.3f);
        sh.transmission = 0.4f;                  // read by TransmissiveMetallicRoughness only
        sh.sheenColour = vec3(0.9f, 0.5f, 0.2f); // read by SheenMetallicRoughness only
        sh.sheenRoughness = 0.4f;
        f.shaders.push_back(sh);
    }
    float total = 0.0f;
    for (int i = 0; i < emitters; ++i) {
        f.emitters.push_back(randomEmitter(rng, i,
                                           everyKind && i + 1 == emitters ? 4
                                           : everyKind                    ? i % 4
                                                                          : 0));
        total += f.emitters.back().pickPdf;
    }
    float sum = 0.0f;
    for (Emitter& e : f.emitters) {
        e.pickPdf /= total;
        sum += e.pickPdf;
        f.cdf.push_back(sum);
    }
    if (!f.cdf.empty()) f.cdf.back() = 1.0f;
    return f;
}

std::vector<ShadeInput> randomHits(std::mt19937& rng, const Fixture& f, size_t n) {
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<ShadeInput> hits(n);
    for (size_t i = 0; i < n; ++i) {
        ShadeInput& in = hits[i];
        SurfaceHit& h = in.hit;
        h.p = vec3(u(rng), u(rng), u(rng)) * 4.0f - 1.0f;
        h.t = 0.1f + 5.0f * u(rng);
        h.ng = unitVector(rng);
        // Mostly a shading normal near ng, sometimes one beyond the geometric surface.
        h.ns = u(rng) < 0.1f ? -h.ng : normalize(h.ng + 0.3f * unitVector(rng));
        // Runs of one shader, of every length from 1 to 8, in a changing order.
        h.shader = uint((i / (1 + i % 8) * 7) % f.shaders.size());
        h.emitter = !f.emitters.empty() && u(rng) < 0.1f ? uint(i % f.emitters.size()) : kNoEmitter;
        h.albedo = vec3(u(rng), u(rng), u(rng));
        h.offset = 1e-6f * (1.0f + u(rng));
        h.material = uint(rng()); // metallic and roughness, where the shader takes them per hit
        // Lifted toward either side (a smooth-shaded mesh), or not at all.
        h.lift = u(rng) < 0.4f ? 0.0f : 0.05f * (u(rng) - 0.3f);
        in.rayDir = unitVector(rng);
        PathState& st = in.path;
        st.beta = u(rng) < 0.05f ? vec3(0.0f) : vec3(u(rng), u(rng), u(rng)) * 2.0f;
        st.prevPdf = u(rng) < 0.2f ? 0.0f : 3.0f * u(rng);
        st.pathId = uint(rng() % 100000u);
        st.bounce = uint(rng() % 9u);
        st.flags = u(rng) < 0.2f ? kPathSpecular : 0u;
        st.cone = uint(rng() & 0xFFFFu);
    }
    return hits;
}

// How many results have each flag, so that a test can check it exercised them.
struct FlagCounts {
    size_t emitted = 0, shadow = 0, next = 0, specular = 0;
    std::map<uint, size_t> nextOf, shadowOf; // by model
};

FlagCounts compareWithShadeSurface(const SceneView& view, const RenderParams& rp,
                                   const std::vector<ShadeInput>& hits, const char* what) {
    std::vector<ShadeResult> simd(hits.size()), scalar(hits.size());
    std::memset(simd.data(), 0xAB, simd.size() * sizeof(ShadeResult));
    shadeHits(view, rp, true, hits.data(), hits.size(), simd.data());
    shadeHits(view, rp, false, hits.data(), hits.size(), scalar.data());
    FlagCounts counts;
    size_t mismatches = 0;
    for (size_t i = 0; i < hits.size(); ++i) {
        if (std::memcmp(&simd[i], &scalar[i], sizeof(ShadeResult)) != 0 && ++mismatches <= 3)
            ADD_FAILURE() << what << ": hit " << i << " (model "
                          << view.shaders[hits[i].hit.shader].model << ", bounce "
                          << hits[i].path.bounce << ") flags " << simd[i].flags << " against "
                          << scalar[i].flags << ", next dir " << simd[i].nextDir.x << " against "
                          << scalar[i].nextDir.x << ", shadow " << simd[i].shadowContribution.x
                          << " against " << scalar[i].shadowContribution.x;
        counts.emitted += (scalar[i].flags & kShadeEmitted) != 0;
        counts.shadow += (scalar[i].flags & kShadeShadow) != 0;
        counts.next += (scalar[i].flags & kShadeContinue) != 0;
        counts.specular +=
            (scalar[i].flags & kShadeContinue) != 0 && (scalar[i].next.flags & kPathSpecular) != 0;
        const uint model = view.shaders[hits[i].hit.shader].model;
        counts.nextOf[model] += (scalar[i].flags & kShadeContinue) != 0;
        counts.shadowOf[model] += (scalar[i].flags & kShadeShadow) != 0;
    }
    EXPECT_EQ(mismatches, 0u) << what << ": of " << hits.size() << " hits";
    return counts;
}

void expectEveryModelsHitsAreShadeSurface();

RenderParams params(uint strategy, uint sampling, uint emitters) {
    RenderParams rp{};
    rp.seed = 7;
    rp.iteration = 3;
    rp.samplesPerIteration = 4;
    rp.minDepth = 2;
    rp.maxDepth = 6;
    rp.threshold = 0.5f;
    rp.strategy = strategy;
    rp.emitterCount = emitters;
    rp.sampling = sampling;
    rp.environment = kNoEmitter;
    return rp;
}

// In every instruction set this machine has that the kernel was compiled for (SSE4, AVX2,
// AVX-512, and Highway's portable 128-bit emulation).
TEST(SimdShading, EveryModelsHitsAreShadeSurfaceToTheBit) {
    std::vector<int64_t> targets = hwy::SupportedAndGeneratedTargets();
    ASSERT_FALSE(targets.empty());
    std::set<std::string> ran;
    for (int64_t target : targets) {
        hwy::SetSupportedTargetsForTest(target);
        ran.insert(simdTarget());
        SCOPED_TRACE(simdTarget());
        expectEveryModelsHitsAreShadeSurface();
    }
    hwy::SetSupportedTargetsForTest(0);
    EXPECT_EQ(ran.size(), targets.size()); // each target ran its own code
}

void expectEveryModelsHitsAreShadeSurface() {
    std::mt19937 rng(2024);
    for (int emitters : {3, 1, 0, -6}) { // -6: six of every kind
        const bool everyKind = emitters < 0;
        emitters = std::abs(emitters);
        const Fixture f = makeFixture(rng, emitters, everyKind);
        // 2003 hits: blocks of one model's hits, some full (64), most ragged.
        const std::vector<ShadeInput> hits = randomHits(rng, f, 2003);
        for (uint strategy : {kStrategyMis, kStrategyLight, kStrategyBsdf})
            for (uint sampling : {kSamplerIndependent, kSamplerSobol}) {
                const std::string what = std::to_string(emitters) + " emitters" +
                                         (everyKind ? " of every kind" : "") + ", strategy " +
                                         std::to_string(strategy) + ", sampler " +
                                         std::to_string(sampling);
                RenderParams rp = params(strategy, sampling, uint(emitters));
                if (everyKind) rp.environment = uint(emitters - 1);
                const FlagCounts c = compareWithShadeSurface(f.view(), rp, hits, what.c_str());
                // The comparison reached every outcome it can have here.
                EXPECT_GT(c.next, 400u) << what;
                EXPECT_GT(c.specular, 40u) << what;
                for (uint model : kWideModels) {
                    ASSERT_TRUE(c.nextOf.count(model))
                        << surfaceModel(model)->name
                        << " is SIMD-wide (host/cpu/wide_models.h), but makeFixture above has no "
                           "shader of it: add one";
                    EXPECT_GT(c.nextOf.at(model), 40u) << what << ", model " << model;
                }
                if (emitters > 0 && strategy != kStrategyBsdf) {
                    EXPECT_GT(c.shadow, 200u) << what;
                    for (uint model : kWideModels)
                        EXPECT_GT(c.shadowOf.at(model), 10u) << what << ", model " << model;
                }
                if (emitters > 0) {
                    EXPECT_GT(c.emitted, 5u) << what;
                }
            }
    }
}

// A scene of many lights over [-1, 3]^2, from 0.1 to 2.6 above y = 0: emissive triangles
// (half of them two-sided), quads and spots facing down, and with `points`, point lights too
// (without them, picks above the lights find none).
Scene manyLightsScene(test::TempDir& dir, std::mt19937& rng, bool points) {
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::string obj[2], lights = "[";
    int vertices[2] = {0, 0};
    char buf[256];
    for (int i = 0; i < 80; ++i) {
        const float x = -1.0f + 4.0f * unit(rng), z = -1.0f + 4.0f * unit(rng);
        const float y = 0.1f + 2.5f * unit(rng), power = std::pow(10.0f, 2.0f * unit(rng));
        if (i % 4 < 2) { // an emissive triangle, tilted at random
            std::string& o = obj[i % 2];
            for (int k = 0; k < 3; ++k) { // one draw a statement: arguments' order is unspecified
                const float dx = 0.3f * unit(rng);
                const float dy = 0.2f * (unit(rng) - 0.5f);
                const float dz = 0.3f * unit(rng);
                std::snprintf(buf, sizeof buf, "v %g %g %g\n", x + dx, y + dy, z + dz);
                o += buf;
            }
            const int v = vertices[i % 2] += 3;
            o += "f " + std::to_string(v - 2) + " " + std::to_string(v - 1) + " " +
                 std::to_string(v) + "\n";
            continue;
        }
        if (i % 4 == 2 || !points)
            std::snprintf(buf, sizeof buf,
                          i % 8 == 3 ? "{type: Quad, translation: [%g, %g, %g], rotation: [90, 0, "
                                       "0], scale: [0.3, 0.2], intensity: %g}"
                                     : "{type: Spot, position: [%g, %g, %g], direction: [0.3, -1, "
                                       "0.1], intensity: %g, inner angle: 20, outer angle: 50}",
                          x, y, z, power);
        else
            std::snprintf(buf, sizeof buf, "{type: Point, position: [%g, %g, %g], intensity: %g}",
                          x, y, z, power);
        lights += std::string(lights.size() > 1 ? ", " : "") + buf;
    }
    dir.write("floor.obj", test::floorObj(4.0f));
    dir.write("one-sided.obj", obj[0]);
    dir.write("two-sided.obj", obj[1]);
    return loadScene(dir.write(
        "lights.yaml",
        "image: {width: 16, height: 16}\n"
        "camera: {look at: {eye: [0.2, 0.6, 0.1], target: [0.2, 0, 0.1], up: [0, 0, -1]}}\n"
        "shaders:\n  - {type: Lambert}\n  - {type: Null, emission: [3, 2, 1]}\n"
        "  - {type: Null, emission: [1, 2, 3], two sided: true}\n"
        "objects:\n  - {filename: floor.obj, shader: 0}\n"
        "  - {filename: one-sided.obj, shader: 1}\n  - {filename: two-sided.obj, shader: 2}\n"
        "lights: " +
            lights + "]\n"));
}

// Under a light tree, whose descent the kernel's light pick runs SIMD-wide: every hit shaded as
// shadeSurface shades it, in every instruction set, with two-sided and one-sided emitters, where
// point lights reach every hit and where, without them, picks above the lights find none.
TEST(SimdShading, HitsUnderALightTreeAreShadeSurfaceToTheBit) {
    std::mt19937 rng(77);
    for (bool points : {true, false}) {
        test::TempDir dir;
        const Scene scene = manyLightsScene(dir, rng, points);
        const SceneLights sceneLights(scene);
        ASSERT_GT(sceneLights.treeEmitters(), 60u);
        const Fixture f = makeFixture(rng, 0);
        SceneView view = sceneLights.view();
        view.shaders = f.shaders.data();
        std::vector<ShadeInput> hits = randomHits(rng, f, 2003);
        std::uniform_real_distribution<float> unit(-1.0f, 3.0f);
        for (ShadeInput& h : hits) { // over and among the lights, hitting no emitter
            const float x = unit(rng), y = unit(rng), z = unit(rng); // in this order
            h.hit.p = vec3(x, y, z) - vec3(scene.origin);            // the scene is camera-relative
            h.hit.emitter = kNoEmitter;
        }
        RenderParams rp = params(kStrategyMis, kSamplerSobol, sceneLights.sampledEmitters());
        rp.treeEmitters = sceneLights.treeEmitters();
        // The comparison reached picks that find a light and picks that find none.
        size_t found = 0, none = 0;
        for (const ShadeInput& h : hits) {
            float pdf;
            const uint e = pickLight(view, rp, h.hit.p, 0.37f, pdf);
            (e == kNoEmitter ? none : found)++;
        }
        EXPECT_GT(found, 1000u);
        if (!points) {
            EXPECT_GT(none, 200u);
        }
        for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
            hwy::SetSupportedTargetsForTest(target);
            SCOPED_TRACE(simdTarget());
            for (uint sampling : {kSamplerIndependent, kSamplerSobol}) {
                rp.sampling = sampling;
                const FlagCounts c = compareWithShadeSurface(
                    view, rp, hits, points ? "light tree, points" : "light tree");
                EXPECT_GT(c.shadow, 200u);
            }
        }
        hwy::SetSupportedTargetsForTest(0);
    }
}

TEST(SimdShading, RunsInTheWidestInstructionSet) {
    EXPECT_STRNE(simdTarget(), "");
}

// The registry's every model names its wide twin in this engine, or none, in the registry's
// order; and the cpu backend's stats say which of the scene's models were shaded a run at a
// time and which one hit at a time (scenes/every-model.yaml holds every model: Lambert,
// Conductor, Dielectric and MetallicRoughness wide; its quad light's emissive Null, which only
// passes the path on, not; CoatedMetallicRoughness, TransmissiveMetallicRoughness,
// SheenMetallicRoughness and Principled have no twin yet, and are shaded one hit at a time), all of
// them scalar with SIMD off.
TEST(SimdShading, EveryModelNamesItsWideTwinAndTheStatsNameTheScalarOnes) {
    for (size_t i = 0; i < kSurfaceModelCount; ++i) {
        EXPECT_EQ(kWideTwins[i].model, kSurfaceModels[i].model) << kSurfaceModels[i].name;
        const bool listed = std::find(std::begin(kWideModels), std::end(kWideModels),
                                      kSurfaceModels[i].model) != std::end(kWideModels);
        EXPECT_EQ(kWideTwins[i].shade != nullptr, listed) << kSurfaceModels[i].name;
    }
    Scene scene = loadScene(test::sourceDir() + "/scenes/every-model.yaml");
    scene.image.width = scene.image.height = 16;
    RenderConfig cfg;
    cfg.backend = BackendKind::Cpu;
    cfg.spp = 4;
    using Names = std::vector<std::string>;
    const std::unique_ptr<RenderResult> wide = render(scene, cfg);
    const nlohmann::json& stats = wide->stats.extra;
    EXPECT_EQ(stats["wide_models"].get<Names>(),
              (Names{"Lambert", "Conductor", "Dielectric", "MetallicRoughness"}));
    EXPECT_EQ(stats["scalar_models"].get<Names>(),
              (Names{"Null", "CoatedMetallicRoughness", "TransmissiveMetallicRoughness",
                     "SheenMetallicRoughness", "Principled"}));
    cfg.pipeline.simdShading = false;
    const std::unique_ptr<RenderResult> scalarRun = render(scene, cfg);
    const nlohmann::json& scalar = scalarRun->stats.extra;
    EXPECT_EQ(scalar["wide_models"].get<Names>(), Names{});
    Names every;
    for (const SurfaceModelInfo& m : kSurfaceModels)
        every.push_back(m.name);
    EXPECT_EQ(scalar["scalar_models"].get<Names>(), every);
}

} // namespace
} // namespace spw
