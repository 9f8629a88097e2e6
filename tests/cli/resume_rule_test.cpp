// What a resume keeps of the render it continues: the rule that stopped it (a render that
// stopped on its target stops again at once), the way its tiles share samples toward a target
// (part of the checkpoint's identity), and its samples an iteration when more are asked for.
#include "scene/gltf_builder.h"
#include "test_util.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

namespace spw::test {
namespace {

using nlohmann::json;

json statsOf(const std::string& path) {
    return json::parse(std::ifstream(path));
}

// Stopped on its target (after 2 of 16 iterations: a target far above the estimate), then
// resumed with the same command: it stops again before any iteration, with the same image, the
// same samples and the same reason.
TEST(ResumeRule, ARenderThatStoppedOnItsTargetStopsAgainAtOnce) {
    TempDir dir;
    const std::string scene = smallCornellBox(dir, 24, 24);
    const std::vector<std::string> args = {"render",  scene,          "--backend",       "cpu",
                                           "--spp",   "16",           "--target-error",  "1e9",
                                           "--quiet", "--checkpoint", dir.file("ck.exr")};
    auto run = [&](const std::string& name, std::vector<std::string> extra) {
        std::vector<std::string> a = args;
        a.insert(a.end(), extra.begin(), extra.end());
        a.insert(a.end(), {"-o", dir.file(name + ".exr"), "--stats", dir.file(name + ".json")});
        return runChild(a);
    };
    ChildResult first = run("first", {});
    ASSERT_EQ(first.status, 0) << first.output;
    const json a = statsOf(dir.file("first.json"));
    ASSERT_EQ(a["stop_reason"], "target error");
    ASSERT_EQ(a["spp"], 2);
    ChildResult again = run("again", {"--resume", dir.file("ck.exr")});
    ASSERT_EQ(again.status, 0) << again.output;
    const json b = statsOf(dir.file("again.json"));
    EXPECT_EQ(b["stop_reason"], "target error");
    EXPECT_EQ(b["spp"], 2);
    EXPECT_EQ(b["samples_taken"], a["samples_taken"]);
    EXPECT_TRUE(samePixels(dir.file("first.exr"), dir.file("again.exr")));
}

// Toward a target the tiles share the samples by their noise; uniformly (--uniform) they do not.
// A checkpoint made one way resumes only the same way, toward the same target: any other is
// refused (exit 2, saying so). The same way, to more samples, gives the uninterrupted render.
TEST(ResumeRule, HowTheTilesShareSamplesIsPartOfTheCheckpoint) {
    TempDir dir;
    const std::string scene = smallCornellBox(dir, 24, 24);
    auto run = [&](const std::string& spp, std::vector<std::string> extra) {
        std::vector<std::string> a = {"render", scene, "--backend", "cpu", "--spp", spp, "--quiet"};
        a.insert(a.end(), extra.begin(), extra.end());
        return runChild(a);
    };
    const std::string shared = dir.file("shared.exr"), uniform = dir.file("uniform.exr");
    ASSERT_EQ(run("4", {"--target-error", "1e-12", "--checkpoint", shared}).status, 0);
    ASSERT_EQ(run("4", {"--target-error", "1e-12", "--uniform", "--checkpoint", uniform}).status,
              0);
    for (const auto& [ck, extra] : std::vector<std::pair<std::string, std::vector<std::string>>>{
             {shared, {"--target-error", "1e-12", "--uniform"}},
             {shared, {"--target-error", "2e-12"}},
             {uniform, {"--target-error", "1e-12"}},
             {shared, {}}}) {
        std::vector<std::string> a = extra;
        a.insert(a.end(), {"--resume", ck, "-o", dir.file("refused.exr")});
        const ChildResult r = run("8", a);
        EXPECT_EQ(r.status, 2) << r.output;
        EXPECT_NE(r.output.find("samples shared by the tiles toward"), std::string::npos)
            << r.output;
        EXPECT_FALSE(std::filesystem::exists(dir.file("refused.exr")));
    }
    ASSERT_EQ(run("8", {"--target-error", "1e-12", "-o", dir.file("full.exr")}).status, 0);
    const ChildResult r =
        run("8", {"--target-error", "1e-12", "--resume", shared, "-o", dir.file("resumed.exr")});
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(samePixels(dir.file("full.exr"), dir.file("resumed.exr")));
}

// A glTF file takes 16 samples a pixel an iteration where --spp allows (a multiple of 16), one
// otherwise. A checkpoint made at --spp 8 (one an iteration) resumes to --spp 16, keeping one
// an iteration: the same render as one resumed from --spp 4, sample for sample.
TEST(ResumeRule, AResumeToMoreSamplesKeepsTheCheckpointsSamplesAnIteration) {
    TempDir dir;
    GltfBuilder b;
    b.doc["materials"] = json::array({material(vec3(0.7f), 0.0f, 0.5f)});
    b.doc["cameras"] =
        json::array({{{"type", "perspective"},
                      {"perspective", {{"yfov", 0.5}, {"aspectRatio", 1.0}, {"znear", 0.1}}}}});
    b.scene({b.node({{"mesh", b.mesh(b.quad(0))}}),
             b.node({{"camera", 0}, {"translation", {0.5, 0.5, 3}}})});
    const std::string scene = b.binary(dir, "quad.glb");
    auto run = [&](std::vector<std::string> extra) {
        std::vector<std::string> a = {"render",  scene, "--backend", "cpu", "--quiet",
                                      "--width", "16",  "--height",  "16"};
        a.insert(a.end(), extra.begin(), extra.end());
        return runChild(a);
    };
    for (const std::string spp : {"8", "4"}) {
        const std::string ck = dir.file("ck" + spp + ".exr");
        ASSERT_EQ(run({"--spp", spp, "--checkpoint", ck}).status, 0);
        const ChildResult r =
            run({"--spp", "16", "--resume", ck, "-o", dir.file("r" + spp + ".exr"), "--stats",
                 dir.file("r" + spp + ".json")});
        ASSERT_EQ(r.status, 0) << r.output;
        const json s = statsOf(dir.file("r" + spp + ".json"));
        EXPECT_EQ(s["spp"], 16);
        EXPECT_EQ(s["resumed_iterations"], std::stoi(spp));
    }
    EXPECT_TRUE(samePixels(dir.file("r8.exr"), dir.file("r4.exr")));
    // Without --spp the file's default sampling applies: toward a target, whose tiles share the
    // samples, where the checkpoint's were uniform. That is another rule: refused.
    const ChildResult d = run({"--resume", dir.file("ck8.exr"), "-o", dir.file("d.exr")});
    EXPECT_EQ(d.status, 2) << d.output;
    EXPECT_NE(d.output.find("samples shared by the tiles toward no target"), std::string::npos)
        << d.output;
}

} // namespace
} // namespace spw::test
