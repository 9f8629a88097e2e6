// glTF materials' images as the tests write them: base colour images embedded or beside the
// file, KHR_texture_transform, sampler wrap modes, the texture coordinate set each image names,
// and alpha (MASK cut-outs and BLEND's stochastic transparency), on every backend where the
// render depends on it.
#include "host/loaders/scene_loader.h"
#include "scene/gltf_builder.h"
#include "test_util.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>

namespace spw::test {
namespace {

using nlohmann::json;

// A base colour image, embedded in a .glb's buffer, as a data: URI, or a file beside the .gltf,
// read through the same texture cache: a green image under a white factor renders green.
TEST(Gltf, BaseColourImagesEmbeddedOrBesideTheFileAreRendered) {
    TempDir dir;
    const std::string png = dir.file("green.png");
    {
        OIIO::ImageBuf green(OIIO::ImageSpec(4, 4, 3, OIIO::TypeDesc::UINT8));
        const float g[3] = {0.0f, 1.0f, 0.0f};
        OIIO::ImageBufAlgo::fill(green, g);
        ASSERT_TRUE(green.write(png));
    }
    const std::string pngBytes = readFile(png);
    auto channelMeans = [](const Scene& scene) {
        RenderConfig cfg;
        cfg.backend = BackendKind::Reference;
        cfg.spp = 4;
        Scene small = scene;
        small.image.width = small.image.height = 8;
        const std::vector<float> img = render(small, cfg)->film->image();
        vec3 sum(0.0f);
        for (size_t i = 0; i + 2 < img.size(); i += 3)
            sum += vec3(img[i], img[i + 1], img[i + 2]);
        return sum;
    };
    for (const char* how : {"glb", "data", "file"}) {
        GltfBuilder b;
        json mat = material(vec3(1.0f), 0.0f, 1.0f);
        mat["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
        b.doc["materials"] = json::array({mat});
        b.doc["textures"] = json::array({{{"source", 0}}});
        if (std::string(how) == "file") {
            b.doc["images"] = json::array({{{"uri", "green.png"}}});
        } else if (std::string(how) == "data") {
            b.doc["images"] =
                json::array({{{"uri", "data:image/png;base64," + GltfBuilder::base64(pngBytes)}}});
        } else {
            while (b.bytes.size() % 4 != 0)
                b.bytes.push_back('\0');
            b.doc["bufferViews"].push_back(
                {{"buffer", 0}, {"byteOffset", b.bytes.size()}, {"byteLength", pngBytes.size()}});
            b.bytes += pngBytes;
            b.doc["images"] = json::array(
                {{{"bufferView", b.doc["bufferViews"].size() - 1}, {"mimeType", "image/png"}}});
        }
        json prim = b.quad(0);
        b.doc["cameras"] = json::array(
            {{{"type", "perspective"},
              {"perspective", {{"yfov", 0.25}, {"aspectRatio", 1.0}, {"znear", 0.1}}}}});
        b.scene({b.node({{"mesh", b.mesh(prim)}}),
                 b.node({{"camera", 0}, {"translation", {0.5, 0.5, 3}}})});
        const std::string path =
            std::string(how) == "glb" ? b.binary(dir, "g.glb") : b.embedded(dir, "g.gltf");
        const Scene scene = loadScene(path);
        ASSERT_TRUE(scene.usesTextures()) << how;
        EXPECT_TRUE(scene.warnings.empty()) << how << ": " << scene.warnings.at(0);
        const vec3 m = channelMeans(scene);
        EXPECT_GT(m.y, 0.0f) << how;
        EXPECT_LT(m.x, 0.1f * m.y) << how << ": the image's green, not the white factor";
    }
}

// An image red in its left half, green in its right (16 x 4), as halves.png in `dir`.
void writeHalves(const TempDir& dir) {
    OIIO::ImageBuf img(OIIO::ImageSpec(16, 4, 3, OIIO::TypeDesc::UINT8));
    const float red[3] = {1.0f, 0.0f, 0.0f}, green[3] = {0.0f, 1.0f, 0.0f};
    OIIO::ImageBufAlgo::fill(img, red, OIIO::ROI(0, 8, 0, 4));
    OIIO::ImageBufAlgo::fill(img, green, OIIO::ROI(8, 16, 0, 4));
    ASSERT_TRUE(img.write(dir.file("halves.png")));
}

// A glTF file as halvesQuad writes it: `info` is the texture reference (its index set here;
// its extensions kept), `sampler` the texture's sampler (none: glTF's default); `uv1`, where
// not empty, the quad's TEXCOORD_1.
std::string halvesFile(const TempDir& dir, json info, const json& sampler = json(),
                       const std::vector<float>& uv1 = {}) {
    GltfBuilder b;
    json mat = material(vec3(1.0f), 0.0f, 1.0f);
    info["index"] = 0;
    mat["pbrMetallicRoughness"]["baseColorTexture"] = info;
    b.doc["materials"] = json::array({mat});
    b.doc["textures"] = json::array({{{"source", 0}}});
    if (!sampler.is_null()) {
        b.doc["samplers"] = json::array({sampler});
        b.doc["textures"][0]["sampler"] = 0;
    }
    b.doc["images"] = json::array({{{"uri", "halves.png"}}});
    b.doc["extensionsUsed"] = {"KHR_texture_transform"};
    b.doc["cameras"] =
        json::array({{{"type", "perspective"},
                      {"perspective", {{"yfov", 0.25}, {"aspectRatio", 1.0}, {"znear", 0.1}}}}});
    json prim = b.quad(0);
    if (!uv1.empty()) prim["attributes"]["TEXCOORD_1"] = b.accessor<float>(uv1, 5126, "VEC2");
    b.scene({b.node({{"mesh", b.mesh(prim)}}),
             b.node({{"camera", 0}, {"translation", {0.5, 0.5, 3}}})});
    return b.embedded(dir, "halves.gltf");
}

// halves.png as the base colour of a view-filling quad (halvesFile's arguments). The 16 x 16
// image, 4 spp, on `backend`.
std::vector<float> halvesQuad(const TempDir& dir, json info, const json& sampler = json(),
                              const std::vector<float>& uv1 = {},
                              BackendKind backend = BackendKind::Cpu) {
    Scene scene = loadScene(halvesFile(dir, std::move(info), sampler, uv1));
    EXPECT_TRUE(scene.warnings.empty()) << scene.warnings.at(0);
    scene.image.width = scene.image.height = 16;
    RenderConfig cfg;
    cfg.backend = backend;
    cfg.spp = 4;
    return render(scene, cfg)->film->image();
}

// Red over green in the whole of a 16 x 16 image.
double redOverGreen(const std::vector<float>& img) {
    double r = 0, g = 0;
    for (size_t i = 0; i < img.size(); i += 3)
        r += img[i], g += img[i + 1];
    return r / g;
}

// KHR_texture_transform: an image red in its left half, green in its right; offset 0.5 and
// scale 0.5 in u map the quad onto the green half alone, where without it both halves show.
TEST(Gltf, TextureTransformMovesTheLookups) {
    TempDir dir;
    writeHalves(dir);
    // Red over green in image rows [row0, row1) of a 16 x 16 render.
    auto redOverGreen = [&](const json& transform, int row0 = 0, int row1 = 16) {
        json info = json::object();
        if (!transform.is_null()) info["extensions"]["KHR_texture_transform"] = transform;
        const std::vector<float> img = halvesQuad(dir, info);
        double r = 0, g = 0;
        for (size_t i = size_t(row0) * 16 * 3; i < size_t(row1) * 16 * 3; i += 3)
            r += img[i], g += img[i + 1];
        return r / g;
    };
    const double plain = redOverGreen(json());
    const double moved = redOverGreen({{"offset", {0.5, 0.0}}, {"scale", {0.5, 1.0}}});
    EXPECT_GT(plain, 0.5);
    EXPECT_LT(plain, 2.0);
    EXPECT_LT(moved, 0.1);
    // Turned a quarter, then moved by (1, 0): u' = v + 1, read as v under the default repeat
    // (glTF's v runs down the quad), so the image's red half lies along the quad's top, its
    // green along the bottom: the image turned clockwise as seen. Turned the other way, the
    // other way round.
    const json quarter = {{"offset", {1.0, 0.0}}, {"rotation", M_PI / 2}};
    EXPECT_GT(redOverGreen(quarter, 0, 6), 10.0);
    EXPECT_LT(redOverGreen(quarter, 10, 16), 0.1);
}

// The arrangement of Khronos' TextureTransformTest (its bottom-left quad), made here: an image
// black but for a red mark on its u axis near the top edge, turned 22.5 degrees about the
// texture coordinates' origin (the image's top-left corner) and clamped to its edges. Turned as
// the extension's reference model, Blender and three.js turn it, the mark moves clockwise as
// seen, into the quad, where the model's green marker is; turned the other way it would leave
// the quad (the model's red marker), and nothing red would show. On every backend.
TEST(Gltf, TextureRotationTurnsTheImageAsTheReferenceModelDoes) {
    TempDir dir;
    constexpr int kSide = 40; // the mark: texels [30, 34) x [2, 6), centred on (0.8, 0.1)
    {
        OIIO::ImageBuf img(OIIO::ImageSpec(kSide, kSide, 3, OIIO::TypeDesc::UINT8));
        const float black[3] = {0.0f, 0.0f, 0.0f}, red[3] = {1.0f, 0.0f, 0.0f};
        OIIO::ImageBufAlgo::fill(img, black);
        OIIO::ImageBufAlgo::fill(img, red, OIIO::ROI(30, 34, 2, 6));
        ASSERT_TRUE(img.write(dir.file("halves.png"))); // the file halvesFile names
    }
    const double angle = 0.392699; // the model's 22.5 degrees
    const json info = {{"extensions", {{"KHR_texture_transform", {{"rotation", angle}}}}}};
    const json clamp = {{"wrapS", 33071}, {"wrapT", 33071}};
    // Where the mark (0.8, 0.1) shows: the quad's (u, v) whose turned coordinates are the mark's.
    const double c = std::cos(angle), s = std::sin(angle);
    const double wantU = 0.8 * c - 0.1 * s, wantV = 0.8 * s + 0.1 * c; // (0.70, 0.40)
    constexpr int kRes = 32;
    const double halfView = 3.0 * std::tan(0.125); // the camera's yfov 0.25 at distance 3
    for (BackendKind backend : {BackendKind::Reference, BackendKind::Cpu, BackendKind::Vulkan}) {
        SCOPED_TRACE(backendName(backend));
        Scene scene = loadScene(halvesFile(dir, info, clamp));
        ASSERT_TRUE(scene.warnings.empty()) << scene.warnings.at(0);
        scene.image.width = scene.image.height = kRes;
        RenderConfig cfg;
        cfg.backend = backend;
        cfg.spp = 4;
        const std::vector<float> img = render(scene, cfg)->film->image();
        // The red mark's centroid, as the quad's (u, v): u = x, v = 1 - y (glTF's quad). Red
        // over green: the black quad's grey specular reflection of the environment left out.
        double red = 0, u = 0, v = 0;
        for (int py = 0; py < kRes; ++py)
            for (int px = 0; px < kRes; ++px) {
                const size_t i = size_t(py * kRes + px) * 3;
                const double r = double(img[i]) - double(img[i + 1]);
                red += r;
                u += r * (0.5 + ((px + 0.5) / kRes * 2 - 1) * halfView);
                v += r * (0.5 + ((py + 0.5) / kRes * 2 - 1) * halfView);
            }
        ASSERT_GT(red, 2.0) << "the mark turned out of the quad: the other way round";
        EXPECT_NEAR(u / red, wantU, 0.03);
        EXPECT_NEAR(v / red, wantV, 0.03);
    }
}

// The red-left, green-right image on the view-filling quad, u stretched to 3u - 1 (the quad's
// visible u, 0.12-0.88, reads the image from -0.63 to 1.63) under the sampler `sampler` (none:
// glTF's default, repeat); red over green in each of the 16 columns of a 16 x 16 render.
std::vector<double> wrappedColumns(const TempDir& dir, const json& sampler) {
    const json stretch = {{"offset", {-1.0, 0.0}}, {"scale", {3.0, 1.0}}};
    const std::vector<float> img =
        halvesQuad(dir, {{"extensions", {{"KHR_texture_transform", stretch}}}}, sampler);
    std::vector<double> ratio;
    for (int x = 0; x < 16; ++x) {
        double r = 0, g = 0;
        for (int y = 0; y < 16; ++y)
            r += img[size_t(y * 16 + x) * 3], g += img[size_t(y * 16 + x) * 3 + 1];
        ratio.push_back(r / g);
    }
    return ratio;
}

// TEXCOORD_1 maps the quad onto the image's green half alone (u from 0.5 to 1), where
// TEXCOORD_0 spans both halves. An image reads the set its texCoord names, or the one
// KHR_texture_transform's texCoord overrides it with, on every backend; a set the primitive
// lacks is warned about and read as (0, 0), the red corner; a texCoord that is no set index is
// refused, naming where.
TEST(Gltf, ImagesReadTheTextureCoordinateSetTheyName) {
    TempDir dir;
    writeHalves(dir);
    const std::vector<float> greenHalf = {0.5f, 1, 1, 1, 1, 0, 0.5f, 0};
    for (BackendKind backend : {BackendKind::Reference, BackendKind::Cpu, BackendKind::Vulkan}) {
        SCOPED_TRACE(backendName(backend));
        const double first =
            redOverGreen(halvesQuad(dir, json::object(), json(), greenHalf, backend));
        const double second =
            redOverGreen(halvesQuad(dir, {{"texCoord", 1}}, json(), greenHalf, backend));
        const json toSecond = {{"extensions", {{"KHR_texture_transform", {{"texCoord", 1}}}}}};
        const double overridden =
            redOverGreen(halvesQuad(dir, toSecond, json(), greenHalf, backend));
        EXPECT_GT(first, 0.5);
        EXPECT_LT(first, 2.0);
        EXPECT_LT(second, 0.05); // bilinear filtering lets a little red in at u = 0.5
        EXPECT_LT(overridden, 0.05);
    }
    Scene missing = loadScene(halvesFile(dir, {{"texCoord", 1}}));
    ASSERT_EQ(missing.warnings.size(), 1u);
    EXPECT_NE(missing.warnings[0].find("has no TEXCOORD_1"), std::string::npos)
        << missing.warnings[0];
    EXPECT_EQ(missing.meshes[0].uvs.size(), 0u);
    for (const json& bad : {json{{"texCoord", -1}}, json{{"texCoord", 256}}}) {
        try {
            loadScene(halvesFile(dir, bad, json(), greenHalf));
            ADD_FAILURE() << bad.dump();
        } catch (const SceneError& e) {
            EXPECT_NE(std::string(e.what()).find(
                          "/materials/0/pbrMetallicRoughness/baseColorTexture/texCoord: must be"),
                      std::string::npos)
                << e.what();
        }
    }
    const json half = {{"extensions", {{"KHR_texture_transform", {{"texCoord", 0.5}}}}}};
    try {
        loadScene(halvesFile(dir, half, json(), greenHalf));
        ADD_FAILURE();
    } catch (const SceneError& e) {
        EXPECT_NE(std::string(e.what()).find(
                      "baseColorTexture/extensions/KHR_texture_transform/texCoord: must be"),
                  std::string::npos)
            << e.what();
    }
}

// A sampler's wrap modes: repeat (the default, and 10497) alternates the halves along the quad;
// clamp to edge (33071) stretches the edge texels, red all the way left and green right;
// mirrored repeat (33648) folds the image back at its edges, green again at the far left and
// red at the far right. Columns 1-3 read u' from -0.49 to -0.07, 12-14 from 1.07 to 1.49,
// column 0 from -0.63 to -0.49.
TEST(Gltf, SamplerWrapModesRepeatClampOrMirror) {
    TempDir dir;
    writeHalves(dir);
    const auto columns = [](const std::vector<double>& r, int x0, int x1) {
        double lo = 1e30, hi = 0;
        for (int x = x0; x < x1; ++x)
            lo = std::min(lo, r[size_t(x)]), hi = std::max(hi, r[size_t(x)]);
        return std::make_pair(lo, hi);
    };
    for (const json& sampler : {json(), json{{"wrapS", 10497}, {"wrapT", 10497}}}) {
        const std::vector<double> repeat = wrappedColumns(dir, sampler);
        EXPECT_LT(columns(repeat, 1, 4).second, 0.1);   // u' -0.49 .. -0.07: the green half
        EXPECT_GT(columns(repeat, 12, 15).first, 10.0); // 1.07 .. 1.49: the red half
    }
    const std::vector<double> clamp = wrappedColumns(dir, {{"wrapS", 33071}, {"wrapT", 10497}});
    EXPECT_GT(columns(clamp, 0, 4).first, 10.0);
    EXPECT_LT(columns(clamp, 12, 16).second, 0.1);
    const std::vector<double> mirror = wrappedColumns(dir, {{"wrapS", 33648}, {"wrapT", 33071}});
    EXPECT_GT(columns(mirror, 1, 4).first, 10.0);
    EXPECT_LT(columns(mirror, 12, 15).second, 0.1);
    EXPECT_LT(mirror[0], 0.5);  // mostly beyond -0.5: green, folded back
    EXPECT_GT(mirror[15], 2.0); // mostly beyond 1.5: red
}

// A white floor lit by a directional light slanting down, seen from above; and, unless `veil` is
// null, a quad of material `veil` between them (z = 1). `image`: the veil's base colour image.
// The default layout (a 4 x 4 floor, a unit veil) hides part of the floor from the camera and
// shadows another part; wideVeil() covers the whole view and the whole floor.
struct VeilLayout {
    double floorSize = 4, floorCorner = -1.5, veilSize = 1, veilCorner = 0;
    double yfov = 0.6, cameraXY = 0.5;
    int maxDepth = 0, spp = 4; // maxDepth 0: the file's default
};
VeilLayout wideVeil(int spp) {
    VeilLayout l;
    l.floorSize = 8, l.floorCorner = -4, l.veilSize = 20, l.veilCorner = -10;
    l.yfov = 0.4, l.cameraXY = 0, l.maxDepth = 1, l.spp = spp;
    return l;
}
struct Veiled {
    std::vector<float> image;
    nlohmann::json stats;
};
Veiled renderVeiled(const TempDir& dir, const json& veil, BackendKind backend,
                    const std::string& image = "", const VeilLayout& l = {}) {
    GltfBuilder b;
    b.doc["materials"] = json::array({material(vec3(0.8f), 0.0f, 1.0f)});
    b.doc["extensionsUsed"] = {"KHR_lights_punctual"};
    b.doc["extensions"]["KHR_lights_punctual"]["lights"] =
        json::array({{{"type", "directional"}, {"intensity", 2000.0}}});
    b.doc["cameras"] =
        json::array({{{"type", "perspective"},
                      {"perspective", {{"yfov", l.yfov}, {"aspectRatio", 1.0}, {"znear", 0.1}}}}});
    std::vector<int> nodes = {
        b.node({{"mesh", b.mesh(b.quad(0))},
                {"scale", {l.floorSize, l.floorSize, l.floorSize}},
                {"translation", {l.floorCorner, l.floorCorner, 0}}}),
        b.node({{"camera", 0}, {"translation", {l.cameraXY, l.cameraXY, 5}}}),
        // Down, slanting toward +x: the veil's shadow lies half a unit aside, partly in view.
        b.node({{"rotation", {0, -0.2297529, 0, 0.9732489}},
                {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}})};
    if (!veil.is_null()) {
        b.doc["materials"].push_back(veil);
        if (!image.empty()) {
            b.doc["textures"] = json::array({{{"source", 0}}});
            b.doc["images"] = json::array({{{"uri", image}}});
        }
        nodes.push_back(b.node({{"mesh", b.mesh(b.quad(1))},
                                {"scale", {l.veilSize, l.veilSize, l.veilSize}},
                                {"translation", {l.veilCorner, l.veilCorner, 1}}}));
    }
    b.scene(nodes);
    Scene scene = loadScene(b.embedded(dir, "veiled.gltf"));
    EXPECT_TRUE(scene.warnings.empty()) << scene.warnings.at(0);
    scene.image.width = scene.image.height = 24;
    if (l.maxDepth > 0) scene.settings.maxDepth = l.maxDepth;
    RenderConfig cfg;
    cfg.backend = backend;
    cfg.spp = l.spp;
    const std::unique_ptr<RenderResult> r = render(scene, cfg);
    return {r->film->image(), r->stats.extra};
}

// The veil's material: blue, its alpha mode, base colour alpha and image.
json veilMaterial(const char* mode, float alpha = 1.0f, bool textured = false) {
    json m = material(vec3(0.2f, 0.4f, 0.8f), 0.0f, 0.5f);
    m["alphaMode"] = mode;
    m["pbrMetallicRoughness"]["baseColorFactor"][3] = alpha;
    if (textured) m["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
    return m;
}

// An RGBA image: white, its alpha `left` in the left half and `right` in the right half.
void writeAlphaImage(const std::string& path, float left, float right, int channels = 4) {
    OIIO::ImageBuf img(OIIO::ImageSpec(16, 4, channels, OIIO::TypeDesc::UINT8));
    const float a[4] = {1.0f, 1.0f, 1.0f, left}, c[4] = {1.0f, 1.0f, 1.0f, right};
    OIIO::ImageBufAlgo::fill(img, a, OIIO::ROI(0, 8, 0, 4, 0, 1, 0, channels));
    OIIO::ImageBufAlgo::fill(img, c, OIIO::ROI(8, 16, 0, 4, 0, 1, 0, channels));
    ASSERT_TRUE(img.write(path));
}

// The mean of columns [x0, x1) of a 24 x 24 image.
double columnsMean(const std::vector<float>& img, int x0, int x1) {
    double sum = 0;
    for (int y = 0; y < 24; ++y)
        for (int x = x0; x < x1; ++x)
            for (int c = 0; c < 3; ++c)
                sum += img[size_t(y * 24 + x) * 3 + size_t(c)];
    return sum / (24.0 * (x1 - x0) * 3.0);
}

// alphaMode MASK: where the base colour's alpha (factor times image) is below alphaCutoff, the
// surface is not there, for camera, bounce and shadow rays alike, on every backend. A veil that
// is all hole renders bit for bit the scene without it, its shadow gone too; one with no hole,
// the opaque veil; an image without alpha is opaque; an image half hole shows the floor in that
// half. Meshes without a cut-out get no filter.
TEST(Gltf, AlphaMaskCutsHolesForCameraBounceAndShadowRays) {
    TempDir dir;
    writeAlphaImage(dir.file("holes.png"), 0.0f, 0.0f);
    writeAlphaImage(dir.file("solid.png"), 1.0f, 1.0f);
    writeAlphaImage(dir.file("rgb.png"), 1.0f, 1.0f, 3);
    writeAlphaImage(dir.file("half.png"), 0.0f, 1.0f);
    for (BackendKind backend : {BackendKind::Reference, BackendKind::Cpu, BackendKind::Vulkan}) {
        SCOPED_TRACE(backendName(backend));
        const Veiled bare = renderVeiled(dir, json(), backend);
        const Veiled opaque = renderVeiled(dir, veilMaterial("OPAQUE"), backend);
        const Veiled opaqueImage =
            renderVeiled(dir, veilMaterial("OPAQUE", 1.0f, true), backend, "solid.png");
        EXPECT_FALSE(opaque.stats.contains("cutout_meshes"));
        EXPECT_NE(bare.image, opaque.image); // the veil and its shadow are seen
        // The factor alone: at least the cutoff is no cut-out; below it, no veil.
        const Veiled kept = renderVeiled(dir, veilMaterial("MASK", 0.5f), backend);
        EXPECT_EQ(kept.image, opaque.image);
        EXPECT_FALSE(kept.stats.contains("cutout_meshes"));
        const Veiled gone = renderVeiled(dir, veilMaterial("MASK", 0.3f), backend);
        EXPECT_EQ(gone.image, bare.image);
        EXPECT_EQ(gone.stats.value("cutout_meshes", 0), 1);
        // The image's alpha: all hole, none, or no alpha channel at all (opaque).
        EXPECT_EQ(renderVeiled(dir, veilMaterial("MASK", 1.0f, true), backend, "holes.png").image,
                  bare.image);
        // Embedded in the file: the colour and the alpha read from one image in memory.
        const std::string embedded =
            "data:image/png;base64," + GltfBuilder::base64(readFile(dir.file("holes.png")));
        EXPECT_EQ(renderVeiled(dir, veilMaterial("MASK", 1.0f, true), backend, embedded).image,
                  bare.image);
        EXPECT_EQ(renderVeiled(dir, veilMaterial("MASK", 1.0f, true), backend, "solid.png").image,
                  opaqueImage.image);
        EXPECT_EQ(renderVeiled(dir, veilMaterial("MASK", 1.0f, true), backend, "rgb.png").image,
                  opaqueImage.image);
        // Half a hole: the veil's left half (image columns 7-10) shows the floor as the bare
        // scene does, its right half (14-17) is the opaque veil.
        const Veiled half =
            renderVeiled(dir, veilMaterial("MASK", 1.0f, true), backend, "half.png");
        EXPECT_NEAR(columnsMean(half.image, 7, 11), columnsMean(bare.image, 7, 11),
                    0.02 * columnsMean(bare.image, 7, 11));
        EXPECT_NEAR(columnsMean(half.image, 14, 18), columnsMean(opaqueImage.image, 14, 18),
                    0.02 * columnsMean(opaqueImage.image, 14, 18));
        EXPECT_GT(std::fabs(columnsMean(bare.image, 7, 11) - columnsMean(opaque.image, 7, 11)),
                  0.1 * columnsMean(bare.image, 7, 11));
    }
}

} // namespace
} // namespace spw::test

namespace spw::test {
namespace {

// The mean of the wide veil's image (wideVeil, direct light only): with a BLEND veil of alpha a,
// each pixel is in expectation a times the opaque veil's radiance plus (1 - a)^2 times the bare
// floor's, the camera ray passing the veil with probability 1 - a and then the floor's shadow ray
// with 1 - a again.
double veiledFloorMean(const TempDir& dir, const json& veil, BackendKind backend, int spp,
                       const std::string& image = "") {
    return mean(renderVeiled(dir, veil, backend, image, wideVeil(spp)).image);
}

// alphaMode BLEND: stochastic transparency, the expected image the blend. A veil of alpha 0.3,
// 0.7 and (a texture's) 0.5: the mean within four standard errors of a L_opaque + (1 - a)^2
// L_bare, the standard error bounded from the samples taken: the floor and the veil are each
// evenly lit, so a sample's value lies in [0, twice the brighter of their means], and its
// variance is at most a quarter of that squared. On every backend.
TEST(Gltf, AlphaBlendIsStochasticTransparencyWhoseMeanIsTheBlend) {
    TempDir dir;
    writeAlphaImage(dir.file("half-alpha.png"), 0.5f, 0.5f);
    const int spp = 64;
    for (BackendKind backend : {BackendKind::Reference, BackendKind::Cpu, BackendKind::Vulkan}) {
        SCOPED_TRACE(backendName(backend));
        const double bare = veiledFloorMean(dir, json(), backend, spp);
        const double opaque = veiledFloorMean(dir, veilMaterial("OPAQUE"), backend, spp);
        ASSERT_GT(bare, 0.0);
        ASSERT_GT(opaque, 0.0);
        const double bound = 2.0 * std::max(bare, opaque);
        const double standardError = bound / 2.0 / std::sqrt(24.0 * 24.0 * spp);
        for (const auto& [alpha, textured] :
             {std::pair{0.3f, false}, {0.7f, false}, {1.0f, true}}) {
            const double a = textured ? 128.0 / 255.0 : alpha; // the image's 8-bit 0.5
            const double blend = veiledFloorMean(dir, veilMaterial("BLEND", alpha, textured),
                                                 backend, spp, textured ? "half-alpha.png" : "");
            EXPECT_NEAR(blend, a * opaque + (1 - a) * (1 - a) * bare, 4.0 * standardError)
                << "alpha " << a;
        }
    }
}

} // namespace
} // namespace spw::test
