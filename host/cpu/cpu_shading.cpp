#include "host/cpu/cpu_shading.h"

#include "host/cpu/simd_shading.h"
#include "host/pipeline/slotted_engine.h"
#include "host/pipeline/stages.h"
#include "host/scene/surface_models.h"
#include "host/simd/simd_target.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <set>

namespace spw {
namespace {

// Sorted hits pay on the cpu only where textures are read (coherent tile reads); elsewhere it
// shades the same function whatever the order, and the sort measured a pure cost (0.25 s of a 4 s
// render on the Cornell box). Sorted by shader alone, a shader's hits read its images together
// (texture by texture, the 8-bit lookups SIMD-wide); object and texture order within it pay only
// where the images outgrow the tile cache (neighbouring lookups then share tiles before they are
// evicted: ProductionScene.* reads a third of the tiles), or where --hit-sort on asks for them.
// Where the cache holds the images they cost more than they gain. Measured (docs/performance.md,
// "Time to Cycles' error"): the shader alone 4-12 % faster than the whole key on 2 textured
// shaders (64^2 and 1024^2 images) and on 4, 16 and 64 shaders of 7 images each. The fused loop
// takes unsorted hits straight from traversal (shadeFused); the separate stages set up a slot
// through the order.
HitOrder cpuHitOrder(const RenderContext& ctx) {
    const PipelineConfig& p = ctx.config.pipeline;
    const bool asked = p.hitSort == HitSortMode::On;
    const HitOrderRule rule{p.sortsHits() && (asked || ctx.textures.active()),
                            asked || ctx.textures.outgrowsCache(), p.fuseStages};
    return chooseHitOrder(rule, ctx.textures.active(), ctx.params.environment != kNoEmitter);
}

// What both cpu engines report: the instruction set, and the scene's surface models by how their
// hits were shaded: a run at a time through their wide twin, or one hit at a time (kWideTwins).
void publishCpuStats(const Scene& scene, bool simd, RenderStats& stats) {
    stats.extra["simd_shading"] = simd ? simdTarget() : "off";
    std::set<uint> used;
    for (const Shader& shader : scene.shaders)
        used.insert(shader.params.model);
    nlohmann::json wide = nlohmann::json::array(), scalar = nlohmann::json::array();
    for (uint model : used)
        (simd && kWideTwins[model].shade ? wide : scalar).push_back(surfaceModel(model)->name);
    stats.extra["wide_models"] = wide;
    stats.extra["scalar_models"] = scalar;
}

// The default: every per-hit stage, hit setup to bin, chunk by chunk of sorted hits (stages.h:
// shadeFused), on the host's threads.
class FusedCpuShading : public ShadingEngine {
  public:
    FusedCpuShading(const RenderContext& ctx, bool simd)
        : ShadingEngine(cpuHitOrder(ctx)), ctx_(ctx), view_(ctx.lights.view()), simd_(simd) {}

    void beginIteration(uint iteration) override { iteration_ = iteration; }
    void shadeBatch(const TracedBatch& b, Film& film, DirectionalBins& bins) override {
        const ShadeChunk shade = [&](const RenderParams& rp, const ShadeInput* in, size_t n,
                                     ShadeResult* out) { shadeHits(view_, rp, simd_, in, n, out); };
        shadeFused(ctx_, iteration_, ctx_.config.pipeline.rayFormat, shade, b.rays, b.hits, b.order,
                   b.hitCount, film, bins);
    }
    void publishStats(RenderStats& stats) override {
        stats.extra["stages"] = "fused"; // every per-hit stage chunk by chunk
        publishCpuStats(ctx_.scene, simd_, stats);
    }

  private:
    RenderContext ctx_;
    SceneView view_;
    bool simd_;
    uint iteration_ = 0;
};

// --stages separate: each stage over the whole batch in turn, through one slot, the ranges shaded
// in TBB tasks of `shading size` hits.
class StagedCpuShading : public SlottedEngine {
  public:
    StagedCpuShading(const RenderContext& ctx, bool simd)
        : SlottedEngine(ctx, cpuHitOrder(ctx)), view_(ctx.lights.view()), params_(ctx.params),
          chunk_(size_t(ctx.scene.settings.shadingSize)), simd_(simd) {}

    void beginIteration(uint iteration) override {
        SlottedEngine::beginIteration(iteration);
        params_.iteration = iteration;
    }
    void publishStats(RenderStats& stats) override {
        SlottedEngine::publishStats(stats);
        publishCpuStats(ctx_.scene, simd_, stats);
    }

    int slots() const override { return 1; }
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
    void wait(int /*slot*/) override {}

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
    return ctx.config.pipeline.simdShading;
}

std::unique_ptr<ShadingEngine> makeCpuShading(const RenderContext& ctx) {
    if (ctx.config.pipeline.fuseStages)
        return std::make_unique<FusedCpuShading>(ctx, usesSimdShading(ctx));
    return std::make_unique<StagedCpuShading>(ctx, usesSimdShading(ctx));
}

} // namespace spw
