// The images of glTF's material extensions (KHR_materials_clearcoat's, _sheen's, _specular's and
// _transmission's textures): each scales its factor by the channel the specification names, at
// every hit, on every backend. A sphere with a uniform image renders bit for bit what the same
// material without images renders with the factors the image's channels give; the images' other
// channels hold the opposite value, so a channel read wrongly changes the picture. The coat's
// normal map tilts the coat alone, the base's the base alone. What is not rendered is warned
// about and a malformed texture reference is refused naming where.
#include "host/loaders/scene_loader.h"
#include "host/scene_view/hit_setup.h"
#include "scene/gltf_spheres.h"
#include "test_util.h"

#include "shared/bsdf.h"
#include "shared/metallic_roughness.h"
#include "shared/types.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>

namespace spw::test {
namespace {

// A uniform 8 x 8 8-bit RGBA image of `rgba` (each 0 or 1, exact in 8 bits and in sRGB).
void writeUniform(const std::string& path, vec4 rgba) {
    OIIO::ImageBuf img(OIIO::ImageSpec(8, 8, 4, OIIO::TypeDesc::UINT8));
    const float v[4] = {rgba.x, rgba.y, rgba.z, rgba.w};
    OIIO::ImageBufAlgo::fill(img, v);
    ASSERT_TRUE(img.write(path));
}

// The render of `scene` at 24 x 24, 4 samples a pixel, on `backend`.
std::vector<float> renderOn(Scene scene, BackendKind backend) {
    scene.image.width = scene.image.height = 24;
    RenderConfig cfg;
    cfg.backend = backend;
    cfg.spp = 4;
    return render(scene, cfg)->film->image();
}

// One extension's images: the material with its images (textures 0 and 1, both the image under
// test), the same material without them, and what the image's channels make of its parameters.
struct Case {
    const char* name;
    std::function<json(bool images)> material;
    std::function<void(ShaderParams&, vec4 rgba)> expect;
};

json withImages(json m, const char* extension, std::vector<const char*> keys, bool images) {
    for (int k = 0; images && k < int(keys.size()); ++k)
        m["extensions"][extension][keys[size_t(k)]] = {{"index", k}};
    return m;
}

const Case kCases[] = {
    {"clearcoat",
     [](bool images) {
         return withImages(coated(0.5, 0.5), "KHR_materials_clearcoat",
                           {"clearcoatTexture", "clearcoatRoughnessTexture"}, images);
     },
     [](ShaderParams& sh, vec4 c) { // the weight times red, the roughness times green
         sh.coat = 0.5f * c.x;
         sh.coatAlpha = gltfAlpha(0.5f * c.y);
     }},
    {"sheen",
     [](bool images) {
         return withImages(sheen({0.5, 0.25, 0.75}, 0.5), "KHR_materials_sheen",
                           {"sheenColorTexture", "sheenRoughnessTexture"}, images);
     },
     [](ShaderParams& sh, vec4 c) { // the colour times RGB, the roughness times alpha
         sh.sheenColour = vec3(0.5f, 0.25f, 0.75f) * vec3(c);
         sh.sheenRoughness = 0.5f * c.w;
     }},
    {"specular",
     [](bool images) {
         return withImages(specular(0.5, {0.5, 0.25, 0.75}), "KHR_materials_specular",
                           {"specularColorTexture", "specularTexture"}, images);
     },
     [](ShaderParams& sh, vec4 c) { // the colour times RGB, the weight times alpha
         sh.specularColour = vec3(0.5f, 0.25f, 0.75f) * vec3(c);
         sh.specular = 0.5f * c.w;
     }},
    {"transmission",
     [](bool images) {
         return withImages(glass(0.5, 1.5, 0.5), "KHR_materials_transmission",
                           {"transmissionTexture"}, images);
     },
     [](ShaderParams& sh, vec4 c) { sh.transmission = 0.5f * c.x; }},
};

TEST(GltfExtensionImages, EachImageScalesItsFactorByItsChannelOnEveryBackend) {
    TempDir dir;
    for (vec4 rgba : {vec4(1.0f, 0.0f, 1.0f, 1.0f), vec4(0.0f, 1.0f, 0.0f, 0.0f)}) {
        writeUniform(dir.file("image.png"), rgba);
        for (const Case& c : kCases) {
            SCOPED_TRACE(std::string(c.name) + (rgba.x > 0.0f ? " 1010" : " 0101"));
            const Scene textured =
                loadScene(sphereFile(dir, c.material(true), {"image.png", "image.png"}));
            ASSERT_TRUE(textured.warnings.empty()) << textured.warnings.at(0);
            const ShaderParams& t = textured.shaders.at(0).params;
            EXPECT_NE(t.flags & kShaderHitExtension, 0u);
            Scene plain = loadScene(sphereFile(dir, c.material(false), {"image.png"}));
            ASSERT_EQ(plain.shaders.at(0).params.model, t.model);
            c.expect(plain.shaders.at(0).params, rgba);
            for (BackendKind backend :
                 {BackendKind::Reference, BackendKind::Cpu, BackendKind::Vulkan}) {
                SCOPED_TRACE(backendName(backend));
                EXPECT_EQ(renderOn(textured, backend), renderOn(plain, backend));
            }
        }
    }
}

// An image that varies across the surface varies the parameter across it. The sphere's
// texture coordinates run u = 0.5 .. 1 across the camera's view, left to right, so an image
// coated (red 1) left of u = 0.75 and uncoated right of it coats the left half of the view: there
// the pixels equal those of a sphere coated all over, bit for bit, and on the right those of one
// without a coat (the columns kept clear of the boundary by more than the bilinear filter's
// reach).
TEST(GltfExtensionImages, AnImageVariesItsParameterAcrossTheSurface) {
    TempDir dir;
    OIIO::ImageBuf img(OIIO::ImageSpec(16, 4, 4, OIIO::TypeDesc::UINT8));
    const float on[4] = {1.0f, 0.0f, 0.0f, 1.0f}, off[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    OIIO::ImageBufAlgo::fill(img, on, OIIO::ROI(0, 12, 0, 4, 0, 1, 0, 4));
    OIIO::ImageBufAlgo::fill(img, off, OIIO::ROI(12, 16, 0, 4, 0, 1, 0, 4));
    ASSERT_TRUE(img.write(dir.file("halves.png")));
    json m = coated(1.0, 0.0);
    m["extensions"]["KHR_materials_clearcoat"]["clearcoatTexture"] = {{"index", 0}};
    const Scene halves = loadScene(sphereFile(dir, m, {"halves.png"}));
    Scene uncoated = halves;
    uncoated.shaders[0].params.flags &= ~kShaderHitExtension;
    uncoated.shaders[0].params.coat = 0.0f;
    Scene coatedAll = uncoated;
    coatedAll.shaders[0].params.coat = 1.0f;
    // Columns [x0, x1) of every row.
    auto columns = [](const std::vector<float>& img, int x0, int x1) {
        std::vector<float> out;
        for (int y = 0; y < 24; ++y)
            out.insert(out.end(), img.begin() + (y * 24 + x0) * 3, img.begin() + (y * 24 + x1) * 3);
        return out;
    };
    for (BackendKind backend : {BackendKind::Reference, BackendKind::Cpu, BackendKind::Vulkan}) {
        SCOPED_TRACE(backendName(backend));
        const std::vector<float> h = renderOn(halves, backend), u = renderOn(uncoated, backend),
                                 a = renderOn(coatedAll, backend);
        EXPECT_NE(columns(a, 5, 9), columns(u, 5, 9)); // the coat shows
        EXPECT_EQ(columns(h, 5, 9), columns(a, 5, 9));
        EXPECT_EQ(columns(h, 15, 19), columns(u, 15, 19));
    }
}

// KHR_materials_clearcoat's clearcoatNormalTexture tilts the interpolated normal for the coat
// alone; without it the coat takes the interpolated normal even where the base is normal-mapped,
// as the specification says. Hit setup carries the coat's normal (kShaderCoatNormal), checked
// here hit by hit; what the coat does with it is tests/bsdf/coated_metallic_roughness_test.cpp's.
// Every backend renders the map.
TEST(GltfExtensionImages, TheCoatsNormalMapTiltsTheCoatAloneAndTheBasesTheBase) {
    TempDir dir;
    writeUniform(dir.file("tilt.png"), vec4(1.0f, 0.0f, 1.0f, 1.0f)); // (1, -1, 1), tangent space
    const json untilted = coated(1.0, 0.2);
    json coatMap = untilted, baseMap = untilted;
    coatMap["extensions"]["KHR_materials_clearcoat"]["clearcoatNormalTexture"] = {{"index", 0},
                                                                                  {"scale", 0.5}};
    baseMap["normalTexture"] = {{"index", 0}, {"scale", 0.5}};
    const Scene plain = loadScene(sphereFile(dir, untilted, {"tilt.png"}));
    EXPECT_EQ(plain.shaders.at(0).params.flags & kShaderCoatNormal, 0u);
    for (bool coatTilted : {true, false}) {
        SCOPED_TRACE(coatTilted ? "the coat's map" : "the base's map");
        const Scene s = loadScene(sphereFile(dir, coatTilted ? coatMap : baseMap, {"tilt.png"}));
        ASSERT_TRUE(s.warnings.empty()) << s.warnings.at(0);
        ASSERT_NE(s.shaders.at(0).params.flags & kShaderCoatNormal, 0u);
        const SceneLights lights(s);
        const HitSetup setup(s, lights);
        const TextureResolver textures(s, 64.0);
        // Triangles clear of the poles (the first and last rings are degenerate).
        for (uint prim = 2 * 96; prim < 22 * 96; prim += 89) {
            SCOPED_TRACE(prim);
            const HitRecord h{0, prim, 0.3f, 0.3f, 1.0f};
            SurfaceHit hit, bare;
            setup.setUpHit(h, vec3(0.0f, 0.0f, -1.0f), 0u, textures, true, hit);
            setup.setUpGeometry(h, bare); // the interpolated normal
            const vec3 tilted = setup.tiltedNormal(h, bare.ns, vec3(1.0f, 0.0f, 1.0f), 0.5f);
            ASSERT_LT(glm::dot(tilted, bare.ns), 0.9f); // the map tilts by more than 25 degrees
            const vec3 coat = gltfCoatNormal(shaderAtHit(s.shaders[0].params, hit), hit.ns);
            const vec3 base = coatTilted ? bare.ns : tilted;
            EXPECT_LT(glm::length(coat - (coatTilted ? tilted : bare.ns)), 2e-3f);
            EXPECT_LT(glm::length(hit.ns - base), 1e-5f);
        }
        for (BackendKind backend :
             {BackendKind::Reference, BackendKind::Cpu, BackendKind::Vulkan}) {
            SCOPED_TRACE(backendName(backend));
            const std::vector<float> image = renderOn(s, backend);
            EXPECT_TRUE(std::all_of(image.begin(), image.end(),
                                    [](float x) { return std::isfinite(x) && x >= 0.0f; }));
            if (coatTilted) {
                EXPECT_NE(image, renderOn(plain, backend));
            }
        }
    }
    coatMap["extensions"]["KHR_materials_clearcoat"]["clearcoatNormalTexture"]["scale"] = "a";
    try {
        loadScene(sphereFile(dir, coatMap, {"tilt.png"}));
        ADD_FAILURE() << "a scale that is not a number";
    } catch (const SceneError& e) {
        EXPECT_NE(std::string(e.what()).find("/materials/0/extensions/KHR_materials_clearcoat/"
                                             "clearcoatNormalTexture/scale: must be a number in "
                                             "[-1000, 1000]"),
                  std::string::npos)
            << e.what();
    }
}

TEST(GltfExtensionImages, WhatIsNotRenderedIsWarnedAndBadReferencesRefused) {
    TempDir dir;
    writeUniform(dir.file("image.png"), vec4(1.0f));
    json coatedSpecular = withImages(specular(0.5, {1.0, 1.0, 1.0}), "KHR_materials_specular",
                                     {"specularColorTexture"}, true);
    coatedSpecular["extensions"]["KHR_materials_clearcoat"]["clearcoatFactor"] = 1.0;
    const Scene s = loadScene(sphereFile(dir, coatedSpecular, {"image.png"}));
    EXPECT_EQ(s.shaders.at(0).params.model, kModelCoatedMetallicRoughness);
    ASSERT_EQ(s.warnings.size(), 1u);
    EXPECT_NE(s.warnings[0].find("specular's images are not rendered on a clear coat"),
              std::string::npos)
        << s.warnings[0];
    // A transmission image on glass that transmits all: partial wherever the image says so.
    const Scene glassImage = loadScene(sphereFile(
        dir,
        withImages(glass(1.0, 1.5), "KHR_materials_transmission", {"transmissionTexture"}, true),
        {"image.png"}));
    EXPECT_EQ(glassImage.shaders.at(0).params.model, kModelTransmissiveMetallicRoughness);
    const std::string sheenAt = "/materials/0/extensions/KHR_materials_sheen/sheenColorTexture";
    const struct {
        json reference;
        std::string message;
    } bad[] = {
        {{{"index", 3}}, sheenAt + ": names texture 3 of 1"},
        {{{"index", -1}}, sheenAt + "/index: must be an integer of at least 0"},
        {{{"index", 0.5}}, sheenAt + "/index: must be an integer of at least 0"},
        {{{"texCoord", 0}}, sheenAt + ": a textureInfo needs an index"},
        {{{"index", 0}, {"texCoord", 300}}, sheenAt + "/texCoord: must be an integer in [0, 255]"},
        {{{"index", 0}, {"texCoord", "a"}},
         sheenAt + "/texCoord: must be an integer of at least 0"},
        {{{"index", 0}, {"extensions", 1}}, sheenAt + "/extensions: must be an object"},
        {json::array({0}), sheenAt + ": must be a textureInfo object"},
    };
    for (const auto& c : bad) {
        json m = sheen({1.0, 1.0, 1.0}, 0.5);
        m["extensions"]["KHR_materials_sheen"]["sheenColorTexture"] = c.reference;
        try {
            loadScene(sphereFile(dir, m, {"image.png"}));
            ADD_FAILURE() << c.message;
        } catch (const SceneError& e) {
            EXPECT_NE(std::string(e.what()).find(c.message), std::string::npos) << e.what();
        }
    }
}

} // namespace
} // namespace spw::test
