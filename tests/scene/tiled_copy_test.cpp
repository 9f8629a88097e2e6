// Tiled copies of large untiled images (host/textures/tiled_copy.h): a PNG over 16 MiB decoded
// is read through a 64 x 64-tiled, MIP-mapped copy in an unnamed scratch file. Its finest level
// is the image bit for bit; its coarser levels are averaged in linear light; a render is the
// same image under a texture cache far smaller than the image, which the cache then keeps to;
// no file is left in the scratch folder; copies are made only of the images lookups read, when
// they first read them; a folder where no file can be made is an error naming it, a truncated
// image a scene error naming the file. Images under the threshold are read as
// they always were, with no copy.
#include "host/image/image_io.h"
#include "host/loaders/scene_loader.h"
#include "host/render/render.h"
#include "host/textures/textures.h"
#include "host/textures/tiled_copy.h"
#include "test_util.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#if defined(__SANITIZE_ADDRESS__)
#define SPILLWAY_LSAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SPILLWAY_LSAN 1
#endif
#endif
#if SPILLWAY_LSAN
#include <sanitizer/lsan_interface.h>
#endif

#include <algorithm>
#include <filesystem>
#include <random>
#include <stdexcept>

namespace spw::test {
namespace {

// LeakSanitizer ignores what is allocated while one lives (in the sanitized build).
struct LeakCheckPause {
#if SPILLWAY_LSAN
    LeakCheckPause() {
        __lsan_disable();
    }
    ~LeakCheckPause() {
        __lsan_enable();
    }
#endif
};

// 2400 x 2400 RGB, 8-bit, untiled, in the format `path` names: 17.3 MB decoded, over
// kTiledCopyMinBytes. Red is a checker of 0 and 255 a texel square; green and blue are
// pseudo-random.
constexpr int kSide = 2400;

std::vector<unsigned char> writeLargePng(const std::string& path) {
    std::vector<unsigned char> px(size_t(kSide) * kSide * 3);
    std::mt19937 rng(11);
    for (int y = 0; y < kSide; ++y)
        for (int x = 0; x < kSide; ++x) {
            unsigned char* p = &px[(size_t(y) * kSide + size_t(x)) * 3];
            p[0] = (x + y) % 2 ? 255 : 0;
            p[1] = static_cast<unsigned char>(rng());
            p[2] = static_cast<unsigned char>(rng());
        }
    auto out = OIIO::ImageOutput::create(path);
    EXPECT_TRUE(out && out->open(path, OIIO::ImageSpec(kSide, kSide, 3, OIIO::TypeDesc::UINT8)));
    EXPECT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, px.data()));
    EXPECT_TRUE(out->close());
    return px;
}

// A plane filling the view of a camera above it, textured by `image`.
std::string planeScene(const TempDir& dir, const std::string& image) {
    dir.write("plane.obj", "v -0.5 -0.5 -0.5\nv -0.5 -0.5 0.5\nv 0.5 -0.5 0.5\nv 0.5 -0.5 -0.5\n"
                           "vt 0 0\nvt 0 1\nvt 1 1\nvt 1 0\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n");
    return dir.write("t.yaml",
                     "image: {width: 32, height: 32, sample base: 4, iterations: 1}\n"
                     "settings: {max depth: 1}\n"
                     "camera: {look at: {eye: [0, 0.5, 0], target: [0, -0.5, 0], up: [0, 0, -1]}, "
                     "fov: 40}\n"
                     "shader: {type: Lambert, texture: {type: Standard, string: " +
                         image +
                         "}}\n"
                         "object: {filename: plane.obj}\n"
                         "light: {type: Environment, colour: [1, 1, 1]}\n");
}

TEST(TiledCopy, TheFinestLevelIsTheImageBitForBitAndCoarserLevelsAverageInLinearLight) {
    TempDir dir;
    const std::vector<unsigned char> px = writeLargePng(dir.file("large.png"));
    const Scene scene = loadScene(planeScene(dir, "large.png"));
    const TextureResolver textures(scene, 64.0, true, true, dir.path());
    EXPECT_EQ(textures.statistics().tiledCopies, 0u) << "the copy waits for a lookup to read it";
    EXPECT_TRUE(textures.copiesPending());
    // At the finest level every lookup is the one the same pixels give read as they are (here
    // from a TIFF of 64 x 64 tiles, one level, which needs no copy), to the bit.
    {
        auto out = OIIO::ImageOutput::create("tif");
        OIIO::ImageSpec spec(kSide, kSide, 3, OIIO::TypeDesc::UINT8);
        spec.tile_width = spec.tile_height = 64;
        ASSERT_TRUE(out && out->open(dir.file("tiled.tif"), spec));
        ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, px.data()));
        ASSERT_TRUE(out->close());
    }
    const Scene direct = loadScene(planeScene(dir, "tiled.tif"));
    const TextureResolver reference(direct, 64.0, true, true, dir.path());
    EXPECT_EQ(reference.statistics().tiledCopies, 0u);
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-0.5f, 1.5f);
    for (int i = 0; i < 5000; ++i) {
        const vec2 uv(u(rng), u(rng));
        ASSERT_EQ(textures.albedo(scene.shaders[0], uv, 0.0f),
                  reference.albedo(direct.shaders[0], uv, 0.0f))
            << uv.x << ", " << uv.y;
    }
    const TextureStatistics s = textures.statistics();
    EXPECT_EQ(s.tiledCopies, 1u);
    EXPECT_FALSE(textures.copiesPending());
    // Every level, 2400 down to 1: 4/3 of the finest within the levels' rounding.
    EXPECT_GT(s.tiledCopyBytes, px.size() * 4 / 3 - px.size() / 100);
    EXPECT_LT(s.tiledCopyBytes, px.size() * 4 / 3 + px.size() / 100);
    // A footprint of the whole image reads the coarsest levels: the red checker of 0 and 1
    // averages to 0.5 in linear light (0.216 had the sRGB codes been averaged), within the
    // 8-bit rounding of the levels between.
    const vec3 coarse = textures.albedo(scene.shaders[0], vec2(0.3f, 0.6f), 4.0f);
    EXPECT_NEAR(coarse.x, 0.5f, 0.01f);
    textures.checkErrors();
}

TEST(TiledCopy, ARenderIsTheSameUnderACacheFarSmallerThanTheImageAndLeavesNoFile) {
    TempDir dir, scratch;
    writeLargePng(dir.file("large.png"));
    Scene scene = loadScene(planeScene(dir, "large.png"));
    std::vector<float> images[2];
    std::uint64_t peaks[2];
    const double budgets[2] = {1024.0, 1.0};
    for (int i = 0; i < 2; ++i) {
        scene.settings.textureCacheMiB = budgets[i];
        RenderConfig cfg;
        cfg.backend = BackendKind::Cpu;
        cfg.pipeline.spillDir = scratch.path();
        const auto result = render(scene, cfg);
        images[i] = result->film->image();
        const nlohmann::json t = result->stats.toJson()["textures"];
        EXPECT_EQ(t["tiled_copies"], 1);
        peaks[i] = t["peak_cache_bytes"].get<std::uint64_t>();
        EXPECT_GT(result->stats.stages.get("tile textures"), 0.0);
        // The copy is an unnamed file: nothing in the folder, during the render or after it.
        EXPECT_TRUE(std::filesystem::is_empty(scratch.path()));
    }
    EXPECT_EQ(images[0], images[1]);
    // 17 MB decoded, read through a 1 MiB cache: the cache stays within a few tiles of it.
    EXPECT_LT(peaks[1], std::uint64_t(2) << 20);
}

TEST(TiledCopy, AFolderWhereNoFileCanBeMadeIsAnErrorNamingIt) {
    TempDir dir;
    writeLargePng(dir.file("large.png"));
    const Scene scene = loadScene(planeScene(dir, "large.png"));
    try {
        const TextureResolver textures(scene, 64.0, true, true, dir.file("no-such-folder"));
        ADD_FAILURE() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("cannot create a texture tile file in '" +
                                             dir.file("no-such-folder") + "'"),
                  std::string::npos)
            << e.what();
    }
}

// A scratch folder without room for the copy (a 1 MiB file system, mounted in a namespace of its
// own) is exit 1 saying so: the folder, that it is full, what is free and what the copy needs,
// and the option that chooses another; one line, not one per tile. Where namespaces are not
// allowed (an unprivileged container), skipped.
TEST(TiledCopy, AFullScratchFolderIsSaidToBeFull) {
    TempDir dir;
    writeLargePng(dir.file("large.png"));
    const std::string scene = planeScene(dir, "large.png"), full = dir.file("full");
    std::filesystem::create_directory(full);
    const std::string mount = "unshare -m sh -c 'mount -t tmpfs -o size=1m tmpfs " + full;
    if (runShell(mount + "'").status != 0) GTEST_SKIP() << "no mount namespace here";
    const CommandResult r = runShell(mount + " && exec " + binary() + " render " + scene + " -o " +
                                     dir.file("o.exr") + " --spill-dir " + full + "'");
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("the tiled copy of texture file '" + dir.file("large.png") +
                            "' cannot be made: the scratch folder '" + full +
                            "' is full (1.0 MiB free, the copy needs 22.0 MiB; --spill-dir "
                            "chooses another)"),
              std::string::npos)
        << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir.file("o.exr")));
}

// An image whose copy needs more memory than the process may take (a PNG header claiming 30000²
// under a 1.5 GB address-space limit) is exit 1 naming the image, its size and the memory its
// copy needs, not a bare std::bad_alloc. (Not under the sanitizers, whose shadow memory a
// limit on the address space leaves no room for.)
TEST(TiledCopy, AnImageTooLargeForTheMemoryIsSaidToBe) {
#if SPILLWAY_LSAN
    GTEST_SKIP() << "an address-space limit and AddressSanitizer do not mix";
#endif
    TempDir dir;
    // IHDR 30000 x 30000, 8-bit RGB, and no pixels: the header is all the loader reads.
    const auto be32 = [](std::uint32_t v) {
        std::string out;
        for (int k = 3; k >= 0; --k)
            out += char((v >> (8 * k)) & 0xff);
        return out;
    };
    const auto chunk = [&](const std::string& type, const std::string& data) {
        std::uint32_t crc = 0xffffffffu; // PNG's CRC-32, bit by bit
        for (unsigned char c : type + data) {
            crc ^= c;
            for (int bit = 0; bit < 8; ++bit)
                crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
        }
        return be32(std::uint32_t(data.size())) + type + data + be32(~crc);
    };
    const std::string ihdr = be32(30000) + be32(30000) + std::string("\x08\x02\x00\x00\x00", 5);
    const std::string noPixels("\x78\x9c\x03\x00\x00\x00\x00\x01", 8); // zlib's empty stream
    dir.write("huge.png", std::string("\x89PNG\r\n\x1a\n", 8) + chunk("IHDR", ihdr) +
                              chunk("IDAT", noPixels) + chunk("IEND", ""));
    const std::string scene = planeScene(dir, "huge.png");
    const CommandResult r =
        runShell("ulimit -v 1500000 && MALLOC_ARENA_MAX=2 " + binary() + " render " + scene +
                 " -o " + dir.file("o.exr") + " --backend cpu --threads 2 --quiet");
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("the tiled copy of texture file '" + dir.file("huge.png") +
                            "' cannot be made: not enough memory for image '" +
                            dir.file("huge.png") +
                            "' (30000 x 30000): it needs 5.0 GiB, more "
                            "than this process may take"),
              std::string::npos)
        << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir.file("o.exr")));
}

// A scratch folder that goes away after the render has started (made at the first lookup, the
// copy cannot be written) is a runtime error naming the texture (exit 1), not the scene's.
TEST(TiledCopy, AFolderThatGoesAwayIsARuntimeErrorNotTheScenes) {
    TempDir dir;
    writeLargePng(dir.file("large.png"));
    const Scene scene = loadScene(planeScene(dir, "large.png"));
    const std::string folder = dir.file("scratch");
    std::filesystem::create_directory(folder);
    const TextureResolver textures(scene, 64.0, true, true, folder);
    std::filesystem::remove(folder);
    textures.albedo(scene.shaders[0], vec2(0.5f), 0.0f);
    try {
        textures.checkErrors();
        ADD_FAILURE() << "no error";
    } catch (const SceneError& e) {
        ADD_FAILURE() << "a scene error: " << e.what();
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("the tiled copy of texture file '" +
                                             dir.file("large.png") + "' cannot be made"),
                  std::string::npos)
            << e.what();
    }
}

// A large image whose pixels stop short of its header's size is a scene error naming the
// texture file (exit 2), found when the copy reads it: at the first lookup, reported after the
// iteration as any failed lookup is.
TEST(TiledCopy, ATruncatedImageIsASceneErrorNamingIt) {
    TempDir dir;
    writeLargePng(dir.file("large.png"));
    std::filesystem::resize_file(dir.file("large.png"),
                                 std::filesystem::file_size(dir.file("large.png")) / 2);
    const Scene scene = loadScene(planeScene(dir, "large.png"));
    // OpenImageIO 2.4's PNG reader leaks a string when libpng gives up on a truncated file
    // (tests/fuzz/lsan.supp names it, but only the slow unwinder reaches its frames): what it
    // allocates while reading is not LeakSanitizer's to report here.
    [[maybe_unused]] LeakCheckPause pause;
    const TextureResolver textures(scene, 64.0, true, true, dir.path());
    textures.albedo(scene.shaders[0], vec2(0.5f), 0.0f);
    try {
        textures.checkErrors();
        ADD_FAILURE() << "no error";
    } catch (const SceneError& e) {
        EXPECT_NE(std::string(e.what()).find("texture file '" + dir.file("large.png") +
                                             "' cannot be read"),
                  std::string::npos)
            << e.what();
    }
}

// Copies are made for the images rays read, when they first read them: prepare() makes those of
// the shaders it is given (in parallel, several at once) and no other; a lookup makes its own
// image's where none was prepared. The lookups are the same to the bit either way, and an image
// no shader of a render's hits reads is never copied.
TEST(TiledCopy, CopiesAreMadeForTheImagesLookupsReadAndNoOther) {
    TempDir dir;
    writeLargePng(dir.file("large.png"));
    std::filesystem::copy_file(dir.file("large.png"), dir.file("other.png"));
    Scene scene = loadScene(planeScene(dir, "large.png"));
    // A second shader reading the other file, which no object wears.
    Texture other = scene.textures[size_t(scene.shaders[0].texture)];
    other.path = dir.file("other.png");
    scene.textures.push_back(other);
    scene.shaders.push_back(scene.shaders[0]);
    scene.shaders[1].texture = int(scene.textures.size()) - 1;
    const TextureResolver lazy(scene, 64.0, true, true, dir.path());
    const TextureResolver prepared(scene, 64.0, true, true, dir.path());
    prepared.prepare({true, false});
    EXPECT_EQ(prepared.statistics().tiledCopies, 1u);
    EXPECT_TRUE(prepared.copiesPending());
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int i = 0; i < 200; ++i) {
        const vec2 uv(u(rng), u(rng));
        const float footprint = u(rng) * 0.01f;
        ASSERT_EQ(lazy.albedo(scene.shaders[0], uv, footprint),
                  prepared.albedo(scene.shaders[0], uv, footprint));
    }
    EXPECT_EQ(lazy.statistics().tiledCopies, 1u) << "the lookup made its image's copy";
    prepared.prepare({true, true});
    EXPECT_EQ(prepared.statistics().tiledCopies, 2u);
    EXPECT_FALSE(prepared.copiesPending());
    // A render: its hits read the plane's shader, never the second one.
    RenderConfig cfg;
    cfg.backend = BackendKind::Cpu;
    cfg.pipeline.spillDir = dir.path();
    EXPECT_EQ(render(scene, cfg)->stats.toJson()["textures"]["tiled_copies"], 1);
    lazy.checkErrors();
    prepared.checkErrors();
}

TEST(TiledCopy, ImagesUnderTheThresholdAreReadAsTheyAre) {
    OIIO::ImageSpec small(2048, 2048, 4, OIIO::TypeDesc::UINT8); // 16 MiB exactly
    small.tile_width = small.tile_height = 2048;
    EXPECT_FALSE(needsTiledCopy(small, 1));
    OIIO::ImageSpec large(2049, 2048, 4, OIIO::TypeDesc::UINT8);
    large.tile_width = 2049, large.tile_height = 2048;
    EXPECT_TRUE(needsTiledCopy(large, 1));
    EXPECT_FALSE(needsTiledCopy(large, 2)); // MIP-mapped: made to be read so
    large.tile_width = large.tile_height = 64;
    EXPECT_FALSE(needsTiledCopy(large, 1)); // tiled
}

} // namespace
} // namespace spw::test
