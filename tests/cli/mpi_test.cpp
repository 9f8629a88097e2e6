// Distributed rendering: `mpirun -np 2 spillway render ...` (host/render/ranks.h) makes the image
// one process makes, bit for bit, on every backend; rank 0 writes the outputs and the stats of
// every rank; a rank that fails fails the job with its own message and leaves no file.
#include "host/image/image_io.h"
#include "test_util.h"

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

namespace spw::test {
namespace {

#ifdef SPILLWAY_MPIEXEC
// Open MPI's launcher, as root in CI, with more ranks than cores allowed (2 ranks x 1 thread on
// any machine). `programs`: what each group of ranks runs ("-np 2 BINARY ARGS", or several
// groups joined by " : ").
CommandResult launch(const std::string& programs) {
    return runShell("OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 " +
                    std::string(SPILLWAY_MPIEXEC) + " --oversubscribe " + programs);
}
CommandResult twoRanks(const std::string& args) {
    return launch("-np 2 " + binary() + " " + args);
}
#define REQUIRE_MPI()
#else
CommandResult twoRanks(const std::string&) {
    return {-1, ""};
}
CommandResult launch(const std::string&) {
    return {-1, ""};
}
#define REQUIRE_MPI() GTEST_SKIP() << "built without MPI (SPILLWAY_MPI off)"
#endif

nlohmann::json readJson(const std::string& path) {
    std::ifstream in(path);
    return nlohmann::json::parse(in);
}

size_t lines(const std::string& path) {
    std::istringstream in(readFile(path));
    size_t n = 0;
    for (std::string line; std::getline(in, line);)
        ++n;
    return n;
}

// Renders `args` as one process with 2 threads (dir/NAME-one.exr, .json) and as 2 ranks with 1
// thread each (dir/NAME-two.exr, .json; `twoExtra` added), expects the same pixels, and reads
// both --stats.
void renderOnOneAndTwoRanks(const TempDir& dir, const std::string& args, const std::string& name,
                            nlohmann::json& one, nlohmann::json& two,
                            const std::string& twoExtra = "") {
    const std::string stem = dir.file(name);
    const CommandResult a =
        runSpillway(args + " --threads 2 -o " + stem + "-one.exr --stats " + stem + "-one.json");
    ASSERT_EQ(a.status, 0) << a.output;
    const CommandResult b = twoRanks(args + " --threads 1 -o " + stem + "-two.exr --stats " + stem +
                                     "-two.json " + twoExtra);
    ASSERT_EQ(b.status, 0) << b.output;
    EXPECT_TRUE(samePixels(stem + "-one.exr", stem + "-two.exr")) << name;
    one = readJson(stem + "-one.json");
    two = readJson(stem + "-two.json");
}

// 2 ranks x 1 thread against 1 process: the same pixels, the same rays (each path is traced
// once, by one rank), every iteration in --error-csv, and each rank's share in --stats.
TEST(Mpi, TwoRanksRenderTheSingleProcessImageOnEveryBackend) {
    REQUIRE_MPI();
    TempDir dir;
    const std::string scene = smallCornellBox(dir, 40, 24); // 5 x 3 tiles: uneven shares
    for (const std::string& backend : backendsUnderTest()) {
        nlohmann::json a, b;
        ASSERT_NO_FATAL_FAILURE(
            renderOnOneAndTwoRanks(dir, "render " + scene + " --backend " + backend + " --quiet",
                                   backend, a, b, "--error-csv " + dir.file(backend + ".csv")));
        EXPECT_EQ(b["rays"], a["rays"]) << backend;
        EXPECT_EQ(b["spp"], 16);
        ASSERT_EQ(b["ranks"].size(), 2u);
        std::uint64_t camera = 0;
        for (int r = 0; r < 2; ++r) {
            const nlohmann::json& rank = b["ranks"][size_t(r)];
            EXPECT_EQ(rank["rank"], r);
            EXPECT_EQ(rank["threads"], 1);
            EXPECT_GT(rank["rays"]["camera"].get<std::uint64_t>(), 0u) << "rank " << r;
            camera += rank["rays"]["camera"].get<std::uint64_t>();
        }
        EXPECT_EQ(camera, 40u * 24u * 16u);
        EXPECT_EQ(lines(dir.file(backend + ".csv")), 1u + 16u) << "a header and 16 iterations";
        EXPECT_FALSE(a.contains("ranks")) << "a single process has no ranks";
    }
}

// Image textures (the production workload's test preset, textures four times the cache): the
// single process's image, and --stats counts every rank's lookups, the same lookups one process
// makes (each hit is shaded once, by one rank).
TEST(Mpi, TexturedScenesCountEveryRanksLookups) {
    REQUIRE_MPI();
    TempDir dir;
    const CommandResult made =
        runShell(sourceDir() + "/scripts/make_production_scene.py " + dir.path() + " --small");
    ASSERT_EQ(made.status, 0) << made.output;
    nlohmann::json one, b;
    ASSERT_NO_FATAL_FAILURE(renderOnOneAndTwoRanks(
        dir, "render " + dir.file("scene.yaml") + " --backend cpu --quiet", "textured", one, b));
    const nlohmann::json a = one["textures"];
    ASSERT_GT(a["lookups"].get<std::uint64_t>(), 0u);
    EXPECT_EQ(b["textures"]["lookups"], a["lookups"]);
    EXPECT_EQ(b["textures"]["lookups"].get<std::uint64_t>(),
              b["ranks"][0]["textures"]["lookups"].get<std::uint64_t>() +
                  b["ranks"][1]["textures"]["lookups"].get<std::uint64_t>());
    EXPECT_GT(b["ranks"][1]["textures"]["lookups"].get<std::uint64_t>(), 0u);
}

// The shares follow adaptive sampling (the k-th tile still sampling goes to rank k mod 2), and
// each rank spills through its own anonymous file: still the single process's image, and the
// spill traffic of both ranks adds up in --stats.
TEST(Mpi, AdaptiveSamplingAndSpillingStayBitIdentical) {
    REQUIRE_MPI();
    TempDir dir;
    const std::string scene = smallCornellBox(dir, 48, 32);
    const std::string spill = dir.file("spill");
    ASSERT_EQ(runShell("mkdir " + spill).status, 0);
    nlohmann::json a, b;
    ASSERT_NO_FATAL_FAILURE(renderOnOneAndTwoRanks(
        dir,
        "render " + scene +
            " --backend cpu --quiet --adaptive-threshold 0.3 --adaptive-min-spp 4 "
            "--memory-budget 0.05 --bin-exponent 8 --spill-dir " +
            spill,
        "adaptive", a, b));
    EXPECT_EQ(b["samples_taken"], a["samples_taken"]);
    ASSERT_LT(a["samples_taken"].get<std::uint64_t>(), 48u * 32u * 16u)
        << "adaptive sampling stopped no tile: the test needs a higher threshold";
    const std::uint64_t written = b["bytes_spilled_written"].get<std::uint64_t>();
    EXPECT_GT(written, 0u) << "nothing spilled: the test needs a smaller budget";
    EXPECT_EQ(written, b["ranks"][0]["bytes_spilled_written"].get<std::uint64_t>() +
                           b["ranks"][1]["bytes_spilled_written"].get<std::uint64_t>());
    EXPECT_EQ(filesIn(spill), 0u);
}

// Rank 0 writes checkpoints and partials of the ranks' whole film: a 2-rank partial merged with
// a single process's, and a 2-rank checkpoint resumed by a single process, both give the single
// process's image bit for bit.
TEST(Mpi, PartialsAndCheckpointsOfRanksAreTheSingleProcesssSums) {
    REQUIRE_MPI();
    TempDir dir;
    const std::string scene = smallCornellBox(dir, 24, 16);
    const std::string common = "render " + scene + " --backend cpu --quiet --threads 1 ";
    const CommandResult full = runSpillway(common + "-o " + dir.file("full.exr"));
    ASSERT_EQ(full.status, 0) << full.output;

    const CommandResult a = twoRanks(common + "--spp 16 --samples 0:10 --partial " +
                                     dir.file("a.exr") + " -o " + dir.file("a-image.exr"));
    ASSERT_EQ(a.status, 0) << a.output;
    const CommandResult b = runSpillway(common + "--spp 16 --samples 10:16 --partial " +
                                        dir.file("b.exr") + " -o " + dir.file("b-image.exr"));
    ASSERT_EQ(b.status, 0) << b.output;
    const CommandResult m = runSpillway("merge " + dir.file("a.exr") + " " + dir.file("b.exr") +
                                        " -o " + dir.file("merged.exr"));
    ASSERT_EQ(m.status, 0) << m.output;
    EXPECT_TRUE(samePixels(dir.file("merged.exr"), dir.file("full.exr")));

    const CommandResult first = twoRanks(common + "--spp 6 --checkpoint " + dir.file("ck.exr") +
                                         " -o " + dir.file("six.exr"));
    ASSERT_EQ(first.status, 0) << first.output;
    const CommandResult rest = runSpillway(common + "--spp 16 --resume " + dir.file("ck.exr") +
                                           " -o " + dir.file("resumed.exr"));
    ASSERT_EQ(rest.status, 0) << rest.output;
    EXPECT_TRUE(samePixels(dir.file("resumed.exr"), dir.file("full.exr")));
}

// Ctrl-C on mpirun: it sends SIGTERM to every rank, the ranks agree to stop at the same
// iteration, and rank 0 writes the completed iterations: the image a single process makes of
// that many samples, bit for bit.
TEST(Mpi, InterruptingMpirunKeepsTheCompletedIterations) {
    REQUIRE_MPI();
    TempDir dir;
    const std::string scene = smallCornellBox(dir, 32, 32);
    const std::string common = "render " + scene + " --backend cpu --threads 1 ";
    const std::string log = dir.file("log");
    // mpirun in the background; SIGINT once rank 0 has reported its third iteration or a later
    // one. mpirun stops reading the ranks' output when it is interrupted and sends SIGTERM a
    // second later: a rank that printed a line per iteration (thousands a second here) filled
    // the pipe and was still blocked writing when it was killed, so the lines are throttled.
    const CommandResult r = launch(
        "-np 2 " + binary() + " " + common + "--spp 100000 --progress lines -o " +
        dir.file("two.exr") + " --stats " + dir.file("two.json") + " > " + log +
        " 2>&1 & pid=$!; for i in $(seq 600); do grep -qE 'iteration ([3-9]|[1-9][0-9]+)/' " + log +
        " && break; sleep 0.1; done; kill -INT $pid; wait $pid");
    const std::string output = readFile(log);
    ASSERT_NE(output.find("stopped by signal 15"), std::string::npos) << r.output << output;
    const nlohmann::json stats = readJson(dir.file("two.json"));
    size_t progressLines = 0;
    for (size_t at = output.find("spillway: iteration"); at != std::string::npos;
         at = output.find("spillway: iteration", at + 1))
        ++progressLines;
    EXPECT_LE(double(progressLines), 4.0 * stats["wall_seconds"].get<double>() + 2.0) << output;
    EXPECT_EQ(stats["stop_reason"], "signal");
    const int spp = stats["spp"].get<int>();
    ASSERT_GE(spp, 3);
    ASSERT_LT(spp, 100000);
    const CommandResult one =
        runSpillway(common + "--quiet --spp " + std::to_string(spp) + " -o " + dir.file("one.exr"));
    ASSERT_EQ(one.status, 0) << one.output;
    EXPECT_TRUE(samePixels(dir.file("one.exr"), dir.file("two.exr"))) << spp << " spp";
}

// A scene that is bad on one node only (MPMD: rank 1 runs another file): the job exits non-zero,
// rank 1 prints its file:line error and rank 0 says it stopped with it; nothing is written.
TEST(Mpi, ARankWithABadSceneFailsTheJob) {
    REQUIRE_MPI();
    TempDir dir;
    const std::string good = smallCornellBox(dir, 16, 16);
    const std::string bad = dir.write("bad.yaml", "camera: {\n  type: Pinhole\n");
    const std::string out = dir.file("out.exr");
    const std::string opts = " --backend cpu --threads 1 --quiet -o " + out;
    const CommandResult r = launch("-np 1 " + binary() + " render " + good + opts + " : -np 1 " +
                                   binary() + " render " + bad + opts);
    EXPECT_NE(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("rank 1 of 2: " + bad + ":"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("rank 0 of 2: error: rank 1 failed"), std::string::npos) << r.output;
    EXPECT_FALSE(std::ifstream(out).good()) << "no image from a failed job";
    EXPECT_EQ(filesIn(dir.path()), 2u) << "only the two scenes";
}

// Ranks that would render different things are refused before any collective, on every rank
// with exit 2, naming the rank and what differs: another image size, sample count, sample range,
// seed, scene content, environment map or resumed checkpoint. (Before, these crashed with a
// double free, deadlocked, or exited 0 with a checkerboard of both renders' tiles.)
TEST(Mpi, RanksThatWouldRenderDifferentThingsAreRefusedNamingTheField) {
    REQUIRE_MPI();
    TempDir dir;
    const std::string scene = smallCornellBox(dir, 16, 16);
    const std::string wider = smallCornellBox(dir, 24, 16, "wider.yaml");
    const std::string redder = smallCornellBox(dir, 16, 16, "redder.yaml", "[30, 5, 4]");
    // Two hosts' copies of one scene whose environment maps differ: the same scene text, run
    // from two directories (mpirun -wdir), each with its own sky.exr.
    ImageRGB sky{8, 4, std::vector<float>(8 * 4 * 3, 0.5f)};
    for (const char* host : {"host0", "host1"}) {
        ASSERT_EQ(runShell("mkdir " + dir.file(host)).status, 0);
        writeImage(dir.file(std::string(host) + "/sky.exr"), sky);
        sky.rgb[5] = 0.7f;
        dir.write(std::string(host) + "/sky.yaml",
                  readFile(scene) + "lights:\n  - {type: Environment, string: sky.exr}\n");
    }
    const std::string checkpoint = dir.file("c.exr");
    const std::string out = dir.file("out.exr");
    const std::string common = " --backend cpu --threads 1 --quiet -o " + out;
    ASSERT_EQ(runSpillway("render " + scene + " --spp 4 --quiet --checkpoint " + checkpoint +
                          " -o " + dir.file("first.exr"))
                  .status,
              0);
    struct Case {
        std::string rank0, rank1, field;
    };
    const std::vector<Case> cases = {
        {scene, wider, "image size"},
        {scene + " --spp 8", scene + " --spp 16", "number of samples"},
        {scene + " --spp 8 --samples 0:4 --partial " + dir.file("p.exr"),
         scene + " --spp 8 --samples 4:8 --partial " + dir.file("p.exr"), "sample range"},
        {scene + " --seed 1", scene + " --seed 2", "seed"},
        {scene, redder, "scene (its file"},
        {"-wdir " + dir.file("host0") + " SPILLWAY render sky.yaml",
         "-wdir " + dir.file("host1") + " SPILLWAY render sky.yaml", "environment"},
        {scene + " --spp 8 --resume " + checkpoint, scene + " --spp 8", "checkpoint to resume"},
    };
    for (const Case& c : cases) {
        std::remove(out.c_str());
        auto program = [&](const std::string& args) {
            return args.find("SPILLWAY") != std::string::npos
                       ? replaceAll(args, "SPILLWAY", binary())
                       : binary() + " render " + args;
        };
        const CommandResult r =
            launch("-np 1 " + program(c.rank0) + common + " : -np 1 " + program(c.rank1) + common);
        EXPECT_EQ(r.status, 2) << c.field << "\n" << r.output;
        EXPECT_NE(r.output.find("rank 1 would render another " + c.field), std::string::npos)
            << r.output;
        EXPECT_FALSE(std::ifstream(out).good()) << c.field << ": no image from a refused job";
    }
}

// A rank that fails while rendering (it cannot create its spill file) stops every rank at the
// next iteration boundary: non-zero exit, its message, no image, no spill file anywhere.
TEST(Mpi, ARankFailingWhileRenderingFailsTheJob) {
    REQUIRE_MPI();
    TempDir dir;
    const std::string scene = smallCornellBox(dir, 32, 32);
    const std::string spill = dir.file("spill");
    ASSERT_EQ(runShell("mkdir " + spill).status, 0);
    const std::string out = dir.file("out.exr");
    const std::string opts = " render " + scene +
                             " --backend cpu --threads 1 --quiet --memory-budget 0.02 "
                             "--bin-exponent 8 -o " +
                             out + " --spill-dir ";
    const CommandResult r = launch("-np 1 " + binary() + opts + spill + " : -np 1 " + binary() +
                                   opts + dir.file("missing"));
    EXPECT_NE(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("rank 1 of 2: error: cannot create a spill file in '" +
                            dir.file("missing") + "'"),
              std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("rank 0 of 2: error: rank 1 failed"), std::string::npos) << r.output;
    EXPECT_FALSE(std::ifstream(out).good()) << "no image from a failed job";
    EXPECT_EQ(filesIn(spill), 0u);
}

} // namespace
} // namespace spw::test
