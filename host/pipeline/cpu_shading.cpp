#include "host/pipeline/cpu_shading.h"

#include "host/pipeline/simd_shading.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace spw {
namespace {

class CpuShading : public ShadingEngine {
  public:
    CpuShading(SceneView view, RenderParams params, size_t chunk, bool simd)
        : view_(view), params_(params), chunk_(chunk), simd_(simd) {}
    void beginIteration(uint iteration) override { params_.iteration = iteration; }
    bool shadesOnHostThreads() const override { return true; }
    ShadeSlot reserve(int /*slot*/, size_t count) override {
        inputs_.resize(count);
        results_.resize(count);
        return {inputs_.data(), results_.data()};
    }
    void submit(int /*slot*/, const std::vector<ShadeRange>& ranges) override {
        for (const ShadeRange& range : ranges) {
            const ShadeInput* in = &inputs_[range.begin];
            ShadeResult* out = &results_[range.begin];
            tbb::parallel_for(tbb::blocked_range<size_t>(0, range.count, chunk_),
                              [&](const tbb::blocked_range<size_t>& r) {
                                  shadeHits(view_, params_, simd_, in + r.begin(), r.size(),
                                            out + r.begin());
                              });
        }
    }
    void finish(int /*slot*/) override {}
    void publishStats(RenderStats& stats) override {
        stats.extra["simd_shading"] = simd_ ? simdShadingTarget() : "off";
    }

  private:
    SceneView view_;
    RenderParams params_;
    size_t chunk_;
    bool simd_;
    std::vector<ShadeInput> inputs_;
    std::vector<ShadeResult> results_;
};

} // namespace

bool usesSimdShading(const RenderContext& ctx) {
    return ctx.config.pipeline.simdShading && simdShadingApplies(ctx.lights.view());
}

std::unique_ptr<ShadingEngine> makeCpuShading(const RenderContext& ctx) {
    return std::make_unique<CpuShading>(ctx.lights.view(), ctx.params,
                                        size_t(ctx.scene.settings.shadingSize),
                                        usesSimdShading(ctx));
}

} // namespace spw
