// The shade stage's interface: what the sorted pipeline hands an engine (contiguous ranges of
// set-up hits, one surface model each) and what it gets back (ShadeResult per hit). Two engines
// implement it: C++ in TBB tasks (cpu_shading.h) and Vulkan compute (host/vk/vulkan_shading.h).
#pragma once

#include "host/backend/stats.h"
#include "shared/shade_io.h"

#include <cstddef>
#include <vector>

namespace spw {

// A contiguous range of a batch's hits that one dispatch shades: all of one shader, so of one
// surface model, or (hits unsorted) every hit, of any model: kMixedModels.
struct ShadeRange {
    uint model; // kModel*, or kMixedModels
    size_t begin, count;
};
constexpr uint kMixedModels = 0xFFFFFFFFu;

// Where one batch's hits are shaded. The hit-setup stage writes `inputs` in place (for the Vulkan
// engine that is the mapped device buffer itself: no copy); `results` hold the shadow rays, their
// pending contributions and the continuation rays once ShadingEngine::finish() returns.
struct ShadeSlot {
    ShadeInput* inputs = nullptr;
    const ShadeResult* results = nullptr;
};

// Shades a batch's hits, one pass per range, with shared/path.h's shadeSurface().
class ShadingEngine {
  public:
    virtual ~ShadingEngine() = default;
    virtual void beginIteration(uint iteration) = 0;
    // Batches that may be in flight at once. With 2 the renderer traverses and sets up batch k+1
    // while batch k is being shaded (double buffering); with 1 each batch is shaded in turn.
    virtual int slots() const { return 1; }
    // True when shading runs on the host's own threads (cpu): the renderer may then call
    // shadeSurface() itself, chunk by chunk between the other per-hit stages (stages.h:
    // shadeFused), and the engine's reserve/submit/finish go unused.
    virtual bool shadesOnHostThreads() const { return false; }
    // Storage for `count` hits in `slot` (0 <= slot < slots()); the slot's previous batch must be
    // finished. Valid until the slot's next reserve().
    virtual ShadeSlot reserve(int slot, size_t count) = 0;
    // Starts shading the slot's ranges (in order, each over inputs[begin, begin + count)).
    virtual void submit(int slot, const std::vector<ShadeRange>& ranges) = 0;
    // Returns once the slot's results are complete.
    virtual void finish(int slot) = 0;
    // Adds the engine's own counters to the stats (called at the end of every iteration).
    virtual void publishStats(RenderStats& /*stats*/) {}
};

} // namespace spw
