// The sorted deferred pipeline (Eisenacher et al. 2013, as the thesis builds it), one stage a
// function, in the order docs/design.md draws them:
//
//   generate   camera tiles -> thread-local ray buffers -> six directional bins
//   load       the next batch from RAM or the spill file (the one after it prefetched)
//   decompress 32-byte records -> RayState
//   sort rays  Morton radix sort, median split, or none (RaySortPolicy decides under `auto`)
//   traverse   Embree closest hits for the whole batch
//   sort hits  radix sort by (shader, object, primitive): one contiguous range per shader
//   texture    hit setup and texture lookups in that sorted order
//   shade      one pass per shader range (ShadingEngine: C++, or Vulkan compute in host/vk/),
//              overlapping the next batch's traversal where the engine has two slots
//   shadow     next-event rays traced with Embree's occlusion call
//   accumulate emitted and unoccluded contributions into the film
//   bin        continuation rays -> thread-local buffers -> bins
#pragma once

#include "host/render/backend.h"
#include "host/pipeline/batch_queue.h"
#include "host/pipeline/ray_sort.h"
#include "shared/shade_io.h"

#include <memory>

namespace spw {


// A contiguous range of a batch's hits that one dispatch shades: all of one shader, so of one
// surface model, or (hits unsorted) every hit, of any model: kMixedModels.
struct ShadeRange {
    uint model; // kModel*, or kMixedModels
    size_t begin, count;
};
constexpr uint kMixedModels = 0xFFFFFFFFu;

// Where one batch's hits are shaded. The texture stage writes `inputs` in place (for the Vulkan
// engine that is the mapped device buffer itself: no copy); `results` hold the shadow rays, their
// pending contributions and the continuation rays once ShadingEngine::finish() returns.
struct ShadeSlot {
    ShadeInput* inputs = nullptr;
    const ShadeResult* results = nullptr;
};

// Shades a batch's hits, one pass per range, with shared/path.h's shadeSurface(): as C++ in TBB
// tasks of `shading size` hits (makeCpuShading), or as Vulkan compute dispatches
// (host/vk/vulkan_shading.h).
class ShadingEngine {
  public:
    virtual ~ShadingEngine() = default;
    virtual void beginIteration(uint iteration) = 0;
    // Batches that may be in flight at once. With 2 the renderer traverses and sets up batch k+1
    // while batch k is being shaded (double buffering); with 1 each batch is shaded in turn.
    virtual int slots() const { return 1; }
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

class SortedRenderer : public Backend {
  public:
    SortedRenderer(const RenderContext& ctx, const PipelineConfig& config,
                   std::unique_ptr<ShadingEngine> shading);
    ~SortedRenderer() override;
    void renderIteration(uint iteration, Film& film) override;

  private:
    struct Scratch;
    void generate(uint iteration, Film& film);
    // One batch in two halves, so that a batch's shading can overlap the next one's traversal:
    // decompress .. texture, then submit its shading to `slot`; then wait for it, trace its
    // shadow rays, accumulate and bin its continuation rays.
    void startBatch(RayBatch& batch, int slot);
    void finishBatch(int slot, uint iteration, Film& film);
    vec2 filmPosition(uint pathId, uint iteration) const;
    uint sampleOf(uint pathId, uint iteration) const; // render-wide sample index
    uvec4 roundingBits(const PathState& path, uint iteration) const;
    void publishStats();

    RenderContext ctx_;
    PipelineConfig config_;
    std::unique_ptr<ShadingEngine> shading_;
    std::unique_ptr<BatchQueue> queue_;
    std::unique_ptr<DirectionalBins> bins_;
    RaySortPolicy policy_;
    std::unique_ptr<Scratch> scratch_;
    std::uint64_t batchesProcessed_ = 0;
};

std::unique_ptr<ShadingEngine> makeCpuShading(const RenderContext& ctx);

} // namespace spw
