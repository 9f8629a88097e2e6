// Farms without MPI: `render --samples A:B --partial PART` renders a range of an N-spp render's
// samples and keeps their exact sums; `merge PART... -o IMAGE` adds partials that cover every
// sample once into the image one process would have made, bit for bit, and refuses any other
// set with exit 2.
#include "test_util.h"

#include <gtest/gtest.h>

#include <filesystem>

namespace spw::test {
namespace {

// Renders samples a:b of a 12-spp render of `scene` on `backend` into dir/NAME.exr.
void renderPartial(const TempDir& dir, const std::string& scene, const std::string& backend, int a,
                   int b, const std::string& name, const std::string& extra = "") {
    const CommandResult r = runSpillway(
        "render " + scene + " --backend " + backend + " --spp 12 --samples " + std::to_string(a) +
        ":" + std::to_string(b) + " --partial " + dir.file(name + ".exr") + " --quiet -o " +
        dir.file(name + "-image.exr") + " " + extra);
    ASSERT_EQ(r.status, 0) << r.output;
}

// Three partials (one sample per iteration here, so any boundary goes), merged in another
// order than they were rendered: the single process's image, bit for bit, on every backend.
TEST(Partial, MergedPartialsGiveTheSingleProcessImageOnEveryBackend) {
    TempDir dir;
    const std::string scene = smallCornellBox(dir, 24, 24);
    for (const std::string& backend : backendsUnderTest()) {
        const std::string full = dir.file(backend + "-full.exr");
        const CommandResult f = runSpillway("render " + scene + " --backend " + backend +
                                            " --spp 12 --quiet -o " + full);
        ASSERT_EQ(f.status, 0) << f.output;
        renderPartial(dir, scene, backend, 0, 5, backend + "-a");
        renderPartial(dir, scene, backend, 5, 6, backend + "-b");
        renderPartial(dir, scene, backend, 6, 12, backend + "-c");
        const std::string merged = dir.file(backend + "-merged.exr");
        const CommandResult m = runSpillway("merge " + dir.file(backend + "-c.exr") + " " +
                                            dir.file(backend + "-a.exr") + " " +
                                            dir.file(backend + "-b.exr") + " -o " + merged);
        ASSERT_EQ(m.status, 0) << m.output;
        EXPECT_NE(m.output.find("merged 3 partial renders: 12 spp"), std::string::npos) << m.output;
        EXPECT_TRUE(samePixels(merged, full)) << backend;
        // One partial of all the samples is the whole render too.
        renderPartial(dir, scene, backend, 0, 12, backend + "-all");
        EXPECT_TRUE(samePixels(dir.file(backend + "-all-image.exr"), full)) << backend;
    }
}

// Sets that do not cover the samples exactly once, or partials of another render, are refused
// with exit 2 and a message naming the problem; no image is written.
TEST(Partial, MergeRefusesOverlapsGapsAndOtherRenders) {
    TempDir dir;
    const std::string scene = smallCornellBox(dir, 8, 8);
    renderPartial(dir, scene, "cpu", 0, 4, "a");
    renderPartial(dir, scene, "cpu", 4, 12, "b");
    renderPartial(dir, scene, "cpu", 2, 6, "overlap");
    renderPartial(dir, scene, "cpu", 4, 12, "seed", "--seed 5");
    const CommandResult plain = runSpillway(
        "render " + scene + " --backend cpu --spp 4 --quiet -o " + dir.file("plain.exr"));
    ASSERT_EQ(plain.status, 0) << plain.output;
    struct Case {
        std::string parts, message;
    };
    const Case cases[] = {
        {"a.exr", "no partial holds samples 4:12"},
        {"b.exr", "no partial holds samples 0:4"},
        {"a.exr overlap.exr b.exr", "overlap.exr (samples 2:6) overlaps the samples before 4"},
        {"a.exr seed.exr", "seed.exr is a partial of another render than"},
        {"seed.exr a.exr", "seed 5 where this render has 0"},
        {"a.exr plain.exr", "is not a Spillway checkpoint"},
    };
    for (const Case& c : cases) {
        std::string args;
        for (size_t start = 0; start < c.parts.size();) {
            size_t end = c.parts.find(' ', start);
            if (end == std::string::npos) end = c.parts.size();
            args += " " + dir.file(c.parts.substr(start, end - start));
            start = end + 1;
        }
        const std::string out = dir.file("merged.exr");
        const CommandResult r = runSpillway("merge" + args + " -o " + out);
        EXPECT_EQ(r.status, 2) << c.parts << ": " << r.output;
        EXPECT_NE(r.output.find(c.message), std::string::npos) << c.parts << ": " << r.output;
        EXPECT_FALSE(std::filesystem::exists(out)) << c.parts;
    }
}

// A range off the iteration boundaries (four samples an iteration with sample base 2) is a
// usage error that names the boundaries allowed; so are --samples without --partial and
// adaptive sampling in a partial.
TEST(Partial, RangesOffIterationBoundariesAreUsageErrors) {
    TempDir dir;
    const std::string scene = smallCornellBox(dir, 8, 8);
    const std::string base = "render " + scene + " --quiet -o " + dir.file("x.exr") + " ";
    struct Case {
        std::string args, message;
    };
    const Case cases[] = {
        {"--spp 12 --samples 0:13 --partial " + dir.file("p.exr"), "0 <= A < B <= 12"},
        {"--spp 12 --samples 4:8", "--samples A:B goes with --partial"},
        {"--spp 12 --partial " + dir.file("p.exr"), "--partial goes with --samples"},
        {"--spp 12 --samples 0:4 --partial " + dir.file("p.exr") + " --adaptive-threshold 0.1",
         "cannot sample adaptively"},
    };
    for (const Case& c : cases) {
        const CommandResult r = runSpillway(base + c.args);
        EXPECT_EQ(r.status, 2) << c.args << ": " << r.output;
        EXPECT_NE(r.output.find(c.message), std::string::npos) << c.args << ": " << r.output;
    }
    // Sample base 2: boundaries every 4 samples.
    const std::string four =
        dir.write("four.yaml", replaceAll(readFile(scene), "sample base: 1", "sample base: 2"));
    const CommandResult r = runSpillway("render " + four +
                                        " --quiet --spp 16 --samples 2:8 "
                                        "--partial " +
                                        dir.file("p.exr") + " -o " + dir.file("x.exr"));
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("a multiple of 4 samples (0, 4, 8, ... 16)"), std::string::npos)
        << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir.file("p.exr")));
}

// The docs' Slurm recipe, run as written: each ```sh block with "#SBATCH --array=0-7" in the
// README and docs/command-line.md, its task part once per SLURM_ARRAY_TASK_ID with `spillway`
// this build, then its merge part; the merged frame is the single render of 1024 spp, bit for
// bit. (The recipe as first written merged the tasks' own images too, and failed.)
TEST(Partial, TheDocsSlurmRecipeRunsAsWritten) {
    TempDir scenes;
    const std::string shot = smallCornellBox(scenes, 8, 8, "shot.yaml");
    int recipes = 0;
    for (const char* doc : {"README.md", "docs/command-line.md"}) {
        const std::string text = readFile(sourceDir() + "/" + doc);
        const size_t at = text.find("#SBATCH --array=0-7");
        ASSERT_NE(at, std::string::npos) << doc << " has no Slurm recipe";
        const size_t begin = text.rfind("```sh\n", at) + 6, end = text.find("```", at);
        std::string block = text.substr(begin, end - begin);
        const size_t split = block.find("# then");
        ASSERT_NE(split, std::string::npos) << doc;
        const std::string task = block.substr(0, split), merge = block.substr(split);
        TempDir dir;
        const std::string prelude = "set -e; cd " + dir.path() + "; cp " + shot +
                                    " shot.yaml; spillway() { " + binary() +
                                    " \"$@\" --quiet 2>/dev/null || " + binary() + " \"$@\"; }; ";
        for (int id = 0; id < 8; ++id) {
            const CommandResult r = runShell("SLURM_ARRAY_TASK_ID=" + std::to_string(id) +
                                             " bash -c '" + prelude + task + "'");
            ASSERT_EQ(r.status, 0) << doc << ", task " << id << "\n" << r.output;
        }
        const CommandResult m = runShell("bash -c '" + prelude + merge + "'");
        ASSERT_EQ(m.status, 0) << doc << "\n" << m.output;
        ASSERT_EQ(runSpillway("render " + shot + " --spp 1024 --quiet -o " + dir.file("single.exr"))
                      .status,
                  0);
        EXPECT_TRUE(samePixels(dir.file("shot.exr"), dir.file("single.exr"))) << doc;
        ++recipes;
    }
    EXPECT_EQ(recipes, 2);
}

} // namespace
} // namespace spw::test
