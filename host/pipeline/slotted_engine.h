// The shading engines' common machinery: a batch's hits are set up into a slot's inputs, its
// ranges submitted, and once the slot's results are complete, the stages after shading run
// (shadow, accumulate, bin; fused chunk by chunk, or each over the whole batch). With two slots a
// batch's shading overlaps the next batch's traversal and setup: batch k is finished before
// batch k + 2 starts, in any order, as the film and the random numbers do not depend on it.
// An engine says how many slots it has and how it shades a slot (reserve, submit, wait).
#pragma once

#include "embree_backend/batch_traversal.h"
#include "host/backend/backend.h"
#include "host/pipeline/shading_engine.h"

#include <vector>

namespace spw {

// Where one batch's hits are shaded. The hit-setup stage writes `inputs` in place (for the Vulkan
// engine that is the mapped device buffer itself: no copy); `results` hold the shadow rays, their
// pending contributions and the continuation rays once the slot's wait() returns.
struct ShadeSlot {
    ShadeInput* inputs = nullptr;
    const ShadeResult* results = nullptr;
};

class SlottedEngine : public ShadingEngine {
  public:
    SlottedEngine(const RenderContext& ctx, HitOrder order);
    void beginIteration(uint iteration) override {
        iteration_ = iteration;
        next_ = 0;
    }
    void shadeBatch(const TracedBatch& batch, Film& film, DirectionalBins& bins) override;
    bool busy() const override { return pending_ >= 0; }
    void finish(Film& film, DirectionalBins& bins) override;
    void abandon() override;
    void publishStats(RenderStats& stats) override;

    // The slot primitives an engine implements; public for the tests that compare two engines'
    // kernels hit by hit on the same inputs.
    // Batches that may be in flight at once: 1 or 2.
    virtual int slots() const = 0;
    // Storage for `count` hits in `slot`; the slot's previous batch is finished. Valid until the
    // slot's next reserve().
    virtual ShadeSlot reserve(int slot, size_t count) = 0;
    // Starts shading the slot's ranges (in order, each over inputs[begin, begin + count)).
    virtual void submit(int slot, const std::vector<ShadeRange>& ranges) = 0;
    // Returns once the slot's results are complete.
    virtual void wait(int slot) = 0;

  protected:
    RenderContext ctx_;
    uint iteration_ = 0;

  private:
    void start(const TracedBatch& batch, int slot);
    void finishSlot(int slot, Film& film, DirectionalBins& bins);

    // A batch between its submit and its accumulation.
    struct InFlight {
        size_t hitCount = 0;
        ShadeSlot shading;
        std::vector<uvec2> paths; // (pathId, bounce) per hit: the film needs them, and the
                                  // inputs may sit in write-combined device memory
    };
    ShaderRanks shaderRanks_; // the shaders' ranks in the hit sort (hit_sort.h)
    InFlight inFlight_[2];
    int pending_ = -1; // the slot whose batch is being shaded
    int next_ = 0;
    std::vector<ShadeRange> ranges_;
    std::vector<ShadowRay> shadows_;
    std::vector<std::uint32_t> shadowOwner_;
    std::vector<std::uint8_t> occluded_;
};

} // namespace spw
