#include "host/app/compare_command.h"

#include "host/app/usage_error.h"
#include "host/image/compare.h"
#include "host/image/output_file.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

namespace spw {
namespace {

// The image at `path`, or its layer `layer` where one is named (--layer).
ImageRGB readInput(const std::string& path, const std::string& layer) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec))
        throw std::runtime_error("cannot read '" + path + "': no such file");
    if (std::filesystem::is_directory(path, ec))
        throw std::runtime_error("cannot read '" + path + "': it is a folder");
    ImageRGB img = layer.empty() ? readImage(path) : readImageLayer(path, layer); // name the path
    if (img.width <= 0 || img.height <= 0)
        throw std::runtime_error("cannot read '" + path + "': the image is empty");
    return img;
}

std::string formatValue(double v) {
    if (std::isnan(v)) return "n/a";
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

void printTable(const std::string& pathA, const std::string& pathB, const ImageMetrics& m) {
    std::printf("A (test)       %s\n", pathA.c_str());
    std::printf("B (reference)  %s\n", pathB.c_str());
    std::printf("size           %d x %d, %zu of %zu pixels compared\n", m.width, m.height,
                m.comparedPixels, m.pixels);
    std::printf("non-finite     A: %zu  B: %zu pixels\n\n", m.nonFiniteA, m.nonFiniteB);
    std::printf("  mse          %s\n", formatValue(m.mse).c_str());
    std::printf("  rmse         %s\n", formatValue(m.rmse).c_str());
    std::printf("  relmse       %s\n", formatValue(m.relMse).c_str());
    std::printf("  mae          %s\n", formatValue(m.mae).c_str());
    if (m.maxAbsX >= 0)
        std::printf("  maxabs       %s at pixel (%d, %d)\n", formatValue(m.maxAbs).c_str(),
                    m.maxAbsX, m.maxAbsY);
    else
        std::printf("  maxabs       %s\n", formatValue(m.maxAbs).c_str());
    const bool identical = std::isinf(m.psnr) && m.nonFiniteA == 0 && m.nonFiniteB == 0;
    std::printf("  psnr         %s dB (peak 1.0, linear)%s\n\n", formatValue(m.psnr).c_str(),
                identical ? ", images identical" : "");
    std::printf("  channel means  %-12s %-12s %s\n", "R", "G", "B");
    std::printf("  A              %-12s %-12s %s\n", formatValue(m.meanA[0]).c_str(),
                formatValue(m.meanA[1]).c_str(), formatValue(m.meanA[2]).c_str());
    std::printf("  B              %-12s %-12s %s\n", formatValue(m.meanB[0]).c_str(),
                formatValue(m.meanB[1]).c_str(), formatValue(m.meanB[2]).c_str());
}

struct CompareOptions {
    std::vector<std::string> files;
    std::vector<Threshold> thresholds;
    std::string heatmapPath;
    std::string layer; // --layer: a render pass of both EXRs instead of their image
    bool json = false;
    bool allowNonFinite = false; // thresholds judge the finite pixels alone
    bool help = false;
};

// `--opt value` or `--opt=value`.
CompareOptions parseCompareOptions(const std::vector<std::string>& args) {
    CompareOptions o;
    for (std::size_t i = 0; i < args.size(); ++i) {
        std::string a = args[i], inlineValue;
        bool hasInline = false;
        if (a.rfind("--", 0) == 0 && a.find('=') != std::string::npos) {
            inlineValue = a.substr(a.find('=') + 1);
            a = a.substr(0, a.find('='));
            hasInline = true;
        }
        auto value = [&]() -> std::string {
            if (hasInline) return inlineValue;
            if (i + 1 >= args.size()) throw UsageError(a + " needs a value");
            return args[++i];
        };
        if (a == "-h" || a == "--help") {
            o.help = true;
            return o;
        } else if (a == "--allow-nonfinite") {
            o.allowNonFinite = true;
        } else if (a == "--json") {
            o.json = true;
        } else if (a == "--heatmap") {
            o.heatmapPath = value();
            std::string ext = std::filesystem::path(o.heatmapPath).extension().string();
            std::transform(ext.begin(), ext.end(), ext.begin(),
                           [](unsigned char c) { return char(std::tolower(c)); });
            if (ext != ".png")
                throw UsageError("--heatmap '" + o.heatmapPath + "' must end in .png");
        } else if (a == "--layer") {
            o.layer = value();
            if (o.layer.empty()) throw UsageError("--layer needs a layer's name");
        } else if (a == "--threshold") {
            try {
                o.thresholds.push_back(parseThreshold(value()));
            } catch (const std::invalid_argument& e) {
                throw UsageError(std::string("--threshold: ") + e.what());
            }
        } else if (a.size() > 1 && a[0] == '-') {
            throw UsageError("unknown option '" + a + "'");
        } else {
            o.files.push_back(a);
        }
    }
    if (o.files.size() != 2)
        throw UsageError("compare takes two images, A and the reference B (" +
                         std::to_string(o.files.size()) + " given)");
    // The heatmap would replace an input it is computed from (however the path is spelt: a link,
    // ./, another folder's ..).
    for (const std::string& input : o.files)
        if (!o.heatmapPath.empty() && sameFile(o.heatmapPath, input))
            throw UsageError("--heatmap '" + o.heatmapPath + "' names the input '" + input +
                             "'; write the heatmap to another file");
    return o;
}

// Each --threshold's verdict: as JSON, as a line of the table, and as a failure message.
struct Verdicts {
    bool passed = true;
    nlohmann::json json = nlohmann::json::array();
    std::vector<std::string> lines, failures;
};

// A non-finite pixel in either image fails every threshold unless --allow-nonfinite: a NaN is
// a defect a regression gate must catch, whatever the finite pixels' metrics say.
Verdicts judge(const ImageMetrics& m, const std::vector<Threshold>& thresholds,
               bool allowNonFinite) {
    Verdicts v;
    const size_t nonFinite = m.nonFiniteA + m.nonFiniteB;
    if (!thresholds.empty() && nonFinite > 0 && !allowNonFinite) {
        v.passed = false;
        v.lines.push_back("non-finite pixels: FAIL (A: " + std::to_string(m.nonFiniteA) +
                          ", B: " + std::to_string(m.nonFiniteB) + ")");
        v.failures.push_back(std::to_string(m.nonFiniteA) + " non-finite pixels in A and " +
                             std::to_string(m.nonFiniteB) +
                             " in B (--allow-nonfinite judges the finite ones alone)");
    }
    for (const Threshold& t : thresholds) {
        const bool ok = meetsThreshold(m, t);
        const bool lowerBound = isLowerBound(t.metric);
        const double x = metricValue(m, t.metric);
        v.passed = v.passed && ok;
        v.json.push_back({{"metric", t.metric},
                          {"bound", t.bound},
                          {"kind", lowerBound ? "min" : "max"},
                          {"value", std::isfinite(x) ? nlohmann::json(x) : nlohmann::json()},
                          {"passed", ok}});
        const std::string bound = formatValue(t.bound), value = formatValue(x);
        v.lines.push_back("threshold " + t.metric + (lowerBound ? " >= " : " <= ") + bound + ": " +
                          (ok ? "pass" : "FAIL") + " (" + value + ")");
        if (!ok)
            v.failures.push_back(t.metric + " = " + value +
                                 (lowerBound ? " is below the bound " : " exceeds the bound ") +
                                 bound);
    }
    return v;
}

void printReport(const CompareOptions& o, const ImageMetrics& m, const HeatmapInfo& heat,
                 const Verdicts& v) {
    if (o.json) {
        nlohmann::json out = toJson(m);
        out["a"] = o.files[0];
        out["b"] = o.files[1];
        out["thresholds"] = v.json;
        out["passed"] = v.passed;
        if (!o.heatmapPath.empty())
            out["heatmap"] = {{"path", o.heatmapPath},
                              {"error_low", heat.low},
                              {"error_high", heat.high},
                              {"scale", "log10"}};
        std::printf("%s\n", out.dump(2).c_str());
    } else {
        printTable(o.files[0], o.files[1], m);
        if (!o.heatmapPath.empty())
            std::printf("\nheatmap        %s (relative error, log10 bar from %s to %s)\n",
                        o.heatmapPath.c_str(), formatValue(heat.low).c_str(),
                        formatValue(heat.high).c_str());
        if (!v.lines.empty()) std::printf("\n");
        for (const std::string& l : v.lines)
            std::printf("%s\n", l.c_str());
    }
    std::fflush(stdout);
}

// A failure to write an output (the heatmap): a runtime failure, exit 1, as render's are;
// unreadable or mismatched inputs are bad input, exit 2.
struct OutputFailure : std::runtime_error {
    using std::runtime_error::runtime_error;
};

template <class Step> void outputStep(Step step) {
    try {
        step();
    } catch (const std::exception& e) {
        throw OutputFailure(e.what());
    }
}

int runCompare(const std::vector<std::string>& args) {
    const CompareOptions o = parseCompareOptions(args);
    if (o.help) {
        std::fputs(compareUsage(), stdout);
        return 0;
    }
    // The heatmap's folder is checked before the images are read, as render checks its outputs.
    if (!o.heatmapPath.empty()) outputStep([&] { checkWritable(o.heatmapPath); });
    const ImageRGB a = readInput(o.files[0], o.layer);
    const ImageRGB b = readInput(o.files[1], o.layer);
    if (a.width != b.width || a.height != b.height)
        throw std::runtime_error("image sizes differ: '" + o.files[0] + "' is " +
                                 std::to_string(a.width) + "x" + std::to_string(a.height) + ", '" +
                                 o.files[1] + "' is " + std::to_string(b.width) + "x" +
                                 std::to_string(b.height));
    const ImageMetrics m = compareImages(a, b);
    HeatmapInfo heat;
    if (!o.heatmapPath.empty()) outputStep([&] { heat = writeHeatmap(o.heatmapPath, a, b); });
    const Verdicts v = judge(m, o.thresholds, o.allowNonFinite);
    printReport(o, m, heat, v);
    if (m.comparedPixels == 0)
        std::fprintf(stderr, "spillway compare: warning: no pixel is finite in both images\n");
    for (const std::string& f : v.failures)
        std::fprintf(stderr, "spillway compare: %s\n", f.c_str());
    return v.passed ? 0 : 1;
}

} // namespace

const char* compareUsage() {
    return R"(usage: spillway compare A B [--json] [--heatmap FILE.png] [--threshold METRIC=V]...
                        [--layer NAME]

Compares image A against the reference B (EXR or PNG, same size) over the pixels finite in
both: mse, rmse, relmse (mean (a-b)^2/(b^2+0.01)), mae, maxabs, psnr (peak 1.0, linear),
per-channel means and the count of non-finite pixels in each.

  --json                  print the metrics as JSON instead of a table
  --heatmap FILE.png      write the per-pixel relative error as a false-colour picture
  --threshold METRIC=V    fail (exit 1) when METRIC exceeds V; psnr fails when below V.
                          METRIC: mse, rmse, relmse, mae, maxabs, psnr. May be repeated.
                          A non-finite pixel in A or B fails every threshold.
  --allow-nonfinite       let thresholds judge the finite pixels alone
  --layer NAME            compare a render pass of two EXRs instead of their image: its R, G,
                          B or X, Y, Z channels ("Denoising Albedo", "Normal"; also under a
                          view layer's name, as Blender writes them: "ViewLayer.Normal.X")

exit status: 0 within bounds, 1 a bound exceeded or the heatmap not written (disk), 2 bad
usage or unreadable input
)";
}

int compareCommand(const std::vector<std::string>& args) {
    try {
        return runCompare(args);
    } catch (const UsageError& e) {
        std::fflush(stdout);
        std::fprintf(stderr, "spillway compare: %s\n(try spillway compare --help)\n", e.what());
    } catch (const OutputFailure& e) {
        std::fflush(stdout);
        std::fprintf(stderr, "spillway: error: %s\n", e.what());
        return 1;
    } catch (const std::exception& e) {
        std::fflush(stdout);
        std::fprintf(stderr, "spillway compare: %s\n", e.what());
    }
    return 2;
}

} // namespace spw
