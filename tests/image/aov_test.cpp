// Render passes (--aov, host/image/aov_film.h): the denoising albedo of what each pixel shows
// (through mirrors), the first hits' shading normal in world and camera space and their depth,
// averaged per pixel over the samples that hit, the same bit for bit on every backend and thread
// count, written as layers of the output EXR under Cycles' pass names with their conventions in
// the header; and the ways of asking for them that are refused.
#include "host/image/aov_film.h"
#include "host/loaders/scene_loader.h"
#include "scene/gltf_builder.h"
#include "shared/bsdf.h"
#include "test_util.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

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

// Albedo, normal, depth, and with `cameraNormal` the camera-space normal: 7 or 10 floats a pixel.
std::vector<float> passes(const Scene& scene, BackendKind backend, int threads = 0,
                          bool cameraNormal = false) {
    RenderConfig cfg;
    cfg.backend = backend;
    cfg.spp = 4;
    cfg.threads = threads;
    cfg.aovs = kAovAlbedo | kAovNormal | kAovDepth | (cameraNormal ? kAovCameraNormal : 0u);
    const std::unique_ptr<RenderResult> r = render(scene, cfg);
    EXPECT_TRUE(r->aovs);
    std::vector<float> out(size_t(scene.image.width) * size_t(scene.image.height) *
                           (cameraNormal ? 10 : 7));
    r->aovs->rows(0, scene.image.height, out.data());
    return out;
}

// The directional albedo of shader `sh` of colour `base` seen straight on (wo = ns): its BSDF's
// f cos integrated from 2^16 random samples (to about 0.2 %), where the pass takes 64
// stratified ones.
vec3 directionalAlbedo(const ShaderParams& sh, vec3 base) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
    const vec3 n(0.0f, 0.0f, 1.0f);
    vec3 sum(0.0f);
    constexpr int kSamples = 1 << 16;
    for (int i = 0; i < kSamples; ++i) {
        vec3 wi, weight;
        float pdf = 0.0f;
        bool delta = false;
        const vec3 u(uniform(rng), uniform(rng), uniform(rng));
        if (bsdfSample(sh, base, n, n, n, u, wi, weight, pdf, delta)) sum += weight;
    }
    return sum / float(kSamples);
}

// The albedo is the quad's directional albedo, its diffuse colour and its Fresnel-weighted
// specular reflection (Cycles' "Denoising Albedo" counts both: the base colour alone was 5-19 %
// below it), within 2 % of the integral (the pass's 64 samples, and the pixels' slightly
// oblique views).
TEST(Aov, ThePassesAreTheFirstHitsAlbedoNormalAndDepth) {
    TempDir dir;
    Scene scene = loadScene(quadFile(dir));
    scene.image.width = scene.image.height = 16;
    const vec3 albedo = directionalAlbedo(scene.shaders[0].params, vec3(0.8f, 0.5f, 0.25f));
    EXPECT_GT(albedo.z, 0.25f * 0.96f + 0.03f); // the specular reflection counted
    const std::vector<float> ref = passes(scene, BackendKind::Reference);
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) {
            const float* p = &ref[size_t(y * 16 + x) * 7];
            const bool inside = x >= 4 && x < 12 && y >= 4 && y < 12;
            const bool outside = x < 3 || x > 12 || y < 3 || y > 12;
            if (inside) {
                for (int c = 0; c < 3; ++c)
                    EXPECT_NEAR(p[c], albedo[c], 0.02f * albedo[c]) << x << " " << y;
                EXPECT_EQ(vec3(p[3], p[4], p[5]), vec3(0.0f, 0.0f, 1.0f)) << x << " " << y;
                EXPECT_NEAR(p[6], 3.0f, 1e-5f) << x << " " << y; // planar: 3 at every pixel
            }
            if (outside) { // no sample hit: Cycles' background values, the albedo the
                           // white environment's radiance
                EXPECT_EQ(vec3(p[0], p[1], p[2]), vec3(1.0f));
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
    EXPECT_NEAR(at(centre, "Denoising Albedo.R"), 0.8f * 0.96f + 0.04f, 0.02f);
    // Each layer's convention in the header.
    EXPECT_NE(in->spec().get_string_attribute("spillway/Normal").find("world space"),
              std::string::npos);
    EXPECT_NE(in->spec().get_string_attribute("spillway/Denoising Albedo").find("mirrors"),
              std::string::npos);
    EXPECT_EQ(at(centre, "Normal.Z"), 1.0f);
    EXPECT_NEAR(at(centre, "Depth.Z"), 3.0f, 1e-5f);
    EXPECT_EQ(at(0, "Depth.Z"), 1e10f);
}

// A polished metal quad (glTF's roughness 0: a mirror to its maker) facing the camera, and
// behind the camera a rough green wall it reflects: the albedo is the wall's, times the
// metal's reflectance straight on (its base colour), as denoisers expect of a mirror; the
// normal and depth stay the first hit's.
TEST(Aov, TheAlbedoIsWhatAMirrorShows) {
    TempDir dir;
    GltfBuilder b;
    b.doc["materials"] = json::array({material(vec3(0.9f, 0.6f, 0.3f), 1.0f, 0.0f),
                                      material(vec3(0.2f, 0.8f, 0.4f), 0.0f, 1.0f)});
    b.doc["cameras"] = json::array(
        {{{"type", "perspective"},
          {"perspective",
           {{"yfov", 2.0 * std::atan(1.0 / 3.0)}, {"aspectRatio", 1.0}, {"znear", 0.1}}}}});
    b.scene({b.node({{"mesh", b.mesh(b.quad(0))}, {"translation", {-0.5, -0.5, 0}}}),
             // The wall: the quad turned to face -Z, 10 x 10, 6 in front of the metal.
             b.node({{"mesh", b.mesh(b.quad(1))},
                     {"rotation", {0, 1, 0, 0}},
                     {"scale", {10, 10, 1}},
                     {"translation", {5, -5, 6}}}),
             b.node({{"camera", 0}, {"translation", {0, 0, 3}}})});
    Scene scene = loadScene(b.embedded(dir, "mirror.gltf"));
    scene.image.width = scene.image.height = 16;
    const vec3 wall = directionalAlbedo(scene.shaders[1].params, vec3(0.2f, 0.8f, 0.4f));
    const vec3 want = vec3(0.9f, 0.6f, 0.3f) * wall;
    const std::vector<float> ref = passes(scene, BackendKind::Reference);
    for (int y = 5; y < 11; ++y)
        for (int x = 5; x < 11; ++x) {
            const float* p = &ref[size_t(y * 16 + x) * 7];
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(p[c], want[c], 0.03f * want[c]) << x << " " << y;
            EXPECT_EQ(vec3(p[3], p[4], p[5]), vec3(0.0f, 0.0f, 1.0f));
            EXPECT_NEAR(p[6], 3.0f, 1e-5f);
        }
    // The other backends: the first hit's passes to the bit; the albedo, which the wall's hit
    // gives times the path's throughput, within a bfloat16 step of the reference's (2^-7 of it):
    // the sorted pipeline's compact rays carry the throughput rounded to bfloat16
    // (host/pipeline/ray_record.h), stochastically, so each sample is one step off at most.
    for (BackendKind backend : {BackendKind::Cpu, BackendKind::Vulkan}) {
        SCOPED_TRACE(backendName(backend));
        const std::vector<float> other = passes(scene, backend);
        ASSERT_EQ(other.size(), ref.size());
        for (size_t i = 0; i < ref.size(); ++i) {
            if (i % 7 < 3)
                EXPECT_NEAR(other[i], ref[i], std::ldexp(ref[i], -7)) << i;
            else
                EXPECT_EQ(other[i], ref[i]) << i;
        }
    }
}

// The camera-space normal of a quad facing the camera is +Z whichever way the camera looks;
// the world-space one is the quad's normal in the world: here +X, the camera looking along -X.
TEST(Aov, TheCameraNormalIsOnTheCamerasAxes) {
    TempDir dir;
    GltfBuilder b;
    b.doc["materials"] = json::array({material(vec3(0.5f), 0.0f, 1.0f)});
    b.doc["cameras"] =
        json::array({{{"type", "perspective"},
                      {"perspective", {{"yfov", 0.3}, {"aspectRatio", 1.0}, {"znear", 0.1}}}}});
    const json quarter = {0, 0.7071068, 0, 0.7071068}; // +Z turned to +X
    b.scene(
        {b.node(
             {{"mesh", b.mesh(b.quad(0))}, {"rotation", quarter}, {"translation", {0, -0.5, 0.5}}}),
         b.node({{"camera", 0}, {"rotation", quarter}, {"translation", {3, 0, 0}}})});
    Scene scene = loadScene(b.embedded(dir, "side.gltf"));
    scene.image.width = scene.image.height = 8;
    const std::vector<float> ref = passes(scene, BackendKind::Reference, 0, true);
    for (int i = 0; i < 64; ++i) {
        const float* p = &ref[size_t(i) * 10];
        EXPECT_NEAR(p[3], 1.0f, 1e-6f);
        EXPECT_NEAR(p[4], 0.0f, 1e-6f);
        EXPECT_NEAR(p[5], 0.0f, 1e-6f);
        EXPECT_NEAR(p[6], 0.0f, 1e-6f); // the camera-space normal, after the world's
        EXPECT_NEAR(p[7], 0.0f, 1e-6f);
        EXPECT_NEAR(p[8], 1.0f, 1e-6f);
    }
    EXPECT_EQ(passes(scene, BackendKind::Cpu, 0, true), ref);
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

// `spillway compare --layer` reads a pass of two EXRs: Spillway's own layer, and the same values
// under a view layer's name as Blender writes them ("ViewLayer.Denoising Albedo.R", here with
// the channels in another order), compare as identical; a file without the layer is exit 2,
// naming it.
TEST(Aov, CompareReadsAPassByItsLayer) {
    TempDir dir;
    const std::string scene = quadFile(dir), ours = dir.file("ours.exr");
    ASSERT_EQ(runSpillway("render " + scene + " --width 8 --height 8 --spp 1 -o " + ours +
                          " --aov albedo --quiet")
                  .status,
              0);
    auto in = OIIO::ImageInput::open(ours);
    ASSERT_TRUE(in);
    const OIIO::ImageSpec spec = in->spec();
    std::vector<float> pixels(size_t(64 * spec.nchannels));
    ASSERT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data()));
    in.reset();
    // Blender's way: B, G, R under a view layer, then its Combined.
    OIIO::ImageSpec theirs(8, 8, 6, OIIO::TypeDesc::FLOAT);
    theirs.channelnames = {"ViewLayer.Denoising Albedo.B", "ViewLayer.Denoising Albedo.G",
                           "ViewLayer.Denoising Albedo.R", "ViewLayer.Combined.R",
                           "ViewLayer.Combined.G",         "ViewLayer.Combined.B"};
    std::vector<float> out(64 * 6, 0.5f);
    for (size_t i = 0; i < 64; ++i)
        for (int c = 0; c < 3; ++c) {
            const std::string name = std::string("Denoising Albedo.") + "RGB"[c];
            const auto at = std::find(spec.channelnames.begin(), spec.channelnames.end(), name);
            ASSERT_NE(at, spec.channelnames.end()) << name;
            out[i * 6 + size_t(2 - c)] =
                pixels[i * size_t(spec.nchannels) + size_t(at - spec.channelnames.begin())];
        }
    {
        auto o = OIIO::ImageOutput::create(dir.file("blender.exr"));
        ASSERT_TRUE(o && o->open(dir.file("blender.exr"), theirs));
        ASSERT_TRUE(o->write_image(OIIO::TypeDesc::FLOAT, out.data()));
        o->close();
    }
    const CommandResult same = runSpillway("compare " + ours + " " + dir.file("blender.exr") +
                                           " --layer 'Denoising Albedo' --threshold mse=0");
    EXPECT_EQ(same.status, 0) << same.output;
    EXPECT_NE(same.output.find("images identical"), std::string::npos) << same.output;
    // The image itself differs from the pass.
    EXPECT_EQ(runSpillway("compare " + ours + " " + dir.file("blender.exr") + " --threshold mse=0")
                  .status,
              1);
    const CommandResult none = runSpillway("compare " + ours + " " + ours + " --layer Normal");
    EXPECT_EQ(none.status, 2) << none.output;
    EXPECT_NE(none.output.find("has no layer 'Normal'"), std::string::npos) << none.output;
}

TEST(Aov, PassesThatCannotBeWrittenAreRefused) {
    TempDir dir;
    const std::string scene = quadFile(dir);
    const struct {
        std::string args, message;
    } cases[] = {
        {"--aov albedo,shadow -o " + dir.file("a.exr"),
         "--aov albedo,shadow: 'shadow' is not a pass (albedo, normal, camera-normal, depth)"},
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

// What the passes keep is a pixel's sums, not a sample's values: 4096 samples an iteration add
// a bit a sample (whether its albedo is still to come) to what one sample needs, and a pixel
// holds 24 bytes a value (7 of them) and 16 for its counts.
TEST(Aov, ThePassesKeepBytesAPixelNotASample) {
    const unsigned all = kAovAlbedo | kAovNormal | kAovDepth;
    const AovFilm one(64, 64, 1, all, mat3(1.0f)), many(64, 64, 4096, all, mat3(1.0f));
    const size_t pixels = 64 * 64;
    EXPECT_EQ(one.bytes(), pixels * (7 * 24 + 16) + pixels / 8);
    EXPECT_LE(many.bytes() - one.bytes(), pixels * 4096 / 8);
    EXPECT_EQ(AovFilm(64, 64, 4096, kAovDepth, mat3(1.0f)).bytes(), pixels * (24 + 16));
}

// A pixel's sums are exact, so they do not depend on the order the samples come in: depths
// from 1e-3 to 1e15 (the scene format's farthest) give the same bits in every order, and their
// mean is the exact sum's as a double, divided and rounded to float (a float or double sum of
// the samples would depend on their order).
TEST(Aov, APixelsSumsAreExactInAnyOrder) {
    const std::vector<float> depths = {1e15f, 1e-3f, 3.0f, 7e11f, 1e-3f, 0.5f, 2e-2f, 1e15f};
    std::vector<int> order = {0, 1, 2, 3, 4, 5, 6, 7};
    auto passMeans = [&]() {
        AovFilm film(1, 1, int(depths.size()), kAovDepth | kAovNormal, mat3(1.0f));
        for (int i : order) {
            PathState path{};
            path.pathId = uint(i);
            SurfaceHit hit{};
            hit.p = vec3(0.0f, 0.0f, -depths[size_t(i)]); // the camera looks down -Z
            hit.ns = glm::normalize(vec3(float(i), 1.0f, -2.0f));
            film.record(path, hit);
        }
        film.endIteration();
        std::vector<float> out(4);
        film.rows(0, 1, out.data());
        return out;
    };
    const std::vector<float> first = passMeans();
    __int128 exact = 0; // in units of 2^-33, of which every float here is a multiple
    for (float d : depths)
        exact += static_cast<__int128>(std::ldexp(double(d), 33));
    EXPECT_EQ(first[3], float(std::ldexp(double(exact), -33) / double(depths.size())));
    std::mt19937 rng(3);
    for (int k = 0; k < 20; ++k) {
        std::shuffle(order.begin(), order.end(), rng);
        EXPECT_EQ(passMeans(), first);
    }
}

TEST(Aov, AListNamesEachPassOnce) {
    EXPECT_EQ(parseAovList("normal"), unsigned(kAovNormal));
    EXPECT_EQ(parseAovList("depth,albedo,depth"), unsigned(kAovDepth | kAovAlbedo));
    EXPECT_EQ(parseAovList("camera-normal"), unsigned(kAovCameraNormal));
    EXPECT_THROW(parseAovList(""), std::invalid_argument);
    EXPECT_THROW(parseAovList("Albedo"), std::invalid_argument);
}

} // namespace
} // namespace spw::test
