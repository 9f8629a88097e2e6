// The fused stages: hit setup .. bin (shadeFused, the C++ engine's --stages fused) or shadow ..
// bin (finishFused, after a Vulkan dispatch) run chunk by chunk of hits on one thread, so that a
// chunk's records stay in cache between the stages. The per-hit functions are stages.cpp's, and
// so is the image, bit for bit.
#include "host/pipeline/stages.h"

#include "host/pipeline/parallel.h"
#include "host/pipeline/stage_chunks.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <memory>

namespace spw {

namespace {
// The fused stages' working set: one chunk of hits through every per-hit stage.
constexpr size_t kFusedChunk = kChunk;
struct FusedChunk {
    ShadeInput in[kFusedChunk];
    ShadeResult out[kFusedChunk];
    ShadowRay shadows[kFusedChunk];
    std::uint8_t owner[kFusedChunk];
    std::uint8_t occluded[kFusedChunk];
    SortedHit hits[kFusedChunk]; // the chunk's hits when the batch's hits were not sorted
};
static_assert(kFusedChunk <= 256, "owner indices are bytes");

enum FusedStage { kSetUp, kShade, kShadow, kAccumulate, kBin, kFusedStages };
const char* const kFusedStageNames[kFusedStages] = {"hit setup", "shade", "shadow", "accumulate",
                                                    "bin"};

// One task's share of a fused loop: its stage clock, continuation rays and film splats.
class FusedTask {
  public:
    using Clock = std::chrono::steady_clock;
    explicit FusedTask(Film& film) : c(std::make_unique<FusedChunk>()), splats(film) {}

    // The time since the last lap goes to `stage`.
    void lap(FusedStage stage) {
        const auto now = Clock::now();
        ns[stage] += std::chrono::duration_cast<std::chrono::nanoseconds>(now - t_).count();
        t_ = now;
    }

    // The stages after shading, for the results out[0, n) (n <= kFusedChunk) of the hits whose
    // (pathId, bounce) pathOf(i) gives: their shadow rays traced, what they emitted and what
    // their unoccluded shadow rays bring splatted, their continuation rays encoded.
    template <class PathOf>
    void finishChunk(const RenderContext& ctx, const RenderParams& rp, RayFormat format,
                     const ShadeResult* out, size_t n, PathOf pathOf) {
        size_t m = 0;
        for (size_t i = 0; i < n; ++i)
            if (out[i].flags & kShadeShadow) {
                const ShadeResult& res = out[i];
                c->owner[m] = std::uint8_t(i);
                c->shadows[m++] = {res.shadowOrigin, res.shadowDir, res.shadowTmax};
            }
        occludedRange(ctx.embree, c->shadows, m, false, c->occluded);
        shadowRays += m;
        lap(kShadow);
        for (size_t i = 0; i < n; ++i)
            if (out[i].flags & kShadeEmitted) splats.emitted(ctx, rp, out[i], pathOf(i));
        for (size_t j = 0; j < m; ++j)
            if (!c->occluded[j]) {
                const size_t i = c->owner[j];
                splats.shadow(ctx, rp, out[i], pathOf(i));
            }
        splats.flush();
        lap(kAccumulate);
        buffer.pushContinuations(rp, format, out, n);
        lap(kBin);
    }

    std::unique_ptr<FusedChunk> c;
    RayBuffer buffer;
    SplatBatch splats;
    std::uint64_t shadowRays = 0;
    std::int64_t ns[kFusedStages] = {};

  private:
    Clock::time_point t_ = Clock::now();
};

// What the tasks of one fused loop add up to, and its wall time shared among the stages in
// proportion to their thread time, into --stats.
class FusedTimes {
  public:
    void add(FusedTask& task, DirectionalBins& bins) {
        bins.add(task.buffer);
        task.lap(kBin);
        for (int s = 0; s < kFusedStages; ++s)
            threadNs_[s] += task.ns[s];
        shadowRays_ += task.shadowRays;
    }
    // The stages from `first` on are this loop's.
    void publish(const RenderContext& ctx, FusedStage first) const {
        ctx.stats.shadowRays += shadowRays_.load();
        const double wall = std::chrono::duration<double>(FusedTask::Clock::now() - start_).count();
        double total = 0.0;
        for (const auto& ns : threadNs_)
            total += double(ns.load());
        for (int s = first; s < kFusedStages; ++s)
            ctx.stats.stages.add(kFusedStageNames[s],
                                 total > 0.0 ? wall * double(threadNs_[s].load()) / total : 0.0);
    }

  private:
    FusedTask::Clock::time_point start_ = FusedTask::Clock::now();
    std::atomic<std::int64_t> threadNs_[kFusedStages] = {};
    std::atomic<std::uint64_t> shadowRays_{0};
};
} // namespace

void shadeFused(const RenderContext& ctx, uint iteration, RayFormat format, const ShadeChunk& shade,
                const std::vector<RayState>& rays, const std::vector<HitRecord>& hits,
                const std::vector<SortedHit>& order, size_t hitCount, Film& film,
                DirectionalBins& bins) {
    const RenderParams rp = paramsAt(ctx, iteration);
    FusedTimes times;
    const bool inTraversalOrder = order.empty();
    prepareTextures(ctx, hits, inTraversalOrder ? nullptr : order.data(), hitCount);
    // Tasks of up to `shading size` hits, each handing its continuation rays to the bins once.
    const size_t grain = batchGrain(hitCount, kFusedChunk, size_t(ctx.scene.settings.shadingSize));
    tbb::parallel_for(tbb::blocked_range<size_t>(0, hitCount, grain),
                      [&](const tbb::blocked_range<size_t>& r) {
                          FusedTask task(film);
                          FusedChunk& c = *task.c;
                          for (size_t begin = r.begin(); begin < r.end(); begin += kFusedChunk) {
                              size_t n = std::min(kFusedChunk, r.end() - begin);
                              const SortedHit* chunk = inTraversalOrder ? c.hits : &order[begin];
                              if (inTraversalOrder) {
                                  size_t h = 0;
                                  for (size_t i = begin; i < begin + n; ++i)
                                      if (hits[i].mesh != kNoHit)
                                          c.hits[h++] = {0, std::uint32_t(i)};
                                  n = h;
                              }
                              setUpChunk(ctx, rays, hits, chunk, n, c.in);
                              task.lap(kSetUp);
                              shade(rp, c.in, n, c.out);
                              task.lap(kShade);
                              task.finishChunk(ctx, rp, format, c.out, n, [&](size_t i) {
                                  return uvec2(c.in[i].path.pathId, c.in[i].path.bounce);
                              });
                          }
                          times.add(task, bins);
                      });
    times.publish(ctx, kSetUp);
}

void finishFused(const RenderContext& ctx, uint iteration, RayFormat format,
                 const ShadeResult* results, const uvec2* paths, size_t hitCount, Film& film,
                 DirectionalBins& bins) {
    const RenderParams rp = paramsAt(ctx, iteration);
    FusedTimes times;
    const size_t grain = batchGrain(hitCount, kFusedChunk, size_t(ctx.scene.settings.shadingSize));
    tbb::parallel_for(tbb::blocked_range<size_t>(0, hitCount, grain),
                      [&](const tbb::blocked_range<size_t>& r) {
                          FusedTask task(film);
                          for (size_t begin = r.begin(); begin < r.end(); begin += kFusedChunk) {
                              const size_t n = std::min(kFusedChunk, r.end() - begin);
                              task.finishChunk(ctx, rp, format, results + begin, n,
                                               [&](size_t i) { return paths[begin + i]; });
                          }
                          times.add(task, bins);
                      });
    times.publish(ctx, kShadow);
}

} // namespace spw
