// Checkpoint and resume: a render stopped at any point (a signal, a kill between checkpoints,
// a spill in flight) and resumed ends with the uninterrupted render's image bit for bit, on
// every backend; a checkpoint of another render is refused with exit 2.
#include "host/image/image_io.h"
#include "host/render/checkpoint.h"
#include "scene/gltf_builder.h"
#include "test_util.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <thread>
#include <unistd.h>

namespace spw::test {
namespace {

namespace fs = std::filesystem;

const std::vector<std::string> kSpilling = {"--memory-budget", "0.05", "--bin-exponent", "8"};

std::vector<std::string> renderArgs(const std::string& scene, const std::string& backend,
                                    std::vector<std::string> extra) {
    std::vector<std::string> args = {"render", scene, "--backend", backend, "--spp", "24"};
    args.insert(args.end(), kSpilling.begin(), kSpilling.end());
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
}

// Stopped by SIGINT (the checkpoint written at the stop) and by SIGKILL (only the last
// interval's checkpoint survives), both while batches are on disk, then resumed: the resumed
// image is the uninterrupted one, bit for bit. The checkpoint itself is an EXR whose RGB is the
// image so far.
TEST(Checkpoint, StoppedAnywhereAndResumedGivesTheUninterruptedImageOnEveryBackend) {
    TempDir dir, spill;
    const std::string scene = smallCornellBox(dir, 40, 40);
    for (const std::string& backend : backendsUnderTest()) {
        const std::string full = dir.file(backend + "-full.exr");
        ChildResult f = runChild(renderArgs(scene, backend, {"--quiet", "-o", full}));
        ASSERT_EQ(f.status, 0) << f.output;

        for (int signal : {SIGINT, SIGKILL}) {
            const std::string tag = backend + "-" + std::to_string(signal);
            const std::string ck = dir.file(tag + "-ck.exr"), part = dir.file(tag + "-part.exr");
            ChildResult p = runChild(
                renderArgs(scene, backend,
                           {"--progress", "lines", "--spill-dir", spill.path(), "--checkpoint", ck,
                            "--checkpoint-interval", "0.001", "-o", part}),
                [&](pid_t pid) {
                    waitForChildOutput(pid, "iteration 5/");
                    kill(pid, signal);
                });
            EXPECT_EQ(p.status, signal == SIGKILL ? -SIGKILL : 130) << tag << "\n" << p.output;
            EXPECT_EQ(filesIn(spill.path()), 0u) << tag;
            ASSERT_TRUE(std::filesystem::exists(ck)) << tag << "\n" << p.output;
            const Checkpoint c = readCheckpoint(ck);
            EXPECT_GE(c.iterations, signal == SIGKILL ? 4 : 5) << tag;
            EXPECT_LT(c.iterations, 24) << tag;
            if (signal == SIGINT) {
                EXPECT_TRUE(samePixels(ck, part)) << tag;
            }

            const std::string resumed = dir.file(tag + "-resumed.exr");
            ChildResult r = runChild(renderArgs(
                scene, backend,
                {"--quiet", "--resume", ck, "-o", resumed, "--stats", dir.file(tag + ".json")}));
            ASSERT_EQ(r.status, 0) << tag << "\n" << r.output;
            const nlohmann::json s = nlohmann::json::parse(std::ifstream(dir.file(tag + ".json")));
            EXPECT_EQ(s["resumed_iterations"], c.iterations) << tag;
            EXPECT_EQ(s["spp"], 24) << tag;
            EXPECT_TRUE(samePixels(resumed, full)) << tag << ": resumed at " << c.iterations;
            // The resume wrote its own checkpoint back to the file: now complete.
            EXPECT_EQ(readCheckpoint(ck).iterations, 24) << tag;
        }
    }
}

// Adaptive sampling and the Sobol sampler resume exactly too: the tiles' decisions come back
// from the checkpoint's sums and sample counts, so the resumed render takes the same samples.
TEST(Checkpoint, AdaptiveSobolRenderResumesToTheSameImageAndSamples) {
    TempDir dir;
    // 64 x 64 at up to 256 spp: about a second after the 6th iteration, so that SIGINT surely
    // lands before the render ends (at 40 x 40 and 64 spp it was 70 ms).
    const std::string scene = smallCornellBox(dir, 64, 64);
    const std::vector<std::string> adaptive = {
        "--sampler", "Sobol", "--adaptive-threshold", "0.05", "--adaptive-min-spp", "4"};
    auto args = [&](std::vector<std::string> extra) {
        std::vector<std::string> a = {"render", scene, "--backend", "cpu", "--spp", "256"};
        a.insert(a.end(), adaptive.begin(), adaptive.end());
        // and every batch through the disk
        a.insert(a.end(), kSpilling.begin(), kSpilling.end());
        a.insert(a.end(), extra.begin(), extra.end());
        return a;
    };
    const std::string full = dir.file("full.exr"), ck = dir.file("ck.exr");
    ChildResult f = runChild(args({"--quiet", "-o", full, "--stats", dir.file("full.json")}));
    ASSERT_EQ(f.status, 0) << f.output;
    ChildResult p =
        runChild(args({"--progress", "lines", "--checkpoint", ck, "-o", dir.file("part.exr")}),
                 [&](pid_t pid) {
                     waitForChildOutput(pid, "iteration 6/");
                     kill(pid, SIGINT);
                 });
    ASSERT_EQ(p.status, 130) << p.output;
    const std::string resumed = dir.file("resumed.exr");
    ChildResult r =
        runChild(args({"--quiet", "--resume", ck, "-o", resumed, "--stats", dir.file("r.json")}));
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(samePixels(resumed, full));
    const nlohmann::json a = nlohmann::json::parse(std::ifstream(dir.file("full.json")));
    const nlohmann::json b = nlohmann::json::parse(std::ifstream(dir.file("r.json")));
    EXPECT_EQ(a["samples_taken"], b["samples_taken"]);
    EXPECT_LT(a["samples_taken"].get<std::uint64_t>(), std::uint64_t(64 * 64 * 256));
}

// A checkpoint of another render is refused before any work: exit 2, the reason named, nothing
// written. Backends may differ (they trace the same paths).
// A checkpoint's identity covers the files a YAML scene places, not only the scene's own text:
// a placed glTF file whose material changed since the checkpoint is another scene, for --resume
// and for merging partials.
TEST(Checkpoint, AChangedPlacedGltfFileIsAnotherScene) {
    TempDir dir;
    const auto writeGltf = [&](float roughness) {
        GltfBuilder b;
        b.doc["materials"] = json::array({material(vec3(0.7f), 0.0f, roughness, vec3(1.0f))});
        b.scene({b.node({{"mesh", b.mesh(b.quad(0))}})});
        b.external(dir, "quad.gltf");
    };
    writeGltf(0.5f);
    const std::string scene = dir.write(
        "scene.yaml", "image: {width: 16, height: 16, sample base: 1, iterations: 4}\n"
                      "camera: {type: PinHole, look at: {eye: [0.5, 0.5, 3], target: [0.5, 0.5, "
                      "0]}, fov: 40}\n"
                      "objects:\n  - {type: Gltf, filename: quad.gltf}\n");
    const std::vector<std::string> common = {"--backend", "cpu", "--quiet", "-o",
                                             dir.file("out.exr")};
    auto run = [&](std::vector<std::string> args) {
        args.insert(args.end(), common.begin(), common.end());
        return runChild(args);
    };
    const ChildResult first =
        run({"render", scene, "--spp", "2", "--checkpoint", dir.file("ck.exr")});
    ASSERT_EQ(first.status, 0) << first.output;
    ASSERT_EQ(
        run({"render", scene, "--spp", "4", "--samples", "0:2", "--partial", dir.file("a.exr")})
            .status,
        0);
    writeGltf(0.25f); // the material, not the geometry
    const ChildResult resumed =
        run({"render", scene, "--spp", "4", "--resume", dir.file("ck.exr")});
    EXPECT_EQ(resumed.status, 2) << resumed.output;
    EXPECT_NE(resumed.output.find("another scene"), std::string::npos) << resumed.output;
    ASSERT_EQ(
        run({"render", scene, "--spp", "4", "--samples", "2:4", "--partial", dir.file("b.exr")})
            .status,
        0);
    const ChildResult merged =
        runChild({"merge", dir.file("a.exr"), dir.file("b.exr"), "-o", dir.file("m.exr")});
    EXPECT_NE(merged.status, 0) << merged.output;
    EXPECT_FALSE(fs::exists(dir.file("m.exr")));
}

// --error-csv on a resumed render keeps the rows the first run wrote for the iterations the
// checkpoint holds, and adds its own: one CSV of the whole render, the uninterrupted one's.
TEST(Checkpoint, TheErrorCsvOfAResumedRenderKeepsTheFirstRunsRows) {
    TempDir dir;
    const std::string scene = smallCornellBox(dir, 24, 24);
    const std::vector<std::string> common = {"--backend", "cpu", "--quiet", "-o",
                                             dir.file("out.exr")};
    auto run = [&](std::vector<std::string> args) {
        args.insert(args.end(), common.begin(), common.end());
        return runChild(args);
    };
    ASSERT_EQ(run({"render", scene, "--spp", "3", "--checkpoint", dir.file("ck.exr"), "--error-csv",
                   dir.file("e.csv")})
                  .status,
              0);
    ASSERT_EQ(run({"render", scene, "--spp", "6", "--resume", dir.file("ck.exr"), "--error-csv",
                   dir.file("e.csv")})
                  .status,
              0);
    ASSERT_EQ(run({"render", scene, "--spp", "6", "--error-csv", dir.file("whole.csv")}).status, 0);
    // The columns but the seconds are the uninterrupted render's.
    const auto withoutSeconds = [](const std::string& text) {
        std::string out;
        std::istringstream in(text);
        for (std::string line; std::getline(in, line);) {
            const size_t a = line.find(',', line.find(',') + 1), b = line.find(',', a + 1);
            out += line.substr(0, a) + line.substr(b) + "\n";
        }
        return out;
    };
    const std::string resumed = withoutSeconds(readFile(dir.file("e.csv")));
    EXPECT_EQ(resumed, withoutSeconds(readFile(dir.file("whole.csv"))));
    EXPECT_EQ(std::count(resumed.begin(), resumed.end(), '\n'), 7); // the header and 6 rows
    // The first row (one sample: one half buffer empty) has no estimate: empty cells, not 0
    // (the whole image's and its standard error, the subject's and its share).
    EXPECT_EQ(resumed.substr(resumed.find('\n') + 1, 8), "1,1,,,,\n");
}

TEST(Checkpoint, ACheckpointOfAnotherRenderIsRefused) {
    TempDir dir;
    const std::string scene = smallCornellBox(dir, 40, 40);
    const std::string ck = dir.file("ck.exr");
    ChildResult a = runChild({"render", scene, "--backend", "cpu", "--quiet", "--spp", "4",
                              "--ray-format", "full", "--checkpoint", ck, "-o", dir.file("a.exr")});
    ASSERT_EQ(a.status, 0) << a.output;

    // The reference backend may continue a full-ray cpu checkpoint: the same paths.
    ChildResult ok =
        runChild({"render", scene, "--backend", "reference", "--quiet", "--spp", "8", "--resume",
                  ck, "--checkpoint", dir.file("ok.exr"), "-o", dir.file("ok-image.exr")});
    EXPECT_EQ(ok.status, 0) << ok.output;

    // Another scene: the same file name, another light colour.
    TempDir other;
    const std::string changed = smallCornellBox(other, 40, 40, "box.yaml", "[17, 12, 5]");
    const Checkpoint c = readCheckpoint(ck);
    Checkpoint newer = c;
    newer.key.version = "99.0.0";
    writeCheckpoint(dir.file("newer.exr"), newer, readImage(ck).rgb);
    struct Case {
        std::vector<std::string> args;
        const char* says;
    };
    const std::vector<Case> cases = {
        {{"render", scene, "--seed", "9", "--resume", ck}, "seed 0 where this render has 9"},
        {{"render", changed, "--resume", ck}, "another scene"},
        {{"render", scene, "--ray-format", "compact", "--resume", ck}, "ray format"},
        {{"render", scene, "--texture-filter", "finest", "--resume", ck}, "texture filter"},
        {{"render", scene, "--resume", dir.file("newer.exr")}, "Spillway version 99.0.0"},
        {{"render", scene, "--resume", dir.file("a.exr")}, "not a Spillway checkpoint"},
        {{"render", scene, "--resume", dir.file("missing.exr")}, "missing.exr"},
        {{"render", scene, "--checkpoint", dir.file("x.png")}, "must end in .exr"},
    };
    for (const Case& k : cases) {
        std::vector<std::string> args = k.args;
        args.insert(args.end(), {"--backend", "cpu", "--quiet", "-o", dir.file("never.exr")});
        ChildResult r = runChild(args);
        EXPECT_EQ(r.status, 2) << k.says << "\n" << r.output;
        EXPECT_NE(r.output.find(k.says), std::string::npos) << k.says << "\n" << r.output;
        EXPECT_FALSE(std::filesystem::exists(dir.file("never.exr"))) << k.says;
    }
    EXPECT_EQ(readCheckpoint(ck).iterations, c.iterations) << "a refused resume wrote to it";
}

// What a resume must refuse before any work, exit 2, naming it: an environment map swapped for
// another of the same peak (its texels are in the checkpoint's identity, not only the scene
// text), fewer samples than the checkpoint holds, and a partial render's checkpoint resumed
// with another sample range. (Before: the first resumed silently into a wrong image, the second
// wrote an image of more samples than asked and a checkpoint past its total, the third exited 1.)
TEST(Checkpoint, AResumeOfAnotherEnvironmentFewerSamplesOrAnotherRangeIsRefused) {
    TempDir dir;
    ImageRGB sky{8, 4, std::vector<float>(8 * 4 * 3, 0.5f)};
    sky.rgb[0] = 2.0f; // the peak
    writeImage(dir.file("sky.exr"), sky);
    const std::string scene =
        dir.write("sky.yaml", readFile(smallCornellBox(dir, 24, 24)) +
                                  "lights:\n  - {type: Environment, string: sky.exr}\n");
    const std::string ck = dir.file("ck.exr"), part = dir.file("part.exr");
    auto run = [&](std::vector<std::string> args) {
        args.insert(args.end(), {"--backend", "cpu", "--quiet"});
        return runChild(args);
    };
    ASSERT_EQ(
        run({"render", scene, "--spp", "8", "--checkpoint", ck, "-o", dir.file("a.exr")}).status,
        0);
    ASSERT_EQ(run({"render", scene, "--spp", "8", "--samples", "0:4", "--partial", part, "-o",
                   dir.file("part-image.exr")})
                  .status,
              0);

    struct Case {
        std::vector<std::string> args;
        const char* says;
    };
    const std::vector<Case> cases = {
        {{"render", scene, "--spp", "4", "--resume", ck, "-o", dir.file("never.exr")},
         "8 samples per pixel done, more than this render's 4"},
        {{"render", scene, "--spp", "8", "--samples", "4:8", "--resume", part, "--partial",
          dir.file("never.exr"), "-o", dir.file("never-image.exr")},
         "partial render from sample 0"},
        // Last: the same peak, another texel.
        {{"render", scene, "--spp", "16", "--resume", ck, "-o", dir.file("never.exr")},
         "another environment"},
    };
    for (const Case& k : cases) {
        if (std::string(k.says) == "another environment") {
            sky.rgb[7] = 0.25f;
            writeImage(dir.file("sky.exr"), sky);
        }
        const ChildResult r = run(k.args);
        EXPECT_EQ(r.status, 2) << k.says << "\n" << r.output;
        EXPECT_NE(r.output.find(k.says), std::string::npos) << k.says << "\n" << r.output;
        EXPECT_FALSE(std::filesystem::exists(dir.file("never.exr"))) << k.says;
    }
}

// A texture swapped for another image of the same size, given the old modification time back (a
// copy with `cp -p`, a sync tool): its texels are in the checkpoint's identity, so the resume is
// refused, exit 2 (before: size and time alone were hashed, and it resumed into a wrong image).
TEST(Checkpoint, ATextureSwappedForOneOfTheSameSizeAndTimeIsRefused) {
    TempDir dir;
    dir.write("quad.obj", "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\n"
                          "vt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n");
    // A binary PPM: uncompressed, so one changed texel keeps the file's size.
    std::string texels(4 * 4 * 3, char(128));
    dir.write("tex.ppm", "P6\n4 4\n255\n" + texels);
    const std::string scene = dir.write(
        "scene.yaml", "image: {width: 8, height: 8}\n"
                      "shader: {type: Lambert, texture: {type: Standard, filename: tex.ppm}}\n"
                      "object: {filename: quad.obj, translation: [0, 0, -4]}\n"
                      "light: {type: Environment}\n");
    const std::string ck = dir.file("ck.exr");
    auto run = [&](std::vector<std::string> args) {
        args.insert(args.end(), {"--backend", "cpu", "--quiet", "-o", dir.file("out.exr")});
        return runChild(args);
    };
    ASSERT_EQ(run({"render", scene, "--spp", "2", "--checkpoint", ck}).status, 0);
    const auto time = std::filesystem::last_write_time(dir.file("tex.ppm"));
    texels[5] = char(200);
    dir.write("tex.ppm", "P6\n4 4\n255\n" + texels);
    std::filesystem::last_write_time(dir.file("tex.ppm"), time);
    const ChildResult r = run({"render", scene, "--spp", "4", "--resume", ck});
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("another scene"), std::string::npos) << r.output;
}

// A checkpoint's integrity. A bit flipped anywhere in the last 96 bytes (the final scanlines'
// data) either is refused on resume (exit 2: the checksum over the film's state, or the EXR's
// own decoding) or touched only the RGB preview, which nothing reads back: the resumed image is
// then the undamaged one, bit for bit. Never a wrong image with exit 0 (before: relMSE 3059).
// And crafted metadata with a valid checksum (more iterations than its render has, a render time
// that is not a number) is refused on resume and on merge.
TEST(Checkpoint, ADamagedOrCraftedCheckpointIsRefused) {
    TempDir dir;
    const std::string scene = smallCornellBox(dir, 16, 16);
    const std::string ck = dir.file("ck.exr");
    auto render = [&](std::vector<std::string> args) {
        args.insert(args.begin(), {"render", scene, "--backend", "cpu", "--quiet"});
        return runChild(args);
    };
    ASSERT_EQ(render({"--spp", "4", "--checkpoint", ck, "-o", dir.file("a.exr")}).status, 0);
    ASSERT_EQ(render({"--spp", "8", "--resume", ck, "-o", dir.file("whole.exr")}).status, 0);

    const std::string bytes = readFile(ck);
    int refused = 0;
    for (size_t back = 1; back <= 96; back += 5) {
        std::string damaged = bytes;
        damaged[damaged.size() - back] ^= char(0x10);
        const std::string file = dir.write("damaged.exr", damaged);
        std::filesystem::remove(dir.file("out.exr"));
        const ChildResult r = render({"--spp", "8", "--resume", file, "-o", dir.file("out.exr")});
        if (r.status == 2) {
            ++refused;
            EXPECT_FALSE(std::filesystem::exists(dir.file("out.exr")));
            continue;
        }
        ASSERT_EQ(r.status, 0) << "byte -" << back << "\n" << r.output;
        EXPECT_TRUE(samePixels(dir.file("out.exr"), dir.file("whole.exr")))
            << "a bit flipped at byte -" << back << " resumed into another image";
    }
    EXPECT_GT(refused, 0) << "no flip reached the film's state";

    const Checkpoint good = readCheckpoint(ck);
    const std::vector<float> image = readImage(ck).rgb;
    struct Case {
        std::function<void(Checkpoint&)> edit;
        const char* says;
    };
    const std::vector<Case> cases = {
        {[](Checkpoint& c) { c.iterations = 2147483647; }, "it claims 2147483647 iterations"},
        {[](Checkpoint& c) { c.renderSeconds = std::numeric_limits<double>::quiet_NaN(); },
         "render time"},
        {[](Checkpoint& c) { c.totalIterations = 0; }, "outside what a render takes"},
    };
    for (const Case& k : cases) {
        Checkpoint c = good;
        k.edit(c);
        writeCheckpoint(dir.file("crafted.exr"), c, image);
        const ChildResult resume = render(
            {"--spp", "8", "--resume", dir.file("crafted.exr"), "-o", dir.file("never.exr")});
        EXPECT_EQ(resume.status, 2) << k.says << "\n" << resume.output;
        EXPECT_NE(resume.output.find(k.says), std::string::npos) << resume.output;
        const ChildResult merge =
            runChild({"merge", dir.file("crafted.exr"), "-o", dir.file("never.exr")});
        EXPECT_EQ(merge.status, 2) << k.says << "\n" << merge.output;
        EXPECT_FALSE(std::filesystem::exists(dir.file("never.exr"))) << k.says;
    }
}

} // namespace
} // namespace spw::test
