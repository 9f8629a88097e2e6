// The sorted deferred pipeline (Eisenacher et al. 2013, as the thesis builds it), one stage a
// function, in the order DESIGN.md draws them:
//
//   generate   camera tiles -> thread-local ray buffers -> six directional bins
//   load       the next batch from RAM or the spill file (the one after it prefetched)
//   decompress 32-byte records -> RayState
//   sort rays  Morton radix sort, median split, or none (RaySortPolicy decides under `auto`)
//   traverse   Embree closest hits for the whole batch
//   sort hits  radix sort by (shader, object, primitive): one contiguous range per shader
//   texture    hit setup and texture lookups in that sorted order
//   shade      one pass per shader range (ShadingEngine: C++ here, Vulkan compute later)
//   shadow     next-event rays traced with Embree's occlusion call
//   accumulate emitted and unoccluded contributions into the film
//   bin        continuation rays -> thread-local buffers -> bins
#pragma once

#include "host/backend.h"
#include "host/pipeline/batch_queue.h"
#include "host/pipeline/ray_sort.h"

#include <memory>

namespace spw {


// One shader's contiguous range of hits, as the shading stage receives it.
struct ShadeInput {
    SurfaceHit hit;
    PathState path;
    vec3 rayDir;
    float pad0;
};

// Shades ranges of hits that share one surface model. The CPU engine runs shared/path.h's
// shadeSurface() in TBB tasks of `shading size` hits.
class ShadingEngine {
  public:
    virtual ~ShadingEngine() = default;
    virtual void beginIteration(uint iteration) = 0;
    virtual void shade(uint model, const ShadeInput* in, size_t count, ShadeResult* out) = 0;
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
    void processBatch(RayBatch& batch, uint iteration, Film& film);
    vec2 filmPosition(uint pathId, uint iteration) const;
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
