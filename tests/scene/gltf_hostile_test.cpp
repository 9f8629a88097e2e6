// Hostile glTF files and the images they carry, each class made by the test: sizes a file's
// numbers feed that wrap or reach past a buffer, JSON nested to overflow a parser's stack, node
// graphs that are not trees, FIFOs and folders named as files, image headers that claim
// gigabytes, grey-and-alpha images, GLB framing that lies, and versions and extensions Spillway
// does not read. Each is refused as a SceneError naming the file and where in it, exit 2 from the
// binary, and never crashes or hangs (the sanitized suite runs these too).
#include "host/image/image_io.h"
#include "host/loaders/scene_loader.h"
#include "host/textures/textures.h"
#include "scene/gltf_builder.h"
#include "test_util.h"

#include <OpenImageIO/imagebuf.h>
#include <gtest/gtest.h>

#include <tuple>

#include <sys/stat.h>

#include <cstdint>
#include <filesystem>
#include <string>

namespace spw::test {
namespace {

namespace fs = std::filesystem;

// A quad with a camera in front of it, its one material `mat`.
GltfBuilder quadScene(const json& mat = material(vec3(0.5f), 0.0f, 0.5f)) {
    GltfBuilder b;
    b.doc["materials"] = json::array({mat});
    const int mesh = b.mesh(b.quad(0));
    b.scene({b.node({{"mesh", mesh}})});
    return b;
}

// The binary's render of `file` with a time limit: a hang is status 124.
CommandResult renderLimited(const std::string& file, const TempDir& dir) {
    return runShell("timeout 60 " + binary() + " render " + file + " --spp 1 --width 16 -o " +
                    dir.file("out.exr") + " --backend reference 2>&1");
}

// CRC-32 as PNG computes it over a chunk's type and data.
std::uint32_t crc32(const std::string& bytes) {
    std::uint32_t c = 0xFFFFFFFFu;
    for (unsigned char b : bytes) {
        c ^= b;
        for (int k = 0; k < 8; ++k)
            c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
    }
    return ~c;
}

// A PNG of a few hundred bytes whose header claims width x height RGB pixels: only its first
// row of data is there (stored, uncompressed), so that reading the pixels would fail, and
// allocating them would take width x height x 3 bytes.
std::string pngBomb(std::uint32_t width, std::uint32_t height) {
    auto be = [](std::uint32_t v) {
        return std::string{char(v >> 24), char(v >> 16), char(v >> 8), char(v)};
    };
    auto chunk = [&](const std::string& type, const std::string& data) {
        return be(std::uint32_t(data.size())) + type + data + be(crc32(type + data));
    };
    const std::string ihdr = be(width) + be(height) + std::string{8, 2, 0, 0, 0};
    // A zlib stream of one stored block of 8 zero bytes (filter byte 0 and a few pixels).
    const std::string idat = std::string{0x78, 0x01, 0x01, 0x08, 0x00, char(0xF7), char(0xFF)} +
                             std::string(8, '\0') + be(0x00080001u);
    return std::string("\x89PNG\r\n\x1a\n", 8) + chunk("IHDR", ihdr) + chunk("IDAT", idat) +
           chunk("IEND", "");
}

// 1. Sizes that a file's numbers feed are checked before anything is allocated or written: an
// accessor count whose product with its components wraps 64 bits, whose sparse indices would
// then write past a tiny array, and a count of 2^31 vertices.
TEST(GltfHostile, AccessorCountsPastTheLimitAreRefusedBeforeAllocating) {
    TempDir dir;
    for (const std::uint64_t count : {(std::uint64_t(1) << 62) + 1, std::uint64_t(1) << 31}) {
        GltfBuilder b = quadScene();
        json& position = b.doc["accessors"][0];
        position["count"] = count;
        position.erase("bufferView"); // all zeros, as the specification allows
        const int indices = b.view<std::uint32_t>({0, 1, 2});
        const int values = b.view<float>({1, 2, 3, 4, 5, 6, 7, 8, 9});
        position["sparse"] = {{"count", 3},
                              {"indices", {{"bufferView", indices}, {"componentType", 5125}}},
                              {"values", {{"bufferView", values}}}};
        const std::string e = loadError(b.embedded(dir, "count.gltf"));
        EXPECT_NE(e.find("/accessors/0/count: is " + std::to_string(count)), std::string::npos)
            << e;
        EXPECT_NE(e.find("at most 268435456 values"), std::string::npos) << e;
    }
}

// A node's indices are integers from 0 to 2^31 - 1 and its transform arrays of numbers: past
// 32 bits, fractional, negative or of another JSON type, each is refused with its pointer, where a
// cast would have read 4294967296 as mesh 0 and dropped -1 or "1" as no mesh at all.
TEST(GltfHostile, NodeIndicesAndTransformsOfTheWrongKindAreRefused) {
    TempDir dir;
    const std::string low = "must be an integer of at least 0";
    const std::string high = ": must be an integer of at most 2147483647";
    const std::vector<std::tuple<const char*, json, std::string>> cases = {
        {"mesh", 4294967296ull, "/nodes/0/mesh: is 4294967296" + high},
        {"mesh", 2147483648ull, "/nodes/0/mesh: is 2147483648" + high},
        {"mesh", -1, "/nodes/0/mesh: " + low},
        {"mesh", 0.5, "/nodes/0/mesh: " + low},
        {"mesh", "0", "/nodes/0/mesh: " + low},
        {"camera", 4294967297ull, "/nodes/0/camera: is 4294967297" + high},
        {"children", json::array({1.0}), "/nodes/0/children/0: " + low},
        {"children", 1, "/nodes/0/children: must be an array of node indices"},
        {"translation", json::array({0, "1", 2}),
         "/nodes/0/translation: a translation has 3 numbers"},
        {"scale", json::array({1, 1}), "/nodes/0/scale: a scale has 3 numbers"},
        {"matrix", json::object(), "/nodes/0/matrix: a matrix has 16 numbers"}};
    for (const auto& [key, value, message] : cases) {
        GltfBuilder b = quadScene();
        b.doc["nodes"][0][key] = value;
        const std::string e = loadError(b.binary(dir, "node.glb"));
        EXPECT_NE(e.find(message), std::string::npos) << key << " = " << value.dump() << ": " << e;
    }
    GltfBuilder b = quadScene();
    b.doc["nodes"][0] = 7;
    EXPECT_NE(loadError(b.binary(dir, "node.glb")).find("/nodes/0: a node is a JSON object"),
              std::string::npos);
    b.doc["nodes"] = json::object();
    EXPECT_NE(loadError(b.binary(dir, "node.glb")).find("/nodes: must be an array of nodes"),
              std::string::npos);
}

// Every index and enumeration in a file is an integer from 0 to 2^31 - 1 and every offset,
// length and count a non-negative integer, checked before tinygltf casts them: a texCoord of
// 4294967297 would read TEXCOORD_1, 4294967296, 1.5 or "1" TEXCOORD_0, a texture index of
// 4294967296 texture 0. Anything goes in `extras` and in extensions Spillway does not read.
TEST(GltfHostile, IntegersPastThirtyTwoBitsOrOfAnotherTypeAreRefused) {
    TempDir dir;
    const std::string base = "/materials/0/pbrMetallicRoughness/baseColorTexture";
    const std::string transmission =
        "/materials/0/extensions/KHR_materials_transmission/transmissionTexture";
    const std::string high = ": must be an integer of at most 2147483647";
    const std::string low = ": must be an integer of at least 0";
    const struct {
        std::string at;
        json value;
        std::string message;
    } cases[] = {
        {base + "/texCoord", 4294967297ull, base + "/texCoord: is 4294967297" + high},
        {base + "/texCoord", 4294967296ull, base + "/texCoord: is 4294967296" + high},
        {base + "/texCoord", 1.5, base + "/texCoord" + low},
        {base + "/texCoord", "1", base + "/texCoord" + low},
        {base + "/index", 4294967296ull, base + "/index: is 4294967296" + high},
        {base + "/index", -1, base + "/index" + low},
        {transmission + "/index", 4294967296ull, transmission + "/index: is 4294967296" + high},
        {"/meshes/0/primitives/0/material", 4294967296ull,
         "/meshes/0/primitives/0/material: is 4294967296" + high},
        {"/accessors/0/count", -3, "/accessors/0/count" + low},
        {"/accessors/0/byteOffset", "0", "/accessors/0/byteOffset" + low},
        {"/scene", 4294967296ull, "/scene: is 4294967296" + high},
    };
    for (const auto& c : cases) {
        GltfBuilder b = quadScene();
        b.doc["extensionsUsed"] = {"KHR_materials_transmission"};
        b.doc["materials"][0]["extensions"]["KHR_materials_transmission"] = {
            {"transmissionFactor", 1.0}, {"transmissionTexture", {{"index", 0}}}};
        b.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
        b.doc["textures"] = json::array({{{"source", 0}}});
        b.doc["images"] = json::array({{{"uri", "none.png"}}});
        b.doc[json::json_pointer(c.at)] = c.value;
        const std::string e = loadError(b.binary(dir, "ints.glb"));
        EXPECT_NE(e.find(c.message), std::string::npos)
            << c.at << " = " << c.value.dump() << ": " << e;
    }
    // extras, and an extension not read, may hold any number.
    GltfBuilder b = quadScene();
    b.doc["materials"][0]["extras"] = {{"index", 4294967296ull}, {"count", "many"}};
    b.doc["extensionsUsed"] = {"EXT_unknown"};
    b.doc["materials"][0]["extensions"]["EXT_unknown"] = {{"index", -7}};
    const std::string ok = loadError(b.binary(dir, "extras.glb"));
    EXPECT_EQ(ok, "");
}

// A value of the wrong JSON type is refused with its pointer where tinygltf would drop it for the
// default (an extension that is not an object, a number that is a string), and an extension's
// texture reference is checked whatever its factor: a factor of 0 does not make texture 99 of a
// file without textures valid.
TEST(GltfHostile, WrongTypesAndTexturesBehindAZeroFactorAreRefused) {
    TempDir dir;
    const std::string mat = "/materials/0";
    const struct {
        std::string at;
        json value;
        std::string message;
    } cases[] = {
        {mat + "/extensions/KHR_materials_transmission", 0.5,
         mat + "/extensions/KHR_materials_transmission: must be an object"},
        {mat + "/pbrMetallicRoughness/baseColorTexture",
         {{"index", 0}, {"extensions", {{"KHR_texture_transform", 5}}}},
         mat + "/pbrMetallicRoughness/baseColorTexture/extensions/KHR_texture_transform: must be "
               "an object"},
        {mat + "/alphaCutoff", "0.9", mat + "/alphaCutoff: must be a number"},
        {mat + "/pbrMetallicRoughness/baseColorFactor",
         {1, "1", 1, 1},
         mat + "/pbrMetallicRoughness/baseColorFactor: must be an array of numbers"},
        {mat + "/extensions/KHR_materials_transmission",
         {{"transmissionFactor", 0.0}, {"transmissionTexture", json::object()}},
         mat + "/extensions/KHR_materials_transmission/transmissionTexture: a textureInfo needs "
               "an index"},
        {mat + "/extensions/KHR_materials_transmission",
         {{"transmissionFactor", 0.0}, {"transmissionTexture", {{"index", 99}}}},
         mat + "/extensions/KHR_materials_transmission/transmissionTexture: names texture 99 of 0"},
        {mat + "/extensions/KHR_materials_clearcoat",
         {{"clearcoatFactor", 0.0}, {"clearcoatRoughnessTexture", {{"index", 99}}}},
         mat + "/extensions/KHR_materials_clearcoat/clearcoatRoughnessTexture: names texture 99 "
               "of 0"},
        {mat + "/extensions/KHR_materials_sheen",
         {{"sheenColorTexture", {{"index", 99}}}},
         mat + "/extensions/KHR_materials_sheen/sheenColorTexture: names texture 99 of 0"},
        // assimp's wrongTypes models, and what tinygltf would read as a default.
        {"/meshes/0/primitives", {{"a", json::object()}}, "/meshes/0/primitives: must be an array"},
        {mat + "/pbrMetallicRoughness", "steel", mat + "/pbrMetallicRoughness: must be an object"},
        {mat + "/doubleSided", "yes", mat + "/doubleSided: must be true or false"},
        {mat + "/alphaMode", 3, mat + "/alphaMode: must be a string"},
        {mat + "/name", 5, mat + "/name: must be a string"},
        {mat + "/pbrMetallicRoughness/baseColorTexture",
         {{"index", -1}},
         mat + "/pbrMetallicRoughness/baseColorTexture/index: must be an integer of at least 0"},
    };
    for (const auto& c : cases) {
        GltfBuilder b = quadScene();
        b.doc["extensionsUsed"] = {"KHR_materials_transmission", "KHR_materials_clearcoat",
                                   "KHR_materials_sheen", "KHR_texture_transform"};
        b.doc[json::json_pointer(c.at)] = c.value;
        const std::string e = loadError(b.binary(dir, "types.glb"));
        EXPECT_NE(e.find(c.message), std::string::npos)
            << c.at << " = " << c.value.dump() << ": " << e;
    }
}

// Indices are unsigned integers (the specification's rule), read as 32-bit values: a signed
// type is refused at the accessor, a float type too.
TEST(GltfHostile, IndicesOfASignedOrFloatTypeAreRefused) {
    TempDir dir;
    for (const int type : {5120, 5122, 5124, 5126}) {
        GltfBuilder b = quadScene();
        const int accessor = b.doc["meshes"][0]["primitives"][0]["indices"];
        b.doc["accessors"][size_t(accessor)]["componentType"] = type;
        const std::string e = loadError(b.embedded(dir, "signed.gltf"));
        const std::string at = "/accessors/" + std::to_string(accessor) + "/componentType: ";
        EXPECT_NE(e.find(at + (type == 5126 ? "indices must be integers"
                                            : "indices must be unsigned integers")),
                  std::string::npos)
            << e;
    }
}

// 2. An image's buffer view must lie in its buffer before its bytes are taken (tinygltf hands
// them over unchecked).
TEST(GltfHostile, AnImageBufferViewPastItsBufferIsRefused) {
    TempDir dir;
    GltfBuilder b = quadScene();
    const int view = b.view<std::uint8_t>({0x89, 'P', 'N', 'G'});
    b.doc["bufferViews"][size_t(view)]["byteLength"] = 1 << 30;
    b.doc["images"] = json::array({{{"bufferView", view}, {"mimeType", "image/png"}}});
    b.doc["textures"] = json::array({{{"source", 0}}});
    b.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
    for (const std::string& file : {b.embedded(dir, "view.gltf"), b.binary(dir, "view.glb")}) {
        const std::string e = loadError(file);
        EXPECT_NE(e.find("/images/0/bufferView: buffer view " + std::to_string(view)),
                  std::string::npos)
            << e;
        EXPECT_NE(e.find("reaches past the end of buffer 0"), std::string::npos) << e;
    }
}

// 3. JSON nested 50,000 deep in `extras` (where any JSON may go) is refused before the parser,
// which recurses, sees it; 60 levels load.
TEST(GltfHostile, DeepJsonIsRefusedBeforeTheParserSeesIt) {
    TempDir dir;
    for (const int depth : {60, 50000}) {
        GltfBuilder b = quadScene();
        std::string text = readFile(b.embedded(dir, "deep.gltf"));
        // {"asset": ..., "extras": [[[...]]]}: the document's own object is one level more.
        text.insert(text.size() - 1, ",\"extras\":" + std::string(size_t(depth), '[') +
                                         std::string(size_t(depth), ']'));
        dir.write("deep.gltf", text);
        const std::string e = loadError(dir.file("deep.gltf"));
        if (depth == 60) {
            EXPECT_EQ(e, "");
        } else {
            EXPECT_NE(e.find("its JSON nests deeper than 64 levels"), std::string::npos) << e;
        }
    }
}

// 4. A node graph that is a DAG (64 nodes, each naming the next twice: 2^63 paths) is refused at
// once; so is a scene root that is another node's child.
TEST(GltfHostile, ANodeGraphThatIsNotAForestIsRefused) {
    TempDir dir;
    GltfBuilder b = quadScene();
    const int mesh = 0;
    b.doc["nodes"] = json::array();
    for (int i = 0; i < 64; ++i)
        b.doc["nodes"].push_back(i < 63 ? json{{"children", {i + 1, i + 1}}}
                                        : json{{"mesh", mesh}});
    b.scene({0});
    std::string e = loadError(b.embedded(dir, "dag.gltf"));
    EXPECT_NE(e.find("/nodes/0/children/1: names node 1, which node 0 names too: a glTF node has "
                     "one parent at most"),
              std::string::npos)
        << e;
    b.doc["nodes"] = json::array({{{"children", {1}}}, {{"mesh", mesh}}});
    b.scene({0, 1});
    e = loadError(b.embedded(dir, "root.gltf"));
    EXPECT_NE(
        e.find("/scenes/0/nodes/1: names node 1, a child of node 0: a scene's nodes are roots"),
        std::string::npos)
        << e;
}

// 4. A buffer or image URI naming a FIFO (which would block for ever) or a folder is refused,
// exit 2, naming the JSON pointer; the binary does not hang.
TEST(GltfHostile, FifosAndFoldersNamedByUrisAreRefusedWithoutBlocking) {
    TempDir dir;
    ASSERT_EQ(::mkfifo(dir.file("fifo.bin").c_str(), 0600), 0);
    fs::create_directory(dir.file("folder.bin"));
    for (const std::string target : {"fifo.bin", "folder.bin"}) {
        GltfBuilder b = quadScene();
        std::string file = b.external(dir, "uri.gltf");
        json doc = json::parse(readFile(file));
        doc["buffers"][0]["uri"] = target;
        dir.write("uri.gltf", doc.dump());
        const CommandResult r = renderLimited(file, dir);
        EXPECT_EQ(r.status, 2) << r.output;
        EXPECT_NE(r.output.find("/buffers/0/uri: names '" + target + "', which is a " +
                                (target == "fifo.bin" ? "FIFO" : "folder")),
                  std::string::npos)
            << r.output;
        // The same file as an image.
        b = quadScene();
        b.doc["images"] = json::array({{{"uri", target}}});
        b.doc["textures"] = json::array({{{"source", 0}}});
        b.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
        const CommandResult image = renderLimited(b.embedded(dir, "image.gltf"), dir);
        EXPECT_EQ(image.status, 2) << image.output;
        EXPECT_NE(image.output.find("/images/0/uri: names '" + target + "'"), std::string::npos)
            << image.output;
    }
}

// 5. An image header that claims 100000 x 100000 pixels, as a base colour texture (read tile by
// tile) or an emission texture (read whole), is refused from its header, exit 2, naming the file
// and its size; so is an emission texture past the limit of images read whole.
TEST(GltfHostile, ImageSizeBombsAreRefusedFromTheirHeaders) {
    TempDir dir;
    struct Case {
        std::uint32_t size;
        const char* slot;
        const char* says;
    };
    for (const Case& c : {Case{100000, "base", "is 100000 x 100000 pixels"},
                          Case{100000, "emission", "is 100000 x 100000 pixels"},
                          Case{9000, "emission",
                               "9000 x 9000 pixels; Spillway reads images of 1 "
                               "to 2^26 pixels when read whole"}}) {
        dir.write("bomb.png", pngBomb(c.size, c.size));
        json mat = material(vec3(0.5f), 0.0f, 0.5f, vec3(1.0f));
        if (std::string(c.slot) == "base")
            mat["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
        else
            mat["emissiveTexture"] = {{"index", 0}};
        GltfBuilder b = quadScene(mat);
        b.doc["images"] = json::array({{{"uri", "bomb.png"}}});
        b.doc["textures"] = json::array({{{"source", 0}}});
        const CommandResult r = renderLimited(b.embedded(dir, "bomb.gltf"), dir);
        EXPECT_EQ(r.status, 2) << c.slot << " " << c.size << ": " << r.output;
        EXPECT_NE(r.output.find(c.says), std::string::npos) << r.output;
        EXPECT_NE(r.output.find("bomb.png"), std::string::npos) << r.output;
    }
}

// 6. A grey-and-alpha PNG (two channels, 8 and 16 bit) means grey as a colour, and its second
// channel is the alpha a cut-out reads.
TEST(GltfHostile, GreyAndAlphaImagesReadAsGreyWithTheirAlpha) {
    TempDir dir;
    for (const OIIO::TypeDesc format : {OIIO::TypeDesc::UINT8, OIIO::TypeDesc::UINT16}) {
        OIIO::ImageBuf ga(OIIO::ImageSpec(4, 4, 2, format));
        const float value[2] = {128.0f / 255.0f, 0.0f}; // grey 128, fully transparent
        for (int y = 0; y < 4; ++y)
            for (int x = 0; x < 4; ++x)
                ga.setpixel(x, y, value);
        ASSERT_TRUE(ga.write(dir.file("ga.png")));
        json mat = material(vec3(1.0f), 0.0f, 0.5f);
        mat["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
        mat["alphaMode"] = "MASK";
        GltfBuilder b = quadScene(mat);
        b.doc["images"] = json::array({{{"uri", "ga.png"}}});
        b.doc["textures"] = json::array({{{"source", 0}}});
        const Scene scene = loadScene(b.embedded(dir, "ga.gltf"));
        const TextureResolver textures(scene, 16.0);
        const Shader& shader = scene.shaders.at(0);
        const vec3 colour = textures.albedo(shader, vec2(0.5f), 0.0f);
        textures.checkErrors();
        EXPECT_EQ(colour.x, colour.y);
        EXPECT_EQ(colour.y, colour.z);
        EXPECT_NEAR(colour.x, srgbToLinear(128.0f / 255.0f), 2e-3);
        ASSERT_TRUE(shader.cutout.enabled);
        vec3 alpha;
        const vec2 uv(0.5f);
        const float footprint = 0.0f;
        textures.values(shader.cutout.texture, 1, &uv, &footprint, &alpha);
        EXPECT_EQ(alpha.x, 0.0f); // the cut-out's alpha: transparent everywhere
    }
}

// 9 and 10. GLB framing that claims bytes past the file's end, glTF 1.0 (binary or JSON) and a
// version that is not 2.x, and a file that requires Draco, each refused by name.
TEST(GltfHostile, FramingVersionsAndRequiredExtensionsAreNamed) {
    TempDir dir;
    GltfBuilder b = quadScene();
    std::string glb = readFile(b.binary(dir, "ok.glb"));
    ASSERT_EQ(loadError(dir.file("ok.glb")), "");
    std::string past = glb;
    const std::uint32_t jsonLength = *reinterpret_cast<const std::uint32_t*>(&glb[12]);
    const std::uint32_t huge = 0x7FFFFFF0u;
    std::memcpy(&past[20 + jsonLength], &huge, 4); // the BIN chunk's length
    EXPECT_NE(loadError(dir.write("past.glb", past))
                  .find("the BIN chunk claims 2147483632 bytes, "
                        "past the file's end"),
              std::string::npos);
    std::string v1 = glb;
    v1[4] = 1;
    EXPECT_NE(loadError(dir.write("v1.glb", v1)).find("glTF 1.0 is not supported"),
              std::string::npos);
    for (const std::string version : {"1.0", "3.0"}) {
        b.doc["asset"]["version"] = version;
        const std::string e = loadError(b.embedded(dir, "version.gltf"));
        EXPECT_NE(e.find("/asset/version: is '" + version + "'"), std::string::npos) << e;
    }
    b.doc["asset"]["version"] = "2.0";
    // 9. An extension an object uses that extensionsUsed does not declare.
    b.doc["materials"][0]["extensions"]["KHR_materials_emissive_strength"] = {
        {"emissiveStrength", 2.0}};
    const std::string undeclared = loadError(b.embedded(dir, "undeclared.gltf"));
    EXPECT_NE(undeclared.find("/materials/0/extensions/KHR_materials_emissive_strength: uses the "
                              "extension KHR_materials_emissive_strength, which the file's "
                              "extensionsUsed does not declare"),
              std::string::npos)
        << undeclared;
    b.doc["extensionsUsed"] = {"KHR_materials_emissive_strength"};
    EXPECT_EQ(loadError(b.embedded(dir, "undeclared.gltf")), "");
    // 10. A skin without inverseBindMatrices (optional: identity matrices) loads, in bind pose.
    b.doc["skins"] = json::array({{{"joints", {0}}}});
    b.doc["nodes"][0]["skin"] = 0;
    EXPECT_EQ(loadError(b.embedded(dir, "skin.gltf")), "");
    b.doc.erase("skins");
    b.doc["nodes"][0].erase("skin");
    // 9. An aspect ratio that would squeeze the picture is refused, naming the range.
    b.doc["cameras"] =
        json::array({{{"type", "perspective"},
                      {"perspective", {{"yfov", 0.8}, {"aspectRatio", 1000.0}, {"znear", 0.1}}}}});
    b.doc["nodes"].push_back({{"camera", 0}, {"translation", {0, 0, 3}}});
    b.doc["scenes"][0]["nodes"].push_back(b.doc["nodes"].size() - 1);
    const std::string aspect = loadError(b.embedded(dir, "aspect.gltf"));
    EXPECT_NE(aspect.find("/cameras/0/perspective/aspectRatio: is 1000; Spillway renders aspect "
                          "ratios (width / height) from 0.01 to 100"),
              std::string::npos)
        << aspect;
    b.doc["cameras"][0]["perspective"]["aspectRatio"] = 1.5;
    EXPECT_EQ(loadError(b.embedded(dir, "aspect.gltf")), "");
    b.doc["extensionsUsed"] = b.doc["extensionsRequired"] = {"KHR_draco_mesh_compression"};
    const std::string e = loadError(b.embedded(dir, "draco.gltf"));
    EXPECT_NE(e.find("/extensionsRequired: requires KHR_draco_mesh_compression (Draco-compressed "
                     "meshes)"),
              std::string::npos)
        << e;
}

// 9 and 10. A primitive mode glTF does not have and normalized indices (which would read as
// fractions) are refused; an image is read as the format its bytes are, PNG or JPEG, whatever its
// mimeType says, and anything else (OpenImageIO's `.null` reader included) is refused at loading.
TEST(GltfHostile, ModesIndicesAndImageFormatsAreCheckedAtLoading) {
    TempDir dir;
    GltfBuilder b = quadScene();
    b.doc["meshes"][0]["primitives"][0]["mode"] = 9;
    std::string e = loadError(b.embedded(dir, "mode.gltf"));
    EXPECT_NE(e.find("/mode: is 9, not a glTF primitive mode"), std::string::npos) << e;
    b = quadScene();
    const int indices = b.doc["meshes"][0]["primitives"][0]["indices"].get<int>();
    b.doc["accessors"][size_t(indices)]["normalized"] = true;
    e = loadError(b.embedded(dir, "normalized.gltf"));
    EXPECT_NE(e.find("/accessors/" + std::to_string(indices) +
                     "/normalized: indices are never normalized"),
              std::string::npos)
        << e;

    dir.write("x.null", "nothing an image reader should open");
    json mat = material(vec3(1.0f), 0.0f, 0.5f);
    mat["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
    b = quadScene(mat);
    b.doc["images"] = json::array({{{"uri", "x.null"}}});
    b.doc["textures"] = json::array({{{"source", 0}}});
    e = loadError(b.embedded(dir, "null.gltf"));
    EXPECT_NE(e.find("/images/0/uri: '"), std::string::npos) << e;
    EXPECT_NE(e.find("x.null' is neither a PNG nor a JPEG image"), std::string::npos) << e;

    // A JPEG, embedded and labelled image/png: read as the JPEG it is.
    OIIO::ImageBuf red(OIIO::ImageSpec(8, 8, 3, OIIO::TypeDesc::UINT8));
    const float colour[3] = {1.0f, 0.0f, 0.0f};
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x)
            red.setpixel(x, y, colour);
    ASSERT_TRUE(red.write(dir.file("red.jpg")));
    b = quadScene(mat);
    const std::string jpeg = readFile(dir.file("red.jpg"));
    const int view = b.view(std::vector<std::uint8_t>(jpeg.begin(), jpeg.end()));
    b.doc["images"] = json::array({{{"bufferView", view}, {"mimeType", "image/png"}}});
    b.doc["textures"] = json::array({{{"source", 0}}});
    const Scene scene = loadScene(b.binary(dir, "jpeg.glb"));
    const TextureResolver textures(scene, 16.0);
    const vec3 albedo = textures.albedo(scene.shaders.at(0), vec2(0.5f), 0.0f);
    textures.checkErrors();
    EXPECT_GT(albedo.x, 0.9f);
    EXPECT_LT(albedo.y, 0.05f);
}

// 10. The light-intensity bound the message names is the one checked: 6e22 cd loads, 7e22 is
// refused naming [0, 6.83e22] (1e20 W/sr at 683 lm/W).
TEST(GltfHostile, TheLightIntensityBoundIsTheOneItsMessageNames) {
    TempDir dir;
    for (const double intensity : {6e22, 7e22}) {
        GltfBuilder b = quadScene();
        b.doc["extensionsUsed"] = {"KHR_lights_punctual"};
        b.doc["extensions"]["KHR_lights_punctual"]["lights"] =
            json::array({{{"type", "point"}, {"intensity", intensity}}});
        b.doc["scenes"][0]["nodes"].push_back(
            b.node({{"translation", {0, 0, 2}},
                    {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}}));
        const std::string e = loadError(b.embedded(dir, "light.gltf"));
        if (intensity < 6.83e22) {
            EXPECT_EQ(e, "");
        } else {
            EXPECT_NE(e.find("a light's intensity must lie in [0, 6.83e22]"), std::string::npos)
                << e;
        }
    }
}

} // namespace
} // namespace spw::test
