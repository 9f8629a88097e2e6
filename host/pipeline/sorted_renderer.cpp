#include "host/pipeline/sorted_renderer.h"

#include "host/pipeline/stages.h"

#include <algorithm>
#include <chrono>

namespace spw {

struct SortedRenderer::Scratch {
    std::vector<RayState> rays, rayTmp;
    std::vector<KeyIndex> rayKeys, keyTmp;
    std::vector<HitRecord> hits;
    std::vector<SortedHit> order;
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
      scratch_(std::make_unique<Scratch>()), shaderRanks_(ctx.scene) {
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
    Scratch& s = *scratch_;
    for (;;) {
        if (stopRequested(ctx_.config)) {
            // A batch boundary: let the engine finish what it holds, then drop every ray still
            // waiting (the caller discards this iteration's film).
            shading_->abandon();
            bins_->clear();
            queue_->clear();
            publishStats();
            return false;
        }
        bool camera = false;
        // With a batch being shaded, its continuation rays may yet fill a bin: flush none before.
        if (!nextBatch(film, !shading_->busy(), camera)) {
            if (!shading_->busy()) break;   // nothing queued, binned, pending or still to make
            shading_->finish(film, *bins_); // its continuation rays may refill the queue
            continue;
        }
        const size_t hitCount = traceAndSortBatch(camera);
        addEscapedRadiance(iteration, hitCount, film);
        shading_->shadeBatch({s.rays, s.hits, s.order, hitCount}, film, *bins_);
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

size_t SortedRenderer::traceAndSortBatch(bool camera) {
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
        // Only camera batches take Embree's packet traversal (the coherent flag): a sorted
        // bounce batch's rays share a region and a direction, not a path through the BVH, and
        // traced as packets they took 25-30 % longer than one at a time (3.2 M triangles).
        StageTimer t(times, "traverse");
        traverse(ctx_.embree, s.rays, camera, s.hits);
    }
    if (!camera) {
        policy_.record(mode != RaySortMode::Off, since(sortStart), n);
        ctx_.stats.bounceRays += n;
    }
    const HitOrder order = shading_->hitOrder();
    if (order == HitOrder::AsTraced) {
        // Nothing to sort and no miss to shade: the fused loop takes the hits in traversal
        // order and leaves out the misses chunk by chunk (stages.h: shadeFused).
        s.order.clear();
        return n;
    }
    StageTimer t(times, "sort hits");
    return sortHits(ctx_.scene, shaderRanks_, s.hits, order, s.order, s.keyTmp);
}

void SortedRenderer::addEscapedRadiance(uint iteration, size_t hitCount, Film& film) {
    if (ctx_.params.environment == kNoEmitter) return; // a miss sees black: nothing to add
    StageTimer t(ctx_.stats.stages, "escape");
    accumulateEscapes(ctx_, iteration, scratch_->rays, scratch_->order, hitCount, film);
}

void SortedRenderer::publishStats() {
    const QueueCounters c = queue_->counters();
    SpillCounters spill;
    spill.batchesProcessed = batchesProcessed_;
    spill.batchesQueued = c.batchesQueued;
    spill.batchesSpilled = c.batchesSpilled;
    spill.bytesWritten = c.bytesWritten;
    spill.bytesRead = c.bytesRead;
    spill.peakRayBytesInRam = c.peakRamBytes;
    ctx_.stats.spill = spill;
    nlohmann::json& x = ctx_.stats.extra;
    x["ray_format"] = rayFormatName(config_.rayFormat);
    x["ray_record_bytes"] = rayRecordBytes(config_.rayFormat);
    x["ray_sort"] = raySortName(config_.raySort);
    const HitOrder order = shading_->hitOrder();
    x["hit_order"] = hitOrderName(order);
    x["hit_sort"] = sortsByShader(order);
    if (sortsByShader(order)) x["hit_sort_key"] = hitOrderName(order);
    x["shading"] =
        shadingModeName(sortsByShader(order) ? ShadingMode::Sorted : ShadingMode::Megakernel);
    x["batches_ray_sorted"] = policy_.sortedBatches();
    x["batches_ray_unsorted_measured"] = policy_.unsortedBatches();
    shading_->publishStats(ctx_.stats);
}

} // namespace spw
