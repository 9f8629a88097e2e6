// Error against time: the half-buffer error estimate, the convergence rate of every backend,
// --error-csv and --time-limit.
#include "host/image/compare.h"
#include "host/loaders/scene_loader.h"
#include "test_util.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

namespace spw::test {
namespace {

// The Cornell box as shipped (Stratified sampler, sample base 2, min depth 3, max depth 16), small.
std::string cornellFile() {
    return sourceDir() + "/scenes/cornell-box.yaml";
}
Scene cornell(int size) {
    Scene scene = loadScene(cornellFile());
    scene.image.width = scene.image.height = size;
    return scene;
}

// A high-spp reference of the small Cornell box (one per size, rendered once for the whole
// suite) and its own relMSE (its half-buffer estimate, which a test below shows is accurate at
// these sample counts): a test image's expected relMSE against it is its own plus the reference's.
struct Reference {
    ImageRGB image;
    double ownRelMse;
};
// `scene` rendered at `spp` as a reference: the reference backend, under Sobol (at 32^2 and
// 16384 spp a Stratified reference's own error, 1.6e-5 by its estimate, is a third more than
// that as the truth weighs it, pixels holding a sliver of the light, and the ratio below read
// 0.92 at 1024 spp with any estimator; Sobol's is 4e-6 and reads as a 65536-spp Stratified
// reference does), with a seed independent of the test renders' random numbers. `file`: the
// scene file `scene` was loaded from. Made once for a scripts/test.sh run (runCached): the
// tests that share one, and the sanitized suite after the Release suite, read the first's.
Reference renderReference(const std::string& file, Scene scene, int spp) {
    scene.sampler = SamplerType::Sobol;
    scene.settings.seed = 12345;
    const int w = scene.image.width, h = scene.image.height;
    const std::string key = "convergence reference: " + file + " " + readFile(file) + " " +
                            std::to_string(w) + "x" + std::to_string(h) + " " +
                            std::to_string(spp) + " spp";
    const std::string bytes = runCached(key, [&] {
        RenderConfig cfg;
        cfg.backend = BackendKind::Reference;
        cfg.spp = spp;
        auto result = render(scene, cfg);
        const double own = result->film->halfBufferRelMse();
        const std::vector<float> image = result->film->image();
        std::string out(reinterpret_cast<const char*>(&own), sizeof own);
        out.append(reinterpret_cast<const char*>(image.data()), image.size() * sizeof(float));
        return out;
    });
    Reference ref{ImageRGB{w, h, std::vector<float>(size_t(w) * size_t(h) * 3)}, 0.0};
    const size_t want = sizeof(double) + ref.image.rgb.size() * sizeof(float);
    EXPECT_EQ(bytes.size(), want);
    if (bytes.size() == want) {
        std::memcpy(&ref.ownRelMse, bytes.data(), sizeof(double));
        std::memcpy(ref.image.rgb.data(), bytes.data() + sizeof(double),
                    ref.image.rgb.size() * sizeof(float));
    }
    return ref;
}
const Reference& highSppReference(int size) {
    static std::map<int, Reference> refs;
    auto it = refs.find(size);
    if (it != refs.end()) return it->second;
    // 16x the highest spp a test compares with it: the 32^2 one, 16384 spp, also under the
    // sanitizers, where the tests still reach 1024 spp (with a quarter of the samples its own
    // noise is a third of the truth there, and its estimate of that noise too rough to remove).
    // The 48^2 one serves tests that take a quarter of their samples there.
    return refs[size] = renderReference(cornellFile(), cornell(size),
                                        size < 48 ? 16384 : 4096 / kSanitizedFewer);
}

// The glossy small-light scene with its light out of the frame, size x size, and its 4096-spp
// reference at 64^2 (GlintEstimate below).
std::string glossyFile() {
    return sourceDir() + "/scenes/glossy-small-light-out-of-frame.yaml";
}
Scene glossyScene(int size) {
    Scene scene = loadScene(glossyFile());
    scene.image.width = scene.image.height = size;
    return scene;
}
const Reference& glossyReference() {
    static const Reference ref =
        renderReference(glossyFile(), glossyScene(64), 4096 / kSanitizedFewer);
    return ref;
}

// The references that several tests of a run read (their processes apart), made before any of
// them starts: ctest runs this first, as the fixture that every long-statistics test requires
// (CMakeLists.txt), so that none waits on another for them; without scripts/test.sh's cache
// there is nothing to share, and it skips. Each is finite, its own relMSE small (the 32^2
// Cornell box's about 4e-6 at 16384 spp), and read back the same bit for bit.
TEST(ConvergenceReferences, AreMadeOnceForTheRun) {
    if (!std::getenv("SPILLWAY_TEST_CACHE")) GTEST_SKIP() << "no SPILLWAY_TEST_CACHE to share";
    for (const Reference* ref : {&highSppReference(32), &glossyReference()}) {
        EXPECT_GT(ref->ownRelMse, 0.0);
        EXPECT_LT(ref->ownRelMse, 1e-3);
        for (float v : ref->image.rgb)
            ASSERT_TRUE(std::isfinite(v) && v >= 0.0f);
    }
    const Reference again = renderReference(cornellFile(), cornell(32), 16384);
    EXPECT_EQ(again.image.rgb, highSppReference(32).image.rgb);
    EXPECT_EQ(again.ownRelMse, highSppReference(32).ownRelMse);
}

// One render's error at five sample counts, each twice the last: the true relMSE (against the
// reference, the reference's own removed), the half-buffer estimate, and the final image.
struct Series {
    int spp[5];
    double trueRelMse[5], estimate[5], standardError[5];
    std::vector<float> image;
};

Series convergence(const std::string& backend, std::uint32_t seed, int size, int firstSpp,
                   SamplerType sampler = SamplerType::Stratified) {
    Scene scene = cornell(size);
    scene.sampler = sampler;
    const Reference& ref = highSppReference(size);
    RenderConfig cfg;
    cfg.backend = parseBackend(backend);
    cfg.spp = firstSpp * 16;
    scene.settings.seed = seed;
    Series s{};
    size_t k = 0;
    auto result = render(scene, cfg, [&](int done, int, const Film& film) {
        const int spp = done * 4; // sample base 2
        if (k < 5 && spp == firstSpp << k) {
            s.spp[k] = spp;
            s.trueRelMse[k] =
                compareImages({size, size, film.image()}, ref.image).relMse - ref.ownRelMse;
            s.estimate[k] = film.halfBufferRelMse();
            s.standardError[k] = film.halfBufferRelMseStandardError();
            ++k;
        }
    });
    EXPECT_EQ(k, 5u);
    s.image = result->film->image();
    return s;
}

// Least-squares slope of log(y) against log(spp).
double logLogSlope(const int* spp, const double* y) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (int k = 0; k < 5; ++k) {
        double x = std::log(double(spp[k])), ly = std::log(y[k]);
        sx += x, sy += ly, sxx += x * x, sxy += x * ly;
    }
    return (5 * sxy - sx * sy) / (5 * sxx - sx * sx);
}

struct Sample {
    double mean, stderror;
};
Sample meanOf(const std::vector<double>& v) {
    double s = 0, s2 = 0;
    for (double x : v)
        s += x, s2 += x * x;
    const double n = double(v.size()), m = s / n;
    return {m, std::sqrt(std::max(0.0, (s2 / n - m * m) / (n - 1)))};
}

// Without a reference, the relMSE estimated from the two half buffers must be the true relMSE
// (32^2 Cornell box, sample base 2 as shipped), under the Stratified sampler (halves by
// stratum) and under Sobol (the default: halves by stream, two independent scrambled
// sequences): the ratio of their means over 24 seeds, averaged over 64 to 1024 spp, within 10 %
// (its standard error is about 3 %; at each spp alone, about 6 %, within 20 %), and the
// estimate's log-log slope within 0.07 of the true one (standard error 0.03). A factor of 1.2
// in the estimator fails, as do halves that each take the same strata every iteration (the
// ratio then grows with spp, 10x by 1024) and Sobol halves cut from one scrambled sequence
// (2-3x too high). Below 64 spp the estimate reads low (README: "Error against time").
class HalfBufferEstimate : public ::testing::TestWithParam<SamplerType> {};

TEST_P(HalfBufferEstimate, TracksTrueRelMse) {
    // Under the sanitizers, 6 seeds: every standard error, and so every tolerance, doubles.
    constexpr int kSeeds = 24 / kSanitizedFewer;
    const double widen = std::sqrt(24.0 / kSeeds);
    std::vector<Series> runs;
    for (int seed = 1; seed <= kSeeds; ++seed)
        runs.push_back(convergence("reference", std::uint32_t(seed), 32, 64, GetParam()));
    const int* spp = runs[0].spp;
    double est[5] = {}, tru[5] = {};
    std::vector<double> slopeDiff;
    for (const Series& r : runs) {
        for (int k = 0; k < 5; ++k)
            est[k] += r.estimate[k] / kSeeds, tru[k] += r.trueRelMse[k] / kSeeds;
        slopeDiff.push_back(logLogSlope(spp, r.estimate) - logLogSlope(spp, r.trueRelMse));
    }
    double pooled = 0;
    for (int k = 0; k < 5; ++k) {
        pooled += est[k] / tru[k] / 5;
        std::vector<double> ratios;
        for (const Series& r : runs)
            ratios.push_back(r.estimate[k] / r.trueRelMse[k]);
        Sample per = meanOf(ratios);
        std::printf("%4d spp: true relMSE %.6f, estimate %.6f, ratio of means %.3f (per seed %.3f "
                    "+- %.3f)\n",
                    spp[k], tru[k], est[k], est[k] / tru[k], per.mean, per.stderror);
        EXPECT_GT(est[k] / tru[k], 1.0 - 0.2 * widen) << spp[k] << " spp";
        EXPECT_LT(est[k] / tru[k], 1.0 + 0.2 * widen) << spp[k] << " spp";
    }
    std::printf("ratio averaged over the sample counts %.3f\n", pooled);
    EXPECT_GT(pooled, 1.0 - 0.1 * widen);
    EXPECT_LT(pooled, 1.0 + 0.1 * widen);
    const double slopeEst = logLogSlope(spp, est), slopeTrue = logLogSlope(spp, tru);
    Sample d = meanOf(slopeDiff);
    std::printf("log-log slope: estimate %.3f, true %.3f (per seed difference %.3f +- %.3f)\n",
                slopeEst, slopeTrue, d.mean, d.stderror);
    EXPECT_NEAR(slopeEst, slopeTrue, 0.07 * widen);
    // The estimate's own standard error, from its tiles, against the spread of the estimate
    // over the seeds: their ratio, pooled over the sample counts, within 0.75-1.33 (the spread
    // of 24 values is itself uncertain by about 15 %; a standard error off by sqrt(2) fails).
    double ratio = 0;
    for (int k = 0; k < 5; ++k) {
        std::vector<double> values;
        double reported = 0;
        for (const Series& r : runs) {
            values.push_back(r.estimate[k]);
            reported += r.standardError[k] / kSeeds;
        }
        const double spread = meanOf(values).stderror * std::sqrt(double(kSeeds));
        std::printf("%4d spp: the estimate's standard error %.3g, its spread over the seeds %.3g\n",
                    spp[k], reported, spread);
        ratio += reported / spread / 5;
    }
    std::printf("standard error over spread, pooled %.3f\n", ratio);
    EXPECT_GT(ratio, 1.0 / (1.0 + 0.33 * widen));
    EXPECT_LT(ratio, 1.0 + 0.33 * widen);
}

INSTANTIATE_TEST_SUITE_P(Convergence, HalfBufferEstimate,
                         ::testing::Values(SamplerType::Stratified, SamplerType::Sobol),
                         [](const ::testing::TestParamInfo<SamplerType>& p) {
                             return std::string(samplerName(p.param));
                         });

// Where a scene's error is glints: the glossy small-light scene with the light out of the frame
// (64^2), whose floor takes rare paths of large value through the copper blocks. Its estimate
// over 8 seeds, against a 4096-spp reference (its own noise removed), at 64 and 256 spp, under
// the scene's sampler (Independent) and the default (Sobol): each ratio of means within 12 %
// (its standard error is about 4 %; a factor of 1.2 fails) and the ratio's change between the
// two, as a log-log slope, within 0.07 (standard error about 0.04; a slope off by 0.1 fails).
// With the pixel's own value as every denominator the estimate read 0.33-0.65 here: a glint
// inflates it as much as the halves' difference.
class GlintEstimate : public ::testing::TestWithParam<SamplerType> {};

TEST_P(GlintEstimate, TracksTrueRelMse) {
    constexpr int kSize = 64, kSeeds = kSanitizedFewer > 1 ? 4 : 8; // sanitizers: 4 seeds
    const double widen = std::sqrt(8.0 / kSeeds);
    auto glossy = [&] { return glossyScene(kSize); };
    const Reference& ref = glossyReference();
    const int spp[2] = {64 / kSanitizedFewer, 256 / kSanitizedFewer};
    double est[2] = {}, tru[2] = {};
    for (std::uint32_t seed = 1; seed <= std::uint32_t(kSeeds); ++seed) {
        Scene scene = glossy();
        scene.sampler = GetParam();
        scene.settings.seed = seed;
        RenderConfig cfg;
        cfg.backend = BackendKind::Reference;
        cfg.spp = spp[1];
        render(scene, cfg, [&](int done, int, const Film& film) {
            for (int k = 0; k < 2; ++k)
                if (done == spp[k]) { // sample base 1: one sample an iteration
                    est[k] += film.halfBufferRelMse();
                    tru[k] += compareImages({kSize, kSize, film.image()}, ref.image).relMse -
                              ref.ownRelMse;
                }
        });
    }
    for (int k = 0; k < 2; ++k) {
        std::printf("%4d spp: true relMSE %.5f, estimate %.5f, ratio %.3f\n", spp[k],
                    tru[k] / kSeeds, est[k] / kSeeds, est[k] / tru[k]);
        EXPECT_NEAR(est[k] / tru[k], 1.0, 0.12 * widen) << spp[k] << " spp";
    }
    const double slope = std::log((est[1] / tru[1]) / (est[0] / tru[0])) / std::log(4.0);
    std::printf("the ratio's log-log slope %.3f\n", slope);
    EXPECT_NEAR(slope, 0.0, 0.07 * widen);
}

INSTANTIATE_TEST_SUITE_P(Convergence, GlintEstimate,
                         ::testing::Values(SamplerType::Independent, SamplerType::Sobol),
                         [](const ::testing::TestParamInfo<SamplerType>& p) {
                             return std::string(samplerName(p.param));
                         });

// Every backend converges to the reference's image: no bias (the image mean, per channel,
// within 4 standard errors of the reference's, the error computed from the pixels'
// differences), and relMSE falling as 1/spp (the log-log slope within 4 standard errors of -1,
// the error from the spread of the per-seed slopes).
TEST(Convergence, EveryBackendIsUnbiasedAndRelMseFallsAsOneOverSpp) {
    const ImageRGB& ref = highSppReference(48).image;
    for (const std::string& backend : backendsUnderTest()) {
        constexpr int kSeeds = 4;
        std::vector<double> slopes;
        double tru[5] = {};
        int spp[5] = {};
        std::vector<double> diff[3];
        for (int seed = 101; seed < 101 + kSeeds; ++seed) {
            // Under the sanitizers, 4 to 64 spp rather than 16 to 256 (the tolerances are
            // computed from the samples).
            Series s = convergence(backend, std::uint32_t(seed), 48, 16 / kSanitizedFewer);
            for (int k = 0; k < 5; ++k)
                tru[k] += s.trueRelMse[k] / kSeeds;
            slopes.push_back(logLogSlope(s.spp, s.trueRelMse));
            std::copy(s.spp, s.spp + 5, spp);
            for (size_t i = 0; i < s.image.size(); ++i)
                diff[i % 3].push_back(double(s.image[i]) - ref.rgb[i]);
        }
        for (int c = 0; c < 3; ++c) {
            Sample d = meanOf(diff[c]);
            double refMean = 0;
            for (size_t i = size_t(c); i < ref.rgb.size(); i += 3)
                refMean += ref.rgb[i] / double(ref.rgb.size() / 3);
            std::printf(
                "%s channel %d: mean %.5f, reference %.5f, difference %+.5f +- %.5f (%+.2f %%)\n",
                backend.c_str(), c, refMean + d.mean, refMean, d.mean, d.stderror,
                100 * d.mean / refMean);
            EXPECT_LT(std::fabs(d.mean), 4 * d.stderror) << backend << " channel " << c;
        }
        Sample sl = meanOf(slopes);
        const double slope = logLogSlope(spp, tru);
        std::printf("%s: log-log slope of relMSE against spp %.3f (per seed %.3f +- %.3f)\n",
                    backend.c_str(), slope, sl.mean, sl.stderror);
        EXPECT_LT(std::fabs(slope + 1.0), 4 * sl.stderror) << backend;
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
        for (std::string c; std::getline(ss, c, ',');)
            cells.push_back(c);
        if (header.empty()) {
            header = cells;
            continue;
        }
        std::map<std::string, std::string> row;
        for (size_t i = 0; i < cells.size() && i < header.size(); ++i)
            row[header[i]] = cells[i];
        rows.push_back(row);
    }
    return rows;
}

TEST(ErrorCsv, OneRowPerIterationWithAndWithoutReference) {
    TempDir dir;
    const std::string scene = sourceDir() + "/scenes/cornell-box.yaml";
    CommandResult ref =
        runSpillway("render " + scene + " --quiet --spp 16 -o " + dir.file("ref.exr"));
    ASSERT_EQ(ref.status, 0) << ref.output;
    CommandResult r = runSpillway("render " + scene + " --quiet --spp 8 -o " + dir.file("a.exr") +
                                  " --error-csv " + dir.file("a.csv") + " --reference " +
                                  dir.file("ref.exr") + " --seed 3");
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
        for (const char* k :
             {"relmse_estimate", "relmse_estimate_stderr", "mse", "rmse", "relmse", "mae", "psnr",
              "maxabs", "subject_relmse_estimate", "subject_fraction"})
            EXPECT_TRUE(std::isfinite(std::stod(rows[i][k]))) << k;
        // The subject leaves out flat pixels, whose terms are 0: its mean is the larger.
        EXPECT_GE(std::stod(rows[i]["subject_relmse_estimate"]),
                  std::stod(rows[i]["relmse_estimate"]));
        EXPECT_GT(std::stod(rows[i]["subject_fraction"]), 0.0);
        EXPECT_LE(std::stod(rows[i]["subject_fraction"]), 1.0);
    }
    // The last row's metrics are the final image's, as `spillway compare` computes them.
    ImageMetrics m = compareImages(readImage(dir.file("a.exr")), readImage(dir.file("ref.exr")));
    EXPECT_NEAR(std::stod(rows.back()["relmse"]), m.relMse, 1e-6 * m.relMse);

    CommandResult plain = runSpillway("render " + scene + " --quiet --spp 8 -o " +
                                      dir.file("b.exr") + " --error-csv " + dir.file("b.csv"));
    ASSERT_EQ(plain.status, 0) << plain.output;
    auto rowsB = readCsv(dir.file("b.csv"));
    ASSERT_EQ(rowsB.size(), 2u);
    EXPECT_EQ(rowsB[0].count("relmse"), 0u);
    EXPECT_GT(std::stod(rowsB[0]["relmse_estimate"]), 0.0);

    CommandResult mismatch =
        runSpillway("render " + dir.write("small.yaml", "image: {width: 8, height: 8}\n") +
                    " --quiet -o " + dir.file("c.exr") + " --error-csv " + dir.file("c.csv") +
                    " --reference " + dir.file("ref.exr"));
    EXPECT_EQ(mismatch.status, 2) << mismatch.output;
    EXPECT_NE(mismatch.output.find("ref.exr"), std::string::npos) << mismatch.output;
}

// --target-error stops within one iteration of where the true relMSE (against a 4096-spp
// reference, its own noise removed) crosses the target, under the default sampler (Sobol), on
// the 64^2 Cornell box: four seeds, a target the truth crosses near 32 spp, 4 spp an iteration.
TEST(TargetError, StopsWithinAnIterationOfTheTrueCrossing) {
    const int size = 64;
    const Reference& ref = highSppReference(size);
    const double target = 4e-3;
    for (std::uint32_t seed = 1; seed <= 4; ++seed) {
        Scene scene = cornell(size);
        scene.sampler = SamplerType::Sobol;
        scene.settings.seed = seed;
        RenderConfig cfg;
        cfg.backend = BackendKind::Reference;
        cfg.spp = 256;
        cfg.adaptiveToTarget = false; // the stop rule alone (TargetError.AdaptiveSampling…)
        // The true relMSE after each iteration, without a target: the renders are the same
        // iteration for iteration, so this is the curve the render with the target follows.
        std::vector<double> truth;
        render(scene, cfg, [&](int, int, const Film& film) {
            truth.push_back(compareImages({size, size, film.image()}, ref.image).relMse -
                            ref.ownRelMse);
        });
        size_t crossed = 0;
        while (crossed < truth.size() && truth[crossed] > target)
            ++crossed;
        ASSERT_LT(crossed, truth.size()) << "the truth crosses the target within 256 spp";
        cfg.targetError = target;
        int stopped = 0;
        render(scene, cfg, [&](int done, int, const Film&) { stopped = done; });
        std::printf("seed %u: stopped after iteration %d; the true relMSE crossed %.4f at "
                    "iteration %zu (%.5f, before it %.5f)\n",
                    seed, stopped, target, crossed + 1, truth[crossed],
                    crossed > 0 ? truth[crossed - 1] : 0.0);
        EXPECT_LE(std::abs(stopped - int(crossed + 1)), 1) << "seed " << seed;
    }
}

// --error-map writes the terms the relMSE estimate averages, per pixel and channel: the map's
// mean is the CSV's last estimate, its values are finite and non-negative, and they differ from
// pixel to pixel by orders of magnitude, as the noise does (a uniform map would show nothing).
TEST(ErrorMap, HoldsThePerPixelTermsOfTheEstimate) {
    TempDir dir;
    const std::string scene = sourceDir() + "/scenes/cornell-box.yaml";
    CommandResult r =
        runSpillway("render " + scene + " --quiet --spp 8 -o " + dir.file("a.exr") +
                    " --error-csv " + dir.file("a.csv") + " --error-map " + dir.file("e.exr"));
    ASSERT_EQ(r.status, 0) << r.output;
    const ImageRGB map = readImage(dir.file("e.exr"));
    ASSERT_EQ(map.width, 256);
    ASSERT_EQ(map.height, 256);
    double total = 0, lo = 1e30, hi = 0;
    for (float v : map.rgb) {
        ASSERT_TRUE(std::isfinite(v) && v >= 0.0f) << v;
        total += v;
        lo = std::min(lo, double(v));
        hi = std::max(hi, double(v));
    }
    const double estimate = std::stod(readCsv(dir.file("a.csv")).back()["relmse_estimate"]);
    EXPECT_NEAR(total / double(map.rgb.size()), estimate, 1e-5 * estimate);
    EXPECT_GT(hi, 100.0 * lo + 1e-6) << "a map that is the same everywhere shows nothing";
}

// --time-limit stops after the iteration that crosses it and still writes a valid image.
TEST(TimeLimit, StopsAfterTheCrossingIterationWithAValidImage) {
    TempDir dir;
    CommandResult r =
        runSpillway("render " + sourceDir() +
                    "/scenes/cornell-box.yaml --quiet --spp 4096 --time-limit 0.001 -o " +
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
