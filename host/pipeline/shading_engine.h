// The shading engine: what the sorted pipeline hands over once a batch is traced and its hits
// are sorted, in one call (shadeBatch). The engine does the per-hit stages from there, hit setup
// to bin (stages.h), its own way, and says how it wants the hits ordered (hitOrder). Three
// engines: C++ on the host's threads fusing the stages chunk by chunk (the default) or running
// each over the whole batch (--stages separate), both in host/cpu/cpu_shading.cpp, and Vulkan
// compute (host/vk/vulkan_shading.h), overlapping a batch's shading with the next batch's
// traversal. All shade contiguous ranges of hits, one surface model each (ShadeRange); the last
// two through a slot's inputs and results (SlottedEngine, slotted_engine.h).
#pragma once

#include "host/backend/stats.h"
#include "host/image/film.h"
#include "host/pipeline/directional_bins.h"
#include "host/pipeline/hit_sort.h"
#include "host/pipeline/ray_record.h"
#include "shared/shade_io.h"

#include <cstddef>
#include <vector>

namespace spw {

struct HitRecord; // host/scene_view/hit_setup.h

// A contiguous range of a batch's hits that one dispatch shades: all of one shader, so of one
// surface model, or (hits unsorted) every hit, of any model: kMixedModels.
struct ShadeRange {
    uint model; // kModel*, or kMixedModels
    size_t begin, count;
};
constexpr uint kMixedModels = 0xFFFFFFFFu;

// One traced batch: its rays, their hits, and the hits in shading order (the first `hitCount`
// of `order`; `order` is empty where the engine takes them as traced, HitOrder::AsTraced).
struct TracedBatch {
    const std::vector<RayState>& rays;
    const std::vector<HitRecord>& hits;
    const std::vector<SortedHit>& order;
    size_t hitCount;
};

class ShadingEngine {
  public:
    virtual ~ShadingEngine() = default;
    // How the engine takes a batch's hits (hit_sort.h: chooseHitOrder), the same for every batch
    // of the render.
    HitOrder hitOrder() const { return hitOrder_; }
    virtual void beginIteration(uint iteration) = 0;
    // The batch's per-hit stages, hit setup to bin: contributions into `film`, continuation rays
    // into `bins`. The batch's rays and hits may be reused once this returns; its shading may
    // still be running (busy()).
    virtual void shadeBatch(const TracedBatch& batch, Film& film, DirectionalBins& bins) = 0;
    // Whether a batch is still being shaded; finish() completes it, stages after shading too.
    virtual bool busy() const { return false; }
    virtual void finish(Film& /*film*/, DirectionalBins& /*bins*/) {}
    // A stop: waits for what is in flight and drops it (the iteration is discarded).
    virtual void abandon() {}
    // Adds the engine's own counters and decisions to the stats (at the end of every iteration).
    virtual void publishStats(RenderStats& /*stats*/) {}

  protected:
    explicit ShadingEngine(HitOrder order) : hitOrder_(order) {}

  private:
    HitOrder hitOrder_;
};

} // namespace spw
