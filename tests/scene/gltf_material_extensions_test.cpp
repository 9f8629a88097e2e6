// glTF's material extensions, rendered on every backend against closed forms in a white furnace
// (a uniform environment of radiance 1, glTF's default without lights):
//   * glass (KHR_materials_transmission with KHR_materials_ior): a fully transmissive dielectric
//     material is Spillway's Dielectric, which neither absorbs nor emits, so a glass sphere
//     renders 1 everywhere; its base colour tints each crossing, and KHR_materials_volume's
//     attenuation absorbs inside (Beer-Lambert);
//   * glass transmitting part of the light (0 < transmissionFactor < 1) mixes the glass with the
//     opaque material;
//   * KHR_materials_ior on an opaque material sets its dielectric reflection's F0;
//   * KHR_materials_clearcoat: a coat of weight c reflects 0.04 c at normal incidence over
//     the base, which gets the rest;
//   * KHR_materials_specular: the dielectric reflection's F0 is min(F0(ior) specularColorFactor,
//     1) specularFactor;
//   * KHR_materials_sheen: over a base that reflects nothing, the sheen's colour times its
//     lobe's albedo;
//   * SPILLWAY_materials_principled (the Blender add-on's): Blender's Principled BSDF, whose
//     diffuse alone reflects Burley's closed form;
// and what is not rendered is warned about, and malformed values are refused naming where.
#include "host/loaders/gltf_loader.h"
#include "host/loaders/scene_loader.h"
#include "scene/gltf_spheres.h"
#include "test_util.h"

#include "shared/metallic_roughness.h"
#include "shared/sheen_metallic_roughness.h"
#include "shared/types.h"

#include <gtest/gtest.h>

#include <cmath>

namespace spw::test {
namespace {

// The channels' mean over the 8 x 8 pixels at the centre of a 24 x 24 image (a view within 16
// degrees of the sphere's normal), and its standard error from the pixels' spread.
std::pair<double, double> centreMean(const std::vector<float>& img) {
    double sum = 0.0, sum2 = 0.0;
    const int n = 64;
    for (int y = 8; y < 16; ++y)
        for (int x = 8; x < 16; ++x) {
            double v = 0.0;
            for (int c = 0; c < 3; ++c)
                v += img[size_t(y * 24 + x) * 3 + size_t(c)] / 3.0;
            sum += v, sum2 += v * v;
        }
    const double mean = sum / n;
    return {mean, std::sqrt(std::max(0.0, sum2 / n - mean * mean) / (n - 1))};
}

// The mean of the 2 x 2 pixels at the centre of a 24 x 24 image, per channel.
vec3 centre(const std::vector<float>& img) {
    vec3 sum(0.0f);
    for (int y = 11; y <= 12; ++y)
        for (int x = 11; x <= 12; ++x)
            for (int c = 0; c < 3; ++c)
                sum[c] += img[size_t(y * 24 + x) * 3 + size_t(c)] / 4.0f;
    return sum;
}

// The scene of `file` rendered at 24 x 24, `spp` samples a pixel, on each backend in turn.
template <class Check> void onEveryBackend(Scene scene, const Check& check, int spp = 16) {
    scene.image.width = scene.image.height = 24;
    for (BackendKind backend : {BackendKind::Reference, BackendKind::Cpu, BackendKind::Vulkan}) {
        SCOPED_TRACE(backendName(backend));
        RenderConfig cfg;
        cfg.backend = backend;
        cfg.spp = spp;
        check(render(scene, cfg)->film->image());
    }
}

TEST(GltfGlass, AFullyTransmissiveDielectricIsGlass) {
    TempDir dir;
    const Scene s = loadScene(sphereFile(dir, glass(1.0, 1.33, 0.3)));
    ASSERT_EQ(s.shaders.size(), 1u);
    EXPECT_TRUE(s.warnings.empty()) << s.warnings.at(0);
    EXPECT_EQ(s.shaders[0].params.model, kModelDielectric);
    EXPECT_EQ(s.shaders[0].params.ior, 1.33f);
    EXPECT_EQ(s.shaders[0].params.alpha, 0.3f * 0.3f);
    EXPECT_EQ(s.shaders[0].texture, -1);
}

// Glass in a white furnace. Smooth, every path leaves through the environment with its
// throughput whole (nothing absorbed; the 1/eta^2 of entering undone on leaving), so each pixel is
// 1, up to Russian roulette's noise and the paths cut at max depth. Rough, the microfacet model
// scatters once (dielectric.h): light a microfacet sends below the macro surface is lost, 5 % of
// it at roughness 0.3 (Cycles' multiple-scattering glass keeps it), and no more than that.
TEST(GltfGlass, GlassInAWhiteFurnaceIsInvisible) {
    TempDir dir;
    for (double roughness : {0.0, 0.3}) {
        Scene scene = loadScene(sphereFile(dir, glass(1.0, 1.5, roughness)));
        scene.image.width = scene.image.height = 24;
        for (BackendKind backend :
             {BackendKind::Reference, BackendKind::Cpu, BackendKind::Vulkan}) {
            SCOPED_TRACE(backendName(backend) + std::string(" roughness ") +
                         std::to_string(roughness));
            RenderConfig cfg;
            cfg.backend = backend;
            cfg.spp = 16;
            const std::vector<float> img = render(scene, cfg)->film->image();
            const MeanError m = meanAndError(img);
            const double tolerance = std::max(4.0 * m.stderror, 0.01);
            if (roughness == 0.0) {
                EXPECT_NEAR(m.mean, 1.0, tolerance);
            } else {
                EXPECT_GT(m.mean, 0.93);
                EXPECT_LT(m.mean, 1.0 + tolerance);
            }
        }
    }
}

TEST(GltfGlass, WhatIsNotRenderedIsWarnedAndBadValuesRefused) {
    TempDir dir;
    auto warnings = [&](const json& mat) {
        const Scene s = loadScene(sphereFile(dir, mat));
        std::string all;
        for (const std::string& w : s.warnings)
            all += w + "\n";
        return std::make_pair(s.shaders.at(0).params.model, all);
    };
    const auto partial = warnings(glass(0.5, 1.5));
    EXPECT_EQ(partial.first, kModelTransmissiveMetallicRoughness);
    EXPECT_EQ(partial.second, "");
    json metal = glass(1.0, 1.5);
    metal["pbrMetallicRoughness"]["metallicFactor"] = 0.5;
    EXPECT_EQ(warnings(metal).first, kModelTransmissiveMetallicRoughness); // GltfTransmission.*
    EXPECT_EQ(warnings(metal).second, "");
    json tinted = glass(1.0, 1.5);
    tinted["pbrMetallicRoughness"]["baseColorFactor"] = {0.2, 0.8, 0.3, 1.0};
    const auto tint = warnings(tinted);
    EXPECT_EQ(tint.first, kModelDielectric);
    EXPECT_EQ(tint.second, "");
    json thin = glass(1.0, 1.5);
    thin["extensions"]["KHR_materials_volume"] = {{"attenuationColor", {0.5, 0.5, 0.5}},
                                                  {"attenuationDistance", 1.0}};
    EXPECT_NE(warnings(thin).second.find("thin-walled"), std::string::npos);
    const Scene partialVolume =
        loadScene(sphereFile(dir, volume(glass(0.5, 1.5), {0.5, 0.5, 0.5}, 2.0)));
    EXPECT_EQ(partialVolume.shaders.at(0).params.absorption, vec3(float(std::log(2.0) / 2.0)));
    json coatedGlass = glass(1.0, 1.5);
    coatedGlass["extensions"]["KHR_materials_clearcoat"]["clearcoatFactor"] = 1.0;
    EXPECT_NE(warnings(coatedGlass).second.find("clear coat on glass"), std::string::npos);
    json iorOnly = material(vec3(1.0f), 0.0f, 0.5f);
    iorOnly["extensions"]["KHR_materials_ior"]["ior"] = 1.7;
    EXPECT_EQ(warnings(iorOnly).second, ""); // an opaque material's F0 (GltfIor.*)
    json sheenGlass = glass(1.0, 1.5);
    sheenGlass["extensions"]["KHR_materials_sheen"]["sheenColorFactor"] = {1.0, 1.0, 1.0};
    EXPECT_NE(warnings(sheenGlass).second.find("a sheen on glass"), std::string::npos);
    json specularGlass = glass(1.0, 1.5);
    specularGlass["extensions"]["KHR_materials_specular"]["specularFactor"] = 0.5;
    EXPECT_NE(warnings(specularGlass).second.find("KHR_materials_specular on glass"),
              std::string::npos);
    const struct {
        json mat;
        std::string message;
    } bad[] = {
        {glass(1.5, 1.5), "/materials/0/extensions/KHR_materials_transmission/transmissionFactor: "
                          "must be a number in [0, 1]"},
        {glass(1.0, 0.5), "/materials/0/extensions/KHR_materials_ior/ior: must be 0 or at least 1"},
        {glass(1.0, 20.0), "/materials/0/extensions/KHR_materials_ior/ior: must be a number in "
                           "[0, 10]"},
        {glass(1.0, -1.0), "KHR_materials_ior/ior: must be a number"},
        {volume(glass(1.0, 1.5), {0.5, 0.5, 0.5}, 0.0),
         "KHR_materials_volume/attenuationDistance: must be a positive number"},
        {volume(glass(1.0, 1.5), {0.5, 1.5, 0.5}, 1.0),
         "KHR_materials_volume/attenuationColor/1: must be a number in [0, 1]"},
        {volume(glass(1.0, 1.5), {0.5, 0.5}, 1.0),
         "KHR_materials_volume/attenuationColor: needs 3 numbers in [0, 1]"},
        {coated(2.0, 0.0), "KHR_materials_clearcoat/clearcoatFactor: must be a number in [0, 1]"},
        {coated(1.0, -0.5),
         "KHR_materials_clearcoat/clearcoatRoughnessFactor: must be a number in [0, 1]"},
        {sheen({1.0, 2.0, 1.0}, 0.5),
         "KHR_materials_sheen/sheenColorFactor/1: must be a number in [0, 1]"},
        {sheen({1.0, 1.0, 1.0}, -0.5),
         "KHR_materials_sheen/sheenRoughnessFactor: must be a number in [0, 1]"},
        {specular(1.5, {1.0, 1.0, 1.0}),
         "KHR_materials_specular/specularFactor: must be a number in [0, 1]"},
        {specular(1.0, {1.0, -1.0, 1.0}),
         "KHR_materials_specular/specularColorFactor/1: must be a finite number of at least 0"},
        {specular(1.0, {1.0, 1.0}),
         "KHR_materials_specular/specularColorFactor: needs 3 numbers of at least 0"},
    };
    for (const auto& c : bad) {
        try {
            loadScene(sphereFile(dir, c.mat));
            ADD_FAILURE() << c.message;
        } catch (const SceneError& e) {
            EXPECT_NE(std::string(e.what()).find(c.message), std::string::npos) << e.what();
        }
    }
}

// KHR_materials_ior without transmission sets the dielectric reflection's F0 = ((ior - 1) /
// (ior + 1))^2: a black, smooth, non-metal sphere in a white furnace reflects F(cos) of the
// environment's 1, which at the centre of the view (cos within 0.1 % of 1) is F0: 0.04 without
// the extension (glTF's, to the bit: gltfDielectricF0), 1/9 at ior 2, 0 at ior 1; on every
// backend.
TEST(GltfIor, AnOpaqueMaterialsIorSetsItsReflectanceAtNormalIncidence) {
    TempDir dir;
    EXPECT_EQ(gltfDielectricF0(1.5f), kGltfDielectricF0);
    EXPECT_EQ(gltfDielectricF0(0.0f), kGltfDielectricF0);
    for (double ior : {-1.0, 2.0, 1.0}) {
        json black = material(vec3(0.0f), 0.0f, 0.0f);
        if (ior > 0.0) black["extensions"]["KHR_materials_ior"]["ior"] = ior;
        Scene scene = loadScene(sphereFile(dir, black));
        EXPECT_EQ(scene.shaders.at(0).params.model, kModelMetallicRoughness);
        scene.image.width = scene.image.height = 24;
        const double f0 = ior > 0.0 ? std::pow((ior - 1.0) / (ior + 1.0), 2.0) : 0.04;
        for (BackendKind backend :
             {BackendKind::Reference, BackendKind::Cpu, BackendKind::Vulkan}) {
            SCOPED_TRACE(backendName(backend) + std::string(" ior ") + std::to_string(ior));
            RenderConfig cfg;
            cfg.backend = backend;
            cfg.spp = 16;
            const std::vector<float> img = render(scene, cfg)->film->image();
            double centre = 0.0;
            for (int y = 11; y <= 12; ++y)
                for (int x = 11; x <= 12; ++x)
                    for (int c = 0; c < 3; ++c)
                        centre += img[size_t(y * 24 + x) * 3 + size_t(c)] / 12.0;
            EXPECT_NEAR(centre, f0, 0.03 * f0 + 1e-4);
        }
    }
}

// A glass sphere of ior 1.01 (about as much Fresnel reflection as none: 2.5e-5) in a white
// furnace, seen through its centre: the ray crosses the surface twice, tinted by the base colour
// t each time, and travels the diameter (2, within 0.4 % over the centre pixels) inside, where
// KHR_materials_volume's attenuationColor c is what is left after attenuationDistance 2: each
// channel reads t^2 c. On every backend; without the volume the same sphere reads t^2.
TEST(GltfGlass, TheBaseColourTintsEachCrossingAndTheVolumeAbsorbs) {
    TempDir dir;
    const vec3 tint(1.0f, 0.8f, 1.0f), left(0.25f, 0.5f, 1.0f);
    for (bool absorbs : {true, false}) {
        json m = glass(1.0, 1.01);
        m["pbrMetallicRoughness"]["baseColorFactor"] = {tint.x, tint.y, tint.z, 1.0};
        if (absorbs) m = volume(m, {left.x, left.y, left.z}, 2.0);
        const Scene scene = loadScene(sphereFile(dir, m));
        EXPECT_EQ(scene.shaders.at(0).params.model, kModelDielectric);
        const vec3 expected = tint * tint * (absorbs ? left : vec3(1.0f));
        onEveryBackend(scene, [&](const std::vector<float>& img) {
            const vec3 c = centre(img);
            for (int k = 0; k < 3; ++k)
                EXPECT_NEAR(c[k], expected[k], 0.02 * expected[k])
                    << "channel " << k << (absorbs ? ", absorbing" : ", clear");
        });
    }
}

// KHR_materials_clearcoat over a black smooth dielectric, in a white furnace: at the centre of
// the view (cos within 0.1 % of 1) the coat of weight c reflects 0.04 c and the base its F0, 0.04,
// of the rest: 0.04 c + (1 - 0.04 c) 0.04 (0.0784 at c = 1); a rough coat spreads its reflection
// but keeps its sum. On every backend.
TEST(GltfClearcoat, ACoatReflectsItsWeightTimesItsF0OverTheBase) {
    TempDir dir;
    for (double coat : {1.0, 0.5})
        for (double roughness : {0.0, 0.3}) {
            const Scene scene = loadScene(sphereFile(dir, coated(coat, roughness)));
            ASSERT_EQ(scene.shaders.at(0).params.model, kModelCoatedMetallicRoughness);
            EXPECT_EQ(scene.shaders[0].params.coat, float(coat));
            EXPECT_TRUE(scene.warnings.empty()) << scene.warnings.at(0);
            const double fc = 0.04 * coat, expected = fc + (1.0 - fc) * 0.04;
            onEveryBackend(scene, [&](const std::vector<float>& img) {
                const vec3 c = centre(img);
                const double mean = (double(c.x) + c.y + c.z) / 3.0;
                EXPECT_NEAR(mean, expected, (roughness > 0.0 ? 0.06 : 0.03) * expected)
                    << "coat " << coat << ", roughness " << roughness;
            });
        }
}

// KHR_materials_specular on a black smooth dielectric, in a white furnace: at the centre of the
// view the sphere reflects its F0, min(0.04 c, 1) w per channel for specularColorFactor c and
// specularFactor w: 0.5 (0.08, 0.04, 0.01) for c = (2, 1, 0.25), w = 0.5; nothing at w = 0 (a
// purely diffuse, black material); and 1 where 0.04 c passes 1 (F0 1 is a mirror of the
// environment, whatever the angle: the whole image is 1). The defaults (w 1, c 1) leave glTF's
// own material, without kShaderSpecular. On every backend.
TEST(GltfSpecular, TheWeightAndColourSetTheReflectionAtNormalIncidence) {
    TempDir dir;
    const Scene plain = loadScene(sphereFile(dir, specular(1.0, {1.0, 1.0, 1.0})));
    EXPECT_EQ(plain.shaders.at(0).params.flags & kShaderSpecular, 0u);
    const struct {
        double weight;
        std::vector<double> colour;
        vec3 expected;
    } cases[] = {{0.5, {2.0, 1.0, 0.25}, vec3(0.04f, 0.02f, 0.005f)},
                 {0.0, {1.0, 1.0, 1.0}, vec3(0.0f)},
                 {1.0, {40.0, 40.0, 40.0}, vec3(1.0f)}};
    for (const auto& c : cases) {
        const Scene scene = loadScene(sphereFile(dir, specular(c.weight, c.colour)));
        const ShaderParams& sh = scene.shaders.at(0).params;
        ASSERT_EQ(sh.model, kModelMetallicRoughness);
        EXPECT_NE(sh.flags & kShaderSpecular, 0u);
        EXPECT_EQ(sh.specular, float(c.weight));
        EXPECT_TRUE(scene.warnings.empty()) << scene.warnings.at(0);
        onEveryBackend(scene, [&](const std::vector<float>& img) {
            const vec3 v = centre(img);
            for (int k = 0; k < 3; ++k)
                EXPECT_NEAR(v[k], c.expected[k], 0.03 * c.expected[k] + 1e-4)
                    << "channel " << k << ", weight " << c.weight;
        });
    }
}

// Glass transmitting a share t of the light (ior 1.01: about no Fresnel reflection, 2.5e-5) over
// an opaque base of colour c and metallic m (the glass's weight w = t (1 - m), the
// specification's transmission of the dielectric part alone), a sphere in a white furnace, seen
// within 16 degrees of its normal:
//   * at max depth 1, a path sees the environment only through the opaque part's reflection
//     (what the glass refracts reaches the sphere's far side and ends there): (1 - w) c at
//     metallic 0, and the MetallicRoughness model's reflectance at m / (1 - w) otherwise;
//   * at full depth, with a white base, nothing is absorbed anywhere: 1.
// Each within 4 standard errors (from the pixels' spread; a sample picks a lobe with probability
// t, so 16 spp leave several per cent of noise) and 0.5 % (the Fresnel terms). On every backend.
TEST(GltfTransmission, PartialTransmissionMixesTheGlassWithTheOpaqueMaterial) {
    TempDir dir;
    for (const std::pair<double, double>& tm :
         {std::pair(0.25, 0.0), std::pair(0.75, 0.0), std::pair(1.0, 0.5), std::pair(0.5, 0.5)}) {
        const double t = tm.first, metallic = tm.second; // named, for the lambda to capture
        for (float c : {0.5f, 1.0f}) {
            json m = glass(t, 1.01);
            m["pbrMetallicRoughness"]["baseColorFactor"] = {c, c, c, 1.0};
            m["pbrMetallicRoughness"]["metallicFactor"] = metallic;
            Scene scene = loadScene(sphereFile(dir, m));
            ASSERT_EQ(scene.shaders.at(0).params.model, kModelTransmissiveMetallicRoughness);
            EXPECT_EQ(scene.shaders[0].params.transmission, float(t));
            EXPECT_TRUE(scene.warnings.empty()) << scene.warnings.at(0);
            // The glass's weight is the dielectric part's transmission, t (1 - metallic); the
            // rest is MetallicRoughness at metallic m' = m / (1 - w), which reflects
            // F0 + (1 - F0) (1 - m') c near the centre, F0 = m' c (glTF's appendix B: short of c
            // where 0 < m' < 1, so the furnace's 1 holds only at m' = 0 or 1).
            const double w = t * (1.0 - metallic), mPrime = metallic / (1.0 - w);
            const bool direct = c < 1.0f || (mPrime > 0.0 && mPrime < 1.0);
            if (direct) scene.settings.maxDepth = 1;
            const double f0 = mPrime * c;
            const double expected =
                direct ? (1.0 - w) * (f0 + (1.0 - f0) * (1.0 - mPrime) * c) : 1.0;
            onEveryBackend(
                scene,
                [&](const std::vector<float>& img) {
                    const auto [mean, se] = centreMean(img);
                    EXPECT_NEAR(mean, expected, 4.0 * se + 0.005 * expected)
                        << "transmission " << t << ", metallic " << metallic << ", colour " << c
                        << ", standard error " << se;
                },
                256);
        }
    }
}

// KHR_materials_sheen over a base that reflects nothing (a black dielectric, its reflection off),
// in a white furnace: at the centre of the view (cos within 0.1 % of 1) the sphere reflects the
// sheen's colour times its lobe's albedo E(1, roughness) (sheen_albedo.h, which
// SheenMetallicRoughness.TheAlbedoTable… checks by quadrature), per channel. On every backend.
TEST(GltfSheen, ASheenReflectsItsColourTimesItsAlbedo) {
    TempDir dir;
    const vec3 colour(1.0f, 0.5f, 0.25f);
    for (double roughness : {0.5, 1.0}) {
        const Scene scene =
            loadScene(sphereFile(dir, sheen({colour.x, colour.y, colour.z}, roughness)));
        const ShaderParams& sh = scene.shaders.at(0).params;
        ASSERT_EQ(sh.model, kModelSheenMetallicRoughness);
        EXPECT_EQ(sh.sheenColour, colour);
        EXPECT_TRUE(scene.warnings.empty()) << scene.warnings.at(0);
        const vec3 expected = colour * sheenAlbedo(1.0f, float(roughness));
        onEveryBackend(
            scene,
            [&](const std::vector<float>& img) {
                const vec3 v = centre(img);
                for (int k = 0; k < 3; ++k)
                    EXPECT_NEAR(v[k], expected[k], 0.03 * expected[k])
                        << "channel " << k << ", roughness " << roughness;
            },
            256);
    }
}

// A material of colour c, roughness r and SPILLWAY_materials_principled's `factors`.
json principledMaterial(float c, float r, const json& factors) {
    json m = material(vec3(c), 0.0f, r);
    m["extensions"][kPrincipledExtension] = factors;
    return m;
}

// SPILLWAY_materials_principled makes the material a Principled shader of its factors, Blender's
// defaults where absent; in a white furnace, seen head on (cos within 0.1 % of 1), its diffuse
// alone (specular 0) reflects Burley's c (1 - 1/42 + 5 r / 84) (Principled.* derives it), on
// every backend.
TEST(GltfPrincipled, TheExtensionIsBlendersPrincipledBsdf) {
    TempDir dir;
    const Scene defaults =
        loadScene(sphereFile(dir, principledMaterial(0.5f, 0.5f, json::object())));
    const ShaderParams& d = defaults.shaders.at(0).params;
    ASSERT_EQ(d.model, kModelPrincipled);
    EXPECT_EQ(d.specular, 0.5f);
    EXPECT_EQ(d.sheenTint, 0.5f);
    EXPECT_EQ(d.coat, 0.0f);
    EXPECT_EQ(d.coatAlpha, gltfAlpha(0.03f));
    EXPECT_TRUE(defaults.warnings.empty()) << defaults.warnings.at(0);
    const float r = 0.6f;
    const Scene diffuse =
        loadScene(sphereFile(dir, principledMaterial(0.5f, r, {{"specular", 0.0}})));
    const double burley = 0.5 * (1.0 - 1.0 / 42.0 + 5.0 * r / 84.0);
    onEveryBackend(
        diffuse,
        [&](const std::vector<float>& img) {
            const vec3 v = centre(img);
            for (int k = 0; k < 3; ++k)
                EXPECT_NEAR(v[k], burley, 0.03 * burley) << "channel " << k;
        },
        256);
    const Scene sheened =
        loadScene(sphereFile(dir, principledMaterial(0.2f, 0.5f,
                                                     {{"specular", 1.0},
                                                      {"specularTint", 0.25},
                                                      {"sheen", 1.0},
                                                      {"sheenTint", 0.0},
                                                      {"clearcoat", 0.5},
                                                      {"clearcoatRoughness", 0.2}})));
    const ShaderParams& p = sheened.shaders.at(0).params;
    EXPECT_EQ(p.specular, 1.0f);
    EXPECT_EQ(p.specularTint, 0.25f);
    EXPECT_EQ(p.sheen, 1.0f);
    EXPECT_EQ(p.sheenTint, 0.0f);
    EXPECT_EQ(p.coat, 0.5f);
    EXPECT_EQ(p.coatAlpha, gltfAlpha(0.2f));
}

// On glass the extension is warned about and the glass kept; a factor out of [0, 1] is refused
// with its pointer.
TEST(GltfPrincipled, OnGlassItIsWarnedAboutAndBadFactorsRefused) {
    TempDir dir;
    json onGlass = glass(1.0, 1.5);
    onGlass["extensions"][kPrincipledExtension] = {{"sheen", 0.5}};
    const Scene glassScene = loadScene(sphereFile(dir, onGlass));
    EXPECT_EQ(glassScene.shaders.at(0).params.model, kModelDielectric);
    ASSERT_EQ(glassScene.warnings.size(), 1u);
    EXPECT_NE(glassScene.warnings[0].find("on glass is not rendered"), std::string::npos);
    for (const char* key :
         {"specular", "specularTint", "sheen", "sheenTint", "clearcoat", "clearcoatRoughness"}) {
        try {
            loadScene(sphereFile(dir, principledMaterial(0.5f, 0.5f, {{key, 1.5}})));
            ADD_FAILURE() << key;
        } catch (const SceneError& e) {
            EXPECT_NE(std::string(e.what()).find(std::string("/materials/0/extensions/") +
                                                 kPrincipledExtension + "/" + key +
                                                 ": must be a number in [0, 1]"),
                      std::string::npos)
                << e.what();
        }
    }
}

} // namespace
} // namespace spw::test
