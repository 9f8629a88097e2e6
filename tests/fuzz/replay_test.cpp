// Every input kept in tests/fuzz/, replayed through the fuzzing targets in the normal suite:
// the seeds (valid scenes and OBJ files: they must load, and the scenes render) and every
// crasher fuzzing ever found (each must now end as Accepted or Rejected, never otherwise).
#include "fuzz_targets.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <filesystem>

namespace spw::test {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> keptInputs(const std::string& dir) {
    std::vector<std::string> out;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(sourceDir() + "/tests/fuzz/" + dir, ec))
        if (e.is_regular_file() && e.path().filename().string()[0] != '.')
            out.push_back(e.path().string());
    std::sort(out.begin(), out.end());
    return out;
}

using Target = fuzz::Outcome (*)(const std::uint8_t*, std::size_t, std::string*);

fuzz::Outcome replay(Target target, const std::string& path, std::string* detail) {
    const std::string b = readFile(path);
    return target(reinterpret_cast<const std::uint8_t*>(b.data()), b.size(), detail);
}

TEST(FuzzCorpus, SeedsLoadAndRender) {
    const std::pair<const char*, Target> kinds[] = {{"seeds/scene", fuzz::scene},
                                                    {"seeds/obj", fuzz::obj},
                                                    {"seeds/gltf", fuzz::gltf},
                                                    {"seeds/checkpoint", fuzz::checkpoint}};
    for (const auto& [dir, target] : kinds) {
        const std::vector<std::string> files = keptInputs(dir);
        EXPECT_GE(files.size(), 3u) << dir;
        for (const std::string& f : files) {
            std::string detail;
            EXPECT_EQ(replay(target, f, &detail), fuzz::Outcome::Accepted) << f << " " << detail;
        }
    }
}

TEST(FuzzCorpus, EveryCrasherFoundIsNowRejectedCleanly) {
    const std::pair<const char*, Target> kinds[] = {{"crashers/scene", fuzz::scene},
                                                    {"crashers/obj", fuzz::obj},
                                                    {"crashers/gltf", fuzz::gltf},
                                                    {"crashers/checkpoint", fuzz::checkpoint}};
    for (const auto& [dir, target] : kinds)
        for (const std::string& f : keptInputs(dir)) {
            std::string detail;
            EXPECT_NE(replay(target, f, &detail), fuzz::Outcome::Unexpected) << f << " " << detail;
        }
}

} // namespace
} // namespace spw::test
