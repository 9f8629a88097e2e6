// scripts/device-bench.sh, the one command that measures a GPU machine, in its --quick form on
// this machine's lavapipe: it renders every scene with every backend, writes the JSON that
// docs/performance.md documents and the Markdown table, its figures agree with the renders' own
// --stats, and its strong-scaling renders equal one rank's. Timings are recorded, never judged.
#include "shared/shade_io.h"
#include "test_util.h"

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <set>

namespace spw::test {
namespace {

std::string deviceBench(const std::string& args) {
    return sourceDir() + "/scripts/device-bench.sh " + args;
}

TEST(DeviceBench, QuickRunMeasuresEveryBackendOnEveryScene) {
    TempDir dir;
    std::string mpi;
#ifdef SPILLWAY_MPIEXEC
    mpi = " --mpirun " + std::string(SPILLWAY_MPIEXEC);
#endif
    const CommandResult r = runShell(
        deviceBench("--quick --out " + dir.file("bench") + " --spillway " + binary() + mpi));
    ASSERT_EQ(r.status, 0) << r.output;
    std::ifstream in(dir.file("bench/device-bench.json"));
    const nlohmann::json bench = nlohmann::json::parse(in);
    EXPECT_TRUE(bench["quick"].get<bool>());
    EXPECT_NE(bench["devices"].get<std::string>().find("--backend auto takes"), std::string::npos);

    std::set<std::pair<std::string, std::string>> seen;
    for (const nlohmann::json& run : bench["runs"]) {
        const std::string backend = run["backend"], scene = run["scene"];
        SCOPED_TRACE(scene + " " + backend);
        seen.insert({scene, backend});
        const nlohmann::json& stats = run["stats"];
        EXPECT_EQ(stats["backend"], backend);
        EXPECT_EQ(stats["spp"], run["spp"]);
        EXPECT_EQ(stats["width"], run["width"]);
        const double relmse = run["relmse_vs_reference"];
        EXPECT_TRUE(std::isfinite(relmse) && relmse >= 0.0);
        if (backend == "reference") {
            EXPECT_EQ(relmse, 0.0);
        }
        if (backend != "vulkan") continue;
        // Every record sent to the device comes back as one result.
        const nlohmann::json& v = stats["vulkan"];
        const auto up = v["bytes_uploaded"].get<std::uint64_t>();
        const auto down = v["bytes_downloaded"].get<std::uint64_t>();
        EXPECT_GT(up, 0u);
        EXPECT_EQ(up % sizeof(ShadeInput), 0u);
        EXPECT_EQ(up / sizeof(ShadeInput), down / sizeof(ShadeResult));
        // Lavapipe writes timestamps: the device's seconds are the stages' upload, dispatch and
        // download, and a dispatch's share is their mean.
        ASSERT_TRUE(v["timestamps"].get<bool>());
        const nlohmann::json& gpu = v["gpu_seconds"];
        EXPECT_DOUBLE_EQ(gpu["dispatch"].get<double>(),
                         stats["stage_seconds"]["dispatch"].get<double>());
        EXPECT_NEAR(gpu["per_dispatch"].get<double>() * v["dispatches"].get<double>(),
                    gpu["dispatch"].get<double>(), 1e-12);
        EXPECT_GE(gpu["idle_between_submits"].get<double>(), 0.0);
    }
    EXPECT_EQ(seen.size(), 9u) << "3 scenes x 3 backends";

#ifdef SPILLWAY_MPIEXEC
    // The script itself refuses a rank's image that differs from one rank's; the efficiency is
    // the one-rank time over n times the n-rank time.
    const nlohmann::json& steps = bench["mpi_strong_scaling"]["steps"];
    ASSERT_EQ(steps.size(), 2u);
    const double one = steps[0]["render_seconds"];
    for (const nlohmann::json& s : steps)
        EXPECT_NEAR(s["efficiency"].get<double>(),
                    one / (s["ranks"].get<double>() * s["render_seconds"].get<double>()), 5e-4);
#endif
    // The table: a row a run, and one a scaling step.
    const std::string md = readFile(dir.file("bench/device-bench.md"));
    size_t rows = 0;
    for (size_t at = md.find("\n| "); at != std::string::npos; at = md.find("\n| ", at + 1))
        ++rows;
    EXPECT_EQ(rows, 9u + 2u + bench["mpi_strong_scaling"]["steps"].size());
}

TEST(DeviceBench, RefusesAMissingBinaryAndAnUnknownOption) {
    TempDir dir;
    CommandResult r = runShell(deviceBench("--quick --out " + dir.file("b") + " --spillway " +
                                           dir.file("no-such-binary")));
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("no spillway binary"), std::string::npos) << r.output;
    r = runShell(deviceBench("--fast"));
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("unknown option --fast"), std::string::npos) << r.output;
    r = runShell(deviceBench("--out 2>&1"));
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("device-bench: --out needs a value"), std::string::npos) << r.output;
    r = runShell(deviceBench("--help 2>&1"));
    EXPECT_EQ(r.status, 0);
    EXPECT_NE(r.output.find("Measures a machine in one command"), std::string::npos) << r.output;
}

// The release scripts say what they are for on --help and refuse a missing value by name,
// before they install or build anything; test-bundle names a release that is not there.
TEST(ReleaseScripts, HelpAndMissingValuesAreAnsweredBeforeAnyWork) {
    const std::string scripts = sourceDir() + "/scripts/";
    CommandResult r = runShell(scripts + "bundle.sh --help 2>&1");
    EXPECT_EQ(r.status, 0);
    EXPECT_NE(r.output.find("Builds the release"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("installing"), std::string::npos) << "nothing installed";
    r = runShell(scripts + "bundle.sh --out 2>&1");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("bundle: --out needs a folder"), std::string::npos) << r.output;
    r = runShell(scripts + "bundle.sh --fast 2>&1");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("unknown argument '--fast'"), std::string::npos) << r.output;
    r = runShell(scripts + "test-bundle.sh --help 2>&1");
    EXPECT_EQ(r.status, 0);
    EXPECT_NE(r.output.find("Proves a release runs on a bare Linux box"), std::string::npos);
    TempDir dir;
    r = runShell(scripts + "test-bundle.sh " + dir.file("none.tar.zst") + " 2>&1");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("test-bundle: no release"), std::string::npos) << r.output;
}

} // namespace
} // namespace spw::test
