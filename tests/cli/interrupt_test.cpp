// Stopping a render: Ctrl-C keeps the work (real signals, every backend), a second signal exits
// at once, --target-error stops where the error estimate says, and progress for logs.
#include "host/image/image_io.h"
#include "test_util.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>
#include <unistd.h>

namespace spw::test {
namespace {

// SIGINT after the third iteration: exit 130, the image of every completed iteration (bit for
// bit the image of an uninterrupted render of that many samples), --stats saying why; SIGTERM
// likewise with 143, and SIGHUP (the terminal or ssh connection gone) with 129. On every backend,
// the sorted ones with a budget small enough that the stop lands while batches are on disk.
TEST(Interrupt, SignalKeepsEveryCompletedIterationOnEveryBackend) {
    TempDir dir, spill;
    const std::string scene = smallCornellBox(dir, 48, 48);
    for (const std::string& backend : backendsUnderTest())
        for (int signal : {SIGINT, SIGTERM, SIGHUP}) {
            const std::string tag = backend + "-" + std::to_string(signal);
            const std::string out = dir.file(tag + ".exr"), stats = dir.file(tag + ".json");
            bool seen = false;
            ChildResult r =
                runChild({"render", scene, "--backend", backend, "--progress", "lines", "--spp",
                          "100000", "--memory-budget", "0.05", "--bin-exponent", "8", "--spill-dir",
                          spill.path(), "-o", out, "--stats", stats},
                         [&](pid_t pid) {
                             seen = waitForChildOutput(pid, "iteration 3/");
                             kill(pid, signal);
                         });
            ASSERT_TRUE(seen) << tag << "\n" << r.output;
            EXPECT_EQ(r.status, 128 + signal) << tag << "\n" << r.output;
            EXPECT_NE(r.output.find("stopped by signal " + std::to_string(signal)),
                      std::string::npos)
                << r.output;
            ASSERT_TRUE(std::filesystem::exists(out)) << tag;
            const nlohmann::json s = nlohmann::json::parse(std::ifstream(stats));
            EXPECT_EQ(s["stop_reason"], "signal");
            const int spp = s["spp"].get<int>();
            EXPECT_GE(spp, 3) << tag;
            EXPECT_LT(spp, 100000) << tag;
            EXPECT_EQ(filesIn(spill.path()), 0u) << tag;

            const std::string whole = dir.file(tag + "-whole.exr");
            ChildResult w = runChild({"render", scene, "--backend", backend, "--quiet", "--spp",
                                      std::to_string(spp), "-o", whole});
            ASSERT_EQ(w.status, 0) << w.output;
            EXPECT_TRUE(samePixels(out, whole)) << tag << ": " << spp << " spp";
        }
}

// A second signal while the first is being handled ends the process at once, by the signal,
// leaving no file: the child is stopped, both signals queued (two different ones, which the
// kernel does not merge), then resumed, so that the second surely arrives during the first's stop.
TEST(Interrupt, SecondSignalExitsAtOnceLeavingNoFile) {
    TempDir dir, out, spill;
    const std::string scene = smallCornellBox(dir, 48, 48);
    for (const std::string& backend : backendsUnderTest()) {
        ChildResult r = runChild({"render",
                                  scene,
                                  "--backend",
                                  backend,
                                  "--progress",
                                  "lines",
                                  "--spp",
                                  "100000",
                                  "--memory-budget",
                                  "0.05",
                                  "--bin-exponent",
                                  "8",
                                  "--spill-dir",
                                  spill.path(),
                                  "-o",
                                  out.file("x.exr"),
                                  "--stats",
                                  out.file("x.json"),
                                  "--error-csv",
                                  out.file("x.csv")},
                                 [&](pid_t pid) {
                                     waitForChildOutput(pid, "iteration 2/");
                                     kill(pid, SIGSTOP);
                                     kill(pid, SIGINT);
                                     kill(pid, SIGTERM);
                                     kill(pid, SIGCONT);
                                 });
        EXPECT_LT(r.status, 0) << backend << ": not killed by a signal\n" << r.output;
        EXPECT_EQ(filesIn(out.path()), 0u) << backend;
        EXPECT_EQ(filesIn(spill.path()), 0u) << backend;
    }
}

// --target-error stops after the first iteration whose estimate over the subject (the pixels
// that hold noise) is at or below the target: the same iteration the --error-csv of a full render
// says in its subject_relmse_estimate column (the renders are deterministic, so it is that
// iteration exactly, not merely close).
TEST(Interrupt, TargetErrorStopsWhereTheErrorCsvCrossesIt) {
    TempDir dir;
    const std::string scene = smallCornellBox(dir, 48, 48);
    ChildResult full = runChild({"render", scene, "--backend", "cpu", "--quiet", "--spp", "16",
                                 "--error-csv", dir.file("full.csv"), "-o", dir.file("full.exr")});
    ASSERT_EQ(full.status, 0) << full.output;
    std::vector<double> relMse; // per iteration, from the CSV's subject_relmse_estimate column
    std::istringstream csv(readFile(dir.file("full.csv")));
    std::string line;
    std::getline(csv, line); // header
    int column = 0;
    for (std::istringstream header(line);
         std::getline(header, line, ',') && line != "subject_relmse_estimate";)
        ++column;
    ASSERT_EQ(column, 5) << "the header names no subject_relmse_estimate after its five columns";
    while (std::getline(csv, line)) {
        std::istringstream row(line);
        std::string cell;
        for (int c = 0; c <= column; ++c)
            std::getline(row, cell, ',');
        // Empty where no estimate exists yet (iteration 1: one half buffer has no sample).
        relMse.push_back(cell.empty() ? std::nan("") : std::stod(cell));
    }
    ASSERT_EQ(relMse.size(), 16u);
    // A target between iteration 8's estimate and the smallest before it (the estimate is
    // noisy, not monotone): the first iteration at or below it is then the 8th.
    double before = relMse[1];
    for (int i = 1; i < 7; ++i)
        before = std::min(before, relMse[size_t(i)]);
    ASSERT_LT(relMse[7], before) << "pick another iteration: the 8th is not a new low";
    const double target = 0.5 * (relMse[7] + before);
    ChildResult r =
        runChild({"render", scene, "--backend", "cpu", "--quiet", "--spp", "16", "--target-error",
                  std::to_string(target), "--stats", dir.file("t.json"), "-o", dir.file("t.exr")});
    ASSERT_EQ(r.status, 0) << r.output;
    const nlohmann::json s = nlohmann::json::parse(std::ifstream(dir.file("t.json")));
    EXPECT_EQ(s["stop_reason"], "target error");
    EXPECT_EQ(s["spp"], 8);
    // Iteration 1 (one sample per pixel, one half empty) has no estimate: a huge target still
    // renders two iterations.
    r = runChild({"render", scene, "--backend", "cpu", "--quiet", "--spp", "16", "--target-error",
                  "1e9", "--stats", dir.file("u.json"), "-o", dir.file("u.exr")});
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(nlohmann::json::parse(std::ifstream(dir.file("u.json")))["spp"], 2);
    // And without a target the render does every iteration, saying so.
    r = runChild({"render", scene, "--backend", "cpu", "--quiet", "--spp", "4", "--stats",
                  dir.file("v.json"), "-o", dir.file("v.exr")});
    EXPECT_EQ(nlohmann::json::parse(std::ifstream(dir.file("v.json")))["stop_reason"], "spp");
}

// A render of one iteration has no error estimate (two half buffers need two iterations): its
// --error-csv cells are empty, and the render says so and why it stopped; a render of two
// iterations has an estimate and says nothing of it.
TEST(Interrupt, AnErrorCsvWithoutAnEstimateSaysWhyTheRenderStopped) {
    TempDir dir;
    const std::string scene = smallCornellBox(dir, 32, 32);
    ChildResult one = runChild({"render", scene, "--backend", "cpu", "--quiet", "--spp", "1",
                                "--error-csv", dir.file("one.csv"), "-o", dir.file("one.exr")});
    ASSERT_EQ(one.status, 0) << one.output;
    EXPECT_NE(one.output.find("--error-csv has no relMSE estimate (its cells are empty)"),
              std::string::npos)
        << one.output;
    EXPECT_NE(one.output.find("stopped after 1 (stop reason: spp)"), std::string::npos)
        << one.output;
    const std::string csv = readFile(dir.file("one.csv"));
    EXPECT_EQ(csv.substr(csv.size() - 3), ",,\n") << csv;
    ChildResult two = runChild({"render", scene, "--backend", "cpu", "--quiet", "--spp", "2",
                                "--error-csv", dir.file("two.csv"), "-o", dir.file("two.exr")});
    ASSERT_EQ(two.status, 0) << two.output;
    EXPECT_EQ(two.output.find("no relMSE estimate"), std::string::npos) << two.output;
}

// Progress for logs: a plain line per iteration with spp, elapsed, ETA and the error estimate,
// never a control character; on a non-terminal without --progress, nothing.
TEST(Interrupt, ProgressLinesForLogsAndNothingByDefaultOffATerminal) {
    TempDir dir;
    const std::string scene = smallCornellBox(dir, 48, 48);
    ChildResult lines = runChild({"render", scene, "--backend", "cpu", "--spp", "4", "--progress",
                                  "lines", "-o", dir.file("a.exr")});
    ASSERT_EQ(lines.status, 0) << lines.output;
    for (const char* part :
         {"iteration 1/4, 1/4 spp", "iteration 4/4, 4/4 spp", "elapsed", "ETA", "relMSE -"})
        EXPECT_NE(lines.output.find(part), std::string::npos) << part << "\n" << lines.output;
    // From the second iteration on both halves have samples: an estimate, not "-".
    const std::string last = lines.output.substr(lines.output.find("iteration 4/4"));
    EXPECT_EQ(last.find("relMSE -"), std::string::npos) << last;
    for (char c : lines.output)
        EXPECT_TRUE(c == '\n' || (c >= 32 && c < 127)) << "control character " << int(c);
    ChildResult plain =
        runChild({"render", scene, "--backend", "cpu", "--spp", "4", "-o", dir.file("b.exr")});
    ASSERT_EQ(plain.status, 0);
    EXPECT_EQ(plain.output, "");
    ChildResult bad = runChild({"render", scene, "--progress", "loud", "-o", dir.file("c.exr")});
    EXPECT_EQ(bad.status, 2);
    EXPECT_NE(bad.output.find("loud"), std::string::npos) << bad.output;
}

} // namespace
} // namespace spw::test
