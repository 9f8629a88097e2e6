// The scan of a glTF file's JSON text before it is parsed (host/loaders/gltf_text_scan.h): the
// images' data: URIs it finds and cuts out, whatever pieces the text arrives in, and those it
// leaves alone.
#include "host/loaders/gltf_preflight.h"
#include "host/loaders/gltf_text_scan.h"
#include "scene/gltf_builder.h"
#include "test_util.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace spw::test {
namespace {

using nlohmann::json;

JsonTextScan scanned(const std::string& text, size_t piece, std::uint64_t offset = 0) {
    JsonTextScan scan(kMaxGltfJsonDepth, offset);
    for (size_t at = 0; at < text.size(); at += piece)
        scan.feed(text.data() + at, std::min(piece, text.size() - at));
    return scan;
}

std::string cut(const JsonTextScan& scan, const std::string& text, std::uint64_t offset = 0) {
    return scan.cutPayloads(text.size(), [&](std::uint64_t at, size_t n, std::string& out) {
        out.append(text, size_t(at - offset), n);
    });
}

// Fed in pieces of any size, the scan finds the same payloads: their place in the file, their
// characters and their bytes (0, 1 and 2 padding characters), and the text with them cut out is
// the text with each replaced by its reference.
TEST(GltfTextScan, ImagesDataUrisAreFoundInAnyPieces) {
    const std::string a = GltfBuilder::base64("ABC"), b = GltfBuilder::base64("ABCD"),
                      c = GltfBuilder::base64("ABCDE");
    const std::string text = R"({"images":[{"uri":"data:image/png;base64,)" + a +
                             R"("},{"uri":"data:image/jpeg;base64,)" + b +
                             R"("}],"x":["data:image/png;base64,)" + c + R"("]})";
    const std::uint64_t offset = 20; // as in a .glb's JSON chunk
    const size_t at[3] = {text.find(a), text.find(b, text.find(a) + a.size()), text.rfind(c)};
    for (size_t piece = 1; piece <= text.size(); ++piece) {
        SCOPED_TRACE(piece);
        const JsonTextScan scan = scanned(text, piece, offset);
        ASSERT_EQ(scan.payloads().size(), 3u);
        const size_t bytes[3] = {3, 4, 5};
        const std::string* texts[3] = {&a, &b, &c};
        size_t k = 0;
        for (const auto& [start, p] : scan.payloads()) {
            EXPECT_EQ(p.start, offset + at[k]);
            EXPECT_EQ(p.length, texts[k]->size());
            EXPECT_EQ(p.bytes, bytes[k]);
            ++k;
        }
        EXPECT_EQ(scan.depth(), 3);
        std::string expected = text;
        for (int i = 2; i >= 0; --i)
            expected.replace(at[i], texts[i]->size(),
                             JsonTextScan::kReference + std::to_string(offset + at[i]));
        EXPECT_EQ(cut(scan, text, offset), expected);
    }
}

// Left as they are: a payload with a JSON escape, one that is not base64 (a stray character,
// padding inside it, three padding characters, a length not a multiple of 4), an empty one, a
// buffer's (octet-stream) and a header with an escape; an escaped quote does not end a string,
// and brackets in strings do not nest.
TEST(GltfTextScan, OtherStringsAreLeftAsTheyAre) {
    for (const std::string uri :
         {R"(data:image/png;base64,QU\/D)", "data:image/png;base64,QU*D",
          "data:image/png;base64,Q=JD", "data:image/png;base64,Q===", "data:image/png;base64,QUJ",
          "data:image/png;base64,", "data:application/octet-stream;base64,QUJD",
          R"(data:image\/png;base64,QUJD)", R"(\"data:image/png;base64,QUJD)"}) {
        SCOPED_TRACE(uri);
        const std::string text = R"({"images":[{"uri":")" + uri + R"(", "n": "[[[["}]})";
        const JsonTextScan scan = scanned(text, 7);
        EXPECT_TRUE(scan.payloads().empty());
        EXPECT_EQ(scan.depth(), 3);
        EXPECT_EQ(cut(scan, text), text);
    }
}

// Through the preflight: image 1's URI becomes an image read from the file (image 0 is a file),
// and the same data: URI text elsewhere (an `extras` string) reads as the file wrote it.
TEST(GltfTextScan, ThePreflightReadsImagesFromTheFileAndGivesOtherStringsBack) {
    TempDir dir;
    dir.write("a.png", "a file: the preflight checks only that it is one");
    const std::string payload = GltfBuilder::base64(std::string("\x89PNG\r\n\x1a\n", 8) + "rest");
    const std::string uri = "data:image/png;base64," + payload;
    json doc = {{"asset", {{"version", "2.0"}, {"extras", {{"thumbnail", uri}}}}},
                {"images", json::array({{{"uri", "a.png"}}, {{"uri", uri}}})}};
    for (const bool binary : {false, true}) {
        SCOPED_TRACE(binary);
        std::string file;
        if (binary) {
            std::string text = doc.dump(), glb;
            while (text.size() % 4)
                text += ' ';
            auto u32 = [&](std::uint32_t v) { glb.append(reinterpret_cast<const char*>(&v), 4); };
            u32(0x46546C67u), u32(2u), u32(std::uint32_t(20 + text.size()));
            u32(std::uint32_t(text.size())), u32(0x4E4F534Au), glb += text;
            file = dir.write("refs.glb", glb);
        } else {
            file = dir.write("refs.gltf", doc.dump());
        }
        const GltfDocument d = preflightGltf(file, {});
        EXPECT_EQ(d.doc["asset"]["extras"]["thumbnail"], uri);
        ASSERT_EQ(d.dataUris.size(), 1u);
        ASSERT_EQ(d.dataUris.count(1), 1u);
        const EmbeddedImage& image = *d.dataUris.at(1);
        EXPECT_TRUE(image.base64);
        EXPECT_EQ(image.length, 12u);
        EXPECT_EQ(readFile(file).substr(size_t(image.offset), size_t(image.stored())), payload);
        EXPECT_EQ(d.doc["images"][1]["uri"].get<std::string>().rfind("data:image/png;base64,", 0),
                  0u);
        EXPECT_LT(d.doc["images"][1]["uri"].get<std::string>().size(), uri.size())
            << "the tree holds a reference, not the image";
    }
}

} // namespace
} // namespace spw::test
