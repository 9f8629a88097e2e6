// Render passes (--aov, host/image/aov_film.h): the camera rays' first hits' albedo, shading
// normal and depth, averaged per pixel over the samples that hit, the same bit for bit on every
// backend and thread count, written as layers of the output EXR under Cycles' pass names; and
// the ways of asking for them that are refused.
#include "host/image/aov_film.h"
#include "host/loaders/scene_loader.h"
#include "scene/gltf_builder.h"
#include "test_util.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace spw::test {
namespace {

// A quad of base colour (0.8, 0.5, 0.25) facing a camera 3 units in front of it, filling the
// middle of a 16 x 16 image (columns and rows 4-11 wholly), a uniform environment behind.
std::string quadFile(const TempDir& dir) {
    GltfBuilder b;
    b.doc["materials"] = json::array({material(vec3(0.8f, 0.5f, 0.25f), 0.0f, 0.6f)});
    b.doc["cameras"] = json::array(
        {{{"type", "perspective"},
          {"perspective",
           {{"yfov", 2.0 * std::atan(1.0 / 3.0)}, {"aspectRatio", 1.0}, {"znear", 0.1}}}}});
    b.scene({b.node({{"mesh", b.mesh(b.quad(0))}, {"translation", {-0.5, -0.5, 0}}}),
             b.node({{"camera", 0}, {"translation", {0, 0, 3}}})});
    return b.embedded(dir, "quad.gltf");
}

std::vector<float> passes(const Scene& scene, BackendKind backend, int threads = 0) {
    RenderConfig cfg;
    cfg.backend = backend;
    cfg.spp = 4;
    cfg.threads = threads;
    cfg.aovs = kAovAlbedo | kAovNormal | kAovDepth;
    const std::unique_ptr<RenderResult> r = render(scene, cfg);
    EXPECT_TRUE(r->aovs);
    std::vector<float> out(size_t(scene.image.width) * size_t(scene.image.height) * 7);
    r->aovs->rows(0, scene.image.height, out.data());
    return out;
}

TEST(Aov, ThePassesAreTheFirstHitsAlbedoNormalAndDepth) {
    TempDir dir;
    Scene scene = loadScene(quadFile(dir));
    scene.image.width = scene.image.height = 16;
    const std::vector<float> ref = passes(scene, BackendKind::Reference);
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) {
            const float* p = &ref[size_t(y * 16 + x) * 7];
            const bool inside = x >= 4 && x < 12 && y >= 4 && y < 12;
            const bool outside = x < 3 || x > 12 || y < 3 || y > 12;
            if (inside) {
                EXPECT_EQ(vec3(p[0], p[1], p[2]), vec3(0.8f, 0.5f, 0.25f)) << x << " " << y;
                EXPECT_EQ(vec3(p[3], p[4], p[5]), vec3(0.0f, 0.0f, 1.0f)) << x << " " << y;
                EXPECT_NEAR(p[6], 3.0f, 1e-5f) << x << " " << y; // planar: 3 at every pixel
            }
            if (outside) { // no sample hit: Cycles' background values
                EXPECT_EQ(vec3(p[0], p[1], p[2]), vec3(0.0f));
                EXPECT_EQ(vec3(p[3], p[4], p[5]), vec3(0.0f));
                EXPECT_EQ(p[6], 1e10f);
            }
        }
    // The same bits on every backend and thread count.
    EXPECT_EQ(passes(scene, BackendKind::Cpu), ref);
    EXPECT_EQ(passes(scene, BackendKind::Cpu, 1), ref);
    EXPECT_EQ(passes(scene, BackendKind::Vulkan), ref);
}

TEST(Aov, TheOutputExrHoldsThemAsCyclesNamesThem) {
    TempDir dir;
    const std::string scene = quadFile(dir), out = dir.file("out.exr"), plain = dir.file("p.exr");
    const CommandResult r = runSpillway("render " + scene + " --width 16 --height 16 --spp 4 -o " +
                                        out + " --aov depth,albedo,normal --quiet");
    ASSERT_EQ(r.status, 0) << r.output;
    ASSERT_EQ(
        runSpillway("render " + scene + " --width 16 --height 16 --spp 4 -o " + plain + " --quiet")
            .status,
        0);
    // OpenEXR keeps channels sorted by name: look each up.
    auto in = OIIO::ImageInput::open(out);
    ASSERT_TRUE(in);
    const std::vector<std::string>& names = in->spec().channelnames;
    std::vector<std::string> sorted = names;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(sorted, (std::vector<std::string>{"B", "Denoising Albedo.B", "Denoising Albedo.G",
                                                "Denoising Albedo.R", "Depth.Z", "G", "Normal.X",
                                                "Normal.Y", "Normal.Z", "R"}));
    const int channels = int(names.size());
    std::vector<float> pixels(size_t(16 * 16 * channels));
    ASSERT_TRUE(in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, pixels.data()));
    auto at = [&](size_t pixel, const std::string& name) {
        const size_t c = size_t(std::find(names.begin(), names.end(), name) - names.begin());
        return c < names.size() ? pixels[pixel * size_t(channels) + c] : NAN;
    };
    // The image itself is the one rendered without passes.
    auto plainIn = OIIO::ImageInput::open(plain);
    ASSERT_TRUE(plainIn);
    std::vector<float> rgb(16 * 16 * 3);
    ASSERT_TRUE(plainIn->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, rgb.data()));
    for (size_t i = 0; i < 16 * 16; ++i)
        ASSERT_EQ(vec3(at(i, "R"), at(i, "G"), at(i, "B")),
                  vec3(rgb[i * 3], rgb[i * 3 + 1], rgb[i * 3 + 2]))
            << i;
    const size_t centre = 8 * 16 + 8;
    EXPECT_EQ(at(centre, "Denoising Albedo.R"), 0.8f);
    EXPECT_EQ(at(centre, "Normal.Z"), 1.0f);
    EXPECT_NEAR(at(centre, "Depth.Z"), 3.0f, 1e-5f);
    EXPECT_EQ(at(0, "Depth.Z"), 1e10f);
}

// Passes named by several --aov add up, and an output spelt .EXR takes them as .exr does.
TEST(Aov, RepeatedAovsAddUpAndTheOutputsCaseDoesNotMatter) {
    TempDir dir;
    const std::string scene = quadFile(dir), out = dir.file("OUT.EXR");
    const CommandResult r = runSpillway("render " + scene + " --width 8 --height 8 --spp 1 -o " +
                                        out + " --aov albedo --aov depth --quiet");
    ASSERT_EQ(r.status, 0) << r.output;
    auto in = OIIO::ImageInput::open(out);
    ASSERT_TRUE(in);
    std::vector<std::string> names = in->spec().channelnames;
    std::sort(names.begin(), names.end());
    EXPECT_EQ(names, (std::vector<std::string>{"B", "Denoising Albedo.B", "Denoising Albedo.G",
                                               "Denoising Albedo.R", "Depth.Z", "G", "R"}));
}

TEST(Aov, PassesThatCannotBeWrittenAreRefused) {
    TempDir dir;
    const std::string scene = quadFile(dir);
    const struct {
        std::string args, message;
    } cases[] = {
        {"--aov albedo,shadow -o " + dir.file("a.exr"),
         "--aov albedo,shadow: 'shadow' is not a pass (albedo, normal, depth)"},
        {"--aov , -o " + dir.file("a.exr"), "'' is not a pass"},
        {"--aov albedo -o " + dir.file("a.png"), "--aov writes layers of an EXR"},
        {"--aov albedo -o " + dir.file("a.exr") + " --checkpoint " + dir.file("c.exr"),
         "--aov does not go with --checkpoint"},
    };
    for (const auto& c : cases) {
        const CommandResult r = runSpillway("render " + scene + " --spp 1 " + c.args);
        EXPECT_EQ(r.status, 2) << c.args << "\n" << r.output;
        EXPECT_NE(r.output.find(c.message), std::string::npos) << r.output;
    }
    EXPECT_EQ(filesIn(dir.path()), 1u); // the scene alone: nothing written
}

TEST(Aov, AListNamesEachPassOnce) {
    EXPECT_EQ(parseAovList("normal"), unsigned(kAovNormal));
    EXPECT_EQ(parseAovList("depth,albedo,depth"), unsigned(kAovDepth | kAovAlbedo));
    EXPECT_THROW(parseAovList(""), std::invalid_argument);
    EXPECT_THROW(parseAovList("Albedo"), std::invalid_argument);
}

} // namespace
} // namespace spw::test
