// The sorted deferred pipeline as a backend: for every batch of an iteration it generates or
// loads the rays, sorts them, traverses them and sorts the hits (stages.h), then hands the batch
// to the shading engine in one call (shading_engine.h), which runs the per-hit stages its own way
// (fused on the cpu; overlapped with the next batch's traversal on Vulkan).
#pragma once

#include "host/backend/backend.h"
#include "host/pipeline/batch_queue.h"
#include "host/pipeline/directional_bins.h"
#include "host/pipeline/ray_sort.h"
#include "host/pipeline/shading_engine.h"
#include "host/pipeline/stages.h"

#include <memory>

namespace spw {

class SortedRenderer : public Backend {
  public:
    SortedRenderer(const RenderContext& ctx, const PipelineConfig& config,
                   std::unique_ptr<ShadingEngine> shading);
    ~SortedRenderer() override;
    bool renderIteration(uint iteration, Film& film) override;

  private:
    struct Scratch;
    // The next batch's rays into the scratch: a queued batch of bounce rays (load, decompress),
    // else the next camera rays (generate), else, if `flush`, the part-full bins'
    // (DirectionalBins::flush). False when none.
    bool nextBatch(Film& film, bool flush, bool& camera);
    // sort rays .. sort hits: the batch's hits in shading order in the scratch; their count.
    size_t traceAndSortBatch(bool camera);
    // escape: the batch's misses see the environment (stages.h: accumulateEscapes).
    void addEscapedRadiance(uint iteration, size_t hitCount, Film& film);
    void publishStats();

    RenderContext ctx_;
    PipelineConfig config_;
    std::unique_ptr<ShadingEngine> shading_;
    std::unique_ptr<BatchQueue> queue_;
    std::unique_ptr<DirectionalBins> bins_;
    CameraRays cameraRays_;
    size_t batchRays_; // 2^(bin exponent)
    RaySortPolicy policy_;
    std::unique_ptr<Scratch> scratch_;
    ShaderRanks shaderRanks_; // the shaders' ranks in the hit sort (hit_sort.h)
    std::uint64_t batchesProcessed_ = 0;
};

} // namespace spw
