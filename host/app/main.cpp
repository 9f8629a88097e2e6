// The spillway command line. Exit status: 0 success, 1 runtime failure (disk, device),
// 2 bad input (usage or scene error).
#include "host/app/compare_command.h"
#include "host/app/error_csv.h"
#include "host/app/interrupt.h"
#include "host/app/preview.h"
#include "host/app/progress.h"
#include "host/app/usage_error.h"
#include "host/image/image_io.h"
#include "host/image/output_file.h"
#include "host/render/render.h"
#include "host/scene/scene.h"
#include "host/vk/context.h"

#include <tbb/info.h>

#include <cctype>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <iostream>
#include <string>
#include <thread>
#include <unistd.h>
#include <vector>

#ifndef SPILLWAY_VERSION
#define SPILLWAY_VERSION "0.0.0"
#endif

namespace {

using spw::UsageError;

const char* kUsage = R"(Spillway: a breadth-first, sorted-deferred-shading path tracer.

usage:
  spillway render SCENE [options]   render a scene file (see docs/scene-format.md)
  spillway compare A B [options]    error metrics of image A against reference B
  spillway merge PART... -o IMAGE   add partial renders (--samples A:B --partial PART) that
                                    cover every sample once into the whole render's image,
                                    bit for bit the image one process would have made
  mpirun -np N spillway render SCENE [options]
                                    one render across N MPI ranks (hosts): every rank takes
                                    a share of each iteration's tiles, rank 0 writes the
                                    outputs; the image is the single process's, bit for bit
  spillway devices                  the Vulkan devices, their drivers, and which are usable
  spillway --help                   this text
  spillway --version                the version

render options:
  -o, --output FILE     image to write: .exr (linear float) or .png (8-bit sRGB);
                        default: the scene's name with .exr, in the current folder
  --spp N               total samples per pixel (overrides sample base x iterations)
  --backend NAME        auto (default: a real GPU where one is usable, else cpu), vulkan (the
                        sorted deferred pipeline, shading as Vulkan compute; on a machine
                        without a GPU, lavapipe's software emulation), cpu (the same, shading
                        in C++) or reference (a plain depth-first path tracer on Embree)
  --device N|NAME       the Vulkan device: its index in `spillway devices` or part of its
                        name (default: the first usable one; with auto, a GPU, see
                        `spillway devices`, or the device the Vulkan driver variables name)
  --threads N           worker threads (default: every core)
  --seed S              random seed (overrides settings: seed)
  --sampler TYPE        Independent, Grid, Stratified or Sobol (overrides the scene's sampler)
  --stats FILE.json     write render statistics (rays, stage seconds, ...) as JSON
  --quiet               no progress bar
  --error-csv FILE.csv  after every iteration, a row: seconds, spp, relMSE estimated from
                        two half buffers, and with --reference the compare metrics
  --reference REF.exr   the reference image for --error-csv
  --time-limit SECONDS  stop after the iteration that crosses this render time
  --checkpoint FILE.exr write the render's exact state (an EXR of the image so far, with the
                        film's sums bit for bit in extra channels) at the end, however the
                        render stops, and every --checkpoint-interval SECONDS of rendering
  --resume FILE.exr     continue a checkpointed render (same scene and image settings; more
                        --spp may be asked for) to the image it would have made uninterrupted;
                        checkpoints go back to FILE unless --checkpoint names another
  --samples A:B         a partial render: only sample indices A <= s < B of the --spp N
                        render (A and B on iteration boundaries), written with --partial
  --partial PART.exr    where a partial render's exact sums go, for `spillway merge`
  --target-error E      stop after the first iteration whose relMSE, estimated from two half
                        buffers (the --error-csv estimate), is at or below E
  --adaptive-threshold T  adaptive sampling (settings: adaptive threshold; 0 off, default):
                        8x8 tiles whose relative RMS error, estimated from two half
                        buffers, is below T stop taking samples, once they have
                        --adaptive-min-spp N (settings: adaptive min samples; default 16)
  --preview             a window showing the image as iterations complete (+/- exposure, 0
                        reset; closing it, Esc or q stop the render as Ctrl-C does, but exit
                        0); without a display: exit 2 before rendering
  --progress MODE       auto (default: a bar on a terminal, nothing otherwise), bar, lines (a
                        line per iteration, for logs) or none; --quiet is none
  --texture-cache MiB   the texture system's tile cache (settings: texture cache; default
                        1024): image textures beyond it are read from disk again as needed
  --texture-filter F    cone (default: lookups read the MIP levels each hit's ray-cone
                        footprint needs, trilinear) or finest (always the finest level)

sorted pipeline options (cpu and vulkan backends):
  --bin-exponent E      a directional bin becomes a batch at 2^E rays (settings: bin exponent)
  --memory-budget MiB   RAM for rays waiting in bins and queued batches; the rest spills to
                        disk (settings: memory budget). Peak rays in RAM stay within the
                        budget, or within six batches (2^E rays each) if that is larger;
                        camera rays are made a batch at a time, so they stay under seven
                        batches whatever the budget
  --spill-dir DIR       where spilled batches go (default: the system temp folder)
  --ray-sort MODE       auto (sort only where it measures faster), morton, median or off
  --hit-sort MODE       sort hits by (shader, object, texture order) before shading: auto
                        (default: for vulkan always, for cpu where the scene has image
                        textures), on or off
  --shading MODE        sorted (default: one dispatch per shader range, one kernel per surface
                        model) or megakernel (unsorted hits, one uber-shader switching per hit)
  --ray-format F        compact (34-byte rays, default) or full (50 bytes, every bit kept)
  --stages MODE         fused (default; cpu: hit setup, shade, shadow, accumulate and bin run
                        chunk by chunk of 128 hits, in cache; vulkan: shadow, accumulate and
                        bin, after the device shaded the batch) or separate (each stage over
                        the whole batch in turn)
  --simd-shading on|off cpu: shade Lambert hits 4, 8 or 16 at a time in SIMD registers (default
                        on, where every light is a triangle; the image is the same either way)

Ctrl-C (SIGINT) or SIGTERM stops the render at the next batch boundary, writes the image of
every completed iteration (and --stats, --error-csv) and exits 130 or 143; a second one exits
at once, writing nothing.

exit status: 0 done; 1 runtime failure (disk, device, an output that cannot be written);
2 bad usage or scene error (printed as FILE:LINE: message). On any failure no output file
is written or changed, and no temporary file is left.
)";

long long parseInteger(const std::string& flag, const std::string& v, long long lo, long long hi) {
    size_t used = 0;
    long long n = 0;
    try {
        n = std::stoll(v, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used != v.size() || v.empty())
        throw UsageError(flag + " takes an integer, not '" + v + "'");
    if (n < lo || n > hi)
        throw UsageError(flag + " must be in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                         "]");
    return n;
}

double parseNumber(const std::string& flag, const std::string& v, double lo, double hi) {
    size_t used = 0;
    double x = 0;
    try {
        x = std::stod(v, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used != v.size() || v.empty() || !std::isfinite(x))
        throw UsageError(flag + " takes a number, not '" + v + "'");
    if (x < lo || x > hi)
        throw UsageError(flag + " must be in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                         "]");
    return x;
}

// Parses a named choice with the library's parser, turning its error into a usage error.
template <class Parse> auto choice(const std::string& flag, const std::string& v, Parse parse) {
    try {
        return parse(v);
    } catch (const std::invalid_argument& e) {
        throw UsageError(flag + ": " + e.what());
    }
}

int devicesCommand(const std::vector<std::string>& args) {
    if (!args.empty()) throw UsageError("devices takes no arguments");
    std::vector<spw::vk::DeviceInfo> devices;
    try {
        devices = spw::vk::listDevices();
    } catch (const spw::vk::NoDeviceError& e) {
        std::fprintf(stderr, "spillway: no Vulkan device: %s\n", e.what());
        return 1;
    }
    if (devices.empty()) {
        std::fprintf(stderr,
                     "spillway: no Vulkan device (the loader found drivers but no device)\n");
        return 1;
    }
    for (const spw::vk::DeviceInfo& d : devices)
        std::printf("%u: %s\n   type: %s, Vulkan %s, driver: %s\n   %s\n", d.index, d.name.c_str(),
                    d.type.c_str(), d.api.c_str(), d.driver.c_str(),
                    d.usable ? "usable" : ("unusable: " + d.whyNot).c_str());
    std::printf("--backend auto takes %s\n",
                spw::vk::chooseAutoDevice(devices, spw::vk::driverVariablesSet()).why.c_str());
    return 0;
}

// A distributed render's rank, for the error messages main() prints ("" for one process).
std::string gRankLabel;

// `ranks`: this process's place in a distributed render (mpirun), or nullptr. Every rank renders
// its share; rank 0 alone reads the reference, shows progress and writes every output.
int renderCommand(const std::vector<std::string>& args, spw::Ranks* ranks) {
    const bool writes = !ranks || ranks->rank() == 0;
    std::string scenePath, output, statsPath, errorCsvPath, referencePath, checkpointPath,
        resumePath;
    double checkpointInterval = 0;
    std::optional<spw::SamplerType> samplerOverride;
    std::string partialPath;
    bool quiet = false, previewOn = false;
    std::string progressMode = "auto";
    spw::RenderConfig config;
    config.backend = spw::BackendKind::Auto;
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        auto value = [&]() -> std::string {
            if (i + 1 >= args.size()) throw UsageError(a + " needs a value");
            return args[++i];
        };
        if (a == "-h" || a == "--help") {
            std::fputs(kUsage, stdout);
            return 0;
        }
        if (a == "-o" || a == "--output")
            output = value();
        else if (a == "--spp")
            config.spp = int(parseInteger(a, value(), 1, 1 << 24));
        else if (a == "--backend")
            config.backend = choice(a, value(), spw::parseBackend);
        else if (a == "--device")
            config.vulkan.device = value();
        else if (a == "--shading")
            config.pipeline.shading = choice(a, value(), spw::parseShadingMode);
        else if (a == "--threads")
            config.threads = int(parseInteger(a, value(), 1, 1024));
        else if (a == "--sampler") {
            const std::string v = value();
            samplerOverride = spw::parseSampler(v);
            if (!samplerOverride)
                throw UsageError("--sampler takes Independent, Grid, Stratified or Sobol, not '" +
                                 v + "'");
        } else if (a == "--seed")
            config.seed = std::uint32_t(parseInteger(a, value(), 0, 0xFFFFFFFFLL));
        else if (a == "--stats")
            statsPath = value();
        else if (a == "--preview")
            previewOn = true;
        else if (a == "--checkpoint")
            checkpointPath = value();
        else if (a == "--checkpoint-interval")
            checkpointInterval = parseNumber(a, value(), 1e-3, 1e9);
        else if (a == "--resume")
            resumePath = value();
        else if (a == "--quiet")
            quiet = true;
        else if (a == "--error-csv")
            errorCsvPath = value();
        else if (a == "--reference")
            referencePath = value();
        else if (a == "--time-limit")
            config.timeLimitSeconds = parseNumber(a, value(), 1e-3, 1e9);
        else if (a == "--samples") {
            const std::string v = value();
            const size_t colon = v.find(':');
            if (colon == std::string::npos)
                throw UsageError("--samples takes A:B (sample indices A <= s < B), not '" + v +
                                 "'");
            config.sampleRange =
                std::make_pair(int(parseInteger(a, v.substr(0, colon), 0, 1 << 24)),
                               int(parseInteger(a, v.substr(colon + 1), 0, 1 << 24)));
        } else if (a == "--partial")
            partialPath = value();
        else if (a == "--adaptive-threshold")
            config.adaptiveThreshold = parseNumber(a, value(), 0.0, 1e9);
        else if (a == "--adaptive-min-spp")
            config.adaptiveMinSamples = int(parseInteger(a, value(), 2, 1 << 24));
        else if (a == "--target-error")
            config.targetError = parseNumber(a, value(), 0.0, 1e9);
        else if (a == "--progress") {
            progressMode = value();
            if (progressMode != "auto" && progressMode != "bar" && progressMode != "lines" &&
                progressMode != "none")
                throw UsageError("--progress takes auto, bar, lines or none, not '" + progressMode +
                                 "'");
        } else if (a == "--texture-filter")
            config.textureFilter = choice(a, value(), spw::parseTextureFilter);
        else if (a == "--texture-cache")
            config.textureCacheMiB = parseNumber(a, value(), 1.0, 1 << 20);
        else if (a == "--bin-exponent")
            config.pipeline.binExponent = int(parseInteger(a, value(), 4, 24));
        else if (a == "--memory-budget")
            config.pipeline.memoryBudgetMiB = parseNumber(a, value(), 1.0 / 1024, 1 << 20);
        else if (a == "--spill-dir")
            config.pipeline.spillDir = value();
        else if (a == "--ray-sort")
            config.pipeline.raySort = choice(a, value(), spw::parseRaySortMode);
        else if (a == "--ray-format")
            config.pipeline.rayFormat = choice(a, value(), spw::parseRayFormat);
        else if (a == "--hit-sort") {
            config.pipeline.hitSort = choice(a, value(), spw::parseHitSortMode);
        } else if (a == "--stages") {
            std::string v = value();
            if (v != "fused" && v != "separate")
                throw UsageError("--stages takes fused or separate, not '" + v + "'");
            config.pipeline.fuseStages = v == "fused";
        } else if (a == "--simd-shading") {
            std::string v = value();
            if (v != "on" && v != "off")
                throw UsageError("--simd-shading takes on or off, not '" + v + "'");
            config.pipeline.simdShading = v == "on";
        } else if (!a.empty() && a[0] == '-')
            throw UsageError("unknown option '" + a + "'");
        else if (scenePath.empty())
            scenePath = a;
        else
            throw UsageError("more than one scene given ('" + scenePath + "', '" + a + "')");
    }
    if (scenePath.empty()) throw UsageError("render needs a scene file");
    if (output.empty()) output = std::filesystem::path(scenePath).stem().string() + ".exr";
    if (!spw::isSupportedOutput(output))
        throw UsageError("output '" + output + "' must end in .exr or .png");
    if (!referencePath.empty() && errorCsvPath.empty())
        throw UsageError("--reference goes with --error-csv");
    // Every output path is checked before any work, so that a typo costs no render.
    if (!partialPath.empty() && !config.sampleRange)
        throw UsageError("--partial goes with --samples A:B");
    if (config.sampleRange && partialPath.empty())
        throw UsageError("--samples A:B goes with --partial PART.exr, where its sums go");
    if (!partialPath.empty()) {
        if (!checkpointPath.empty())
            throw UsageError("--partial is the render's checkpoint: give it or --checkpoint");
        checkpointPath = partialPath; // a partial is the checkpoint of its samples
    }
    if (!resumePath.empty() && checkpointPath.empty()) checkpointPath = resumePath;
    if (checkpointInterval > 0 && checkpointPath.empty())
        throw UsageError("--checkpoint-interval goes with --checkpoint");
    if (!checkpointPath.empty()) {
        std::string ext = std::filesystem::path(checkpointPath).extension().string();
        for (char& c : ext)
            c = char(std::tolower(static_cast<unsigned char>(c)));
        if (ext != ".exr") throw UsageError("checkpoint '" + checkpointPath + "' must end in .exr");
    }
    for (const std::string* path : {&output, &statsPath, &errorCsvPath, &checkpointPath})
        if (!path->empty() && writes) spw::checkWritable(*path);
    if (ranks && previewOn && writes)
        std::fprintf(stderr, "spillway: --preview shows rank 0's film, which holds every "
                             "rank's samples after each iteration\n");
    if (!writes) {
        // The outputs are rank 0's: the others only render.
        previewOn = false;
        errorCsvPath.clear();
        referencePath.clear();
        progressMode = "none";
    }
    // Ranks sharing a host share its cores, unless --threads says otherwise; where mpirun bound
    // a rank to fewer cores than its share (one core each, its default for two ranks), those.
    if (ranks && config.threads == 0 && ranks->ranksOnHost() > 1)
        config.threads =
            std::max(1, std::min(tbb::info::default_concurrency(),
                                 int(std::thread::hardware_concurrency()) / ranks->ranksOnHost()));
    std::optional<spw::Checkpoint> resume;
    if (!resumePath.empty()) {
        try {
            resume = spw::readCheckpoint(resumePath);
        } catch (const std::exception& e) {
            throw UsageError(std::string("--resume: ") + e.what());
        }
    }

    spw::Scene scene = spw::loadScene(scenePath);
    if (samplerOverride) scene.sampler = *samplerOverride;
    for (const spw::Mesh& m : scene.meshes)
        if (m.droppedTriangles > 0 && writes)
            std::fprintf(stderr, "spillway: warning: %s: dropped %d zero-area triangle%s\n",
                         m.name.c_str(), m.droppedTriangles, m.droppedTriangles == 1 ? "" : "s");

    std::optional<spw::ImageRGB> reference;
    if (!referencePath.empty()) {
        try {
            reference = spw::readImage(referencePath);
        } catch (const std::exception& e) {
            throw UsageError(e.what());
        }
        if (reference->width != scene.image.width || reference->height != scene.image.height)
            throw UsageError(
                "reference '" + referencePath + "' is " + std::to_string(reference->width) + "x" +
                std::to_string(reference->height) + ", the scene renders " +
                std::to_string(scene.image.width) + "x" + std::to_string(scene.image.height));
    }
    std::unique_ptr<spw::ErrorCsv> errorCsv;
    if (!errorCsvPath.empty())
        errorCsv = std::make_unique<spw::ErrorCsv>(errorCsvPath, std::move(reference));

    if (quiet) progressMode = "none";
    if (progressMode == "auto") progressMode = isatty(STDERR_FILENO) ? "bar" : "none";
    // Under mpirun at most four updates a second (progress.h says why).
    spw::ProgressBar progress(progressMode == "none"  ? spw::ProgressBar::Style::None
                              : progressMode == "bar" ? spw::ProgressBar::Style::Bar
                                                      : spw::ProgressBar::Style::Lines,
                              ranks ? 0.25 : 0.0);
    const spw::SamplingPlan plan = spw::planSampling(scene.image, config.spp);
    const int sppPerIteration = plan.sampleBase * plan.sampleBase;
    if (const std::string why = spw::partialRenderProblem(scene, config, plan); !why.empty())
        throw UsageError(why); // before any work, for exit 2
    spw::InterruptGuard interrupt;
    config.stop = interrupt.flag();
    spw::CheckpointOptions checkpoints{checkpointPath, checkpointInterval,
                                       resume ? &*resume : nullptr, std::nullopt};
    if (!checkpointPath.empty()) {
        // Checked here, before any work, for exit 2; the render reuses the key.
        checkpoints.key = spw::checkpointKey(scene, config, plan.sampleBase);
        const std::string why =
            resume ? spw::checkpointMismatch(*checkpoints.key, resume->key) : "";
        if (!why.empty())
            throw UsageError("--resume " + resumePath +
                             ": the checkpoint is of another render: " + why);
    }
    std::unique_ptr<spw::PreviewWindow> preview;
    if (previewOn) {
        try {
            preview = std::make_unique<spw::PreviewWindow>(
                scene.image.width, scene.image.height,
                "Spillway: " + std::filesystem::path(scenePath).filename().string());
        } catch (const std::runtime_error& e) {
            throw UsageError(e.what()); // no display: said before any work, exit 2
        }
    }
    auto onIteration = [&](const spw::IterationInfo& info, const spw::Film& film) {
        if (errorCsv) errorCsv->addRow(info.done, info.spp, info.renderSeconds, film);
        if (progressMode == "none" && !preview) return;
        const std::optional<double> relMse = film.halfBufferRelMseEstimate(); // O(pixels)
        progress.update(info.done, info.total, info.spp, info.total * sppPerIteration, relMse);
        if (preview) {
            char status[96];
            std::snprintf(status, sizeof status, "%d/%d spp, %.1f s, relMSE %s", info.spp,
                          info.total * sppPerIteration, info.renderSeconds,
                          relMse ? std::to_string(*relMse).c_str() : "-");
            preview->publish(film.image(), status);
        }
    };
    std::unique_ptr<spw::RenderResult> result;
    if (!preview) {
        result = spw::renderWithProgress(scene, config, onIteration, checkpoints, ranks);
    } else {
        // The window on this thread (GLFW's rule), the render on its own.
        std::exception_ptr failure;
        std::atomic<bool> finished{false};
        std::thread worker([&] {
            try {
                result = spw::renderWithProgress(scene, config, onIteration, checkpoints, ranks);
            } catch (...) {
                failure = std::current_exception();
            }
            finished = true;
            preview->wake();
        });
        while (!finished)
            if (!preview->pump(0.1)) interrupt.requestStop(spw::kStopByWindow);
        worker.join();
        preview.reset();
        if (failure) std::rethrow_exception(failure);
    }
    progress.finish();
    // Closing the preview window is a normal way to end a render: exit 0.
    const int signal = std::max(0, interrupt.signal());
    if (!writes) return signal != 0 ? 128 + signal : 0;
    if (interrupt.signal() != 0 && result->stats.iterations == 0) {
        std::fprintf(stderr, "spillway: stopped before an iteration completed; nothing written\n");
        return signal != 0 ? 128 + signal : 0;
    }
    if (signal != 0)
        std::fprintf(stderr, "spillway: stopped by signal %d after %d spp; writing them\n", signal,
                     result->stats.spp);

    // Every output is written whole, and flushed, before any is given its name: a failure in
    // any of them leaves none (host/image/output_file.h).
    spw::OutputFile image(output);
    {
        spw::StageTimer t(result->stats.stages, "write image");
        const std::vector<unsigned char> bytes = spw::encodeImage(
            output, {scene.image.width, scene.image.height, result->film->image()});
        image.write(bytes.data(), bytes.size());
        image.flush();
    }
    std::unique_ptr<spw::OutputFile> stats;
    if (!statsPath.empty()) {
        stats = std::make_unique<spw::OutputFile>(statsPath);
        stats->write(result->stats.toJson().dump(2) + "\n");
        stats->flush();
    }
    if (errorCsv) errorCsv->flush();
    if (result->stats.nonFiniteSamples > 0)
        std::fprintf(stderr, "spillway: warning: %llu non-finite samples were dropped\n",
                     (unsigned long long)result->stats.nonFiniteSamples);
    if (result->stats.saturatedSamples > 0)
        std::fprintf(
            stderr,
            "spillway: warning: %llu sample values exceeded the film's range (at least 2^16 times "
            "the "
            "brightest emitter) and were clamped: the image is darker than it should be where they "
            "landed\n",
            (unsigned long long)result->stats.saturatedSamples);
    image.commit();
    if (stats) stats->commit();
    if (errorCsv) errorCsv->commit();
    return signal != 0 ? 128 + signal : 0;
}

} // namespace

// spillway merge PART... -o IMAGE: partial renders' sums added into the whole render's image.
int mergeCommand(const std::vector<std::string>& args) {
    std::string output;
    std::vector<std::string> parts;
    for (size_t i = 0; i < args.size(); ++i) {
        if (args[i] == "-o" || args[i] == "--output") {
            if (i + 1 >= args.size()) throw UsageError(args[i] + " needs a value");
            output = args[++i];
        } else if (!args[i].empty() && args[i][0] == '-') {
            throw UsageError("unknown merge option '" + args[i] + "'");
        } else {
            parts.push_back(args[i]);
        }
    }
    if (parts.empty()) throw UsageError("merge needs partial renders (render --partial)");
    if (output.empty()) throw UsageError("merge needs -o IMAGE");
    if (!spw::isSupportedOutput(output))
        throw UsageError("output '" + output + "' must end in .exr or .png");
    spw::checkWritable(output);
    std::vector<std::pair<std::string, spw::Checkpoint>> partials;
    for (const std::string& p : parts) {
        try {
            partials.emplace_back(p, spw::readCheckpoint(p));
        } catch (const std::exception& e) {
            throw UsageError(std::string("merge: ") + e.what());
        }
    }
    spw::Checkpoint whole;
    try {
        whole = spw::mergePartials(partials);
    } catch (const std::invalid_argument& e) {
        throw UsageError(std::string("merge: ") + e.what());
    }
    spw::OutputFile image(output);
    const std::vector<unsigned char> bytes = spw::encodeImage(
        output, {whole.key.width, whole.key.height, spw::Film::imageOf(whole.film)});
    image.write(bytes.data(), bytes.size());
    image.flush();
    image.commit();
    std::fprintf(stderr, "spillway: merged %zu partial renders: %d spp\n", partials.size(),
                 whole.iterations * whole.key.sampleBase * whole.key.sampleBase);
    return 0;
}

int main(int argc, char** argv) {
    // A file-size limit must surface as a write error (EFBIG) with a message, not kill us.
    std::signal(SIGXFSZ, SIG_IGN);
    std::vector<std::string> args(argv + 1, argv + argc);
    try {
        if (args.empty()) {
            std::fputs(kUsage, stderr);
            return 2;
        }
        if (args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
            std::fputs(kUsage, stdout);
            return 0;
        }
        if (args[0] == "--version") {
            std::printf("spillway %s\n", SPILLWAY_VERSION);
            return 0;
        }
        if (args[0] == "render") {
            // Started by mpirun as several ranks: one distributed render (host/render/ranks.h).
            std::unique_ptr<spw::Ranks> ranks = spw::joinMpiWorld();
            if (ranks)
                gRankLabel = "rank " + std::to_string(ranks->rank()) + " of " +
                             std::to_string(ranks->size()) + ": ";
            try {
                return renderCommand({args.begin() + 1, args.end()}, ranks.get());
            } catch (...) {
                if (ranks) ranks->failed(); // the other ranks stop at their next agreement
                throw;
            }
        }
        if (args[0] == "compare") return spw::compareCommand({args.begin() + 1, args.end()});
        if (args[0] == "devices") return devicesCommand({args.begin() + 1, args.end()});
        if (args[0] == "merge") return mergeCommand({args.begin() + 1, args.end()});
        throw UsageError("unknown command '" + args[0] + "' (try spillway --help)");
    } catch (const UsageError& e) {
        std::fprintf(stderr, "spillway: %s%s\n", gRankLabel.c_str(), e.what());
        return 2;
    } catch (const spw::SceneError& e) {
        std::fprintf(stderr, "%s%s\n", gRankLabel.c_str(), e.what());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "spillway: %serror: %s\n", gRankLabel.c_str(), e.what());
        return 1;
    }
}
