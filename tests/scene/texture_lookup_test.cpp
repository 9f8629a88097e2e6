// The texture lookups (host/textures/textures.cpp filter on OpenImageIO's cached tiles) against
// OpenImageIO's own TextureSystem as the oracle: bilinear at the finest level, repeating, on
// images whose tiles do not divide them (edge tiles), on untiled images, in 16-bit, half and
// float; and 8-bit images (sRGB unless they say otherwise) linearised per texel before filtering,
// where OpenImageIO would filter the encoded values.
#include "host/loaders/scene_loader.h"
#include "host/textures/textures.h"
#include "test_util.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>
#include <OpenImageIO/texture.h>
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <random>

namespace spw::test {
namespace {

// A W x H RGB image of `type` with pseudo-random texels in [0, 1], tiled (tile x tile) or not.
void writeNoise(const std::string& path, int w, int h, OIIO::TypeDesc type, int tile) {
    auto out = OIIO::ImageOutput::create(path);
    ASSERT_TRUE(out) << OIIO::geterror();
    OIIO::ImageSpec spec(w, h, 3, type);
    if (tile) spec.tile_width = spec.tile_height = tile;
    std::mt19937 rng(w * 7919 + h);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<float> pixels(size_t(w) * size_t(h) * 3);
    for (float& p : pixels)
        p = u(rng);
    ASSERT_TRUE(out->open(path, spec)) << out->geterror();
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, pixels.data())) << out->geterror();
    ASSERT_TRUE(out->close()) << out->geterror();
}

Scene texturedScene(const TempDir& dir, const std::string& image) {
    return loadScene(dir.write("t.yaml", "shader:\n  type: Lambert\n  texture: {type: Standard, "
                                         "string: " +
                                             image + "}\n"));
}

// OpenImageIO's bilinear lookup at the finest level, repeating (its t grows downwards; ours is
// OBJ's v, growing upwards).
vec3 oracle(OIIO::TextureSystem& ts, const std::string& path, vec2 uv) {
    OIIO::TextureOpt opt;
    opt.swrap = opt.twrap = OIIO::TextureOpt::WrapPeriodic;
    opt.interpmode = OIIO::TextureOpt::InterpBilinear;
    opt.mipmode = OIIO::TextureOpt::MipModeOneLevel;
    float rgb[3] = {0, 0, 0};
    EXPECT_TRUE(ts.texture(OIIO::ustring(path), opt, uv.x, 1.0f - uv.y, 0, 0, 0, 0, 3, rgb))
        << ts.geterror();
    return vec3(rgb[0], rgb[1], rgb[2]);
}

TEST(TextureLookup, BilinearAgreesWithOpenImageIOOnEdgeTilesUntiledAndEveryFormat) {
    TempDir dir;
    struct Case {
        const char* file;
        OIIO::TypeDesc type;
        int width, height, tile;
    };
    const Case cases[] = {
        {"u16-tiled.tif", OIIO::TypeDesc::UINT16, 100, 60, 16},
        {"half-tiled.exr", OIIO::TypeDesc::HALF, 37, 53, 16},
        {"float-untiled.exr", OIIO::TypeDesc::FLOAT, 29, 31, 0},
    };
    OIIO::TextureSystem* ts = OIIO::TextureSystem::create(false);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> coord(-2.0f, 3.0f);
    for (const Case& c : cases) {
        const std::string path = dir.file(c.file);
        writeNoise(path, c.width, c.height, c.type, c.tile);
        const Scene scene = texturedScene(dir, c.file);
        const TextureResolver textures(scene, 1.0);
        double worst = 0;
        for (int i = 0; i < 2000; ++i) {
            const vec2 uv(coord(rng), coord(rng));
            const vec3 ours = textures.albedo(scene.shaders[0], uv, 0.0f);
            const vec3 theirs = oracle(*ts, path, uv);
            for (int k = 0; k < 3; ++k)
                worst = std::max(worst, double(std::fabs(ours[k] - theirs[k])));
        }
        std::printf("%s: worst |ours - OpenImageIO| %.2g\n", c.file, worst);
        EXPECT_LE(worst, 1e-4) << c.file; // float rounding of the two bilinear forms
        EXPECT_EQ(textures.statistics().lookups, 2000u) << c.file;
        textures.checkErrors();
    }
    OIIO::TextureSystem::destroy(ts);
}

// An 8-bit sRGB image: each texel is linearised, then the texels are blended. Halfway between
// two texels of 0 and 255 the value is 0.5 (linear), not the 0.214 of linearising the blended
// code 127.5.
TEST(TextureLookup, EightBitSrgbTexelsAreLinearisedBeforeTheyAreBlended) {
    TempDir dir;
    {
        auto out = OIIO::ImageOutput::create(dir.file("bw.png"));
        ASSERT_TRUE(out);
        OIIO::ImageSpec spec(2, 1, 3, OIIO::TypeDesc::UINT8);
        const unsigned char px[6] = {0, 0, 0, 255, 255, 255};
        ASSERT_TRUE(out->open(dir.file("bw.png"), spec));
        ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, px));
        ASSERT_TRUE(out->close());
    }
    const Scene scene = texturedScene(dir, "bw.png");
    const TextureResolver textures(scene, 1.0);
    // Texel centres at u = 0.25 and 0.75; the edge u = 0.5 between them.
    EXPECT_FLOAT_EQ(textures.albedo(scene.shaders[0], vec2(0.25f, 0.5f), 0.0f).x, 0.0f);
    EXPECT_FLOAT_EQ(textures.albedo(scene.shaders[0], vec2(0.75f, 0.5f), 0.0f).x, 1.0f);
    EXPECT_FLOAT_EQ(textures.albedo(scene.shaders[0], vec2(0.5f, 0.5f), 0.0f).y, 0.5f);
    // Repeating: u = 0 lies halfway between the last texel and the first.
    EXPECT_FLOAT_EQ(textures.albedo(scene.shaders[0], vec2(0.0f, 0.5f), 0.0f).z, 0.5f);
}

// An 8-bit image of `channels` pseudo-random channels, w x h: made a tiled, MIP-mapped TIFF
// texture (tiles of `tile` texels) by OpenImageIO's maketx, or written untiled with one level
// (tile 0) in the format `path` names; `colourSpace` in its header if not empty (PNG keeps
// "Linear", as gamma 1).
void writeTexture8(const std::string& path, int w, int h, int channels, int tile,
                   const std::string& colourSpace) {
    OIIO::ImageSpec spec(w, h, channels, OIIO::TypeDesc::UINT8);
    if (!colourSpace.empty()) spec.attribute("oiio:ColorSpace", colourSpace);
    OIIO::ImageBuf image(spec);
    std::mt19937 rng(unsigned(w * 31 + h * 7 + channels));
    std::vector<unsigned char> pixels(size_t(w) * size_t(h) * size_t(channels));
    for (unsigned char& p : pixels)
        p = static_cast<unsigned char>(rng() & 0xFF);
    ASSERT_TRUE(image.set_pixels(OIIO::ROI::All(), OIIO::TypeDesc::UINT8, pixels.data()));
    if (tile == 0) {
        ASSERT_TRUE(image.write(path)) << image.geterror();
        return;
    }
    OIIO::ImageSpec config;
    config.tile_width = config.tile_height = tile;
    config.attribute("maketx:filtername", "box");
    ASSERT_TRUE(
        OIIO::ImageBufAlgo::make_texture(OIIO::ImageBufAlgo::MakeTxTexture, image, path, config))
        << OIIO::geterror();
}

// Runs of lookups in 8-bit images are filtered, and Layered textures blended, SIMD-wide
// (wide_texels.h); one lookup at a time is the oracle. They agree to the bit for grey, RGB and
// RGBA images, sRGB and linear, a Layered texture,
// tiled with edge tiles or untiled, MIP-mapped, in every instruction set this machine has, at
// coordinates in runs (as sorted hits come), far, negative, infinite and NaN, and footprints
// from none through every level to infinite; and so with a cache small enough that a thread
// lets its tiles go as it reads new ones.
TEST(TextureLookup, WideFilteringIsTheScalarLookupBitForBit) {
    TempDir dir;
    struct Case {
        const char* file;
        int width, height, channels, tile;
        const char* colourSpace;
        double cacheMiB;
        bool layered; // the image as a Layered texture's upper layer and mask over a Constant
    };
    const Case cases[] = {
        {"rgb.tif", 100, 60, 3, 16, "", 4.0, false},
        {"grey.tif", 64, 64, 1, 16, "", 4.0, false},
        {"rgba.tif", 37, 53, 4, 16, "", 4.0, false},
        {"linear.png", 64, 32, 3, 0, "Linear", 4.0, false},
        {"untiled.tif", 29, 31, 3, 0, "", 4.0, false},
        {"small-cache.tif", 256, 256, 3, 16, "", 0.02, false},
        {"layered.tif", 100, 60, 3, 16, "", 4.0, true},
    };
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> centre(-2.0f, 3.0f), near(-0.02f, 0.02f),
        level(-1.0f, 10.0f), unit(0.0f, 1.0f);
    const float inf = std::numeric_limits<float>::infinity(),
                nan = std::numeric_limits<float>::quiet_NaN();
    const std::vector<std::int64_t> targets = hwy::SupportedAndGeneratedTargets();
    ASSERT_FALSE(targets.empty());
    for (const Case& c : cases) {
        writeTexture8(dir.file(c.file), c.width, c.height, c.channels, c.tile, c.colourSpace);
        const std::string image = "{type: Standard, string: " + std::string(c.file) + "}";
        const Scene scene =
            c.layered ? loadScene(dir.write("l.yaml", "shader:\n  type: Lambert\n  texture: "
                                                      "{type: Layered, upper: " +
                                                          image + ", mask: " + image +
                                                          ", lower: {type: Constant, colour: "
                                                          "[0.2, 0.5, 0.9]}}\n"))
                      : texturedScene(dir, c.file);
        const TextureResolver wide(scene, c.cacheMiB, true, true),
            scalar(scene, c.cacheMiB, true, false);
        size_t compared = 0, differing = 0;
        for (int run = 0; run < 200; ++run) {
            constexpr size_t kRun = 128;
            std::vector<vec2> uv(kRun);
            std::vector<float> footprint(kRun);
            const vec2 at(centre(rng), centre(rng));
            for (size_t k = 0; k < kRun; ++k) {
                uv[k] = at + vec2(near(rng), near(rng));
                footprint[k] = std::exp2(level(rng)) / float(std::max(c.width, c.height));
                const float odd = unit(rng);
                if (odd < 0.02f)
                    uv[k] = vec2(centre(rng), centre(rng)) * 1e6f;
                else if (odd < 0.03f)
                    uv[k].x = nan;
                else if (odd < 0.04f)
                    uv[k].y = -inf;
                else if (odd < 0.06f)
                    footprint[k] = 0.0f;
                else if (odd < 0.07f)
                    footprint[k] = inf;
                else if (odd < 0.08f)
                    footprint[k] = nan;
            }
            std::vector<vec3> a(kRun), b(kRun);
            // Each run in the next instruction set this machine has.
            hwy::SetSupportedTargetsForTest(targets[size_t(run) % targets.size()]);
            wide.albedos(scene.shaders[0], kRun, uv.data(), footprint.data(), a.data());
            scalar.albedos(scene.shaders[0], kRun, uv.data(), footprint.data(), b.data());
            compared += kRun;
            for (size_t k = 0; k < kRun; ++k)
                differing += std::memcmp(&a[k], &b[k], sizeof(vec3)) != 0;
        }
        hwy::SetSupportedTargetsForTest(0);
        EXPECT_EQ(differing, 0u) << c.file << ": of " << compared;
        wide.checkErrors();
        scalar.checkErrors();
    }
}

// A texture file that is readable when the scene loads but whose pixels are not: the lookup
// returns black for the iteration and checkErrors() names the file and its scene line.
TEST(TextureLookup, UnreadablePixelsAreReportedWithTheSceneLine) {
    TempDir dir;
    writeNoise(dir.file("n.tif"), 64, 64, OIIO::TypeDesc::UINT16, 16);
    const Scene scene = texturedScene(dir, "n.tif");
    const TextureResolver textures(scene, 1.0);
    // Cut the file after its header: its tiles are gone.
    std::filesystem::resize_file(dir.file("n.tif"), 600);
    const vec3 a = textures.albedo(scene.shaders[0], vec2(0.5f), 0.0f);
    EXPECT_EQ(a, vec3(0.0f));
    try {
        textures.checkErrors();
        FAIL() << "no error reported";
    } catch (const SceneError& e) {
        EXPECT_NE(std::string(e.what()).find("n.tif"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("t.yaml:3"), std::string::npos) << e.what();
    }
}

} // namespace
} // namespace spw::test
