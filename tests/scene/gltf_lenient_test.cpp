// What a glTF file's maker meant, where it is unambiguous: a scene root whose extra parent no
// scene holds rendered as a root, KHR_materials_pbrSpecularGlossiness converted to
// metallic-roughness, and a warning said once for every part it applies to.
#include "host/image/image_io.h"
#include "host/loaders/scene_loader.h"
#include "scene/gltf_builder.h"
#include "test_util.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>

namespace spw::test {
namespace {

using nlohmann::json;

// A root that is also the child of a node no scene holds (as UniGLTF's VRM exports write) is
// rendered as a root, with a warning naming where; a parent some scene holds is still refused
// (GltfHostile.*, Gltf.* keep those).
TEST(GltfLenient, ARootWhoseParentNoSceneHoldsIsRenderedAsARoot) {
    TempDir dir;
    GltfBuilder b;
    const int mesh = b.mesh(b.quad());
    b.doc["nodes"] = json::array({{{"children", {1}}}, {{"mesh", mesh}}});
    b.scene({1});
    const Scene s = loadScene(b.embedded(dir, "vrm.gltf"));
    ASSERT_EQ(s.meshes.size(), 1u);
    ASSERT_EQ(s.warnings.size(), 1u);
    EXPECT_NE(s.warnings[0].find("/scenes/0/nodes/0: names node 1, a child of node 0, which no "
                                 "scene holds: rendered as a root"),
              std::string::npos)
        << s.warnings[0];
    b.scene({0, 1}); // now a scene holds the parent
    EXPECT_NE(loadError(b.embedded(dir, "both.gltf")).find("a scene's nodes are roots"),
              std::string::npos);
}

// A quad under material `mat` (its extensions declared in `used`; texture n the image
// images[n] where it has any), seen by a camera; the scene loaded.
Scene quadWith(const TempDir& dir, const json& mat, const std::vector<std::string>& used = {},
               const std::vector<std::string>& images = {}) {
    GltfBuilder b;
    b.doc["materials"] = json::array({mat});
    for (size_t n = 0; n < images.size(); ++n) {
        b.doc["images"].push_back({{"uri", images[n]}});
        b.doc["textures"].push_back({{"source", n}});
    }
    if (!used.empty()) b.doc["extensionsUsed"] = used;
    b.doc["cameras"] =
        json::array({{{"type", "perspective"},
                      {"perspective", {{"yfov", 0.5}, {"aspectRatio", 1.0}, {"znear", 0.1}}}}});
    b.scene({b.node({{"mesh", b.mesh(b.quad(0))}}),
             b.node({{"camera", 0}, {"translation", {0.5, 0.5, 2}}})});
    Scene s = loadScene(b.embedded(dir, "q.gltf"));
    s.image.width = s.image.height = 8;
    return s;
}

// Scenes a and b render the same image, bit for bit, on every backend (2 spp).
void expectSameImages(const Scene& a, const Scene& b) {
    for (BackendKind backend : {BackendKind::Reference, BackendKind::Cpu, BackendKind::Vulkan}) {
        SCOPED_TRACE(backendName(backend));
        RenderConfig cfg;
        cfg.backend = backend;
        cfg.spp = 2;
        EXPECT_EQ(render(a, cfg)->film->image(), render(b, cfg)->film->image());
    }
}

json specularGlossiness(const json& body) {
    return {{"extensions", {{"KHR_materials_pbrSpecularGlossiness", body}}}};
}

// A dielectric in the specular-glossiness workflow (diffuse red, specular 0.04, glossiness 0.7)
// is the metallic-roughness material of that base colour, metallic 0 and roughness 0.3, and
// renders as it to the bit on every backend; a black diffuse under a coloured specular is a
// metal of that colour. The metallic-roughness values beside the extension (a fallback for
// viewers without it) are not read.
TEST(GltfLenient, SpecularGlossinessIsConvertedToMetallicRoughness) {
    TempDir dir;
    const std::vector<std::string> used = {"KHR_materials_pbrSpecularGlossiness"};
    json plastic = specularGlossiness({{"diffuseFactor", {0.8, 0.2, 0.2, 1.0}},
                                       {"specularFactor", {0.04, 0.04, 0.04}},
                                       {"glossinessFactor", 0.7}});
    plastic["pbrMetallicRoughness"] = {{"baseColorFactor", {0, 1, 0, 1}}, {"metallicFactor", 1}};
    const Scene converted = quadWith(dir, plastic, used);
    EXPECT_TRUE(converted.warnings.empty()) << converted.warnings.at(0);
    const Scene direct = quadWith(dir, material(vec3(0.8f, 0.2f, 0.2f), 0.0f, 0.3f));
    const Shader &a = converted.shaders[0], &b = direct.shaders[0];
    EXPECT_EQ(a.params.colour, vec3(0.8f, 0.2f, 0.2f));
    EXPECT_EQ(a.params.metallic, 0.0f);
    EXPECT_EQ(a.roughness, b.roughness);
    expectSameImages(converted, direct);
    const Scene gold = quadWith(dir,
                                specularGlossiness({{"diffuseFactor", {0.0, 0.0, 0.0, 1.0}},
                                                    {"specularFactor", {1.0, 0.75, 0.25}},
                                                    {"glossinessFactor", 0.9}}),
                                used);
    EXPECT_EQ(gold.shaders[0].params.metallic, 1.0f);
    EXPECT_NEAR(gold.shaders[0].params.colour.y, 0.75f, 1e-6f);
    EXPECT_NEAR(gold.shaders[0].params.colour.z, 0.25f, 1e-6f);
    EXPECT_NEAR(gold.shaders[0].roughness, 0.1f, 1e-6f);
    // A value out of range is refused, naming where.
    const json bad = specularGlossiness({{"diffuseFactor", {2.0, 0.0, 0.0, 1.0}}});
    GltfBuilder files;
    files.doc["materials"] = json::array({bad});
    files.doc["extensionsUsed"] = used;
    files.scene({files.node({{"mesh", files.mesh(files.quad(0))}})});
    EXPECT_NE(loadError(files.embedded(dir, "bad.gltf"))
                  .find("/materials/0/extensions/KHR_materials_pbrSpecularGlossiness/"
                        "diffuseFactor/0: must lie in [0, 1]"),
              std::string::npos);
}

// An 8-bit PNG of width x 1 texels (`channels` values each, row-major), as a data: URI.
std::string pngUri(const TempDir& dir, int channels, const std::vector<std::uint8_t>& texels) {
    const int width = int(texels.size()) / channels;
    std::vector<std::uint8_t> copy = texels;
    OIIO::ImageBuf img(OIIO::ImageSpec(width, 1, channels, OIIO::TypeDesc::UINT8), copy.data());
    EXPECT_TRUE(img.write(dir.file("uri.png")));
    return "data:image/png;base64," + GltfBuilder::base64(readFile(dir.file("uri.png")));
}

// The texels of a texture's in-memory PNG (Texture::embedded).
std::vector<std::uint8_t> texelsOf(const TempDir& dir, const Texture& t) {
    EXPECT_TRUE(t.embedded && t.embedded->bytes);
    const std::string file = dir.file(std::to_string(std::hash<std::string>()(t.path)) + ".png");
    std::ofstream(file, std::ios::binary) << *t.embedded->bytes;
    OIIO::ImageBuf img(file);
    const OIIO::ImageSpec& spec = img.spec();
    std::vector<std::uint8_t> out(size_t(spec.width) * size_t(spec.nchannels));
    EXPECT_TRUE(img.get_pixels(img.roi(), OIIO::TypeDesc::UINT8, out.data()));
    return out;
}

// specularGlossinessTexture and diffuseTexture converted texel by texel, the factors with them:
// a texel whose diffuse is black under a white specular (times the factor's gold) is a gold
// metal, one whose specular is black a dielectric of the diffuse colour / 0.96 (what the
// conversion keeps of the diffuse for a specular of 0), roughness 1 - glossiness each; the
// images are in memory, and the material renders on every backend to the bit as the
// metallic-roughness material of those images from files.
TEST(GltfLenient, SpecularGlossinessImagesAreConvertedTexelByTexel) {
    TempDir dir;
    const std::vector<std::string> images = {pngUri(dir, 4, {255, 255, 255, 230, 0, 0, 0, 52}),
                                             pngUri(dir, 3, {0, 0, 0, 255, 255, 255})};
    const json mat = specularGlossiness({{"diffuseFactor", {0.48, 0.24, 0.96, 1.0}},
                                         {"specularFactor", {1.0, 0.75, 0.25}},
                                         {"glossinessFactor", 0.5},
                                         {"diffuseTexture", {{"index", 1}}},
                                         {"specularGlossinessTexture", {{"index", 0}}}});
    const Scene s = quadWith(dir, mat, {"KHR_materials_pbrSpecularGlossiness"}, images);
    EXPECT_TRUE(s.warnings.empty()) << s.warnings.at(0);
    const Shader& sh = s.shaders[0];
    ASSERT_GE(sh.metallicRoughnessTexture, 0);
    ASSERT_GE(sh.texture, 0);
    const Texture& base = s.textures[size_t(s.textures[size_t(sh.texture)].upper)];
    EXPECT_NE(base.path.find("#material0-base.png"), std::string::npos) << base.path;
    EXPECT_EQ(sh.params.colour, vec3(1.0f));
    EXPECT_EQ(sh.params.metallic, 1.0f);
    // Gold, then (0.48, 0.24, 0.96) / 0.96; alpha 1.
    const std::vector<std::uint8_t> baseTexels = {255,
                                                  linearToSrgb8(0.75f),
                                                  linearToSrgb8(0.25f),
                                                  255,
                                                  linearToSrgb8(0.5f),
                                                  linearToSrgb8(0.25f),
                                                  255,
                                                  255};
    EXPECT_EQ(texelsOf(dir, base), baseTexels);
    // Roughness 1 - 0.5 * 230 / 255 (140 / 255), 1 - 0.5 * 52 / 255 (229 / 255); metallic 1, 0.
    const std::vector<std::uint8_t> mrTexels = {255, 140, 255, 255, 229, 0};
    EXPECT_EQ(texelsOf(dir, s.textures[size_t(sh.metallicRoughnessTexture)]), mrTexels);
    json direct = material(vec3(1.0f), 1.0f, 1.0f);
    direct["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
    direct["pbrMetallicRoughness"]["metallicRoughnessTexture"] = {{"index", 1}};
    TempDir other; // the first file still read from where it lies
    const Scene files =
        quadWith(other, direct, {}, {pngUri(dir, 4, baseTexels), pngUri(dir, 3, mrTexels)});
    expectSameImages(s, files);
    // A dielectric's diffuse image (the conversion linear in it) is read as it is, not
    // converted; a texture reference of the wrong form is refused, naming where.
    const Scene plastic = quadWith(other,
                                   specularGlossiness({{"specularFactor", {0.04, 0.04, 0.04}},
                                                       {"diffuseTexture", {{"index", 1}}}}),
                                   {"KHR_materials_pbrSpecularGlossiness"}, images);
    ASSERT_GE(plastic.shaders[0].texture, 0);
    EXPECT_LT(plastic.shaders[0].metallicRoughnessTexture, 0);
    const int upper = plastic.textures[size_t(plastic.shaders[0].texture)].upper;
    EXPECT_NE(plastic.textures[size_t(upper)].path.find("#image1.png"), std::string::npos);
    GltfBuilder bad;
    bad.doc["materials"] = json::array({specularGlossiness({{"specularGlossinessTexture", 0}})});
    bad.doc["extensionsUsed"] = {"KHR_materials_pbrSpecularGlossiness"};
    bad.scene({bad.node({{"mesh", bad.mesh(bad.quad(0))}})});
    EXPECT_NE(loadError(bad.embedded(dir, "bad.gltf"))
                  .find("/materials/0/extensions/KHR_materials_pbrSpecularGlossiness/"
                        "specularGlossinessTexture: must be a textureInfo object"),
              std::string::npos);
}

// A 2 x 2 white PNG as a data: URI.
std::string whitePng(const TempDir& dir) {
    OIIO::ImageBuf img(OIIO::ImageSpec(2, 2, 3, OIIO::TypeDesc::UINT8));
    const float white[3] = {1, 1, 1};
    OIIO::ImageBufAlgo::fill(img, white);
    EXPECT_TRUE(img.write(dir.file("white.png")));
    return "data:image/png;base64," + GltfBuilder::base64(readFile(dir.file("white.png")));
}

// Five materials with an occlusionTexture (which a path tracer has no use for): one warning
// naming three of them and counting the rest. Three meshes each with a zero-area triangle: one
// line from the command line for all of them.
TEST(GltfLenient, AWarningIsSaidOncePerFile) {
    TempDir dir;
    GltfBuilder b;
    b.doc["images"] = json::array({{{"uri", whitePng(dir)}}});
    b.doc["textures"] = json::array({{{"source", 0}}});
    std::vector<int> roots;
    for (int m = 0; m < 5; ++m) {
        json mat = material(vec3(0.5f), 0.0f, 0.5f);
        mat["occlusionTexture"] = {{"index", 0}};
        b.doc["materials"].push_back(mat);
        json prim = b.quad(m);
        if (m < 3) prim["indices"] = b.accessor<uint16_t>({0, 1, 2, 0, 2, 2}, 5123, "SCALAR");
        roots.push_back(b.node({{"mesh", b.mesh(prim)}, {"translation", {m, 0, 0}}}));
    }
    b.scene(roots);
    const std::string file = b.embedded(dir, "many.gltf");
    const Scene s = loadScene(file);
    ASSERT_EQ(s.warnings.size(), 1u);
    EXPECT_NE(s.warnings[0].find("material 0, material 1, material 2 and 2 more: its "
                                 "occlusionTexture is ignored"),
              std::string::npos)
        << s.warnings[0];
    const CommandResult r =
        runSpillway("render " + file + " -o " + dir.file("m.exr") + " --spp 1 --width 8 --quiet");
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("dropped 3 zero-area triangles in 3 meshes (the first: " + file +
                            ": mesh 0)"),
              std::string::npos)
        << r.output;
    EXPECT_EQ(r.output.find("zero-area"), r.output.rfind("zero-area")) << r.output;
}

} // namespace
} // namespace spw::test
