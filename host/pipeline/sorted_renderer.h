// The sorted deferred pipeline as a backend: it runs the stages of host/pipeline/stages.h over
// every batch of an iteration, overlapping a batch's shading with the next batch's traversal
// where the shading engine has two slots, and fusing the per-hit stages chunk by chunk where the
// engine shades on the host's threads.
#pragma once

#include "host/backend/backend.h"
#include "host/pipeline/batch_queue.h"
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
    // One batch in two halves, so that a batch's shading can overlap the next one's traversal:
    // sort rays .. hit setup, then submit its shading to `slot`; then wait for it, trace its
    // shadow rays, accumulate and bin its continuation rays. The misses' environment goes into
    // the film at once.
    void startBatch(bool camera, int slot, uint iteration, Film& film);
    // sort rays .. sort hits: the batch's hits in shading order in the scratch; their count.
    size_t traceBatch(bool camera);
    // The whole batch with the per-hit stages fused (stages.h: shadeFused), for the cpu engine.
    void runFusedBatch(bool camera, uint iteration, Film& film);
    void finishBatch(int slot, uint iteration, Film& film);
    // escape: the batch's misses see the environment (stages.h: accumulateEscapes).
    void escapes(uint iteration, size_t hitCount, Film& film);
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
    bool fused_;
    bool simdShading_; // the fused loop's Lambert hits SIMD-wide (cpu_shading.h: usesSimdShading)
    bool sortHits_;    // the hit sort's auto rule applied (render_config.h: HitSortMode)
    ShaderOrder shaderOrder_; // the shaders' ranks in the hit sort (hit_sort.h)
    std::uint64_t batchesProcessed_ = 0;
};

} // namespace spw
