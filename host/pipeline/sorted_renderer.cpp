#include "host/pipeline/sorted_renderer.h"

#include "host/pipeline/cpu_shading.h"
#include "host/pipeline/stages.h"

#include <algorithm>
#include <chrono>

namespace spw {

struct SortedRenderer::Scratch {
    std::vector<RayState> rays, rayTmp;
    std::vector<KeyIndex> rayKeys, keyTmp;
    std::vector<HitRecord> hits;
    std::vector<SortedHit> order;
    std::vector<ShadeRange> ranges;
    // A batch between its shading submit and its accumulation, one per engine slot.
    struct InFlight {
        size_t hitCount = 0;
        ShadeSlot shading;
        std::vector<uvec2> paths; // (pathId, bounce) per hit: the film needs them, and the
                                  // inputs may sit in write-combined device memory
    };
    InFlight inFlight[2];
    std::vector<ShadowRay> shadows;
    std::vector<std::uint32_t> shadowOwner;
    std::vector<std::uint8_t> occluded;
};

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
}
} // namespace

SortedRenderer::SortedRenderer(const RenderContext& ctx, const PipelineConfig& config,
                               std::unique_ptr<ShadingEngine> shading)
    : ctx_(ctx), config_(config), shading_(std::move(shading)),
      policy_(config.raySort, size_t(1) << uint(ctx.scene.settings.binExponent)),
      scratch_(std::make_unique<Scratch>()),
      fused_(config.fuseStages && shading_->shadesOnHostThreads()),
      simdShading_(fused_ && usesSimdShading(ctx)),
      sortHits_(config.sortsHits() && (config.hitSort == HitSortMode::On ||
                                       !shading_->shadesOnHostThreads() || ctx.textures.active())),
      shaderOrder_(ctx.scene) {
    const double budgetMiB = ctx.scene.settings.memoryBudgetMiB;
    const uint exponent = uint(ctx.scene.settings.binExponent);
    // The budget covers every ray waiting in RAM: the six bins fill up to one batch each, and
    // the queue keeps the rest of the budget (none when six batches already exceed it, so that
    // every batch spills). Peak rays in RAM <= max(budget, six batches), as --help states.
    const std::uint64_t budget = std::uint64_t(budgetMiB * 1024.0 * 1024.0);
    const std::uint64_t binBytes =
        6 * (std::uint64_t(1) << exponent) * rayRecordBytes(config.rayFormat);
    // The spill folder is resolved (and the file made) only when a batch first spills.
    queue_ =
        std::make_unique<BatchQueue>(budget > binBytes ? budget - binBytes : 0, config.spillDir);
    bins_ = std::make_unique<DirectionalBins>(config.rayFormat, exponent, *queue_);
    batchRays_ = size_t(1) << exponent;
}

SortedRenderer::~SortedRenderer() = default;

bool SortedRenderer::renderIteration(uint iteration, Film& film) {
    shading_->beginIteration(iteration);
    {
        StageTimer t(ctx_.stats.stages, "generate");
        cameraRays_.begin(ctx_, iteration, film);
    }
    // With two engine slots, batch k's shading runs while batch k+1 is loaded, traversed and set
    // up; batch k is then finished (its continuation rays binned) before k+2 starts. Batches may
    // be finished in any order: the film and the random numbers do not depend on it.
    const bool overlap = shading_->slots() > 1;
    int pending = -1; // the slot whose batch is being shaded
    int next = 0;
    for (;;) {
        if (stopRequested(ctx_.config)) {
            // A batch boundary: let the engine finish what it holds, then drop every ray still
            // waiting (the caller discards this iteration's film).
            if (pending >= 0) shading_->finish(pending);
            bins_->clear();
            queue_->clear();
            publishStats();
            return false;
        }
        bool camera = false;
        // With a batch pending, its continuation rays may yet fill a bin: flush none before.
        if (!nextBatch(film, pending < 0, camera)) {
            if (pending < 0) break; // nothing queued, binned, pending or still to make
            finishBatch(pending, iteration, film); // its continuation rays may refill the queue
            pending = -1;
            continue;
        }
        if (fused_) {
            runFusedBatch(camera, iteration, film);
            continue;
        }
        startBatch(camera, next, iteration, film);
        if (pending >= 0) finishBatch(pending, iteration, film);
        if (overlap) {
            pending = next;
            next ^= 1;
        } else {
            finishBatch(next, iteration, film);
        }
    }
    publishStats();
    return true;
}

bool SortedRenderer::nextBatch(Film& film, bool flush, bool& camera) {
    Scratch& s = *scratch_;
    StageTimes& times = ctx_.stats.stages;
    // Bounce rays first, so that the rays in flight stay few: camera rays are made only when no
    // batch waits in the queue, and the bins are flushed part-full only once every camera ray of
    // the iteration is made.
    std::optional<RayBatch> batch = queue_->pop(times);
    if (!batch && cameraRays_.remaining() > 0) {
        StageTimer t(times, "generate");
        cameraRays_.generate(ctx_, batchRays_, film, s.rays);
        camera = true;
        return true;
    }
    if (!batch && flush && bins_->flush()) batch = queue_->pop(times);
    if (!batch) return false;
    StageTimer t(times, "decompress");
    decompressRays(*batch, s.rays);
    queue_->recycle(std::move(batch->bytes));
    return true;
}

size_t SortedRenderer::traceBatch(bool camera) {
    Scratch& s = *scratch_;
    StageTimes& times = ctx_.stats.stages;
    const size_t n = s.rays.size();
    ++batchesProcessed_;
    // Camera batches are coherent as made (tile by tile): they are never sorted or measured.
    const RaySortMode mode = camera ? RaySortMode::Off : policy_.choose(n);
    const auto sortStart = Clock::now();
    if (mode == RaySortMode::Morton || mode == RaySortMode::Median) {
        StageTimer t(times, "sort rays");
        if (mode == RaySortMode::Morton)
            sortRaysMorton(s.rays, s.rayKeys, s.keyTmp, s.rayTmp);
        else
            sortRaysMedian(s.rays);
    }
    {
        StageTimer t(times, "traverse");
        traverse(ctx_.embree, s.rays, camera || mode != RaySortMode::Off, s.hits);
    }
    if (!camera) {
        policy_.record(mode != RaySortMode::Off, since(sortStart), n);
        ctx_.stats.bounceRays += n;
    }
    if (fused_ && !sortHits_ && ctx_.params.environment == kNoEmitter) {
        // Nothing to sort and no miss to shade: the fused loop takes the hits in traversal
        // order and leaves out the misses chunk by chunk (stages.h: shadeFused).
        s.order.clear();
        return n;
    }
    StageTimer t(times, "sort hits");
    // Within a shader, texture order only where textures are read: otherwise the traversal
    // order stays, and the radix sort needs one pass instead of three or four.
    return sortHits(ctx_.scene, shaderOrder_, s.hits, sortHits_, ctx_.textures.active(), s.order,
                    s.keyTmp);
}

void SortedRenderer::runFusedBatch(bool camera, uint iteration, Film& film) {
    Scratch& s = *scratch_;
    const size_t hitCount = traceBatch(camera);
    escapes(iteration, hitCount, film);
    shadeFused(ctx_, iteration, config_.rayFormat, simdShading_, s.rays, s.hits, s.order, hitCount,
               film, *bins_);
}

void SortedRenderer::startBatch(bool camera, int slot, uint iteration, Film& film) {
    Scratch& s = *scratch_;
    Scratch::InFlight& flight = s.inFlight[slot];
    StageTimes& times = ctx_.stats.stages;
    flight.hitCount = traceBatch(camera);
    escapes(iteration, flight.hitCount, film);
    {
        StageTimer t(times, "hit setup");
        flight.shading = shading_->reserve(slot, flight.hitCount);
        flight.paths.resize(flight.hitCount);
        setUpHits(ctx_, s.rays, s.hits, s.order, flight.hitCount, flight.shading.inputs,
                  flight.paths.data());
    }
    {
        StageTimer t(times, "shade");
        shadeRanges(ctx_.scene, shaderOrder_, s.order, flight.hitCount, sortHits_, s.ranges);
        shading_->submit(slot, s.ranges);
    }
}

void SortedRenderer::finishBatch(int slot, uint iteration, Film& film) {
    Scratch& s = *scratch_;
    StageTimes& times = ctx_.stats.stages;
    const Scratch::InFlight& flight = s.inFlight[slot];
    const ShadeResult* results = flight.shading.results;
    {
        StageTimer t(times, "shade wait");
        shading_->finish(slot);
    }
    if (config_.fuseStages) {
        finishFused(ctx_, iteration, config_.rayFormat, results, flight.paths.data(),
                    flight.hitCount, film, *bins_);
        return;
    }
    {
        StageTimer t(times, "shadow");
        gatherShadowRays(results, flight.hitCount, s.shadowOwner, s.shadows);
        occludedBatch(ctx_.embree, s.shadows, false, s.occluded);
        ctx_.stats.shadowRays += s.shadows.size();
    }
    {
        StageTimer t(times, "accumulate");
        accumulate(ctx_, iteration, results, flight.paths.data(), flight.hitCount, s.shadowOwner,
                   s.occluded, film);
    }
    {
        StageTimer t(times, "bin");
        binContinuations(ctx_, iteration, config_.rayFormat, results, flight.hitCount, *bins_);
    }
}

void SortedRenderer::escapes(uint iteration, size_t hitCount, Film& film) {
    if (ctx_.params.environment == kNoEmitter) return; // a miss sees black: nothing to add
    StageTimer t(ctx_.stats.stages, "escape");
    accumulateEscapes(ctx_, iteration, scratch_->rays, scratch_->order, hitCount, film);
}

void SortedRenderer::publishStats() {
    const QueueCounters c = queue_->counters();
    nlohmann::json& x = ctx_.stats.extra;
    x["batches_processed"] = batchesProcessed_;
    x["batches_queued"] = c.batchesQueued;
    x["batches_spilled"] = c.batchesSpilled;
    x["bytes_spilled_written"] = c.bytesWritten;
    x["bytes_spilled_read"] = c.bytesRead;
    x["peak_ray_bytes_in_ram"] = c.peakRamBytes;
    x["ray_format"] = rayFormatName(config_.rayFormat);
    x["ray_record_bytes"] = rayRecordBytes(config_.rayFormat);
    x["ray_sort"] = raySortName(config_.raySort);
    x["hit_sort"] = sortHits_;
    x["shading"] = shadingModeName(sortHits_ ? ShadingMode::Sorted : ShadingMode::Megakernel);
    x["batches_ray_sorted"] = policy_.sortedBatches();
    x["batches_ray_unsorted_measured"] = policy_.unsortedBatches();
    // fused: every per-hit stage chunk by chunk; fused after shading: shadow, accumulate and bin
    // (an engine that shades elsewhere); separate: each stage over the whole batch.
    x["stages"] = fused_ ? "fused" : config_.fuseStages ? "fused after shading" : "separate";
    shading_->publishStats(ctx_.stats);
}

} // namespace spw
