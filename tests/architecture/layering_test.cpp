// The architecture as docs/design.md draws it, checked on the sources: every #include goes down
// the layers, never up or sideways, and Embree stays inside host/accel/.
//
//   app -> render -> {reference, cpu and vk (the shading engines) -> pipeline}
//       -> {pipeline -> accel (Embree)} -> backend (what every backend is handed) -> scene
//       -> image -> simd (Highway: the SIMD twins of shared functions) -> shaders/shared
#include "test_util.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <string>

namespace spw::test {
namespace {

namespace fs = std::filesystem;

// The folder a source or an include path belongs to: host/<folder>/..., or shared.
std::string layerOf(const std::string& path) {
    static const std::regex host("^host/([a-z_]+)/");
    std::smatch m;
    if (std::regex_search(path, m, host)) return m[1];
    if (path.rfind("shared/", 0) == 0 || path.rfind("shaders/shared/", 0) == 0) return "shared";
    return "";
}

// What each layer may include besides itself.
const std::map<std::string, std::set<std::string>> kMayInclude = {
    {"shared", {}},
    {"simd", {"shared"}},
    {"image", {"simd", "shared"}},
    {"scene", {"image", "simd", "shared"}},
    {"backend", {"scene", "image", "simd", "shared"}},
    {"accel", {"backend", "scene", "image", "simd", "shared"}},
    {"pipeline", {"accel", "backend", "scene", "image", "simd", "shared"}},
    {"cpu", {"pipeline", "accel", "backend", "scene", "image", "simd", "shared"}},
    {"vk", {"pipeline", "backend", "scene", "image", "simd", "shared"}},
    {"reference", {"accel", "backend", "scene", "image", "simd", "shared"}},
    {"render",
     {"reference", "cpu", "vk", "pipeline", "accel", "backend", "scene", "image", "simd",
      "shared"}},
    {"app",
     {"render", "reference", "cpu", "vk", "pipeline", "accel", "backend", "scene", "image", "simd",
      "shared"}},
};

std::vector<std::string> sources() {
    std::vector<std::string> out;
    for (const char* dir : {"host", "shaders/shared"})
        for (const auto& e : fs::recursive_directory_iterator(sourceDir() + "/" + dir)) {
            const std::string ext = e.path().extension().string();
            if (e.is_regular_file() && (ext == ".h" || ext == ".cpp"))
                out.push_back(fs::relative(e.path(), sourceDir()).generic_string());
        }
    return out;
}

TEST(Architecture, EveryIncludeGoesDownTheLayers) {
    const std::vector<std::string> files = sources();
    ASSERT_GT(files.size(), 50u);
    static const std::regex include("^#include \"([^\"]+)\"");
    size_t checked = 0;
    for (const std::string& file : files) {
        const std::string from = layerOf(file);
        ASSERT_TRUE(kMayInclude.count(from)) << file << ": a folder the layering does not know";
        std::ifstream in(sourceDir() + "/" + file);
        std::string line;
        for (int n = 1; std::getline(in, line); ++n) {
            std::smatch m;
            if (!std::regex_search(line, m, include)) continue;
            const std::string to = layerOf(m[1]);
            if (to.empty() || to == from) continue; // same folder, or a sibling file of shared/
            ++checked;
            EXPECT_TRUE(kMayInclude.at(from).count(to))
                << file << ":" << n << ": " << from << " includes " << m[1] << " (" << to << ")";
        }
    }
    EXPECT_GT(checked, 50u);
}

TEST(Architecture, NoEmbreeTypeOutsideAccel) {
    static const std::regex embree("embree3/|\\bRTC[A-Z][A-Za-z]*\\b|\\brtc[A-Z][A-Za-z0-9]*\\(");
    for (const std::string& file : sources()) {
        if (layerOf(file) == "accel") continue;
        std::ifstream in(sourceDir() + "/" + file);
        std::string line;
        for (int n = 1; std::getline(in, line); ++n)
            EXPECT_FALSE(std::regex_search(line, embree)) << file << ":" << n << ": " << line;
    }
}

} // namespace
} // namespace spw::test
