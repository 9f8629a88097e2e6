#include "host/render/render.h"

#include "embree_backend/embree_scene.h"
#include "embree_backend/reference_renderer.h"
#include "host/backend/backend.h"
#include "host/pipeline/cpu_shading.h"
#include "host/pipeline/sorted_renderer.h"
#include "host/scene/camera.h"
#include "host/scene/textures.h"
#include "host/vk/context.h"
#include "host/vk/vulkan_shading.h"

#include <tbb/global_control.h>
#include <tbb/info.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <stdexcept>

namespace spw {
namespace {

std::string cpuName() {
    std::ifstream in("/proc/cpuinfo");
    std::string line;
    while (std::getline(in, line))
        if (line.rfind("model name", 0) == 0) {
            auto p = line.find(':');
            if (p != std::string::npos) return line.substr(line.find_first_not_of(" \t", p + 1));
        }
    return "unknown CPU";
}

// --stats' `textures`: the texture system's counters, and the traffic per traced ray.
nlohmann::json textureStatistics(const TextureResolver& textures, const RenderStats& stats) {
    const TextureStatistics t = textures.statistics();
    const double rays = double(stats.cameraRays + stats.bounceRays + stats.shadowRays);
    auto perRay = [&](std::uint64_t n) { return rays > 0 ? double(n) / rays : 0.0; };
    return {{"lookups", t.lookups},
            {"tiles_read", t.tilesRead},
            {"bytes_read", t.bytesRead},
            {"files_opened", t.filesOpened},
            {"files_reopened", t.filesReopened},
            {"cache_misses", t.cacheMisses},
            {"peak_cache_bytes", t.peakCacheBytes},
            {"per_ray",
             {{"lookups", perRay(t.lookups)},
              {"tiles_read", perRay(t.tilesRead)},
              {"bytes_read", perRay(t.bytesRead)}}}};
}

// --stats of a distributed render, on rank 0: every rank's own stats (`all`, JSON in rank
// order) as `ranks`, and the traffic (rays, spill, textures) summed over them.
void addRanksToStats(const std::vector<std::string>& all, RenderStats& stats) {
    nlohmann::json perRank = nlohmann::json::array();
    std::uint64_t rays[3] = {0, 0, 0};
    nlohmann::json totals = nlohmann::json::object();
    const char* summed[] = {"batches_processed", "batches_queued", "batches_spilled",
                            "bytes_spilled_written", "bytes_spilled_read"};
    for (size_t r = 0; r < all.size(); ++r) {
        const nlohmann::json j = nlohmann::json::parse(all[r]);
        nlohmann::json entry = {{"rank", r},
                                {"host", j.value("host", "")},
                                {"threads", j["threads"]},
                                {"wall_seconds", j["wall_seconds"]},
                                {"render_seconds", j["render_seconds"]},
                                {"reduce_seconds", j["stage_seconds"].value("reduce", 0.0)},
                                {"agree_seconds", j["stage_seconds"].value("agree", 0.0)},
                                {"rays", j["rays"]}};
        rays[0] += j["rays"]["camera"].get<std::uint64_t>();
        rays[1] += j["rays"]["bounce"].get<std::uint64_t>();
        rays[2] += j["rays"]["shadow"].get<std::uint64_t>();
        for (const char* key : summed)
            if (j.contains(key)) {
                entry[key] = j[key];
                totals[key] = totals.value(key, std::uint64_t(0)) + j[key].get<std::uint64_t>();
            }
        if (j.contains("peak_ray_bytes_in_ram"))
            entry["peak_ray_bytes_in_ram"] = j["peak_ray_bytes_in_ram"];
        if (j.contains("textures")) {
            entry["textures"] = j["textures"];
            // The counters summed; the cache's peak is the largest rank's.
            if (!totals.contains("textures")) totals["textures"] = nlohmann::json::object();
            nlohmann::json& t = totals["textures"];
            for (const char* key : {"lookups", "tiles_read", "bytes_read", "files_opened",
                                    "files_reopened", "cache_misses"})
                t[key] = t.value(key, std::uint64_t(0)) + j["textures"][key].get<std::uint64_t>();
            t["peak_cache_bytes"] =
                std::max(t.value("peak_cache_bytes", std::uint64_t(0)),
                         j["textures"]["peak_cache_bytes"].get<std::uint64_t>());
        }
        perRank.push_back(entry);
    }
    stats.cameraRays = rays[0];
    stats.bounceRays = rays[1];
    stats.shadowRays = rays[2];
    if (totals.contains("textures")) {
        nlohmann::json& t = totals["textures"];
        const double all = double(rays[0] + rays[1] + rays[2]);
        for (const char* key : {"lookups", "tiles_read", "bytes_read"})
            t["per_ray"][key] = all > 0 ? t[key].get<double>() / all : 0.0;
    }
    for (auto it = totals.begin(); it != totals.end(); ++it)
        stats.extra[it.key()] = it.value();
    stats.extra["ranks"] = perRank;
}

std::unique_ptr<RenderResult> renderOnRanks(const Scene& scene, const RenderConfig& config,
                                            const ProgressCallback& onIteration,
                                            const CheckpointOptions& checkpoints, Ranks* ranks);

} // namespace

std::string partialRenderProblem(const Scene& scene, const RenderConfig& config,
                                 const SamplingPlan& plan) {
    if (!config.sampleRange) return "";
    const auto [a, b] = *config.sampleRange;
    const int spi = plan.sampleBase * plan.sampleBase, total = spi * plan.iterations;
    const std::string range = "--samples " + std::to_string(a) + ":" + std::to_string(b) + ": ";
    if (!(a >= 0 && a < b && b <= total))
        return range + "a range A:B needs 0 <= A < B <= " + std::to_string(total) +
               " (the render's spp)";
    if (a % spi != 0 || b % spi != 0)
        return range + "a range starts and ends on an iteration boundary, a multiple of " +
               std::to_string(spi) + " samples (0, " + std::to_string(spi) + ", " +
               std::to_string(2 * spi) + ", ... " + std::to_string(total) + ")";
    if (config.adaptiveThreshold.value_or(scene.settings.adaptiveThreshold) > 0.0)
        return range + "a partial render cannot sample adaptively (its decisions read the "
                       "iterations before it)";
    return "";
}

SamplingPlan planSampling(const ImageSettings& image, std::optional<int> spp) {
    if (!spp) return {image.sampleBase, image.iterations};
    const int n2 = image.samplesPerIteration();
    // Keep the scene's n x n pattern when it divides the request; otherwise one sample per pass.
    if (*spp % n2 == 0) return {image.sampleBase, *spp / n2};
    return {1, *spp};
}

std::unique_ptr<RenderResult> render(const Scene& scene, const RenderConfig& config,
                                     const IterationCallback& onIteration) {
    return renderWithProgress(scene, config, [&](const IterationInfo& info, const Film& film) {
        if (onIteration) onIteration(info.done, info.total, film);
    });
}

std::unique_ptr<RenderResult> renderWithProgress(const Scene& scene, const RenderConfig& config,
                                                 const ProgressCallback& onIteration,
                                                 const CheckpointOptions& checkpoints,
                                                 Ranks* ranks) {
    try {
        return renderOnRanks(scene, config, onIteration, checkpoints, ranks);
    } catch (...) {
        if (ranks) ranks->failed(); // the others learn it at their next agreement
        throw;
    }
}

namespace {

std::unique_ptr<RenderResult> renderOnRanks(const Scene& scene, const RenderConfig& config,
                                            const ProgressCallback& onIteration,
                                            const CheckpointOptions& checkpoints, Ranks* ranks) {
    if (config.pipeline.rayFormat == RayFormat::Compact &&
        scene.settings.maxDepth > int(kMaxCompactBounce))
        throw std::invalid_argument("max depth " + std::to_string(scene.settings.maxDepth) +
                                    " exceeds the compact ray's " +
                                    std::to_string(kMaxCompactBounce) + " bounces");
    const auto start = std::chrono::steady_clock::now();
    const int threads = config.threads > 0 ? config.threads : tbb::info::default_concurrency();
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));

    auto result = std::make_unique<RenderResult>();
    RenderStats& stats = result->stats;
    const SamplingPlan plan = planSampling(scene.image, config.spp);
    stats.backend = backendName(config.backend);
    stats.device = cpuName();

    // Vulkan only when asked for (vulkan, or auto): never for cpu or reference. `auto` takes a
    // real GPU, or the device --device names, or lavapipe when the driver variables ask for it
    // (vk::chooseAutoDevice), and otherwise renders on cpu; --stats says why (backend_auto).
    std::unique_ptr<vk::Context> vulkan;
    if (config.backend == BackendKind::Vulkan || config.backend == BackendKind::Auto) {
        StageTimer t(stats.stages, "vulkan init");
        VulkanConfig vkConfig = config.vulkan;
        bool wanted = config.backend == BackendKind::Vulkan || !vkConfig.device.empty();
        try {
            if (!wanted) {
                const vk::AutoChoice choice =
                    vk::chooseAutoDevice(vk::listDevices(), vk::driverVariablesSet());
                stats.extra["backend_auto"] = choice.why;
                stats.backend = "cpu";
                if (choice.device >= 0) {
                    vkConfig.device = std::to_string(choice.device);
                    wanted = true;
                }
            }
            if (wanted) {
                vulkan = std::make_unique<vk::Context>(vkConfig);
                stats.backend = "vulkan";
                stats.device = vulkan->info().name;
            }
        } catch (const vk::NoDeviceError& e) {
            if (config.backend == BackendKind::Vulkan)
                throw std::runtime_error(std::string("--backend vulkan: ") + e.what());
            // The user asked for Vulkan (--device, or the driver variables) and has none.
            if (wanted || vk::driverVariablesSet())
                std::fprintf(stderr, "spillway: no Vulkan device; rendering on cpu\n");
            stats.backend = "cpu";
            stats.extra["backend_fallback"] = e.what();
        }
    }
    stats.width = scene.image.width;
    stats.height = scene.image.height;
    stats.spp = plan.sampleBase * plan.sampleBase * plan.iterations;
    stats.iterations = plan.iterations;
    stats.threads = threads;

    const SceneLights lights(scene);
    std::unique_ptr<EmbreeScene> embree;
    {
        StageTimer t(stats.stages, "build bvh");
        embree = std::make_unique<EmbreeScene>(scene, lights);
    }
    TextureResolver textures(scene, config.textureCacheMiB.value_or(scene.settings.textureCacheMiB),
                             config.textureFilter == TextureFilter::Cone);
    CameraModel camera(scene, plan.sampleBase);

    RenderParams params{};
    params.seed = config.seed.value_or(scene.settings.seed);
    params.samplesPerIteration = uint(plan.sampleBase * plan.sampleBase);
    params.minDepth = uint(scene.settings.minDepth);
    params.maxDepth = uint(scene.settings.maxDepth);
    params.threshold = scene.settings.threshold;
    params.strategy = config.strategy;
    params.emitterCount = lights.sampledEmitters();
    params.environment = lights.environment();
    params.envWidth = lights.environmentWidth();
    params.envHeight = lights.environmentHeight();
    params.sampling = dimensionSampler(scene.sampler);
    stats.extra["sampler"] = samplerName(scene.sampler);

    RenderContext ctx{scene, config, lights, *embree, textures, camera, params, threads, stats};
    result->film =
        std::make_unique<Film>(scene.image.width, scene.image.height, scene.filter,
                               lights.brightestEmission(), int(params.samplesPerIteration));
    std::unique_ptr<Backend> backend;
    if (config.backend == BackendKind::Reference)
        backend = std::make_unique<ReferenceRenderer>(ctx);
    else if (vulkan)
        backend = std::make_unique<SortedRenderer>(
            ctx, config.pipeline, makeVulkanShading(ctx, config.pipeline, *vulkan));
    else
        backend = std::make_unique<SortedRenderer>(ctx, config.pipeline, makeCpuShading(ctx));
    double renderSeconds = 0;
    // A partial render (--samples A:B) runs iterations [first, end) of the whole render's.
    const int spi = plan.sampleBase * plan.sampleBase;
    if (const std::string why = partialRenderProblem(scene, config, plan); !why.empty())
        throw std::invalid_argument(why);
    const int first = config.sampleRange ? config.sampleRange->first / spi : 0;
    const int end = config.sampleRange ? config.sampleRange->second / spi : plan.iterations;
    int done = first;
    const double adaptiveThreshold =
        config.adaptiveThreshold.value_or(scene.settings.adaptiveThreshold);
    const int adaptiveMinSamples =
        config.adaptiveMinSamples.value_or(scene.settings.adaptiveMinSamples);
    result->film->setAdaptive(adaptiveThreshold, adaptiveMinSamples);
    if (ranks) result->film->setShare(ranks->rank(), ranks->size());
    std::optional<CheckpointKey> key = checkpoints.key;
    if (!key && (!checkpoints.path.empty() || checkpoints.resume))
        key = checkpointKey(scene, config, plan.sampleBase);
    if (const Checkpoint* c = checkpoints.resume) {
        if (const std::string why = checkpointMismatch(*key, c->key); !why.empty())
            throw std::invalid_argument("the checkpoint is of another render: " + why);
        if (c->firstIteration != first)
            throw std::invalid_argument("the checkpoint is of a partial render from sample " +
                                        std::to_string(c->firstIteration * spi) +
                                        ", this render starts at " + std::to_string(first * spi));
        result->film->restore(c->film);
        done = first + c->iterations;
        renderSeconds = c->renderSeconds;
        stats.extra["resumed_iterations"] = c->iterations;
    }
    auto checkpoint = [&] {
        StageTimer t(stats.stages, "checkpoint");
        Checkpoint c;
        c.key = *key;
        c.iterations = done - first;
        c.firstIteration = first;
        c.totalIterations = plan.iterations;
        c.renderSeconds = renderSeconds;
        c.film = result->film->state();
        writeCheckpoint(checkpoints.path, c, result->film->image());
    };
    double lastCheckpoint = renderSeconds;
    const bool writes = !ranks || ranks->rank() == 0; // distributed: rank 0 writes
    const char* stopReason = "spp";
    auto stopBySignal = [&] {
        return config.stop && *config.stop == kStopByWindow ? "window" : "signal";
    };
    for (int ran = 0; done < end; ++ran) {
        // What a rank alone knows is agreed first, so that every rank renders the same
        // iterations; the film's own decisions (adaptive, target error) agree already.
        Ranks::Agreement agreed;
        agreed.stop = stopRequested(config);
        agreed.timeUp =
            ran > 0 && config.timeLimitSeconds && renderSeconds >= *config.timeLimitSeconds;
        if (ranks) {
            StageTimer t(stats.stages, "agree"); // waiting for the slowest rank, mostly
            agreed = ranks->agree(false, agreed.stop, agreed.timeUp);
        }
        if (agreed.timeUp) {
            stopReason = "time limit";
            break;
        }
        if (agreed.stop) {
            stopReason = stopBySignal();
            break;
        }
        if (ran > 0 && !result->film->anySampling()) {
            stopReason = "adaptive"; // every tile is below the adaptive threshold
            break;
        }
        if (ran > 0 && config.targetError) {
            const std::optional<double> estimate = result->film->halfBufferRelMseEstimate();
            if (estimate && *estimate <= *config.targetError) {
                stopReason = "target error";
                break;
            }
        }
        const auto iterationStart = std::chrono::steady_clock::now();
        bool whole = backend->renderIteration(uint(done), *result->film);
        embree->checkError("tracing");
        textures.checkErrors();
        if (ranks) {
            StageTimer t(stats.stages, "agree");
            whole = !ranks->agree(false, !whole, false).stop;
        }
        if (!whole) {
            result->film->discardIteration(); // stopped part-way: keep only whole iterations
            stopReason = stopBySignal();
            break;
        }
        if (ranks) {
            // Every rank's share of the iteration, added exactly: the same film on every rank.
            StageTimer t(stats.stages, "reduce");
            std::vector<std::int64_t> sums = result->film->iterationAccumulators();
            ranks->sum(sums);
            result->film->setIterationAccumulators(sums);
        }
        {
            StageTimer t(stats.stages, "accumulate");
            result->film->endIteration();
        }
        textures.noteCacheUse();
        renderSeconds +=
            std::chrono::duration<double>(std::chrono::steady_clock::now() - iterationStart)
                .count();
        ++done;
        const int sppDone = (done - first) * spi;
        if (onIteration)
            onIteration({done - first, end - first, sppDone, renderSeconds}, *result->film);
        if (writes && !checkpoints.path.empty() && checkpoints.intervalSeconds > 0 &&
            renderSeconds - lastCheckpoint >= checkpoints.intervalSeconds && done < end) {
            checkpoint();
            lastCheckpoint = renderSeconds;
        }
    }
    stats.extra["stop_reason"] = stopReason;
    stats.iterations = done - first;
    stats.spp = (done - first) * spi;
    if (config.sampleRange) stats.extra["samples_range"] = {first * spi, done * spi};
    stats.extra["render_seconds"] = renderSeconds;
    stats.extra["samples_taken"] = result->film->samplesTaken();
    if (adaptiveThreshold > 0.0)
        stats.extra["adaptive"] = {
            {"threshold", adaptiveThreshold},
            {"min_samples", adaptiveMinSamples},
            {"samples_of_full_render",
             std::uint64_t(scene.image.width) * scene.image.height * std::uint64_t(stats.spp)}};
    if (textures.active()) stats.extra["textures"] = textureStatistics(textures, stats);
    if (ranks) {
        stats.wallSeconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        nlohmann::json mine = stats.toJson();
        mine["host"] = ranks->host();
        const std::string text = mine.dump();
        ranks->agree(false, false, false); // a rank that failed since the last one says so here
        const std::vector<std::string> all = ranks->gather(text);
        ranks->finish(); // the last collective: rank 0 writes the outputs alone
        if (writes) addRanksToStats(all, stats);
    }
    if (writes && !checkpoints.path.empty() && done > first) checkpoint();
    stats.nonFiniteSamples = result->film->nonFiniteSamples();
    stats.saturatedSamples = result->film->saturatedSamples();
    stats.wallSeconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

} // namespace
} // namespace spw
