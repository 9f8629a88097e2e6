// Error against time: the half-buffer error estimate, the convergence rate of every backend,
// --error-csv and --time-limit.
#include "host/compare.h"
#include "test_util.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

namespace spw::test {
namespace {

Scene cornell(int size) {
    Scene scene = loadScene(sourceDir() + "/scenes/cornell-box.yaml");
    scene.image.width = scene.image.height = size;
    scene.image.sampleBase = 1;
    return scene;
}

constexpr int kSize = 48;

// A high-spp reference of the small Cornell box, rendered once for the whole suite. Its own
// noise is 1/8 of a 256-spp test image's.
const ImageRGB& highSppReference() {
    static const ImageRGB ref = [] {
        Scene scene = cornell(kSize);
        RenderConfig cfg;
        cfg.backend = "reference";
        cfg.spp = 2048;
        cfg.seed = 12345; // independent of the test renders' random numbers
        return ImageRGB{kSize, kSize, render(scene, cfg)->film->image()};
    }();
    return ref;
}

struct Point {
    int spp;
    double trueRelMse, estimate;
};

// relMSE at 16, 32, ..., 256 spp, averaged over two seeds: relMSE of one small image is a
// heavy-tailed estimate (a few bright outliers dominate it), and the average tames that.
std::vector<Point> convergence(const std::string& backend) {
    Scene scene = cornell(kSize);
    std::vector<Point> points;
    for (std::uint32_t seed : {1u, 2u}) {
        RenderConfig cfg;
        cfg.backend = backend;
        cfg.spp = 256;
        cfg.seed = seed;
        size_t k = 0;
        render(scene, cfg, [&](int done, int, const Film& film) {
            if (done < 16 || (done & (done - 1)) != 0) return;
            double t = compareImages({kSize, kSize, film.image()}, highSppReference()).relMse;
            double e = film.halfBufferRelMse();
            if (k == points.size()) points.push_back({done, 0, 0});
            points[k].trueRelMse += t / 2;
            points[k].estimate += e / 2;
            ++k;
        });
    }
    return points;
}

// Without a reference, the relMSE estimated from two half buffers (even and odd samples) must
// track the true relMSE against a high-spp reference within a factor of 2, 16 to 256 spp.
TEST(Convergence, HalfBufferEstimateTracksTrueRelMse) {
    for (const Point& p : convergence("cpu")) {
        std::printf("%4d spp: true relMSE %.5f, half-buffer estimate %.5f (ratio %.2f)\n", p.spp, p.trueRelMse,
                    p.estimate, p.estimate / p.trueRelMse);
        EXPECT_GT(p.estimate, 0.5 * p.trueRelMse) << p.spp << " spp";
        EXPECT_LT(p.estimate, 2.0 * p.trueRelMse) << p.spp << " spp";
    }
}

// Unbiased Monte Carlo: relMSE ~ 1/spp, a log-log slope of -1 (the reference's own noise,
// 1/8 of the test's at 256 spp, flattens it to about -0.96). Least squares over 16..256 spp.
TEST(Convergence, RelMseFallsWithSlopeMinusOneOnEveryBackend) {
    for (const std::string& backend : backendsUnderTest()) {
        std::vector<Point> pts = convergence(backend);
        ASSERT_EQ(pts.size(), 5u);
        double sx = 0, sy = 0, sxx = 0, sxy = 0;
        for (const Point& p : pts) {
            double x = std::log(double(p.spp)), y = std::log(p.trueRelMse);
            sx += x, sy += y, sxx += x * x, sxy += x * y;
        }
        const double n = double(pts.size());
        const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
        std::printf("%s: log-log slope of relMSE against spp %.3f\n", backend.c_str(), slope);
        EXPECT_GT(slope, -1.3) << backend;
        EXPECT_LT(slope, -0.7) << backend;
    }
}

std::vector<std::map<std::string, std::string>> readCsv(const std::string& path) {
    std::ifstream in(path);
    std::string line;
    std::vector<std::string> header;
    std::vector<std::map<std::string, std::string>> rows;
    while (std::getline(in, line)) {
        std::vector<std::string> cells;
        std::stringstream ss(line);
        for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
        if (header.empty()) {
            header = cells;
            continue;
        }
        std::map<std::string, std::string> row;
        for (size_t i = 0; i < cells.size() && i < header.size(); ++i) row[header[i]] = cells[i];
        rows.push_back(row);
    }
    return rows;
}

TEST(ErrorCsv, OneRowPerIterationWithAndWithoutReference) {
    TempDir dir;
    const std::string scene = sourceDir() + "/scenes/cornell-box.yaml";
    CommandResult ref = runSpillway("render " + scene + " --quiet --spp 16 -o " + dir.file("ref.exr"));
    ASSERT_EQ(ref.status, 0) << ref.output;
    CommandResult r = runSpillway("render " + scene + " --quiet --spp 8 -o " + dir.file("a.exr") + " --error-csv " +
                                  dir.file("a.csv") + " --reference " + dir.file("ref.exr") + " --seed 3");
    ASSERT_EQ(r.status, 0) << r.output;
    auto rows = readCsv(dir.file("a.csv"));
    ASSERT_EQ(rows.size(), 2u); // sample base 2: 4 spp per iteration
    double last = 0;
    for (size_t i = 0; i < rows.size(); ++i) {
        EXPECT_EQ(std::stoi(rows[i]["iteration"]), int(i) + 1);
        EXPECT_EQ(std::stoi(rows[i]["spp"]), 4 * (int(i) + 1));
        double t = std::stod(rows[i]["seconds"]);
        EXPECT_GT(t, last);
        last = t;
        for (const char* k : {"relmse_estimate", "mse", "rmse", "relmse", "mae", "psnr", "maxabs"})
            EXPECT_TRUE(std::isfinite(std::stod(rows[i][k]))) << k;
    }
    // The last row's metrics are the final image's, as `spillway compare` computes them.
    ImageMetrics m = compareImages(readImage(dir.file("a.exr")), readImage(dir.file("ref.exr")));
    EXPECT_NEAR(std::stod(rows.back()["relmse"]), m.relMse, 1e-6 * m.relMse);

    CommandResult plain = runSpillway("render " + scene + " --quiet --spp 8 -o " + dir.file("b.exr") +
                                      " --error-csv " + dir.file("b.csv"));
    ASSERT_EQ(plain.status, 0) << plain.output;
    auto rowsB = readCsv(dir.file("b.csv"));
    ASSERT_EQ(rowsB.size(), 2u);
    EXPECT_EQ(rowsB[0].count("relmse"), 0u);
    EXPECT_GT(std::stod(rowsB[0]["relmse_estimate"]), 0.0);

    CommandResult mismatch = runSpillway("render " + dir.write("small.yaml", "image: {width: 8, height: 8}\n") +
                                         " --quiet -o " + dir.file("c.exr") + " --error-csv " + dir.file("c.csv") +
                                         " --reference " + dir.file("ref.exr"));
    EXPECT_EQ(mismatch.status, 2) << mismatch.output;
    EXPECT_NE(mismatch.output.find("ref.exr"), std::string::npos) << mismatch.output;
}

// --time-limit stops after the iteration that crosses it and still writes a valid image.
TEST(TimeLimit, StopsAfterTheCrossingIterationWithAValidImage) {
    TempDir dir;
    CommandResult r = runSpillway("render " + sourceDir() + "/scenes/cornell-box.yaml --quiet --spp 4096 --time-limit 0.001 -o " +
                                  dir.file("t.exr") + " --stats " + dir.file("s.json"));
    ASSERT_EQ(r.status, 0) << r.output;
    nlohmann::json s = nlohmann::json::parse(std::ifstream(dir.file("s.json")));
    EXPECT_EQ(s["iterations"].get<int>(), 1);
    EXPECT_EQ(s["spp"].get<int>(), 4);
    ImageRGB img = readImage(dir.file("t.exr"));
    EXPECT_EQ(img.width, 256);
    EXPECT_GT(mean(img.rgb), 0.01);
}

} // namespace
} // namespace spw::test
