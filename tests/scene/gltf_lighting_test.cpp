// How a glTF file without punctual lights is lit: by a white environment unless its emissive
// meshes can light it alone (their power against the environment's at the scene's size), and
// by whatever --environment names on every scene format.
#include "host/app/render_options.h"
#include "host/app/usage_error.h"
#include "host/loaders/scene_loader.h"
#include "scene/gltf_builder.h"
#include "test_util.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace spw::test {
namespace {

using nlohmann::json;

// A grey floor 10 x 10 (bounding radius 7.07 and more: a white environment's power there is
// 4 pi^2 r^2 = 1974) under an emissive panel `side` x `side` of radiance `strength`, a little
// above it and facing the camera; `emissionImage` (a PNG's bytes), where not empty, the panel's
// emissiveTexture.
std::string floorAndPanel(const TempDir& dir, double side, double strength,
                          const std::string& emissionImage = "") {
    GltfBuilder b;
    json panel = material(vec3(0.0f), 0.0f, 1.0f, vec3(1.0f));
    panel["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"] = strength;
    if (!emissionImage.empty()) {
        panel["emissiveTexture"] = {{"index", 0}};
        b.doc["textures"] = json::array({{{"source", 0}}});
        b.doc["images"] =
            json::array({{{"uri", "data:image/png;base64," + GltfBuilder::base64(emissionImage)}}});
    }
    b.doc["materials"] = json::array({material(vec3(0.5f), 0.0f, 1.0f), panel});
    b.doc["extensionsUsed"] = {"KHR_materials_emissive_strength"};
    b.doc["cameras"] =
        json::array({{{"type", "perspective"},
                      {"perspective", {{"yfov", 0.8}, {"aspectRatio", 1.0}, {"znear", 0.1}}}}});
    b.scene({b.node({{"mesh", b.mesh(b.quad(0))},
                     {"translation", {-5, 0, 5}},
                     {"rotation", {-0.7071068, 0, 0, 0.7071068}}, // +Y up, the quad on y = 0
                     {"scale", {10, 10, 1}}}),
             b.node({{"mesh", b.mesh(b.quad(1))},
                     {"translation", {-0.5 * side, 0.01, 0}},
                     {"scale", {side, side, 1}}}),
             b.node({{"camera", 0}, {"translation", {0, 2, 8}}})});
    return b.embedded(dir, "panel.gltf");
}

bool says(const Scene& s, const std::string& what) {
    for (const std::string& w : s.warnings)
        if (w.find(what) != std::string::npos) return true;
    return false;
}

// A 16 x 16 PNG, white in `lit` of its texels (from the first), black elsewhere.
std::string partlyWhite(const TempDir& dir, int lit) {
    OIIO::ImageBuf img(OIIO::ImageSpec(16, 16, 3, OIIO::TypeDesc::UINT8));
    const float black[3] = {0, 0, 0}, white[3] = {1, 1, 1};
    OIIO::ImageBufAlgo::fill(img, black);
    for (int i = 0; i < lit; ++i)
        img.setpixel(i % 16, i / 16, white);
    EXPECT_TRUE(img.write(dir.file("emission.png")));
    return readFile(dir.file("emission.png"));
}

// A panel 4 x 4 of radiance 30 (power pi 30 16 = 1508, 71 % of the environment's at the
// scene's radius of 7.35) lights the scene alone, as it does under an emission map white in
// every texel. Under one white in 4 of its 256 texels it emits about 1 % of the environment's:
// a decal, so the floor is lit by the white environment as well, and a warning says so; as it is
// under a small panel 0.1 x 0.1 of radiance 1000 (1.6 %).
TEST(GltfLighting, EmittersTooDimToLightTheSceneAddTheWhiteEnvironment) {
    TempDir dir;
    const Scene bright = loadScene(floorAndPanel(dir, 4.0, 30.0));
    EXPECT_FALSE(bright.environment);
    EXPECT_TRUE(bright.warnings.empty()) << bright.warnings.at(0);
    const Scene whollyLit = loadScene(floorAndPanel(dir, 4.0, 30.0, partlyWhite(dir, 256)));
    EXPECT_FALSE(whollyLit.environment);
    for (const Scene& dim : {loadScene(floorAndPanel(dir, 4.0, 30.0, partlyWhite(dir, 4))),
                             loadScene(floorAndPanel(dir, 0.1, 1000.0))}) {
        ASSERT_TRUE(dim.environment);
        EXPECT_EQ(dim.environment->radiance, vec3(1.0f));
        EXPECT_TRUE(dim.environment->path.empty());
        ASSERT_EQ(dim.warnings.size(), 1u);
        EXPECT_TRUE(says(dim, "lit by that environment as well")) << dim.warnings[0];
    }
    // The small panel's share, said: pi 1000 0.01 / (4 pi^2 50.006).
    EXPECT_TRUE(says(loadScene(floorAndPanel(dir, 0.1, 1000.0)), "power is 1.59 %"));
}

// Rendered, the decal's floor reads what the environment gives a grey Lambert-like floor (about
// its albedo, 0.5), where the floor lit by the bright panel alone is what it was.
TEST(GltfLighting, TheDecalsFloorIsLitOnEveryBackend) {
    TempDir dir;
    Scene scene = loadScene(floorAndPanel(dir, 0.1, 1000.0));
    scene.image.width = scene.image.height = 16;
    for (BackendKind backend : {BackendKind::Reference, BackendKind::Cpu, BackendKind::Vulkan}) {
        SCOPED_TRACE(backendName(backend));
        RenderConfig cfg;
        cfg.backend = backend;
        cfg.spp = 4;
        const std::vector<float> img = render(scene, cfg)->film->image();
        // The bottom row sees the floor only, far from the small panel.
        double floor = 0;
        for (size_t i = 15 * 16 * 3; i < img.size(); ++i)
            floor += img[i];
        floor /= 16 * 3;
        EXPECT_GT(floor, 0.3);
        EXPECT_LT(floor, 0.7);
    }
}

// --environment replaces the scene's environment on every format: a constant R,G,B or an image,
// times --environment-strength; what cannot be one is a usage error naming the option. The
// warning that a glTF file's dim emitters are helped by a white environment goes with the
// environment it speaks of.
TEST(GltfLighting, EnvironmentOptionReplacesTheScenesOwn) {
    TempDir dir;
    const std::string gltf = floorAndPanel(dir, 4.0, 30.0);
    const std::string yaml = sourceDir() + "/scenes/cornell-box.yaml";
    {
        OIIO::ImageBuf map(OIIO::ImageSpec(8, 4, 3, OIIO::TypeDesc::FLOAT));
        const float sky[3] = {0.25f, 0.5f, 1.0f};
        OIIO::ImageBufAlgo::fill(map, sky);
        ASSERT_TRUE(map.write(dir.file("sky.exr")));
    }
    auto withOptions = [](const std::string& file, std::vector<std::string> args) {
        args.insert(args.begin(), file);
        const RenderOptions o = parseRenderOptions(args);
        Scene s = loadScene(file);
        applyOverrides(o, s);
        return s;
    };
    const std::string dim = floorAndPanel(dir, 0.1, 1000.0);
    ASSERT_EQ(loadScene(dim).warnings.size(), 1u);
    EXPECT_EQ(withOptions(dim, {}).warnings.size(), 1u);
    const Scene replaced = withOptions(dim, {"--environment", "0,0,0"});
    EXPECT_TRUE(replaced.warnings.empty()) << replaced.warnings.at(0);
    EXPECT_EQ(replaced.environment->radiance, vec3(0.0f));
    for (const std::string& file : {gltf, yaml}) {
        SCOPED_TRACE(file);
        const Scene constant = withOptions(file, {"--environment", "0.5,1,2"});
        ASSERT_TRUE(constant.environment);
        EXPECT_EQ(constant.environment->radiance, vec3(0.5f, 1.0f, 2.0f));
        const Scene stronger =
            withOptions(file, {"--environment", "0.5,1,2", "--environment-strength", "4"});
        EXPECT_EQ(stronger.environment->radiance, vec3(2.0f, 4.0f, 8.0f));
        const Scene image = withOptions(
            file, {"--environment", dir.file("sky.exr"), "--environment-strength", "2"});
        ASSERT_TRUE(image.environment);
        EXPECT_EQ(image.environment->width, 8);
        EXPECT_EQ(image.environment->height, 4);
        EXPECT_EQ(image.environment->radiance, vec3(2.0f));
        ASSERT_EQ(image.environment->rgb.size(), 8u * 4u * 3u);
        EXPECT_EQ(image.environment->rgb[2], 1.0f);
    }
    const std::pair<std::vector<std::string>, std::string> bad[] = {
        {{"--environment-strength", "2"}, "--environment-strength scales --environment"},
        {{"--environment", dir.file("absent.hdr")}, "does not exist"},
        {{"--environment", "1,2"}, "an image or R,G,B"},
        {{"--environment", "1,-1,1"}, "must lie in 0 .. 1e20"},
        {{"--environment", "1e19,1,1", "--environment-strength", "100"}, "must lie in 0 .. 1e20"},
    };
    for (const auto& [args, message] : bad) {
        try {
            withOptions(gltf, args);
            ADD_FAILURE() << args[0] << " " << args[1];
        } catch (const UsageError& e) {
            EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
        }
    }
}

} // namespace
} // namespace spw::test
