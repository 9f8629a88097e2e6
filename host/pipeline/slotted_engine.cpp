#include "host/pipeline/slotted_engine.h"

#include "host/pipeline/stages.h"

namespace spw {

SlottedEngine::SlottedEngine(const RenderContext& ctx, HitOrder order)
    : ShadingEngine(order), ctx_(ctx), shaderRanks_(ctx.scene) {}

void SlottedEngine::shadeBatch(const TracedBatch& batch, Film& film, DirectionalBins& bins) {
    start(batch, next_);
    if (pending_ >= 0) finishSlot(pending_, film, bins);
    if (slots() > 1) {
        pending_ = next_;
        next_ ^= 1;
    } else {
        pending_ = -1;
        finishSlot(next_, film, bins);
    }
}

void SlottedEngine::finish(Film& film, DirectionalBins& bins) {
    if (pending_ < 0) return;
    const int slot = pending_;
    pending_ = -1;
    finishSlot(slot, film, bins); // its continuation rays may refill the queue
}

void SlottedEngine::abandon() {
    if (pending_ >= 0) wait(pending_);
    pending_ = -1;
}

void SlottedEngine::publishStats(RenderStats& stats) {
    // fused after shading: shadow, accumulate and bin chunk by chunk; separate: each stage over
    // the whole batch.
    stats.extra["stages"] = ctx_.config.pipeline.fuseStages ? "fused after shading" : "separate";
}

// hit setup, then the slot's shading submitted.
void SlottedEngine::start(const TracedBatch& batch, int slot) {
    InFlight& flight = inFlight_[slot];
    StageTimes& times = ctx_.stats.stages;
    flight.hitCount = batch.hitCount;
    {
        StageTimer t(times, "hit setup");
        flight.shading = reserve(slot, flight.hitCount);
        flight.paths.resize(flight.hitCount);
        setUpHits(ctx_, batch.rays, batch.hits, batch.order, flight.hitCount, flight.shading.inputs,
                  flight.paths.data());
    }
    {
        StageTimer t(times, "shade");
        shadeRanges(ctx_.scene, shaderRanks_, batch.order, flight.hitCount, hitOrder(), ranges_);
        submit(slot, ranges_);
    }
}

// Waits for the slot's results, traces its shadow rays, accumulates and bins its continuation
// rays.
void SlottedEngine::finishSlot(int slot, Film& film, DirectionalBins& bins) {
    StageTimes& times = ctx_.stats.stages;
    const InFlight& flight = inFlight_[slot];
    const ShadeResult* results = flight.shading.results;
    const RayFormat format = ctx_.config.pipeline.rayFormat;
    {
        StageTimer t(times, "shade wait");
        wait(slot);
    }
    if (ctx_.config.pipeline.fuseStages) {
        finishFused(ctx_, iteration_, format, results, flight.paths.data(), flight.hitCount, film,
                    bins);
        return;
    }
    {
        StageTimer t(times, "shadow");
        gatherShadowRays(results, flight.hitCount, shadowOwner_, shadows_);
        occludedBatch(ctx_.embree, shadows_, false, occluded_);
        ctx_.stats.shadowRays += shadows_.size();
    }
    {
        StageTimer t(times, "accumulate");
        accumulate(ctx_, iteration_, results, flight.paths.data(), flight.hitCount, shadowOwner_,
                   occluded_, film);
    }
    {
        StageTimer t(times, "bin");
        binContinuations(ctx_, iteration_, format, results, flight.hitCount, bins);
    }
}

} // namespace spw
