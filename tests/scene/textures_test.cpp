// Texture values on every backend: a Layered texture (an image blended over a constant by an
// image mask) on a plane in a white furnace, each pixel's centre on a texel's centre, rendered
// with BSDF sampling only and max depth 1 so that every sample is exactly the albedo it found.
// And the texture system exists only for scenes with image textures.
#include "host/loaders/scene_loader.h"
#include "host/textures/textures.h"
#include "test_util.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cmath>

namespace spw::test {
namespace {

constexpr int kTexels = 8;

// An 8 x 8 float RGB image whose texel (column c, row r) is f(c, r).
template <class F> void writeImage(const std::string& path, F f) {
    auto out = OIIO::ImageOutput::create(path);
    ASSERT_TRUE(out) << OIIO::geterror();
    OIIO::ImageSpec spec(kTexels, kTexels, 3, OIIO::TypeDesc::FLOAT);
    std::vector<float> pixels;
    for (int r = 0; r < kTexels; ++r)
        for (int c = 0; c < kTexels; ++c) {
            const vec3 v = f(c, r);
            pixels.insert(pixels.end(), {v.x, v.y, v.z});
        }
    ASSERT_TRUE(out->open(path, spec)) << out->geterror();
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, pixels.data())) << out->geterror();
    ASSERT_TRUE(out->close()) << out->geterror();
}

vec3 upper(int c, int r) {
    return vec3(0.1f + 0.1f * c, 0.9f - 0.1f * r, 0.05f * float((c + r) % 4));
}
vec3 mask(int c, int r) {
    return vec3(float(c + kTexels * r) / float(kTexels * kTexels - 1));
}
const vec3 kLower(0.2f, 0.4f, 0.6f);

// A square of half-size 0.5 at y = -0.5 facing +Y, u along +x and v along +z (OBJ's v grows
// upwards in the image: row 0 is v = 1).
const char* kPlaneObj = "v -0.5 -0.5 -0.5\nv -0.5 -0.5 0.5\nv 0.5 -0.5 0.5\nv 0.5 -0.5 -0.5\n"
                        "vt 0 0\nvt 0 1\nvt 1 1\nvt 1 0\n"
                        "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";

TEST(Textures, LayeredImageOverConstantByImageMaskOnEveryBackend) {
    TempDir dir;
    dir.write("enclosure.obj", insideCubeObj());
    dir.write("plane.obj", kPlaneObj);
    writeImage(dir.file("upper.exr"), upper);
    writeImage(dir.file("mask.exr"), mask);
    // The camera 1 above the plane sees exactly its square (fov 53.13: tan = 0.5), so the 8 x 8
    // pixel centres land on the 8 x 8 texel centres.
    const Scene scene = loadScene(
        dir.write("t.yaml", "image: {width: 8, height: 8, sample base: 1, iterations: 4}\n"
                            "settings: {max depth: 1}\n"
                            "sampler: {type: Grid}\n"
                            "camera: {look at: {eye: [0, 0.5, 0], target: [0, -0.5, 0], up: [0, 0, "
                            "-1]}, fov: 53.130102354}\n"
                            "shaders:\n"
                            "  - {type: Emissive, emission: [1, 1, 1]}\n"
                            "  - type: Lambert\n"
                            "    texture:\n"
                            "      type: Layered\n"
                            "      upper: {type: Standard, string: upper.exr}\n"
                            "      lower: {type: Constant, colour: [0.2, 0.4, 0.6]}\n"
                            "      mask: {type: Standard, string: mask.exr}\n"
                            "objects:\n"
                            "  - {filename: enclosure.obj, shader: 0}\n"
                            "  - {filename: plane.obj, shader: 1}\n"));
    for (const std::string& backend : backendsUnderTest()) {
        RenderConfig cfg;
        cfg.backend = parseBackend(backend);
        cfg.strategy = kStrategyBsdf;
        // Full-precision rays: the compact record would round the albedo (now the throughput)
        // to bfloat16, unbiased but 2^-8 apart (CompactRay.* test that on its own).
        cfg.pipeline.rayFormat = RayFormat::Full;
        const auto result = render(scene, cfg);
        const std::vector<float> img = result->film->image();
        // --stats' texture counters: 256 camera hits on the plane, two image nodes each (the
        // bounces find the untextured enclosure); each 8 x 8 float image is one tile, read once.
        const nlohmann::json t = result->stats.toJson()["textures"];
        EXPECT_EQ(t["lookups"], 256 * 2) << backend;
        EXPECT_EQ(t["files_opened"], 2) << backend;
        EXPECT_EQ(t["files_reopened"], 0) << backend;
        EXPECT_EQ(t["tiles_read"], 2) << backend;
        EXPECT_EQ(t["bytes_read"], 2 * 8 * 8 * 3 * 4) << backend;
        EXPECT_GE(t["peak_cache_bytes"].get<double>(), 2 * 8 * 8 * 3 * 4) << backend;
        const double rays =
            double(result->stats.cameraRays + result->stats.bounceRays + result->stats.shadowRays);
        EXPECT_DOUBLE_EQ(t["per_ray"]["lookups"].get<double>(), 512 / rays) << backend;
        double worst = 0;
        for (int y = 0; y < 8; ++y)
            for (int x = 0; x < 8; ++x) {
                // Image column x looks at u = (x + 0.5) / 8; image row y (down) at z growing
                // downwards (up is -z), so v = (y + 0.5) / 8, texel row 7 - y.
                const int c = x, r = kTexels - 1 - y;
                const vec3 m = mask(c, r), expected = m * upper(c, r) + (vec3(1.0f) - m) * kLower;
                for (int k = 0; k < 3; ++k) {
                    const double got = img[size_t(y * 8 + x) * 3 + size_t(k)];
                    worst = std::max(worst, std::fabs(got - expected[k]));
                    EXPECT_NEAR(got, expected[k], 1e-6)
                        << backend << ", pixel " << x << ", " << y << ", channel " << k;
                }
            }
        std::printf("%s: worst |albedo - expected| %.3g\n", backend.c_str(), worst);
    }
}

// "Leave out what the scene does not need": Constant textures are evaluated without
// OpenImageIO; a Standard texture brings the texture system in.
TEST(Textures, NoTextureSystemWithoutImageTextures) {
    TempDir dir;
    writeImage(dir.file("a.exr"), upper);
    const std::string head = "shader:\n  type: Lambert\n  texture:\n";
    const Scene constant = loadScene(dir.write(
        "c.yaml", head + "    type: Layered\n    upper: {type: Constant, colour: [1, 0, 0]}\n"
                         "    lower: {type: Constant, colour: [0, 1, 0]}\n    mask: {type: "
                         "Constant, colour: [0.25, 0.5, 1]}\n"));
    TextureResolver none(constant, 64.0);
    EXPECT_FALSE(none.active());
    const vec3 a = none.albedo(constant.shaders[0], vec2(0.3f, 0.7f), 0.0f);
    EXPECT_EQ(a, vec3(0.25f, 0.5f, 0.0f));
    const Scene image =
        loadScene(dir.write("i.yaml", head + "    {type: Standard, string: a.exr}\n"));
    EXPECT_TRUE(TextureResolver(image, 64.0).active());
    EXPECT_EQ(none.statistics().lookups, 0u);
}

// --stats has no `textures` object (not even zeros) for a scene without image textures.
TEST(Textures, NoTextureStatisticsWithoutImageTextures) {
    const Scene box = loadScene(sourceDir() + "/scenes/cornell-box.yaml");
    RenderConfig cfg;
    cfg.spp = 1;
    EXPECT_FALSE(render(box, cfg)->stats.toJson().contains("textures"));
}

} // namespace
} // namespace spw::test
