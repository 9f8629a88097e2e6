#include "host/render/render.h"

#include "embree_backend/cutouts.h"
#include "embree_backend/embree_scene.h"
#include "embree_backend/reference_renderer.h"
#include "host/backend/backend.h"
#include "host/cpu/cpu_shading.h"
#include "host/pipeline/sorted_renderer.h"
#include "host/render/backend_choice.h"
#include "host/render/rank_policy.h"
#include "host/render/stop_rule.h"
#include "host/scene/camera.h"
#include "host/textures/textures.h"
#include "host/vk/context.h"
#include "host/vk/vulkan_shading.h"

#include <tbb/global_control.h>
#include <tbb/info.h>

#include <chrono>
#include <climits>
#include <cstdio>
#include <optional>
#include <stdexcept>

namespace spw {
namespace {

// --stats' `textures`: the texture system's counters.
TextureCounters textureCounters(const TextureResolver& textures) {
    const TextureStatistics t = textures.statistics();
    TextureCounters c;
    c.lookups = t.lookups;
    c.tilesRead = t.tilesRead;
    c.bytesRead = t.bytesRead;
    c.filesOpened = t.filesOpened;
    c.filesReopened = t.filesReopened;
    c.cacheMisses = t.cacheMisses;
    c.peakCacheBytes = t.peakCacheBytes;
    c.tiledCopies = t.tiledCopies;
    c.tiledCopyBytes = t.tiledCopyBytes;
    return c;
}

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
    if (scene.settings.adaptiveThreshold > 0.0)
        return range + "a partial render cannot sample adaptively (its decisions read the "
                       "iterations before it)";
    return "";
}

SamplingPlan planSampling(const ImageSettings& image, std::optional<int> spp, int resumedBase) {
    // A resume keeps its checkpoint's samples an iteration where they divide the samples asked
    // for (more --spp than the checkpoint's render, or the scene's own after an --spp).
    const long long total = spp ? *spp : (long long)image.samplesPerIteration() * image.iterations;
    const long long resumed = (long long)resumedBase * resumedBase;
    if (resumedBase > 0 && total % resumed == 0 && total / resumed <= INT_MAX)
        return {resumedBase, int(total / resumed)};
    if (!spp) return {image.sampleBase, image.iterations};
    const int n2 = image.samplesPerIteration();
    // Keep the scene's n x n pattern when it divides the request; otherwise one sample per pass.
    if (*spp % n2 == 0) return {image.sampleBase, *spp / n2};
    return {1, *spp};
}

std::string resumeProblem(const CheckpointKey& expected, const CheckpointKey& found,
                          const ImageSettings& image, std::optional<int> spp) {
    const std::string why = checkpointMismatch(expected, found);
    if (why.empty()) return "";
    if (spp && found.sampleBase == image.sampleBase && expected.sampleBase != found.sampleBase) {
        const int n2 = found.sampleBase * found.sampleBase;
        return "the checkpoint takes " + std::to_string(n2) +
               " samples per pixel each iteration (the scene's sample base " +
               std::to_string(found.sampleBase) + "), and --spp " + std::to_string(*spp) +
               " is not a multiple of " + std::to_string(n2) +
               " (this render would take 1 each iteration): ask for a multiple of " +
               std::to_string(n2) + ", such as " + std::to_string((*spp / n2 + 1) * n2);
    }
    return "the checkpoint is of another render: " + why;
}

namespace {

// One render from start to finish: what it is built of, where it starts, its loop and its report.
class RenderSession {
  public:
    RenderSession(const Scene& scene, const RenderConfig& config,
                  const CheckpointOptions& checkpoints, RankPolicy& sync)
        : scene_(scene), config_(config), checkpoints_(checkpoints), sync_(sync),
          plan_(planSampling(scene.image, config.spp,
                             checkpoints.resume ? checkpoints.resume->key.sampleBase : 0)),
          spi_(plan_.sampleBase * plan_.sampleBase), stop_(config) {}

    std::unique_ptr<RenderResult> run(const ProgressCallback& onIteration);

  private:
    void checkConfig() const;
    RenderIdentity identity() const;
    void chooseBackend();
    void build();
    // --stats' "geometry": meshes, prototypes, instances, triangles, and the peak memory so far.
    void recordGeometry();
    void startAt();
    void writeCheckpoint();
    const char* iterate(const ProgressCallback& onIteration);
    void report(const char* stopReason);
    double sinceStart() const {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    }

    const Scene& scene_;
    const RenderConfig& config_;
    const CheckpointOptions& checkpoints_;
    RankPolicy& sync_;
    const SamplingPlan plan_;
    const int spi_; // samples per pixel and iteration
    const StopRule stop_;
    const std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
    // Declared before everything built under it, so that it outlives them.
    std::optional<tbb::global_control> threadLimit_;

    std::unique_ptr<RenderResult> result_ = std::make_unique<RenderResult>();
    RenderStats& stats_ = result_->stats;
    BackendChoice choice_;
    int threads_ = 0;
    std::optional<SceneLights> lights_;
    std::optional<TextureResolver> textures_;
    std::optional<Cutouts> cutouts_; // the BVH's hit filter: built before it, outlives it
    std::unique_ptr<EmbreeScene> embree_;
    std::optional<HitSetup> hitSetup_;
    std::optional<CameraModel> camera_;
    std::optional<RenderContext> ctx_;
    std::unique_ptr<Backend> backend_;
    // Iterations [first_, end_) of the whole render's (a partial render's range); done_ so far.
    int first_ = 0, end_ = 0, done_ = 0;
    double renderSeconds_ = 0; // in iterations, callbacks excluded; resumed from a checkpoint
    std::optional<CheckpointKey> key_;
};

std::unique_ptr<RenderResult> RenderSession::run(const ProgressCallback& onIteration) {
    checkConfig();
    sync_.agreeIdentity([&] { return identity(); });
    threads_ = config_.threads > 0 ? config_.threads : tbb::info::default_concurrency();
    threadLimit_.emplace(tbb::global_control::max_allowed_parallelism, size_t(threads_));
    chooseBackend();
    build();
    startAt();
    report(iterate(onIteration));
    return std::move(result_);
}

// What decides the image, field by field, for the ranks of a distributed render to compare
// before any other collective: the checkpoint key's fields (scene, every input's content, seed,
// size, sampler, ray format, ...), the samples asked for, and the checkpoint resumed from.
RenderIdentity RenderSession::identity() const {
    const CheckpointKey k = key_ ? *key_ : checkpointKey(scene_, config_, plan_.sampleBase);
    const Settings& st = scene_.settings;
    const std::pair<int, int> range = config_.sampleRange.value_or(std::pair<int, int>{-1, -1});
    Fnv resume;
    if (const Checkpoint* c = checkpoints_.resume) {
        resume.value(c->iterations).value(c->firstIteration);
        resume.array(c->film.sums);
        resume.array(c->film.samples);
    }
    auto text = [](const std::string& t) {
        Fnv f;
        f.text(t);
        return f.h;
    };
    return {
        {"Spillway version", text(k.version)},
        {"image size", Fnv().value(k.width).value(k.height).h},
        {"number of samples (--spp)", Fnv().value(plan_.sampleBase).value(plan_.iterations).h},
        {"sample range (--samples)", Fnv().value(range).h},
        {"seed", Fnv().value(k.seed).h},
        {"sampler", text(k.sampler)},
        {"ray format, texture filter or sampling strategy",
         Fnv().value(text(k.rayFormat)).value(text(k.textureFilter)).value(k.strategy).h},
        {"depth, roulette or adaptive-sampling settings", Fnv()
                                                              .value(st.minDepth)
                                                              .value(st.maxDepth)
                                                              .value(st.threshold)
                                                              .value(k.adaptiveThreshold)
                                                              .value(k.adaptiveMinSamples)
                                                              .h},
        {"checkpoint to resume from (--resume)", resume.h},
        // Last: a scene file that differs in a setting above is named by the setting.
        {"scene (its file, meshes or textures)", k.sceneHash},
        {"environment (its radiance or map)", k.environmentHash},
    };
}

void RenderSession::checkConfig() const {
    if (config_.pipeline.rayFormat == RayFormat::Compact &&
        scene_.settings.maxDepth > int(kMaxCompactBounce))
        throw std::invalid_argument("max depth " + std::to_string(scene_.settings.maxDepth) +
                                    " exceeds the compact ray's " +
                                    std::to_string(kMaxCompactBounce) + " bounces");
}

void RenderSession::chooseBackend() {
    {
        // Timed only where Vulkan may be asked for, as a stage of its own.
        std::optional<StageTimer> t;
        if (config_.backend == BackendKind::Vulkan || config_.backend == BackendKind::Auto)
            t.emplace(stats_.stages, "vulkan init");
        choice_ = resolveBackend(config_);
    }
    stats_.backend = backendName(choice_.kind);
    stats_.device = choice_.device;
    if (!choice_.autoWhy.empty()) stats_.extra["backend_auto"] = choice_.autoWhy;
    if (!choice_.fallbackWhy.empty()) stats_.extra["backend_fallback"] = choice_.fallbackWhy;
    stats_.width = scene_.image.width;
    stats_.height = scene_.image.height;
    stats_.spp = spi_ * plan_.iterations;
    stats_.iterations = plan_.iterations;
    stats_.threads = threads_;
}

// What the scene needs (BVH, textures, camera), the render-wide parameters, the film and the
// backend.
void RenderSession::recordGeometry() {
    double stored = 0.0;
    for (const Mesh& m : scene_.meshes)
        stored += double(m.triangles.size());
    stats_.extra["geometry"] = {
        {"meshes", scene_.meshes.size()},
        {"prototypes", scene_.prototypes.size()},
        {"instances", scene_.instances.size()},
        {"triangles_stored", stored},
        {"triangles_rendered", scene_.renderedTriangles()},
        {"peak_rss_mib_after_bvh", peakResidentMiB()},
        {"bvh", embree_->compact() ? "compact" : "fast"},
    };
}

void RenderSession::build() {
    textures_.emplace(scene_, scene_.settings.textureCacheMiB,
                      config_.textureFilter == TextureFilter::Cone, config_.pipeline.simdShading,
                      config_.pipeline.spillDir);
    {
        StageTimer t(stats_.stages, "build lights");
        lights_.emplace(scene_, &*textures_);
    }
    stats_.extra["lights"] = {{"emitters", double(lights_->emitters().size())},
                              {"instances", double(lights_->instanceLightCount())},
                              {"bytes", double(lights_->bytes())}};
    if (lights_->emissionImages() > 0) stats_.extra["emission_maps"] = lights_->emissionImages();
    cutouts_.emplace(scene_, *textures_);
    if (cutouts_->meshes() > 0) stats_.extra["cutout_meshes"] = cutouts_->meshes();
    {
        StageTimer t(stats_.stages, "build bvh");
        embree_ =
            std::make_unique<EmbreeScene>(scene_, cutouts_->meshes() > 0 ? &*cutouts_ : nullptr);
    }
    recordGeometry();
    hitSetup_.emplace(scene_, *lights_);
    camera_.emplace(scene_, plan_.sampleBase);

    RenderParams params{};
    params.seed = scene_.settings.seed;
    params.samplesPerIteration = uint(spi_);
    params.minDepth = uint(scene_.settings.minDepth);
    params.maxDepth = uint(scene_.settings.maxDepth);
    params.threshold = scene_.settings.threshold;
    params.strategy = config_.strategy;
    params.emitterCount = lights_->sampledEmitters();
    params.treeEmitters = lights_->treeEmitters();
    params.instanceLights = lights_->instanceLights();
    params.instanceLightCount = lights_->instanceLightCount();
    stats_.extra["light_tree_emitters"] = double(lights_->treeEmitters());
    params.environment = lights_->environment();
    params.envWidth = lights_->environmentWidth();
    params.envHeight = lights_->environmentHeight();
    params.sampling = dimensionSampler(scene_.sampler);
    stats_.extra["sampler"] = samplerName(scene_.sampler);

    if (config_.aovs != 0)
        result_->aovs = std::make_unique<AovFilm>(scene_.image.width, scene_.image.height, spi_,
                                                  config_.aovs, mat3(scene_.camera.cameraToWorld));
    ctx_.emplace(RenderContext{scene_, config_, *lights_, *embree_, *hitSetup_, *textures_,
                               *camera_, params, threads_, stats_, result_->aovs.get()});
    result_->film = std::make_unique<Film>(
        scene_.image.width, scene_.image.height, scene_.filter, lights_->brightestEmission(),
        int(params.samplesPerIteration),
        params.sampling == kSamplerSobol ? Film::Halves::ByStream : Film::Halves::ByStratum);
    if (choice_.kind == BackendKind::Reference)
        backend_ = std::make_unique<ReferenceRenderer>(*ctx_);
    else if (choice_.vulkan)
        backend_ = std::make_unique<SortedRenderer>(
            *ctx_, config_.pipeline, makeVulkanShading(*ctx_, config_.pipeline, *choice_.vulkan));
    else
        backend_ = std::make_unique<SortedRenderer>(*ctx_, config_.pipeline, makeCpuShading(*ctx_));
}

// Where the render starts: a partial render's first iteration, and a checkpoint's progress.
void RenderSession::startAt() {
    if (const std::string why = partialRenderProblem(scene_, config_, plan_); !why.empty())
        throw RenderRefused(why);
    first_ = config_.sampleRange ? config_.sampleRange->first / spi_ : 0;
    end_ = config_.sampleRange ? config_.sampleRange->second / spi_ : plan_.iterations;
    done_ = first_;
    result_->film->setAdaptive(scene_.settings.adaptiveThreshold,
                               scene_.settings.adaptiveMinSamples);
    // Toward a target the tiles share the samples by their noise; not in a partial render,
    // whose samples are the whole render's range and not its own to share.
    if (const double target = adaptiveTarget(scene_, config_); target > 0)
        result_->film->setAdaptiveTarget(target);
    sync_.share(*result_->film);
    key_ = checkpoints_.key;
    if (!key_ && (!checkpoints_.path.empty() || checkpoints_.resume))
        key_ = checkpointKey(scene_, config_, plan_.sampleBase);
    const Checkpoint* c = checkpoints_.resume;
    if (!c) return;
    if (const std::string why = resumeProblem(*key_, c->key, scene_.image, config_.spp);
        !why.empty())
        throw RenderRefused(why);
    if (c->firstIteration != first_)
        throw RenderRefused("the checkpoint is of a partial render from sample " +
                            std::to_string(c->firstIteration * spi_) + ", this render starts at " +
                            std::to_string(first_ * spi_));
    if (c->iterations > end_ - first_)
        throw RenderRefused("the checkpoint has " + std::to_string(c->iterations * spi_) +
                            " samples per pixel done, more than this render's " +
                            std::to_string((end_ - first_) * spi_) +
                            " (ask for at least as many with --spp)");
    result_->film->restore(c->film);
    done_ = first_ + c->iterations;
    renderSeconds_ = c->renderSeconds;
    stats_.extra["resumed_iterations"] = c->iterations;
}

void RenderSession::writeCheckpoint() {
    StageTimer t(stats_.stages, "checkpoint");
    Checkpoint c;
    c.key = *key_;
    c.iterations = done_ - first_;
    c.firstIteration = first_;
    c.totalIterations = plan_.iterations;
    c.renderSeconds = renderSeconds_;
    c.film = result_->film->state();
    spw::writeCheckpoint(checkpoints_.path, c, result_->film->image());
}

// The iterations, until the last or a stop; returns why it stopped.
const char* RenderSession::iterate(const ProgressCallback& onIteration) {
    Film& film = *result_->film;
    double lastCheckpoint = renderSeconds_;
    const bool periodic =
        sync_.writes() && !checkpoints_.path.empty() && checkpoints_.intervalSeconds > 0;
    for (int ran = 0; done_ < end_; ++ran) {
        const Ranks::Agreement agreed =
            sync_.agreeBefore(stop_.stopAsked(), stop_.timeUp(ran, renderSeconds_), stats_.stages);
        if (const char* why = stop_.before(done_ > first_, agreed, film)) return why;
        const auto iterationStart = std::chrono::steady_clock::now();
        {
            StageTimer t(stats_.stages, "accumulate");
            film.beginIteration();
            if (result_->aovs) result_->aovs->beginIteration();
        }
        bool whole = backend_->renderIteration(uint(done_), film);
        embree_->checkError("tracing");
        textures_->checkErrors();
        if (!sync_.agreeWhole(whole, stats_.stages)) {
            film.discardIteration(); // stopped part-way: keep only whole iterations
            return stop_.bySignal();
        }
        {
            StageTimer t(stats_.stages, "accumulate");
            film.finishSamples(); // wide filters: each sample's sum through its footprint
        }
        sync_.reduce(film, stats_.stages);
        {
            StageTimer t(stats_.stages, "accumulate");
            film.endIteration();
            if (result_->aovs) result_->aovs->endIteration();
        }
        textures_->noteCacheUse();
        renderSeconds_ +=
            std::chrono::duration<double>(std::chrono::steady_clock::now() - iterationStart)
                .count();
        ++done_;
        if (onIteration)
            onIteration({done_ - first_, end_ - first_, (done_ - first_) * spi_, renderSeconds_},
                        film);
        if (periodic && renderSeconds_ - lastCheckpoint >= checkpoints_.intervalSeconds &&
            done_ < end_) {
            writeCheckpoint();
            lastCheckpoint = renderSeconds_;
        }
    }
    return "spp";
}

// --stats, the last collectives, and the final checkpoint however the render stopped.
void RenderSession::report(const char* stopReason) {
    const Film& film = *result_->film;
    stats_.extra["stop_reason"] = stopReason;
    stats_.iterations = done_ - first_;
    stats_.spp = (done_ - first_) * spi_;
    if (config_.sampleRange) stats_.extra["samples_range"] = {first_ * spi_, done_ * spi_};
    stats_.extra["render_seconds"] = renderSeconds_;
    stats_.extra["peak_rss_mib"] = peakResidentMiB();
    stats_.extra["samples_taken"] = film.samplesTaken();
    if (config_.targetError) {
        const Film::ErrorEstimate e = film.halfBufferError();
        stats_.extra["target_error"] = {
            {"target", *config_.targetError},
            {"rule", "relMSE estimate over the pixels that hold noise (halves differing by more "
                     "than float precision)"},
            {"estimate", e.subjectRelMse ? *e.subjectRelMse : e.relMse.value_or(0.0)},
            {"whole_image_estimate", e.relMse.value_or(0.0)},
            {"subject_fraction", e.subjectFraction}};
    }
    if (scene_.settings.adaptiveThreshold > 0.0)
        stats_.extra["adaptive"] = {
            {"threshold", scene_.settings.adaptiveThreshold},
            {"min_samples", scene_.settings.adaptiveMinSamples},
            {"samples_of_full_render",
             std::uint64_t(scene_.image.width) * scene_.image.height * std::uint64_t(stats_.spp)}};
    if (textures_->active()) stats_.textures = textureCounters(*textures_);
    // Made on first use, within hit setup's time (TextureResolver::prepare).
    if (const double s = textures_->statistics().tiledCopySeconds; s > 0.0)
        stats_.stages.add("tile textures", s);
    sync_.finish(stats_, sinceStart());
    if (sync_.writes() && !checkpoints_.path.empty() && done_ > first_) writeCheckpoint();
    stats_.nonFiniteSamples = film.nonFiniteSamples();
    stats_.saturatedSamples = film.saturatedSamples();
    stats_.wallSeconds = sinceStart();
}

} // namespace

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
        const std::unique_ptr<RankPolicy> sync = rankPolicy(ranks);
        return RenderSession(scene, config, checkpoints, *sync).run(onIteration);
    } catch (...) {
        if (ranks) ranks->failed(); // the others learn it at their next agreement
        throw;
    }
}

} // namespace spw
