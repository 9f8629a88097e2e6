// Ray cones (shared/cone.h) pick the MIP level a pixel needs. A plane seen straight down from
// height h, through a 16 x 16 image of a 53.13-degree field (tan = 0.5), has a pixel footprint of
// h/16 world units at the image centre; the plane's texture coordinates are its world x and z, so
// on a 64^2 texture the footprint is 4h texels of level 0 and the level read is log2(4h). Each
// render is a white furnace seen through BSDF sampling at max depth 1, so a pixel is exactly the
// albedo its lookups returned, on every backend. (The camera stands half a texel off the origin,
// so that at height 16 the pixels' centres fall on texel centres, not between texels.)
#include "host/loaders/scene_loader.h"
#include "test_util.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cmath>

namespace spw::test {
namespace {

constexpr int kRes = 64, kImage = 16;

// A tiled, MIP-mapped one-channel float OpenEXR whose level k (kRes >> k texels wide) is
// level(k, column, row).
template <class F> void writeMipmapped(const std::string& path, F level) {
    auto out = OIIO::ImageOutput::create(path);
    ASSERT_TRUE(out && out->supports("mipmap")) << OIIO::geterror();
    for (int k = 0; (kRes >> k) >= 1; ++k) {
        const int n = kRes >> k;
        OIIO::ImageSpec spec(n, n, 1, OIIO::TypeDesc::FLOAT);
        spec.tile_width = spec.tile_height = 16;
        spec.attribute("textureformat", "Plain Texture");
        spec.attribute("wrapmodes", "periodic,periodic");
        ASSERT_TRUE(out->open(
            path, spec, k == 0 ? OIIO::ImageOutput::Create : OIIO::ImageOutput::AppendMIPLevel))
            << out->geterror();
        std::vector<float> pixels(size_t(n) * size_t(n));
        for (int r = 0; r < n; ++r)
            for (int c = 0; c < n; ++c)
                pixels[size_t(r * n + c)] = level(k, c, r);
        ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, pixels.data())) << out->geterror();
    }
    ASSERT_TRUE(out->close()) << out->geterror();
}

// The 16 x 16 image of the plane from height h, with `texture` on it.
std::vector<float> planeFromAbove(const TempDir& dir, const std::string& texture, double h,
                                  const std::string& backend, TextureFilter filter) {
    const Scene scene = loadScene(dir.write(
        "plane.yaml", "image: {width: 16, height: 16, sample base: 1, iterations: 1}\n"
                      "settings: {max depth: 1}\n"
                      "sampler: {type: Grid}\n"
                      "camera: {look at: {eye: [0.5078125, " +
                          std::to_string(h) +
                          ", 0.5078125], target: [0.5078125, 0, 0.5078125], up: [0, 0, -1]}, fov: "
                          "53.130102354}\n"
                          "shaders:\n"
                          "  - {type: Emissive, emission: [1, 1, 1]}\n"
                          "  - {type: Lambert, texture: {type: Standard, string: " +
                          texture +
                          "}}\n"
                          "objects:\n"
                          "  - {filename: enclosure.obj, shader: 0, scale: [500, 500, 500]}\n"
                          "  - {filename: plane.obj, shader: 1}\n"));
    RenderConfig cfg;
    cfg.backend = parseBackend(backend);
    cfg.strategy = kStrategyBsdf;
    cfg.pipeline.rayFormat = RayFormat::Full;
    cfg.textureFilter = filter;
    return render(scene, cfg)->film->image();
}

// The mean of the central 4 x 4 pixels' first channel (their rays within 5 degrees of the
// normal, so their footprint is the centre's to 1 %).
double centre(const std::vector<float>& img) {
    double sum = 0;
    for (int y = 6; y < 10; ++y)
        for (int x = 6; x < 10; ++x)
            sum += img[size_t(y * kImage + x) * 3];
    return sum / 16;
}

void writeScene(const TempDir& dir) {
    dir.write("enclosure.obj", insideCubeObj());
    // A 200 x 200 square at y = 0 facing +Y whose texture coordinates are its x and z.
    dir.write("plane.obj", "v -100 0 -100\nv -100 0 100\nv 100 0 100\nv 100 0 -100\n"
                           "vt -100 100\nvt -100 -100\nvt 100 -100\nvt 100 100\n"
                           "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n");
}

// Each MIP level a constant: level k reads k / 8, so a pixel says which level it read, the
// trilinear blend of two levels included. Doubling the height moves one level coarser.
TEST(TextureFilter, ThePlaneFartherAwayReadsCoarserMipLevels) {
    TempDir dir;
    writeScene(dir);
    writeMipmapped(dir.file("levels.exr"), [](int k, int, int) { return float(k) / 8.0f; });
    for (const std::string& backend : backendsUnderTest()) {
        for (double h : {0.5, 1.0, 2.0, 4.0, 8.0}) {
            const double expected = std::log2(4.0 * h);
            const double level =
                8.0 * centre(planeFromAbove(dir, "levels.exr", h, backend, TextureFilter::Cone));
            std::printf("%s, height %g: level read %.3f, footprint's log2 %.3f\n", backend.c_str(),
                        h, level, expected);
            // The cone's spread is quantised (up to 12.5 %: 0.17 of a level).
            EXPECT_NEAR(level, expected, 0.25) << backend << ", height " << h;
        }
        // Without the cone, the finest level whatever the distance.
        EXPECT_EQ(centre(planeFromAbove(dir, "levels.exr", 8.0, backend, TextureFilter::Finest)),
                  0.0)
            << backend;
    }
}

// A texel checkerboard of 0 and 1, box-filtered into its MIP levels (all 0.5 from level 1 on).
// Seen from afar each pixel is the prefiltered mean, 0.5, from one sample; read at the finest
// level each pixel is a point sample of the checker, 0 or 1.
TEST(TextureFilter, AFarPlaneConvergesToThePrefilteredMean) {
    TempDir dir;
    writeScene(dir);
    writeMipmapped(dir.file("checker.exr"),
                   [](int k, int c, int r) { return k == 0 ? float((c + r) % 2) : 0.5f; });
    for (const std::string& backend : backendsUnderTest()) {
        double previous = 1.0;
        for (double h : {0.25, 1.0, 4.0, 16.0}) {
            const std::vector<float> img =
                planeFromAbove(dir, "checker.exr", h, backend, TextureFilter::Cone);
            double worst = 0;
            for (int y = 4; y < 12; ++y)
                for (int x = 4; x < 12; ++x)
                    worst = std::max(worst, std::fabs(img[size_t(y * kImage + x) * 3] - 0.5));
            std::printf("%s, height %g: worst |pixel - 0.5| %.4f\n", backend.c_str(), h, worst);
            EXPECT_LE(worst, previous + 1e-6) << backend << ", height " << h;
            previous = worst;
        }
        EXPECT_LE(previous, 1e-6) << backend;
        const std::vector<float> finest =
            planeFromAbove(dir, "checker.exr", 16.0, backend, TextureFilter::Finest);
        EXPECT_NEAR(std::fabs(finest[size_t(8 * kImage + 8) * 3] - 0.5), 0.5, 1e-3) << backend;
    }
}

} // namespace
} // namespace spw::test
