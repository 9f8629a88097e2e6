#include "host/app/render_command.h"

#include "host/app/error_csv.h"
#include "host/app/interrupt.h"
#include "host/app/preview.h"
#include "host/app/progress.h"
#include "host/app/render_options.h"
#include "host/app/usage.h"
#include "host/app/usage_error.h"
#include "host/image/image_io.h"
#include "host/image/output_file.h"
#include "host/loaders/scene_loader.h"
#include "host/render/render.h"

#include <tbb/info.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <functional>
#include <thread>
#include <unistd.h>

namespace spw {
namespace {

// A distributed render's outputs are rank 0's: the other ranks only render. Ranks sharing a host
// share its cores, unless --threads says otherwise; where mpirun bound a rank to fewer cores than
// its share (one core each, its default for two ranks), those.
void fitToRank(RenderOptions& o, Ranks* ranks, bool writes) {
    if (ranks && ranks->size() > 1 && o.config.aovs != 0)
        throw UsageError("--aov does not go with more than one MPI rank yet: the ranks do not "
                         "share the passes");
    if (ranks && o.preview && writes)
        std::fprintf(stderr, "spillway: --preview shows rank 0's film, which holds every "
                             "rank's samples after each iteration\n");
    if (!writes) {
        o.preview = false;
        o.errorCsvPath.clear();
        o.errorMapPath.clear();
        o.referencePath.clear();
        o.progress = "none";
    }
    if (ranks && o.config.threads == 0 && ranks->ranksOnHost() > 1)
        o.config.threads =
            std::max(1, std::min(tbb::info::default_concurrency(),
                                 int(std::thread::hardware_concurrency()) / ranks->ranksOnHost()));
}

std::optional<Checkpoint> readResume(const RenderOptions& o) {
    if (o.resumePath.empty()) return std::nullopt;
    try {
        return readCheckpoint(o.resumePath);
    } catch (const std::exception& e) {
        throw UsageError(std::string("--resume: ") + e.what());
    }
}

// A file that carries no sampling setting (glTF), rendered with none on the command line, renders
// progressively, one sample a pixel an iteration, until the error estimate reaches a clean
// image's (a relMSE of 2e-3: about 100 spp of Sobol on the Cornell box) or 1024 spp, and says so.
constexpr double kDefaultTargetError = 2e-3;
constexpr int kDefaultSppCap = 1024;

void applyDefaultSampling(RenderOptions& o, const Scene& scene, bool writes) {
    const RenderConfig& c = o.config;
    if (scene.image.samplingStated || c.spp || c.targetError || c.timeLimitSeconds || c.sampleRange)
        return;
    o.config.spp = kDefaultSppCap;
    o.config.targetError = kDefaultTargetError;
    if (writes)
        std::fprintf(stderr,
                     "spillway: %s carries no sampling setting: rendering until the relMSE "
                     "estimate over the pixels that hold noise reaches %g, at most %d spp "
                     "(--spp, --target-error or --time-limit choose)\n",
                     scene.file.c_str(), kDefaultTargetError, kDefaultSppCap);
}

Scene loadForRender(const RenderOptions& o, bool writes) {
    Scene scene = loadScene(o.scenePath);
    applyOverrides(o, scene);
    for (const std::string& w : scene.warnings)
        if (writes) std::fprintf(stderr, "spillway: warning: %s\n", w.c_str());
    // Zero-area triangles, said once for the whole scene (a CAD file drops some in most meshes).
    long long dropped = 0;
    int meshes = 0;
    const Mesh* first = nullptr;
    for (const Mesh& m : scene.meshes)
        if (m.droppedTriangles > 0) {
            dropped += m.droppedTriangles, ++meshes;
            if (!first) first = &m;
        }
    if (first && writes) {
        const char* plural = dropped == 1 ? "" : "s";
        if (meshes == 1)
            std::fprintf(stderr, "spillway: warning: %s: dropped %lld zero-area triangle%s\n",
                         first->name.c_str(), dropped, plural);
        else
            std::fprintf(stderr,
                         "spillway: warning: dropped %lld zero-area triangle%s in %d meshes (the "
                         "first: %s)\n",
                         dropped, plural, meshes, first->name.c_str());
    }
    return scene;
}

std::unique_ptr<ErrorCsv> openErrorCsv(const RenderOptions& o, const Scene& scene,
                                       const std::optional<Checkpoint>& resume) {
    if (o.errorCsvPath.empty()) return nullptr;
    std::optional<ImageRGB> reference;
    if (!o.referencePath.empty()) {
        try {
            reference = readImage(o.referencePath);
        } catch (const std::exception& e) {
            throw UsageError(e.what());
        }
        if (reference->width != scene.image.width || reference->height != scene.image.height)
            throw UsageError(
                "reference '" + o.referencePath + "' is " + std::to_string(reference->width) + "x" +
                std::to_string(reference->height) + ", the scene renders " +
                std::to_string(scene.image.width) + "x" + std::to_string(scene.image.height));
    }
    std::optional<int> resumed;
    if (resume) resumed = resume->iterations; // the rows count iterations from the range's start
    try {
        return std::make_unique<ErrorCsv>(o.errorCsvPath, std::move(reference), resumed);
    } catch (const std::invalid_argument& e) {
        throw UsageError(e.what());
    }
}

// --progress auto: a bar on a terminal, nothing otherwise.
ProgressBar::Style progressStyle(std::string& mode) {
    if (mode == "auto") mode = isatty(STDERR_FILENO) ? "bar" : "none";
    return mode == "none"  ? ProgressBar::Style::None
           : mode == "bar" ? ProgressBar::Style::Bar
                           : ProgressBar::Style::Lines;
}

// The checkpoint's key is checked here, before any work, for exit 2; the render reuses it.
CheckpointOptions checkpointOptions(const RenderOptions& o, const Scene& scene,
                                    const SamplingPlan& plan,
                                    const std::optional<Checkpoint>& resume) {
    CheckpointOptions checkpoints{o.checkpointPath, o.checkpointInterval,
                                  resume ? &*resume : nullptr, std::nullopt};
    if (o.checkpointPath.empty()) return checkpoints;
    checkpoints.key = checkpointKey(scene, o.config, plan.sampleBase);
    const std::string why =
        resume ? resumeProblem(*checkpoints.key, resume->key, scene.image, o.config.spp) : "";
    if (!why.empty()) throw UsageError("--resume " + o.resumePath + ": " + why);
    return checkpoints;
}

std::unique_ptr<PreviewWindow> openPreview(const RenderOptions& o, const Scene& scene) {
    if (!o.preview) return nullptr;
    try {
        return std::make_unique<PreviewWindow>(
            scene.image.width, scene.image.height,
            "Spillway: " + std::filesystem::path(o.scenePath).filename().string());
    } catch (const std::runtime_error& e) {
        throw UsageError(e.what()); // no display: said before any work, exit 2
    }
}

// The render, with the preview window on this thread (GLFW's rule) and the render on its own.
std::unique_ptr<RenderResult>
renderBesideWindow(PreviewWindow& preview, InterruptGuard& interrupt,
                   const std::function<std::unique_ptr<RenderResult>()>& run) {
    std::unique_ptr<RenderResult> result;
    std::exception_ptr failure;
    std::atomic<bool> finished{false};
    std::thread worker([&] {
        try {
            result = run();
        } catch (...) {
            failure = std::current_exception();
        }
        finished = true;
        preview.wake();
    });
    while (!finished)
        if (!preview.pump(0.1))
            interrupt.requestStop(preview.lost() ? kStopByLostDisplay : kStopByWindow);
    worker.join();
    if (failure) std::rethrow_exception(failure);
    return result;
}

void warnAboutSamples(const RenderStats& stats) {
    if (stats.nonFiniteSamples > 0)
        std::fprintf(stderr, "spillway: warning: %llu non-finite samples were dropped\n",
                     (unsigned long long)stats.nonFiniteSamples);
    if (stats.saturatedSamples > 0)
        std::fprintf(stderr,
                     "spillway: warning: %llu sample values exceeded the film's range (at least "
                     "2^16 times the brightest emitter) and were clamped: the image is darker "
                     "than it should be where they landed\n",
                     (unsigned long long)stats.saturatedSamples);
}

// An --error-csv whose estimate cells stayed empty says why: the estimate compares two half
// buffers, which takes two iterations, and names the reason the render stopped before those.
void explainMissingEstimate(const RenderResult& result) {
    if (result.film->halfBufferRelMseEstimate()) return;
    const auto reason = result.stats.extra.find("stop_reason");
    const std::string why = reason != result.stats.extra.end() ? reason->get<std::string>() : "";
    std::fprintf(stderr,
                 "spillway: --error-csv has no relMSE estimate (its cells are empty): the "
                 "estimate compares two half buffers, which takes 2 iterations, and the render "
                 "stopped after %d (stop reason: %s); ask for more samples than one iteration "
                 "takes (--spp)\n",
                 result.stats.iterations, why.c_str());
}

// The image's R, G and B, then the passes' channels (AovFilm::channelNames).
// Where the peak resident memory went, as far as the parts can say (--stats' `memory`): the
// process at the end of loading (the file, the parser and the scene's arrays), after the BVH,
// at its peak; the scene's own arrays, the lights' records, the texture cache's and the ray
// batches' peaks, the film's fine levels (film_levels.h: held where a contribution was too small
// for its fixed point); and the peak over the stored triangles and the instances.
void reportMemory(RenderStats& stats, const Scene& scene, const Film& film, double loadPeakMiB) {
    auto bytes = [](const auto& v) { return double(v.size() * sizeof(v[0])); };
    double geometry = 0.0, triangles = 0.0;
    for (const Mesh& m : scene.meshes) {
        geometry += bytes(m.positions) + bytes(m.normals) + bytes(m.uvs) + bytes(m.colours) +
                    bytes(m.triangles);
        triangles += double(m.triangles.size());
    }
    const double peak = stats.extra.value("peak_rss_mib", 0.0) * 1048576.0;
    nlohmann::json memory = {
        {"peak_rss_mib", peak / 1048576.0},
        {"after_load_mib", loadPeakMiB},
        {"scene_geometry_bytes", geometry},
        {"instances_bytes", double(scene.instances.size() * sizeof(Instance))},
        {"lights_bytes",
         stats.extra.contains("lights") ? stats.extra["lights"].value("bytes", 0.0) : 0.0},
        {"texture_cache_peak_bytes", stats.textures ? stats.textures->peakCacheBytes : 0},
        {"ray_batches_peak_bytes", stats.spill ? stats.spill->peakRayBytesInRam : 0},
        {"film_fine_levels_bytes", double(film.levelBytes())},
    };
    if (stats.extra.contains("geometry"))
        memory["after_bvh_mib"] = stats.extra["geometry"].value("peak_rss_mib_after_bvh", 0.0);
    if (triangles > 0) memory["peak_bytes_per_triangle_stored"] = peak / triangles;
    if (!scene.instances.empty())
        memory["peak_bytes_per_instance"] = peak / double(scene.instances.size());
    stats.extra["memory"] = memory;
}

void writeImageWithPasses(OutputFile& file, const std::string& path, const Film& film,
                          const AovFilm& aovs) {
    const std::vector<std::string> names = aovs.channelNames();
    const size_t extra = names.size(), channels = 3 + extra;
    std::vector<float> rgb, passes;
    writeImageRows(
        file, path, film.width(), film.height(),
        [&](int y0, int y1, float* out) {
            const size_t pixels = size_t(film.width()) * size_t(y1 - y0);
            rgb.resize(pixels * 3), passes.resize(pixels * extra);
            film.imageRows(y0, y1, rgb.data());
            aovs.rows(y0, y1, passes.data());
            for (size_t i = 0; i < pixels; ++i) {
                std::copy_n(&rgb[i * 3], 3, out + i * channels);
                std::copy_n(&passes[i * extra], extra, out + i * channels + 3);
            }
        },
        names, aovs.layerNotes());
}

// Every output is written whole, and flushed, before any is given its name: a failure in any of
// them leaves none (host/image/output_file.h).
void writeOutputs(const RenderOptions& o, const Scene& scene, RenderResult& result,
                  ErrorCsv* errorCsv) {
    OutputFile image(o.output);
    {
        StageTimer t(result.stats.stages, "write image");
        const Film& film = *result.film;
        if (result.aovs)
            writeImageWithPasses(image, o.output, film, *result.aovs);
        else
            writeImageRows(image, o.output, scene.image.width, scene.image.height,
                           [&](int y0, int y1, float* rgb) { film.imageRows(y0, y1, rgb); });
        image.flush();
    }
    std::unique_ptr<OutputFile> errorMap;
    if (!o.errorMapPath.empty()) {
        errorMap = std::make_unique<OutputFile>(o.errorMapPath);
        const Film& film = *result.film;
        writeImageRows(*errorMap, o.errorMapPath, scene.image.width, scene.image.height,
                       [&](int y0, int y1, float* rgb) { film.errorRows(y0, y1, rgb); });
        errorMap->flush();
    }
    std::unique_ptr<OutputFile> stats;
    if (!o.statsPath.empty()) {
        stats = std::make_unique<OutputFile>(o.statsPath);
        stats->write(result.stats.toJson().dump(2) + "\n");
        stats->flush();
    }
    if (errorCsv) errorCsv->flush();
    warnAboutSamples(result.stats);
    image.commit();
    if (errorMap) errorMap->commit();
    if (stats) stats->commit();
    if (errorCsv) errorCsv->commit();
}

} // namespace

int renderCommand(const std::vector<std::string>& args, Ranks* ranks) {
    RenderOptions o = parseRenderOptions(args);
    if (o.help) {
        std::fputs(usageText().c_str(), stdout);
        return 0;
    }
    const bool writes = !ranks || ranks->rank() == 0;
    // Every output path is checked before any work, so that a typo costs no render.
    for (const std::string* path :
         {&o.output, &o.statsPath, &o.errorCsvPath, &o.errorMapPath, &o.checkpointPath})
        if (!path->empty() && writes) checkWritable(*path);
    fitToRank(o, ranks, writes);
    const std::optional<Checkpoint> resume = readResume(o);
    const auto loadStart = std::chrono::steady_clock::now();
    const Scene scene = loadForRender(o, writes);
    const double loadSeconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - loadStart).count();
    const double loadPeakMiB = peakResidentMiB();
    applyDefaultSampling(o, scene, writes);
    if (!o.config.adaptiveToTarget && !o.config.targetError)
        throw UsageError("--uniform goes with --target-error (or a glTF file's default target): "
                         "without a target every pixel takes every sample already");
    const std::unique_ptr<ErrorCsv> errorCsv = openErrorCsv(o, scene, resume);
    // Under mpirun at most four updates a second (progress.h says why).
    ProgressBar progress(progressStyle(o.progress), ranks ? 0.25 : 0.0);
    const SamplingPlan plan =
        planSampling(scene.image, o.config.spp, resume ? resume->key.sampleBase : 0);
    const int sppPerIteration = plan.sampleBase * plan.sampleBase;
    if (const std::string why = partialRenderProblem(scene, o.config, plan); !why.empty())
        throw UsageError(why); // before any work, for exit 2
    InterruptGuard interrupt;
    o.config.stop = interrupt.flag();
    const CheckpointOptions checkpoints = checkpointOptions(o, scene, plan, resume);
    std::unique_ptr<PreviewWindow> preview = openPreview(o, scene);

    auto onIteration = [&](const IterationInfo& info, const Film& film) {
        if (errorCsv) errorCsv->addRow(info.done, info.spp, info.renderSeconds, film);
        if (o.progress == "none" && !preview) return;
        // What the stop judges (the pixels that hold noise); O(pixels).
        const std::optional<double> relMse = film.subjectRelMseEstimate();
        progress.update(info.done, info.total, info.spp, info.total * sppPerIteration, relMse);
        if (preview) {
            char status[96];
            std::snprintf(status, sizeof status, "%d/%d spp, %.1f s, relMSE %s", info.spp,
                          info.total * sppPerIteration, info.renderSeconds,
                          relMse ? std::to_string(*relMse).c_str() : "-");
            preview->publish(film.image(), status);
        }
    };
    auto run = [&] { return renderWithProgress(scene, o.config, onIteration, checkpoints, ranks); };
    std::unique_ptr<RenderResult> result =
        preview ? renderBesideWindow(*preview, interrupt, run) : run();
    preview.reset();
    progress.finish();

    // Closing the preview window is a normal way to end a render: exit 0. Losing its display is
    // the session going away, as SIGHUP is: 129.
    const bool displayLost = interrupt.signal() == kStopByLostDisplay;
    const int signal = displayLost ? SIGHUP : std::max(0, interrupt.signal());
    const int status = signal != 0 ? 128 + signal : 0;
    if (!writes) return status;
    if (interrupt.signal() != 0 && result->stats.iterations == 0) {
        std::fprintf(stderr, "spillway: stopped before an iteration completed; nothing written\n");
        return status;
    }
    if (displayLost)
        std::fprintf(stderr,
                     "spillway: the preview's display went away after %d spp; writing them\n",
                     result->stats.spp);
    else if (signal != 0)
        std::fprintf(stderr, "spillway: stopped by signal %d after %d spp; writing them\n", signal,
                     result->stats.spp);
    if (errorCsv) explainMissingEstimate(*result);
    result->stats.stages.add("load scene", loadSeconds);
    result->stats.extra["peak_rss_mib_after_load"] = loadPeakMiB;
    reportMemory(result->stats, scene, *result->film, loadPeakMiB);
    writeOutputs(o, scene, *result, errorCsv.get());
    return status;
}

} // namespace spw
