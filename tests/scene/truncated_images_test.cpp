// A JPEG cut short is refused when the scene loads (host/image/jpeg_check.h), on every path an
// image takes: a YAML scene's texture file, a glTF file's image beside it and one embedded in a
// .glb (exit 2 naming the file, or the image's JSON pointer). libjpeg alone reads such a file
// with its missing rows grey and says nothing an application sees. A whole JPEG, one with bytes
// after its end, and one whose thumbnail's end-of-image marker lies before the scan are judged
// by the marker after the scan alone.
#include "host/image/jpeg_check.h"
#include "host/loaders/scene_loader.h"
#include "scene/gltf_builder.h"
#include "test_util.h"

#include <OpenImageIO/imagebuf.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstring>

namespace spw::test {
namespace {

using nlohmann::json;

// A 512 x 512 JPEG of varied texels, as bytes.
std::string jpegBytes(const TempDir& dir) {
    OIIO::ImageBuf img(OIIO::ImageSpec(512, 512, 3, OIIO::TypeDesc::UINT8));
    for (int y = 0; y < 512; ++y)
        for (int x = 0; x < 512; ++x) {
            const float c[3] = {float(x % 37) / 37.0f, float(y % 29) / 29.0f, 0.5f};
            img.setpixel(x, y, c);
        }
    EXPECT_TRUE(img.write(dir.file("whole.jpg")));
    return readFile(dir.file("whole.jpg"));
}

std::string judge(const std::string& bytes) {
    return jpegCutShort(
        [&](void* out, size_t n, std::uint64_t at) {
            if (at >= bytes.size()) return size_t(0);
            n = std::min<size_t>(n, bytes.size() - size_t(at));
            std::memcpy(out, bytes.data() + at, n);
            return n;
        },
        bytes.size(), "'x.jpg'");
}

TEST(TruncatedImages, AJpegIsWholeWhenItsEndMarkerFollowsItsScan) {
    TempDir dir;
    const std::string whole = jpegBytes(dir);
    ASSERT_GT(whole.size(), 4096u);
    EXPECT_EQ(judge(whole), "");
    EXPECT_EQ(judge(whole + std::string(200000, '\x17')), "") << "bytes after the end";
    const std::string cut = judge(whole.substr(0, whole.size() / 2));
    EXPECT_EQ(cut, "'x.jpg' is a JPEG cut short: it has no end-of-image marker after its image "
                   "data (a truncated or damaged file)");
    EXPECT_NE(judge(whole.substr(0, whole.size() - 2)), "") << "only the marker cut";
    // A thumbnail (an APP1 segment holding FF D9) before the scan does not make a cut file whole.
    const std::string app1 = std::string("\xFF\xE1\x00\x06", 4) + "ab\xFF\xD9";
    const std::string thumbed = whole.substr(0, 2) + app1 + whole.substr(2);
    EXPECT_EQ(judge(thumbed), "");
    EXPECT_NE(judge(thumbed.substr(0, thumbed.size() / 2)), "");
    EXPECT_NE(judge(whole.substr(0, 20)), "") << "the file ends before its scan";
    EXPECT_EQ(judge("\x89PNG\r\n\x1a\n...."), "") << "not a JPEG: not judged here";
}

TEST(TruncatedImages, AJpegCutShortIsRefusedOnEveryPath) {
    TempDir dir;
    const std::string whole = jpegBytes(dir);
    const std::string cut = whole.substr(0, whole.size() / 2);
    dir.write("cut.jpg", cut);
    // A YAML scene's texture file.
    dir.write("quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nf 1/1 2/2 3/3\n");
    const std::string yaml = "camera: {translation: [0.5, 0.5, 3]}\n"
                             "shader: {type: Lambert, texture: {type: Standard, string: ";
    const std::string rest = "}}\nobject: {filename: quad.obj}\n";
    EXPECT_EQ(loadError(dir.write("whole.yaml", yaml + "whole.jpg" + rest)), "");
    const std::string y = loadError(dir.write("cut.yaml", yaml + "cut.jpg" + rest));
    EXPECT_NE(y.find("texture file '" + dir.file("cut.jpg") + "' is a JPEG cut short"),
              std::string::npos)
        << y;
    // A glTF file's image beside it, and one embedded in a .glb.
    for (const bool embedded : {false, true}) {
        GltfBuilder b;
        json mat = material(vec3(1.0f), 0.0f, 1.0f);
        mat["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
        b.doc["materials"] = json::array({mat});
        b.doc["textures"] = json::array({{{"source", 0}}});
        if (embedded) {
            const int view =
                b.view<std::uint8_t>(std::vector<std::uint8_t>(cut.begin(), cut.end()));
            b.doc["images"] = json::array({{{"bufferView", view}, {"mimeType", "image/jpeg"}}});
        } else {
            b.doc["images"] = json::array({{{"uri", "cut.jpg"}}});
        }
        b.scene({b.node({{"mesh", b.mesh(b.quad(0))}})});
        const std::string e = loadError(b.binary(dir, "cut.glb"));
        const std::string expected =
            embedded ? "/images/0: the embedded image is a JPEG cut short"
                     : "/images/0/uri: '" + dir.file("cut.jpg") + "' is a JPEG cut short";
        EXPECT_NE(e.find(expected), std::string::npos) << e;
    }
}

} // namespace
} // namespace spw::test
