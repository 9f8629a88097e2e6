// A surface model is one registry line (shaders/shared/surface_models.h), its shared header, its
// kernel and its test: docs/adding-a-surface-model.md. Everything else is derived from the
// registry, and this test checks both halves: it fails for a registered model that lacks its
// header, its kernel or its TEST(<Name>, ...), and for a loader that does not take exactly the
// scene keys the registry line names. (That the kernels are embedded and the kModel* constants
// follow the registry's order is checked in tests/vk,
// SurfaceModels.EveryRegisteredModelHasItsKernel.)
#include "host/loaders/scene_loader.h"
#include "host/scene/scene.h"
#include "host/scene/surface_models.h"
#include "test_util.h"

#include "shared/metallic_roughness.h"

#include <gtest/gtest.h>

#include <cctype>
#include <filesystem>
#include <string>

namespace spw::test {
namespace {

std::string shaderScene(const std::string& shader) {
    return "image: {width: 4, height: 4}\n"
           "camera: {type: PinHole, look at: {eye: [278, 273, -800], target: [278, 273, 0]}, "
           "fov: 39.3}\n"
           "shaders:\n  - {" +
           shader + "}\nobjects:\n  - {filename: " + sourceDir() +
           "/scenes/cornell-box/white.obj, shader: 0}\n";
}

// A model's name in snake_case: SheenMetallicRoughness is sheen_metallic_roughness.
std::string snakeCase(const std::string& name) {
    std::string s;
    for (char c : name) {
        if (std::isupper(static_cast<unsigned char>(c))) {
            if (!s.empty()) s += '_';
            c = char(std::tolower(static_cast<unsigned char>(c)));
        }
        s += c;
    }
    return s;
}

// Each model's files are named after it: a reader looking for SheenMetallicRoughness finds
// shaders/shared/sheen_metallic_roughness.h.
TEST(SurfaceModels, EveryModelsFilesAreNamedAfterIt) {
    EXPECT_EQ(snakeCase("SheenMetallicRoughness"), "sheen_metallic_roughness");
    for (const SurfaceModelInfo& m : kSurfaceModels)
        EXPECT_EQ(std::string(m.kernel), snakeCase(m.name)) << m.name;
}

TEST(SurfaceModels, EveryRegisteredModelHasItsHeaderItsKernelAndItsTest) {
    for (const SurfaceModelInfo& m : kSurfaceModels) {
        const std::string stem = m.kernel, name = m.name;
        EXPECT_TRUE(std::filesystem::exists(sourceDir() + "/shaders/" + stem + ".comp"))
            << name << ": no shaders/" << stem << ".comp";
        EXPECT_TRUE(std::filesystem::exists(sourceDir() + "/shaders/shared/" + stem + ".h"))
            << name << ": no shaders/shared/" << stem << ".h";
        const std::string test = readFile(sourceDir() + "/tests/bsdf/" + stem + "_test.cpp");
        EXPECT_NE(test.find("TEST(" + name + ","), std::string::npos)
            << name << ": no TEST(" << name << ", ...) in tests/bsdf/" << stem << "_test.cpp";
    }
}

// scenes/every-model.yaml holds a shader of every registered model (its quad light's emissive
// Null among them), so that scripts/check-identical.sh and the backend tests that render it
// cover each one.
TEST(SurfaceModels, EveryModelYamlHoldsEveryRegisteredModel) {
    const Scene scene = loadScene(sourceDir() + "/scenes/every-model.yaml");
    for (const SurfaceModelInfo& m : kSurfaceModels) {
        bool used = false;
        for (const Shader& shader : scene.shaders)
            used = used || shader.params.model == m.model;
        EXPECT_TRUE(used) << "scenes/every-model.yaml has no shader of " << m.name
                          << ": add one (and an object that takes it)";
    }
}

// The loader takes `type: <Name>`, gives the registry's constant, and takes each optional key
// exactly when the registry line names it.
TEST(SurfaceModels, TheLoaderTakesEachModelWithExactlyItsRegisteredKeys) {
    const std::pair<uint, std::string> keys[] = {
        {kTakesReflectance, "reflectance: 0.5"},
        {kTakesColour, "colour: [0.5, 0.5, 0.5]"},
        {kTakesTexture, "texture: {type: Constant, colour: [0.5, 0.5, 0.5]}"},
        {kTakesAlpha, "alpha: 0.5"},
        {kTakesIor, "ior: 1.33"},
        {kTakesMetallic, "metallic: 0.5"},
        {kTakesRoughness, "roughness: 0.5"},
        {kTakesAbsorption, "absorption: [0.1, 0.2, 0.3]"},
        {kTakesCoat, "coat: 0.5"},
        {kTakesCoat, "coat roughness: 0.5"},
        {kTakesSpecular | kTakesPrincipled, "specular: 0.5"},
        {kTakesSpecular, "specular colour: [2, 1, 0.5]"},
        {kTakesTransmission, "transmission: 0.5"},
        {kTakesSheen, "sheen colour: [1, 0.5, 0.2]"},
        {kTakesSheen, "sheen roughness: 0.3"},
        {kTakesPrincipled, "specular tint: 0.5"},
        {kTakesPrincipled, "sheen: 0.5"},
        {kTakesPrincipled, "sheen tint: 0.25"}};
    TempDir dir;
    for (const SurfaceModelInfo& m : kSurfaceModels) {
        const std::string type = std::string("type: ") + m.name;
        const Scene scene = loadScene(dir.write("plain.yaml", shaderScene(type)));
        ASSERT_EQ(scene.shaders.size(), 1u) << m.name;
        EXPECT_EQ(scene.shaders[0].params.model, m.model) << m.name;
        for (const auto& [bit, key] : keys) {
            const std::string path = dir.write("keyed.yaml", shaderScene(type + ", " + key));
            if (m.params & bit) {
                EXPECT_NO_THROW(loadScene(path)) << m.name << " should take " << key;
            } else {
                EXPECT_THROW(loadScene(path), SceneError) << m.name << " should refuse " << key;
            }
        }
    }
}

// The scene format: roughness is glTF's perceptual roughness (alpha = roughness^2, floored at
// 0.045^2), and both factors default to glTF's 1.
TEST(SurfaceModels, MetallicRoughnessTakesGltfFactorsAndDefaults) {
    TempDir dir;
    const auto load = [&](const std::string& keys) {
        return loadScene(dir.write("s.yaml", shaderScene("type: MetallicRoughness" + keys)))
            .shaders.at(0)
            .params;
    };
    const ShaderParams plain = load("");
    EXPECT_EQ(plain.metallic, 1.0f);
    EXPECT_EQ(plain.alpha, 1.0f);
    const ShaderParams set = load(", metallic: 0.25, roughness: 0.5");
    EXPECT_EQ(set.metallic, 0.25f);
    EXPECT_EQ(set.alpha, 0.25f);
    EXPECT_EQ(load(", roughness: 0").alpha, kGltfMinAlpha);
    EXPECT_THROW(load(", roughness: 1.5"), SceneError);
    EXPECT_THROW(load(", alpha: 0.5"), SceneError);
    // KHR_materials_specular's weight and F0 colour: set only where a key is given.
    EXPECT_EQ(plain.flags & kShaderSpecular, 0u);
    const ShaderParams specular = load(", specular: 0.5, specular colour: [2, 1, 0.5]");
    EXPECT_NE(specular.flags & kShaderSpecular, 0u);
    EXPECT_EQ(specular.specular, 0.5f);
    EXPECT_EQ(specular.specularColour, vec3(2.0f, 1.0f, 0.5f));
    const ShaderParams colourOnly = load(", specular colour: [0.5, 0.5, 0.5]");
    EXPECT_EQ(colourOnly.specular, 1.0f);
    EXPECT_EQ(load(", specular: 0").specularColour, vec3(1.0f));
}

// The Principled model takes Blender's Principled BSDF's defaults for every key it shares with
// the glTF models (base colour 0.8, metallic 0, roughness 0.5, clear coat 0 of roughness 0.03)
// and its own (specular 0.5, specular tint 0, sheen 0, sheen tint 0.5).
TEST(SurfaceModels, PrincipledTakesBlendersDefaults) {
    TempDir dir;
    const auto load = [&](const std::string& keys) {
        return loadScene(dir.write("s.yaml", shaderScene("type: Principled" + keys)))
            .shaders.at(0)
            .params;
    };
    const ShaderParams plain = load("");
    EXPECT_EQ(plain.colour, vec3(0.8f));
    EXPECT_EQ(plain.metallic, 0.0f);
    EXPECT_EQ(plain.alpha, 0.25f);
    EXPECT_EQ(plain.specular, 0.5f);
    EXPECT_EQ(plain.specularTint, 0.0f);
    EXPECT_EQ(plain.sheen, 0.0f);
    EXPECT_EQ(plain.sheenTint, 0.5f);
    EXPECT_EQ(plain.coat, 0.0f);
    EXPECT_EQ(plain.coatAlpha, gltfAlpha(0.03f));
    EXPECT_EQ(plain.flags & kShaderSpecular, 0u);
    const ShaderParams set = load(", specular: 1, specular tint: 0.25, sheen: 0.75, sheen tint: 1, "
                                  "coat: 1, coat roughness: 0.5");
    EXPECT_EQ(set.specular, 1.0f);
    EXPECT_EQ(set.specularTint, 0.25f);
    EXPECT_EQ(set.sheen, 0.75f);
    EXPECT_EQ(set.sheenTint, 1.0f);
    EXPECT_EQ(set.coat, 1.0f);
    EXPECT_EQ(set.coatAlpha, 0.25f);
    EXPECT_THROW(load(", sheen: 1.5"), SceneError);
    EXPECT_THROW(load(", specular colour: [1, 1, 1]"), SceneError);
}

// The transmissive model's roughness is its glass's: alpha = roughness^2 unfloored (smooth glass
// at 0; the opaque part floors it itself); transmission defaults to 1, metallic to 0.
TEST(SurfaceModels, TransmissiveMetallicRoughnessTakesItsGlassAlphaAndTransmission) {
    TempDir dir;
    const auto load = [&](const std::string& keys) {
        return loadScene(
                   dir.write("s.yaml", shaderScene("type: TransmissiveMetallicRoughness" + keys)))
            .shaders.at(0)
            .params;
    };
    EXPECT_EQ(load("").transmission, 1.0f);
    EXPECT_EQ(load("").alpha, 1.0f);
    const ShaderParams set = load(", roughness: 0, transmission: 0.25, ior: 1.33");
    EXPECT_EQ(set.alpha, 0.0f);
    EXPECT_EQ(set.transmission, 0.25f);
    EXPECT_EQ(set.ior, 1.33f);
    EXPECT_THROW(load(", transmission: 1.5"), SceneError);
    EXPECT_EQ(load("").metallic, 0.0f); // glass, not a metal, unless told
    EXPECT_EQ(load(", metallic: 0.5").metallic, 0.5f);
}

} // namespace
} // namespace spw::test
