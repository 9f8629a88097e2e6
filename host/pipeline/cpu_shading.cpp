#include "host/pipeline/cpu_shading.h"

#include "shared/path.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace spw {
namespace {

class CpuShading : public ShadingEngine {
  public:
    CpuShading(SceneView view, RenderParams params, size_t chunk)
        : view_(view), params_(params), chunk_(chunk) {}
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
                                  for (size_t i = r.begin(); i < r.end(); ++i)
                                      shadeSurface(view_, params_, in[i].hit, in[i].rayDir,
                                                   in[i].path, out[i]);
                              });
        }
    }
    void finish(int /*slot*/) override {}

  private:
    SceneView view_;
    RenderParams params_;
    size_t chunk_;
    std::vector<ShadeInput> inputs_;
    std::vector<ShadeResult> results_;
};

} // namespace

std::unique_ptr<ShadingEngine> makeCpuShading(const RenderContext& ctx) {
    return std::make_unique<CpuShading>(ctx.lights.view(), ctx.params,
                                        size_t(ctx.scene.settings.shadingSize));
}

} // namespace spw
