// The architecture as docs/design.md draws it, checked on the sources: every #include goes down
// the layers, never up or sideways, and Embree stays inside embree_backend/.
//
//   app -> render -> {cpu, vk (the shading engines)} -> pipeline -> embree_backend (the Embree
//   scene, traversal, the reference backend) -> backend (what every backend is handed)
//   -> {loaders (YAML, glTF, OBJ: only render and app load scenes), scene_view (lights, hit
//   setup)} -> textures -> scene (the model) -> image -> simd -> shaders/shared
#include "test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace spw::test {
namespace {

namespace fs = std::filesystem;

// The folder a source or an include path belongs to: host/<folder>/..., embree_backend, or shared.
std::string layerOf(const std::string& path) {
    static const std::regex host("^host/([a-z_]+)/");
    std::smatch m;
    if (std::regex_search(path, m, host)) return m[1];
    if (path.rfind("embree_backend/", 0) == 0) return "embree_backend";
    if (path.rfind("shared/", 0) == 0 || path.rfind("shaders/shared/", 0) == 0) return "shared";
    return "";
}

// The layers from the bottom up, as docs/design.md draws them. A layer may include any layer
// below it, except where kSiblings says two stand side by side (neither includes the other).
const std::vector<std::string> kLayers = {
    "shared",  "simd",           "image",    "scene", "textures", "scene_view", "loaders",
    "backend", "embree_backend", "pipeline", "cpu",   "vk",       "render",     "app"};
const std::set<std::pair<std::string, std::string>> kSiblings = {{"loaders", "scene_view"},
                                                                 {"loaders", "backend"},
                                                                 {"loaders", "embree_backend"},
                                                                 {"loaders", "pipeline"},
                                                                 {"loaders", "cpu"},
                                                                 {"loaders", "vk"},
                                                                 {"vk", "cpu"},
                                                                 {"vk", "embree_backend"}};

bool mayInclude(const std::string& from, const std::string& to) {
    const auto at = [](const std::string& layer) {
        return std::find(kLayers.begin(), kLayers.end(), layer) - kLayers.begin();
    };
    return at(to) < at(from) && !kSiblings.count({from, to}) && !kSiblings.count({to, from});
}

std::vector<std::string> sources() {
    std::vector<std::string> out;
    for (const char* dir : {"host", "embree_backend", "shaders/shared"})
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
        ASSERT_NE(std::find(kLayers.begin(), kLayers.end(), from), kLayers.end())
            << file << ": a folder the layering does not know";
        std::ifstream in(sourceDir() + "/" + file);
        std::string line;
        for (int n = 1; std::getline(in, line); ++n) {
            std::smatch m;
            if (!std::regex_search(line, m, include)) continue;
            const std::string to = layerOf(m[1]);
            if (to.empty() || to == from) continue; // same folder, or a sibling file of shared/
            ++checked;
            EXPECT_TRUE(mayInclude(from, to))
                << file << ":" << n << ": " << from << " includes " << m[1] << " (" << to << ")";
        }
    }
    EXPECT_GT(checked, 50u);
}

// Every folder of code says what it holds, in a README of its own, and is a layer the test knows.
TEST(Architecture, EveryFolderOpensWithAReadme) {
    size_t folders = 0;
    for (const std::string dir : {"host", "embree_backend"}) {
        std::vector<fs::path> paths = {fs::path(sourceDir()) / dir};
        if (dir == "host")
            for (const auto& e : fs::directory_iterator(paths[0]))
                if (e.is_directory()) paths.push_back(e.path());
        for (const fs::path& p : paths) {
            if (p.filename() == "host") continue;
            ++folders;
            const std::string layer = layerOf(fs::relative(p, sourceDir()).generic_string() + "/");
            EXPECT_NE(std::find(kLayers.begin(), kLayers.end(), layer), kLayers.end()) << p;
            EXPECT_TRUE(fs::is_regular_file(p / "README.md")) << p << " has no README.md";
        }
    }
    EXPECT_GE(folders, 13u);
}

TEST(Architecture, NoEmbreeTypeOutsideTheEmbreeBackend) {
    static const std::regex embree("embree3/|\\bRTC[A-Z][A-Za-z]*\\b|\\brtc[A-Z][A-Za-z0-9]*\\(");
    for (const std::string& file : sources()) {
        if (layerOf(file) == "embree_backend") continue;
        std::ifstream in(sourceDir() + "/" + file);
        std::string line;
        for (int n = 1; std::getline(in, line); ++n)
            EXPECT_FALSE(std::regex_search(line, embree)) << file << ":" << n << ": " << line;
    }
}

} // namespace
} // namespace spw::test
