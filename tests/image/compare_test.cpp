// `spillway compare`: the metrics against closed forms (identical images, a constant offset,
// non-finite pixels, channel means), the thresholds' exit status, the errors' exit status and
// messages, the JSON output and the heatmap's pixels. The command is run through
// compareCommand, the function main calls for "compare".
#include "host/app/compare_command.h"
#include "host/image/compare.h"
#include "test_util.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>

namespace spw::test {
namespace {

ImageRGB makeImage(int w, int h, const std::function<float(int x, int y, int c)>& f) {
    ImageRGB img{w, h, std::vector<float>(std::size_t(w) * h * 3)};
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c)
                img.rgb[(std::size_t(y) * w + x) * 3 + c] = f(x, y, c);
    return img;
}

// Dyadic values in [0, 63/64]: adding 1/8 to them is exact in float.
ImageRGB dyadicImage(int w, int h) {
    return makeImage(w, h,
                     [](int x, int y, int c) { return float((x * 7 + y * 13 + c * 5) % 64) / 64; });
}

ImageRGB offsetImage(const ImageRGB& b, float c) {
    ImageRGB a = b;
    for (float& v : a.rgb)
        v += c;
    return a;
}

// Closed form of relmse for a - b = c everywhere: mean over values of c^2 / (b^2 + 0.01).
double relMseOfOffset(const ImageRGB& b, double c) {
    double s = 0;
    for (float v : b.rgb)
        s += c * c / (double(v) * v + 0.01);
    return s / double(b.rgb.size());
}

struct CliResult {
    int status;
    std::string out, err;
};

CliResult compareCli(const std::vector<std::string>& args) {
    testing::internal::CaptureStdout();
    testing::internal::CaptureStderr();
    const int status = compareCommand(args);
    std::string out = testing::internal::GetCapturedStdout();
    std::string err = testing::internal::GetCapturedStderr();
    return {status, out, err};
}

bool contains(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// ---- metrics --------------------------------------------------------------------------------

TEST(CompareMetrics, IdenticalImagesHaveZeroErrorAndInfinitePsnr) {
    const ImageRGB b = makeImage(17, 9, [](int x, int y, int c) { return 0.37f * x + y - c; });
    const ImageMetrics m = compareImages(b, b);
    EXPECT_EQ(m.pixels, 17u * 9u);
    EXPECT_EQ(m.comparedPixels, m.pixels);
    EXPECT_EQ(m.mse, 0.0);
    EXPECT_EQ(m.rmse, 0.0);
    EXPECT_EQ(m.relMse, 0.0);
    EXPECT_EQ(m.mae, 0.0);
    EXPECT_EQ(m.maxAbs, 0.0);
    EXPECT_TRUE(std::isinf(m.psnr) && m.psnr > 0);
    const nlohmann::json j = toJson(m);
    EXPECT_TRUE(j["psnr"].is_null()); // JSON has no infinity
    EXPECT_EQ(j["mse"].get<double>(), 0.0);
}

TEST(CompareMetrics, ConstantOffsetGivesClosedFormsExactly) {
    const ImageRGB b = dyadicImage(64, 32);
    const double c = 0.125;
    const ImageMetrics m = compareImages(offsetImage(b, float(c)), b);
    EXPECT_DOUBLE_EQ(m.mse, c * c);
    EXPECT_DOUBLE_EQ(m.rmse, c);
    EXPECT_DOUBLE_EQ(m.mae, c);
    EXPECT_DOUBLE_EQ(m.maxAbs, c);
    EXPECT_NEAR(m.relMse, relMseOfOffset(b, c), 1e-12 * relMseOfOffset(b, c));
    EXPECT_NEAR(m.psnr, -10.0 * std::log10(c * c), 1e-12);
    EXPECT_EQ(m.nonFiniteA, 0u);
    EXPECT_EQ(m.nonFiniteB, 0u);

    // A negative offset: the same magnitudes.
    const ImageMetrics n = compareImages(offsetImage(b, float(-c)), b);
    EXPECT_DOUBLE_EQ(n.mse, c * c);
    EXPECT_DOUBLE_EQ(n.mae, c);
    EXPECT_DOUBLE_EQ(n.maxAbs, c);
}

TEST(CompareMetrics, ConstantOffsetWithinFloatRounding) {
    // Values in [0, 2): a = b + c is rounded to float, off by at most half an ulp of 2.
    const ImageRGB b = makeImage(40, 30, [](int x, int y, int c) {
        return std::fmod(0.0137f * float(x * 31 + y * 17 + c * 3), 2.0f);
    });
    const double c = 0.03, ulp = 1.2e-7;
    const ImageMetrics m = compareImages(offsetImage(b, float(c)), b);
    EXPECT_NEAR(m.mse, c * c, 2 * c * ulp);
    EXPECT_NEAR(m.rmse, c, 2 * ulp);
    EXPECT_NEAR(m.mae, c, 2 * ulp);
    EXPECT_NEAR(m.maxAbs, c, 2 * ulp);
    EXPECT_NEAR(m.relMse, relMseOfOffset(b, c), 1e-5 * relMseOfOffset(b, c));
}

TEST(CompareMetrics, NonFinitePixelsAreCountedAndExcluded) {
    const int w = 8, h = 4;
    const ImageRGB b0 = dyadicImage(w, h);
    ImageRGB a = offsetImage(b0, 0.125f), b = b0;
    auto at = [&](ImageRGB& img, int x, int y, int c) -> float& {
        return img.rgb[(std::size_t(y) * w + x) * 3 + c];
    };
    at(a, 1, 2, 1) = kNaN;                         // A only
    at(b, 3, 0, 0) = kInf;                         // B only
    at(a, 5, 3, 2) = -kInf, at(b, 5, 3, 0) = kNaN; // both, same pixel
    const ImageMetrics m = compareImages(a, b);
    EXPECT_EQ(m.nonFiniteA, 2u);
    EXPECT_EQ(m.nonFiniteB, 2u);
    EXPECT_EQ(m.comparedPixels, std::size_t(w * h - 3));
    EXPECT_DOUBLE_EQ(m.mse, 0.125 * 0.125); // finite, the NaN pixel left out
    EXPECT_DOUBLE_EQ(m.maxAbs, 0.125);

    // The channel means are over the compared pixels only.
    std::array<double, 3> expected{};
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if ((x == 1 && y == 2) || (x == 3 && y == 0) || (x == 5 && y == 3)) continue;
            for (int c = 0; c < 3; ++c)
                expected[c] += at(b, x, y, c);
        }
    for (int c = 0; c < 3; ++c) {
        EXPECT_DOUBLE_EQ(m.meanB[c], expected[c] / m.comparedPixels);
        EXPECT_DOUBLE_EQ(m.meanA[c], expected[c] / m.comparedPixels + 0.125);
    }
}

TEST(CompareMetrics, NoComparablePixelMakesMetricsNaNAndThresholdsFail) {
    const ImageRGB a = makeImage(2, 2, [](int, int, int) { return kNaN; });
    const ImageRGB b = makeImage(2, 2, [](int, int, int) { return 1.0f; });
    const ImageMetrics m = compareImages(a, b);
    EXPECT_EQ(m.nonFiniteA, 4u);
    EXPECT_EQ(m.comparedPixels, 0u);
    EXPECT_TRUE(std::isnan(m.mse));
    EXPECT_FALSE(meetsThreshold(m, parseThreshold("mse=1e30")));
    EXPECT_FALSE(meetsThreshold(m, parseThreshold("psnr=-1e30")));
}

TEST(CompareMetrics, PerChannelMeans) {
    // R: a ramp 0..1 across (mean 1/2); G: 1/4; B: 2 on the top half, 0 below (mean 1).
    const ImageRGB a = makeImage(9, 6, [](int x, int y, int c) {
        return c == 0 ? float(x) / 8 : c == 1 ? 0.25f : (y < 3 ? 2.0f : 0.0f);
    });
    const ImageRGB b = makeImage(9, 6, [](int, int, int c) { return 0.125f * (c + 1); });
    const ImageMetrics m = compareImages(a, b);
    EXPECT_NEAR(m.meanA[0], 0.5, 1e-12);
    EXPECT_NEAR(m.meanA[1], 0.25, 1e-12);
    EXPECT_NEAR(m.meanA[2], 1.0, 1e-12);
    EXPECT_NEAR(m.meanB[0], 0.125, 1e-12);
    EXPECT_NEAR(m.meanB[1], 0.25, 1e-12);
    EXPECT_NEAR(m.meanB[2], 0.375, 1e-12);
}

TEST(CompareMetrics, MaxAbsNamesItsPixel) {
    ImageRGB a = dyadicImage(10, 7);
    const ImageRGB b = a;
    a.rgb[(std::size_t(4) * 10 + 6) * 3 + 2] += 0.75f;
    const ImageMetrics m = compareImages(a, b);
    EXPECT_DOUBLE_EQ(m.maxAbs, 0.75);
    EXPECT_EQ(m.maxAbsX, 6);
    EXPECT_EQ(m.maxAbsY, 4);
    EXPECT_DOUBLE_EQ(m.mse, 0.75 * 0.75 / (10 * 7 * 3));
}

TEST(CompareMetrics, SizeMismatchThrows) {
    EXPECT_THROW(compareImages(dyadicImage(4, 4), dyadicImage(4, 5)), std::invalid_argument);
}

TEST(CompareThreshold, ParsesNamesAndBounds) {
    const Threshold t = parseThreshold("RMSE=0.25");
    EXPECT_EQ(t.metric, "rmse");
    EXPECT_EQ(t.bound, 0.25);
    EXPECT_THROW(parseThreshold("sharpness=1"), std::invalid_argument);
    EXPECT_THROW(parseThreshold("rmse=abc"), std::invalid_argument);
    EXPECT_THROW(parseThreshold("rmse"), std::invalid_argument);
    EXPECT_THROW(parseThreshold("rmse="), std::invalid_argument);

    ImageMetrics m;
    m.rmse = 0.1;
    m.psnr = 20;
    EXPECT_TRUE(meetsThreshold(m, parseThreshold("rmse=0.1"))); // at the bound passes
    EXPECT_FALSE(meetsThreshold(m, parseThreshold("rmse=0.09")));
    EXPECT_TRUE(meetsThreshold(m, parseThreshold("psnr=20"))); // psnr is a lower bound
    EXPECT_FALSE(meetsThreshold(m, parseThreshold("psnr=21")));
    EXPECT_TRUE(meetsThreshold(m, parseThreshold("psnr=19")));
}

// ---- the command ----------------------------------------------------------------------------

// A reference and a test image offset from it, both written as EXR.
struct Pair {
    TempDir dir;
    std::string a, b;
    explicit Pair(float offset, int w = 16, int h = 12) {
        const ImageRGB ref = dyadicImage(w, h);
        a = dir.file("a.exr");
        b = dir.file("b.exr");
        writeImage(a, offsetImage(ref, offset));
        writeImage(b, ref);
    }
};

TEST(CompareCommand, RmseThresholdPassesSmallOffsetAndFailsLargeOne) {
    Pair small(0.015625f), large(0.5f);
    const CliResult pass = compareCli({small.a, small.b, "--threshold", "rmse=0.1"});
    EXPECT_EQ(pass.status, 0) << pass.out << pass.err;
    EXPECT_TRUE(contains(pass.out, "threshold rmse <= 0.1: pass")) << pass.out;

    const CliResult fail = compareCli({large.a, large.b, "--threshold", "rmse=0.1"});
    EXPECT_EQ(fail.status, 1) << fail.out << fail.err;
    EXPECT_TRUE(contains(fail.err, "rmse = 0.5 exceeds the bound 0.1")) << fail.err;
}

TEST(CompareCommand, PsnrThresholdIsALowerBound) {
    Pair p(0.015625f); // mse = 2^-12, psnr = 36.12 dB
    EXPECT_EQ(compareCli({p.a, p.b, "--threshold", "psnr=30"}).status, 0);
    const CliResult fail = compareCli({p.a, p.b, "--threshold=psnr=40"});
    EXPECT_EQ(fail.status, 1);
    EXPECT_TRUE(contains(fail.err, "psnr")) << fail.err;
    EXPECT_TRUE(contains(fail.err, "below the bound 40")) << fail.err;
}

TEST(CompareCommand, SeveralThresholdsAllMustHold) {
    Pair p(0.015625f);
    EXPECT_EQ(compareCli({p.a, p.b, "--threshold", "mse=1", "--threshold", "mae=0.1"}).status, 0);
    const CliResult r =
        compareCli({p.a, p.b, "--threshold", "mse=1", "--threshold", "maxabs=0.001"});
    EXPECT_EQ(r.status, 1);
    EXPECT_TRUE(contains(r.err, "maxabs")) << r.err;
    EXPECT_FALSE(contains(r.err, "mse =")) << r.err;
}

TEST(CompareCommand, UnknownMetricIsAUsageError) {
    Pair p(0.0f);
    const CliResult r = compareCli({p.a, p.b, "--threshold", "sharpness=3"});
    EXPECT_EQ(r.status, 2);
    EXPECT_TRUE(contains(r.err, "unknown metric 'sharpness'")) << r.err;
}

TEST(CompareCommand, UsageErrorsExitTwo) {
    Pair p(0.0f);
    EXPECT_EQ(compareCli({p.a}).status, 2);
    EXPECT_EQ(compareCli({p.a, p.b, p.a}).status, 2);
    EXPECT_EQ(compareCli({p.a, p.b, "--frobnicate"}).status, 2);
    EXPECT_EQ(compareCli({p.a, p.b, "--threshold"}).status, 2);
    EXPECT_EQ(compareCli({p.a, p.b, "--heatmap", p.dir.file("h.jpg")}).status, 2);
    EXPECT_EQ(compareCli({"--help"}).status, 0);
}

// One NaN pixel in the test image against a clean reference: never "identical", and every
// threshold fails (exit 1, naming the count) unless --allow-nonfinite asks to judge the finite
// pixels alone. (Before: "images identical", and relmse=1e-3 passed.)
TEST(CompareCommand, ANonFinitePixelFailsEveryThresholdUnlessAllowed) {
    TempDir dir;
    const ImageRGB ref = dyadicImage(16, 12);
    ImageRGB nan = ref;
    nan.rgb[7] = std::numeric_limits<float>::quiet_NaN();
    const std::string a = dir.file("a.exr"), b = dir.file("b.exr");
    writeImage(a, nan);
    writeImage(b, ref);
    const CliResult fail = compareCli({a, b, "--threshold", "relmse=1e-3"});
    EXPECT_EQ(fail.status, 1) << fail.out << fail.err;
    EXPECT_FALSE(contains(fail.out, "images identical")) << fail.out;
    EXPECT_TRUE(contains(fail.err, "1 non-finite pixels in A")) << fail.err;
    const CliResult allowed = compareCli({a, b, "--threshold", "relmse=1e-3", "--allow-nonfinite"});
    EXPECT_EQ(allowed.status, 0) << allowed.out << allowed.err;
    EXPECT_EQ(compareCli({b, a, "--threshold", "psnr=10"}).status, 1) << "a NaN in the reference";
}

// An upper bound below zero can never be met: refused as bad usage, not accepted.
TEST(CompareCommand, ANegativeUpperBoundIsAUsageError) {
    Pair p(0.0f);
    const CliResult r = compareCli({p.a, p.b, "--threshold", "relmse=-1"});
    EXPECT_EQ(r.status, 2);
    EXPECT_TRUE(contains(r.err, "must be 0 or more")) << r.err;
    EXPECT_EQ(compareCli({p.a, p.b, "--threshold", "psnr=-5"}).status, 0) << "psnr may be any";
}

TEST(CompareCommand, MismatchedSizesExitTwoNamingBothFiles) {
    TempDir dir;
    const std::string a = dir.file("small.exr"), b = dir.file("big.exr");
    writeImage(a, dyadicImage(8, 8));
    writeImage(b, dyadicImage(8, 9));
    const CliResult r = compareCli({a, b});
    EXPECT_EQ(r.status, 2);
    EXPECT_TRUE(contains(r.err, "sizes differ")) << r.err;
    EXPECT_TRUE(contains(r.err, a) && contains(r.err, b)) << r.err;
    EXPECT_TRUE(contains(r.err, "8x8") && contains(r.err, "8x9")) << r.err;
}

TEST(CompareCommand, MissingFileExitsTwoNamingIt) {
    Pair p(0.0f);
    const std::string missing = p.dir.file("nowhere.exr");
    const CliResult r = compareCli({missing, p.b});
    EXPECT_EQ(r.status, 2);
    EXPECT_TRUE(contains(r.err, missing)) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
}

TEST(CompareCommand, NonImageFileExitsTwoNamingIt) {
    Pair p(0.0f);
    const std::string text = p.dir.write("notes.exr", "this is not an image\n");
    const CliResult r = compareCli({p.a, text});
    EXPECT_EQ(r.status, 2);
    EXPECT_TRUE(contains(r.err, text)) << r.err;
    const std::string txt = p.dir.write("notes.txt", "neither is this\n");
    const CliResult r2 = compareCli({txt, p.b});
    EXPECT_EQ(r2.status, 2);
    EXPECT_TRUE(contains(r2.err, txt)) << r2.err;
}

TEST(CompareCommand, TablePrintsEveryMetric) {
    Pair p(0.125f);
    const CliResult r = compareCli({p.a, p.b});
    EXPECT_EQ(r.status, 0) << r.err;
    for (const char* key :
         {"mse", "rmse", "relmse", "mae", "maxabs", "psnr", "channel means", "non-finite"})
        EXPECT_TRUE(contains(r.out, key)) << key << "\n" << r.out;
    EXPECT_TRUE(contains(r.out, "rmse         0.125")) << r.out;
}

TEST(CompareCommand, JsonParsesAndHoldsTheMetrics) {
    Pair p(0.125f, 20, 10);
    const CliResult r = compareCli({p.a, p.b, "--json", "--threshold", "rmse=0.2"});
    ASSERT_EQ(r.status, 0) << r.err;
    nlohmann::json j;
    ASSERT_NO_THROW(j = nlohmann::json::parse(r.out)) << r.out;
    for (const char* key : {"mse", "rmse", "relmse", "mae", "maxabs", "psnr", "mean_a", "mean_b",
                            "nonfinite_a", "nonfinite_b", "compared_pixels", "thresholds"})
        EXPECT_TRUE(j.contains(key)) << key;
    EXPECT_DOUBLE_EQ(j["mse"].get<double>(), 0.125 * 0.125);
    EXPECT_DOUBLE_EQ(j["rmse"].get<double>(), 0.125);
    EXPECT_EQ(j["width"], 20);
    EXPECT_EQ(j["height"], 10);
    EXPECT_EQ(j["compared_pixels"], 200);
    EXPECT_EQ(j["nonfinite_a"], 0);
    EXPECT_EQ(j["mean_a"].size(), 3u);
    EXPECT_TRUE(j["passed"].get<bool>());
    EXPECT_EQ(j["thresholds"][0]["metric"], "rmse");
    EXPECT_TRUE(j["thresholds"][0]["passed"].get<bool>());

    const CliResult same = compareCli({p.b, p.b, "--json"});
    const nlohmann::json k = nlohmann::json::parse(same.out);
    EXPECT_EQ(k["mse"].get<double>(), 0.0);
    EXPECT_TRUE(k["psnr"].is_null()); // infinite
}

TEST(CompareCommand, ReadsPngInputs) {
    TempDir dir;
    const ImageRGB img = dyadicImage(12, 12);
    const std::string a = dir.file("a.png"), b = dir.file("b.png");
    writeImage(a, img);
    writeImage(b, img);
    const CliResult r = compareCli({a, b, "--json", "--threshold", "maxabs=0"});
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["mse"].get<double>(), 0.0);
    writeImage(b, offsetImage(img, 0.25f));
    EXPECT_EQ(compareCli({a, b, "--threshold", "maxabs=0"}).status, 1);
}

// ---- heatmap --------------------------------------------------------------------------------

struct Rgb8Image {
    int width = 0, height = 0;
    std::vector<unsigned char> px;
    std::string description;
    std::array<unsigned char, 3> at(int x, int y) const {
        const unsigned char* p = &px[(std::size_t(y) * width + x) * 3];
        return {p[0], p[1], p[2]};
    }
};

Rgb8Image readPng(const std::string& path) {
    auto in = OIIO::ImageInput::open(path);
    if (!in) return {};
    Rgb8Image img;
    img.width = in->spec().width;
    img.height = in->spec().height;
    img.description = in->spec().get_string_attribute("ImageDescription");
    img.px.resize(std::size_t(img.width) * img.height * 3);
    in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, img.px.data());
    return img;
}

TEST(CompareHeatmap, ColoursFollowTheLogScaledRelativeError) {
    TempDir dir;
    const ImageRGB b = makeImage(32, 16, [](int, int, int) { return 0.5f; });
    ImageRGB a = b;
    auto px = [&](int x, int y) { return &a.rgb[(std::size_t(y) * 32 + x) * 3]; };
    for (int c = 0; c < 3; ++c)
        px(5, 5)[c] += 0.5f, px(10, 5)[c] += 0.05f;
    px(20, 8)[1] = kNaN;
    const std::string path = dir.file("heat.png");
    const HeatmapInfo info = writeHeatmap(path, a, b);
    EXPECT_NEAR(info.high, 0.25 / 0.26, 1e-6);
    EXPECT_NEAR(info.low, 0.0025 / 0.26, 1e-6);

    const Rgb8Image img = readPng(path);
    ASSERT_EQ(img.width, info.width);
    ASSERT_EQ(img.height, info.height);
    const int s = 8; // 32 pixels wide, enlarged to 256
    EXPECT_EQ(img.width, 32 * s);
    EXPECT_GT(img.height, 16 * s + 20);                     // the colour bar below
    EXPECT_EQ(img.at(5 * s + 4, 5 * s + 4), viridis(1.0));  // largest error
    EXPECT_EQ(img.at(10 * s + 4, 5 * s + 4), viridis(0.0)); // the smallest non-zero
    EXPECT_EQ(img.at(2 * s + 4, 2 * s + 4), viridis(0.0));  // no error
    const std::array<unsigned char, 3> red{255, 0, 0};
    EXPECT_EQ(img.at(20 * s + 4, 8 * s + 4), red); // NaN in A
    EXPECT_TRUE(contains(img.description, "log10")) << img.description;

    // The bar runs from viridis(0) on the left to viridis(1) on the right.
    // (The bar starts 8 pixels in from either side at this width.)
    const int barY = 16 * s + 8;
    const auto left = img.at(9, barY), right = img.at(img.width - 10, barY);
    EXPECT_LT(std::abs(left[0] - 0x44) + std::abs(left[2] - 0x54), 12);
    EXPECT_LT(std::abs(right[0] - 0xFD) + std::abs(right[1] - 0xE7), 12);
}

TEST(CompareHeatmap, CommandWritesAReadablePng) {
    Pair p(0.125f, 300, 40);
    const std::string heat = p.dir.file("heat.png");
    const CliResult r = compareCli({p.a, p.b, "--heatmap", heat});
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_TRUE(contains(r.out, heat)) << r.out;
    const ImageRGB img = readImage(heat);
    EXPECT_EQ(img.width, 300);
    EXPECT_GT(img.height, 40);
    EXPECT_LT(img.height, 40 + 100);

    // A folder that is missing: a disk failure, exit 1 (the README's exit table).
    const CliResult bad = compareCli({p.a, p.b, "--heatmap", p.dir.file("no/such/dir/h.png")});
    EXPECT_EQ(bad.status, 1);
    EXPECT_TRUE(contains(bad.err, "no/such/dir/h.png")) << bad.err;
}

TEST(CompareHeatmap, IdenticalImagesGiveAFlatMap) {
    TempDir dir;
    const ImageRGB b = dyadicImage(8, 8);
    const HeatmapInfo info = writeHeatmap(dir.file("flat.png"), b, b);
    EXPECT_EQ(info.low, 0.0);
    EXPECT_EQ(info.high, 0.0);
    const Rgb8Image img = readPng(dir.file("flat.png"));
    EXPECT_EQ(img.at(img.width / 2, 10), viridis(0.0)); // 8 wide: 128 centred on 256
}

} // namespace
} // namespace spw::test
