// Where a glTF file's bytes are read from (host/loaders/gltf_sources.h): an image in a buffer in
// a file is left in the file and read from it a piece at a time, the buffer tinygltf is handed
// holds only the views meshes read (aligned as they were), and everything renders as when the
// same bytes come from memory.
#include "host/loaders/gltf_preflight.h"
#include "host/loaders/gltf_sources.h"
#include "host/loaders/scene_loader.h"
#include "host/render/checkpoint.h"
#include "host/textures/embedded_reader.h"
#include "scene/gltf_builder.h"
#include "test_util.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>

namespace spw::test {
namespace {

using nlohmann::json;

// A PNG (or, with ext ".jpg", a JPEG) of w x h texels, each channel a function of its place.
std::string pngBytes(const TempDir& dir, int w, int h, const std::string& ext = ".png") {
    OIIO::ImageBuf img(OIIO::ImageSpec(w, h, 3, OIIO::TypeDesc::UINT8));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const float c[3] = {float(x) / float(w), float(y) / float(h),
                                float((x * y) % 7) / 7.0f};
            img.setpixel(x, y, c);
        }
    const std::string path = dir.file("texels" + ext);
    EXPECT_TRUE(img.write(path));
    return readFile(path);
}

// A quad textured with `png`, its image's view between its accessors' (so that a buffer cut down
// to the meshes' views moves the views after it), and the image's bytes odd in number.
GltfBuilder texturedQuad(const std::string& png) {
    GltfBuilder b;
    json mat = material(vec3(1.0f), 0.0f, 1.0f);
    mat["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
    b.doc["materials"] = json::array({mat});
    const size_t at = b.bytes.size();
    b.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", at}, {"byteLength", png.size()}});
    b.bytes += png + "\x01"; // one byte more: the views after it start at an odd offset mod 16
    b.doc["images"] =
        json::array({{{"bufferView", b.doc["bufferViews"].size() - 1}, {"mimeType", "image/png"}}});
    b.doc["textures"] = json::array({{{"source", 0}}});
    b.doc["cameras"] =
        json::array({{{"type", "perspective"},
                      {"perspective", {{"yfov", 0.25}, {"aspectRatio", 1.0}, {"znear", 0.1}}}}});
    b.scene({b.node({{"mesh", b.mesh(b.quad(0))}}),
             b.node({{"camera", 0}, {"translation", {0.5, 0.5, 3}}})});
    return b;
}

// The scene's one image texture.
const Texture& image(const Scene& scene) {
    for (const Texture& t : scene.textures)
        if (t.type == TextureType::Standard) return t;
    ADD_FAILURE() << "no image texture";
    return scene.textures.at(0);
}

std::vector<float> renderSmall(const Scene& scene) {
    RenderConfig cfg;
    cfg.backend = BackendKind::Cpu;
    cfg.spp = 4;
    Scene small = scene;
    small.image.width = small.image.height = 16;
    return render(small, cfg)->film->image();
}

// An image in a .glb's BIN chunk or in a .bin beside a .gltf stays in its file: the texture names
// the bytes' place, which hold the PNG; geometry, render and scene hash are those of the same
// file with its buffer as a data: URI, whose image the JSON held in memory; PNG and JPEG.
TEST(GltfSources, AnImageInABufferFileIsReadFromTheFileAndRendersAsFromMemory) {
    for (const std::string ext : {".png", ".jpg"}) { // a JPEG is read through a mapping
        SCOPED_TRACE(ext);
        TempDir dir;
        const std::string png = pngBytes(dir, 40, 24, ext);
        GltfBuilder b = texturedQuad(png);
        const Scene inMemory = loadScene(b.embedded(dir, "memory.gltf"));
        ASSERT_TRUE(image(inMemory).embedded && image(inMemory).embedded->bytes);
        EXPECT_EQ(*image(inMemory).embedded->bytes, png);
        const std::vector<float> expected = renderSmall(inMemory);
        for (const std::string& file : {b.binary(dir, "file.glb"), b.external(dir, "file.gltf")}) {
            const Scene scene = loadScene(file);
            const std::shared_ptr<const EmbeddedImage> embedded = image(scene).embedded;
            ASSERT_TRUE(embedded) << file;
            EXPECT_FALSE(embedded->bytes) << file << ": the image's bytes are left in the file";
            EXPECT_EQ(
                readFile(embedded->file).substr(size_t(embedded->offset), size_t(embedded->length)),
                png)
                << file;
            ASSERT_EQ(scene.meshes.size(), inMemory.meshes.size());
            EXPECT_EQ(scene.meshes[0].positions, inMemory.meshes[0].positions) << file;
            EXPECT_EQ(scene.meshes[0].uvs, inMemory.meshes[0].uvs) << file;
            EXPECT_EQ(scene.meshes[0].triangles, inMemory.meshes[0].triangles) << file;
            EXPECT_EQ(renderSmall(scene), expected) << file;
            // The same bytes hash the same, read from the file or from memory.
            Scene copied = scene;
            for (Texture& t : copied.textures)
                if (t.type == TextureType::Standard) t.embedded = image(inMemory).embedded;
            EXPECT_EQ(sceneHash(scene), sceneHash(copied)) << file;
        }
    }
}

// The buffer tinygltf is handed holds the meshes' views only, each at its old offset modulo 16:
// the image's bytes (and the odd byte after them) are left out, and the views after it move.
TEST(GltfSources, TheParsersBufferHoldsOnlyTheViewsMeshesRead) {
    TempDir dir;
    const std::string png = pngBytes(dir, 8, 8);
    GltfBuilder b = texturedQuad(png);
    const std::string file = b.binary(dir, "cut.glb");
    const json before = b.doc;
    GltfSources sources(file, preflightGltf(file, {}));
    const json after = json::parse(sources.text());
    ASSERT_EQ(after["images"][0]["uri"], "spillway:image:0");
    EXPECT_FALSE(after["images"][0].contains("bufferView"));
    ASSERT_EQ(sources.embedded().count(0), 1u);
    const size_t imageView = before["images"][0]["bufferView"].get<size_t>();
    std::uint64_t kept = 0;
    for (size_t v = 0; v < before["bufferViews"].size(); ++v) {
        if (v == imageView) continue;
        const std::uint64_t was = before["bufferViews"][v].value("byteOffset", 0ull);
        const std::uint64_t is = after["bufferViews"][v].value("byteOffset", 0ull);
        EXPECT_EQ(is % 16, was % 16) << "view " << v;
        if (was > before["bufferViews"][imageView]["byteOffset"].get<std::uint64_t>()) {
            EXPECT_LT(is, was) << "view " << v << " moves down over the image's bytes";
        }
        kept += before["bufferViews"][v]["byteLength"].get<std::uint64_t>();
    }
    const std::uint64_t size = after["buffers"][0]["byteLength"].get<std::uint64_t>();
    EXPECT_GE(size, kept);
    EXPECT_LT(size, kept + 16 * before["bufferViews"].size()) << "only alignment between views";
    // The image's bytes are gone; what the views after it gain back is their alignment alone.
    EXPECT_LE(size, b.bytes.size() - png.size() + 15);
    EXPECT_EQ(sources.bufferFiles(), std::vector<std::string>{}) << "a .glb's BIN: the file itself";
}

// A file that no longer holds an embedded image's bytes (cut short after loading) is named when
// the image is read, not read past its end.
TEST(GltfSources, AnEmbeddedImagePastItsFilesEndIsRefusedByName) {
    TempDir dir;
    const std::string file = dir.write("short.glb", std::string(100, 'x'));
    EXPECT_NO_THROW(embeddedReader({file, 60, 40, nullptr}));
    try {
        embeddedReader({file, 60, 41, nullptr});
        FAIL() << "read past the end";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("'" + file + "' no longer holds its embedded image"),
                  std::string::npos)
            << e.what();
    }
    auto reader = embeddedReader({file, 90, 10, nullptr});
    char got[16] = {};
    EXPECT_EQ(reader->pread(got, 16, 0), 10u) << "a read stops at the image's end";
    EXPECT_EQ(reader->pread(got, 16, 10), 0u);
    EXPECT_EQ(reader->size(), 10u);
}

// An image written out as a data: URI is read from its base64 text in the file, never held in
// memory, in a .gltf and in a .glb's JSON chunk: it renders as the same bytes in a buffer do,
// PNG and JPEG. A URI with characters the writer escaped ("\/", "\u0041", legal JSON) is not
// the file's text as it is: it is decoded into memory, as before, and renders the same.
TEST(GltfSources, AnImageInADataUriIsReadFromItsTextInTheFile) {
    for (const std::string ext : {".png", ".jpg"}) { // a JPEG is decoded while it is read
        SCOPED_TRACE(ext);
        TempDir dir;
        const std::string png = pngBytes(dir, 40, 24, ext);
        GltfBuilder b = texturedQuad(png);
        const std::vector<float> expected = renderSmall(loadScene(b.binary(dir, "view.glb")));
        const std::string text = GltfBuilder::base64(png);
        const std::string mime = ext == ".png" ? "image/png" : "image/jpeg";
        b.doc["images"] = json::array({{{"uri", "data:" + mime + ";base64," + text}}});
        for (const std::string& file : {b.external(dir, "uri.gltf"), b.binary(dir, "uri.glb")}) {
            const Scene scene = loadScene(file);
            const std::shared_ptr<const EmbeddedImage> embedded = image(scene).embedded;
            ASSERT_TRUE(embedded) << file;
            EXPECT_FALSE(embedded->bytes) << file << ": the image is left in the file's text";
            EXPECT_TRUE(embedded->base64) << file;
            EXPECT_EQ(embedded->file, file);
            EXPECT_EQ(embedded->length, png.size());
            EXPECT_EQ(readFile(file).substr(size_t(embedded->offset), size_t(embedded->stored())),
                      text)
                << file;
            EXPECT_EQ(renderSmall(scene), expected) << file;
        }
        // Every '/' escaped as "\/", and the first character as "\u00XX" (so that some
        // character is escaped whatever the image's bytes).
        std::string escaped = readFile(dir.file("uri.gltf"));
        const size_t at = escaped.find(text);
        ASSERT_NE(at, std::string::npos);
        char first[8];
        std::snprintf(first, sizeof first, "\\u%04x",
                      unsigned(static_cast<unsigned char>(text[0])));
        std::string written = first;
        for (const char c : text.substr(1))
            written += c == '/' ? std::string("\\/") : std::string(1, c);
        escaped.replace(at, text.size(), written);
        const Scene scene = loadScene(dir.write("escaped.gltf", escaped));
        ASSERT_TRUE(image(scene).embedded && image(scene).embedded->bytes);
        EXPECT_EQ(*image(scene).embedded->bytes, png);
        EXPECT_EQ(renderSmall(scene), expected);
    }
}

// Base64 text in a file decodes to its bytes over any range read (each of 0, 1 and 2 padding
// characters; reads that start and end inside a group of 4), and stops short at a character
// that is not base64 (a file changed since it was loaded).
TEST(GltfSources, Base64TextInAFileDecodesOverAnyRange) {
    TempDir dir;
    for (const size_t n : {1u, 2u, 3u, 4u, 5u, 200000u}) {
        SCOPED_TRACE(n);
        std::string bytes(n, '\0');
        for (size_t i = 0; i < n; ++i)
            bytes[i] = char((i * 2654435761u) >> 13);
        const std::string text = GltfBuilder::base64(bytes);
        const std::string file = dir.write("b64.txt", "<" + text + ">");
        EmbeddedImage image{file, 1, n, nullptr, true};
        ASSERT_EQ(image.stored(), text.size());
        auto reader = embeddedReader(image);
        EXPECT_EQ(reader->size(), n);
        for (const size_t from : {size_t(0), size_t(1), size_t(2), n / 2, n - 1})
            for (const size_t count : {size_t(1), size_t(2), size_t(4), n, size_t(70000)}) {
                if (from >= n) continue;
                std::string got(count, '\0');
                const size_t read = reader->pread(got.data(), count, std::int64_t(from));
                EXPECT_EQ(got.substr(0, read), bytes.substr(from, count))
                    << "from " << from << ", " << count;
            }
        EXPECT_EQ(reader->pread(&bytes[0], 1, std::int64_t(n)), 0u) << "past the end";
    }
    const std::string file = dir.write("bad.txt", "QUJD" + std::string("QU*D") + "QUJD");
    auto reader = embeddedReader({file, 0, 9, nullptr, true});
    char got[9] = {};
    EXPECT_EQ(reader->pread(got, 9, 0), 3u) << "the 3 bytes before the character '*'";
    EXPECT_EQ(std::string(got, 3), "ABC");
}

// A buffer file whose size is not the buffer's byteLength is refused by pointer, as is a .glb
// whose buffer claims more than its BIN chunk holds.
TEST(GltfSources, BufferFilesOfTheWrongSizeAreRefusedByPointer) {
    TempDir dir;
    GltfBuilder b = texturedQuad(pngBytes(dir, 4, 4));
    const std::string gltf = b.external(dir, "sized.gltf");
    ASSERT_EQ(loadError(gltf), "");
    dir.write("sized.gltf.bin", b.bytes.substr(0, b.bytes.size() - 4));
    const std::string e = loadError(gltf);
    EXPECT_NE(e.find("/buffers/0/byteLength: is " + std::to_string(b.bytes.size())),
              std::string::npos)
        << e;
    // A .glb (as GltfBuilder::binary writes it) whose buffer claims 64 bytes more than its BIN.
    json d = b.doc;
    d["buffers"] = json::array({{{"byteLength", b.bytes.size() + 64}}});
    std::string text = d.dump(), bin = b.bytes, glb;
    while (text.size() % 4)
        text += ' ';
    while (bin.size() % 4)
        bin += '\0';
    auto u32 = [&](std::uint32_t v) { glb.append(reinterpret_cast<const char*>(&v), 4); };
    u32(0x46546C67u), u32(2u), u32(std::uint32_t(28 + text.size() + bin.size()));
    u32(std::uint32_t(text.size())), u32(0x4E4F534Au), glb += text;
    u32(std::uint32_t(bin.size())), u32(0x004E4942u), glb += bin;
    const std::string claim = loadError(dir.write("claim.glb", glb));
    EXPECT_NE(claim.find("/buffers/0/byteLength: is " + std::to_string(b.bytes.size() + 64) +
                         "; the GLB's BIN chunk holds " + std::to_string(bin.size()) + " bytes"),
              std::string::npos)
        << claim;
}

} // namespace
} // namespace spw::test
