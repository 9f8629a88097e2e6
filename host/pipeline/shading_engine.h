// The shading engine: what the sorted pipeline hands over once a batch is traced and its hits
// are sorted, in one call (shadeBatch). The engine does the per-hit stages from there, hit setup
// to bin (stages.h), its own way, and says how it wants the hits ordered. Two engines: C++ on the
// host's threads (cpu_shading.h), fusing the stages chunk by chunk, and Vulkan compute
// (host/vk/vulkan_shading.h), overlapping a batch's shading with the next batch's traversal.
// Both shade contiguous ranges of hits, one surface model each (ShadeRange), through a slot's
// inputs and results (SlottedEngine, slotted_engine.h).
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
// of `order`; `order` is empty where the engine takes the hits in traversal order,
// takesTraversalOrder()).
struct TracedBatch {
    const std::vector<RayState>& rays;
    const std::vector<HitRecord>& hits;
    const std::vector<SortedHit>& order;
    size_t hitCount;
};

class ShadingEngine {
  public:
    virtual ~ShadingEngine() = default;
    // Whether the hits are sorted by (shader, object, texture order) before shading: the
    // engine's rule for --hit-sort auto (render_config.h: HitSortMode).
    virtual bool sortsHits() const = 0;
    // Whether, within a shader, sorted hits follow object and texture order where the scene reads
    // image textures (neighbouring lookups share tiles); otherwise they keep traversal order, and
    // the radix sort takes one pass instead of three or four.
    virtual bool ordersByTexture() const { return true; }
    // Whether, where the scene has no environment for the misses to see, the engine takes the
    // hits unsorted, in traversal order, misses in place (no hit sort at all).
    virtual bool takesTraversalOrder() const { return false; }
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
};

} // namespace spw
