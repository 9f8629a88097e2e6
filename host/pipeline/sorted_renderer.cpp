#include "host/pipeline/sorted_renderer.h"

#include "embree_backend/batch_traversal.h"
#include "host/pipeline/hit_sort.h"
#include "host/pipeline/parallel.h"
#include "host/pipeline/radix_sort.h"
#include "shared/path.h"

#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <chrono>

namespace spw {

struct SortedRenderer::Scratch {
    std::vector<RayState> rays, rayTmp;
    std::vector<KeyIndex> keys, keyTmp;
    std::vector<RTCRayHit> hits;
    std::vector<ShadeRange> ranges;
    // A batch between its shading submit and its accumulation, one per engine slot.
    struct InFlight {
        size_t hitCount = 0;
        ShadeSlot shading;
        std::vector<uvec2> paths; // (pathId, bounce) per hit: the film needs them, and the
                                  // inputs may sit in write-combined device memory
    };
    InFlight inFlight[2];
    std::vector<ShadowRay> shadows;
    std::vector<std::uint32_t> shadowOwner;
    std::vector<std::uint8_t> occluded;
};

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// The same shadeSurface() the kernels run, as C++: shaded at submit, one slot (TBB already
// keeps every core busy, so there is nothing to overlap).
class CpuShading : public ShadingEngine {
  public:
    CpuShading(SceneView view, RenderParams params, size_t chunk) : view_(view), params_(params), chunk_(chunk) {}
    void beginIteration(uint iteration) override { params_.iteration = iteration; }
    ShadeSlot reserve(int /*slot*/, size_t count) override {
        inputs_.resize(count);
        results_.resize(count);
        return {inputs_.data(), results_.data()};
    }
    void submit(int /*slot*/, const std::vector<ShadeRange>& ranges) override {
        for (const ShadeRange& range : ranges) {
            const ShadeInput* in = &inputs_[range.begin];
            ShadeResult* out = &results_[range.begin];
            tbb::parallel_for(tbb::blocked_range<size_t>(0, range.count, chunk_), [&](const tbb::blocked_range<size_t>& r) {
                for (size_t i = r.begin(); i < r.end(); ++i)
                    shadeSurface(view_, params_, in[i].hit, in[i].rayDir, in[i].path, out[i]);
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

ShadingMode parseShadingMode(const std::string& name) {
    if (name == "sorted") return ShadingMode::Sorted;
    if (name == "megakernel") return ShadingMode::Megakernel;
    throw std::invalid_argument("unknown shading '" + name + "' (sorted or megakernel)");
}

const char* shadingModeName(ShadingMode mode) { return mode == ShadingMode::Sorted ? "sorted" : "megakernel"; }

std::unique_ptr<ShadingEngine> makeCpuShading(const RenderContext& ctx) {
    return std::make_unique<CpuShading>(ctx.embree.view(), ctx.params, size_t(ctx.scene.settings.shadingSize));
}

SortedRenderer::SortedRenderer(const RenderContext& ctx, const PipelineConfig& config,
                               std::unique_ptr<ShadingEngine> shading)
    : ctx_(ctx), config_(config), shading_(std::move(shading)), policy_(config.raySort),
      scratch_(std::make_unique<Scratch>()) {
    const double budgetMiB = config.memoryBudgetMiB.value_or(ctx.scene.settings.memoryBudgetMiB);
    const uint exponent = uint(config.binExponent.value_or(ctx.scene.settings.binExponent));
    // The budget covers every ray waiting in RAM: the six bins fill up to one batch each, and
    // the queue keeps the rest of the budget (none when six batches already exceed it, so that
    // every batch spills). Peak rays in RAM <= max(budget, six batches), as --help states.
    const std::uint64_t budget = std::uint64_t(budgetMiB * 1024.0 * 1024.0);
    const std::uint64_t binBytes = 6 * (std::uint64_t(1) << exponent) * rayRecordBytes(config.rayFormat);
    // The spill folder is resolved (and the file made) only when a batch first spills.
    queue_ = std::make_unique<BatchQueue>(budget > binBytes ? budget - binBytes : 0, config.spillDir);
    bins_ = std::make_unique<DirectionalBins>(config.rayFormat, exponent, *queue_);
}

SortedRenderer::~SortedRenderer() = default;

vec2 SortedRenderer::filmPosition(uint pathId, uint iteration) const {
    const uint spi = ctx_.params.samplesPerIteration;
    const uint pixel = pathId / spi, s = pathId % spi;
    const uint width = uint(ctx_.scene.image.width);
    const uint x = pixel % width, y = pixel / width;
    // The Box filter needs only the pixel: skip re-deriving the sample's position in it.
    if (ctx_.scene.filter.type == FilterType::Box) return vec2(float(x) + 0.5f, float(y) + 0.5f);
    return ctx_.camera.filmPosition(x, y, s, iteration * spi + s, ctx_.params.seed);
}

uint SortedRenderer::sampleOf(uint pathId, uint iteration) const {
    const uint spi = ctx_.params.samplesPerIteration;
    return iteration * spi + pathId % spi;
}

uvec4 SortedRenderer::roundingBits(const PathState& path, uint iteration) const {
    const uint spi = ctx_.params.samplesPerIteration;
    return pcg4d(uvec4(path.pathId / spi, iteration * spi + path.pathId % spi, (path.bounce << 8u) | kDimRounding,
                       ctx_.params.seed));
}

void SortedRenderer::generate(uint iteration, Film& film) {
    StageTimer timer(ctx_.stats.stages, "generate");
    const Scene& scene = ctx_.scene;
    const int width = scene.image.width, height = scene.image.height, tile = scene.settings.bucketSize;
    const uint spi = ctx_.params.samplesPerIteration;
    const int tilesX = (width + tile - 1) / tile, tilesY = (height + tile - 1) / tile;
    tbb::parallel_for(0, tilesX * tilesY, [&](int t) {
        const int x0 = (t % tilesX) * tile, y0 = (t / tilesX) * tile;
        RayBuffer buffer; // the tile's thread-local buffer, handed to the bins whole
        for (int y = y0; y < std::min(height, y0 + tile); ++y)
            for (int x = x0; x < std::min(width, x0 + tile); ++x)
                for (uint s = 0; s < spi; ++s) {
                    CameraRay cr = ctx_.camera.generate(uint(x), uint(y), s, iteration * spi + s, ctx_.params.seed);
                    film.addSample(cr.filmPos, iteration * spi + s);
                    RayState r;
                    r.origin = cr.origin;
                    r.dir = cr.dir;
                    r.path = PathState{};
                    r.path.beta = vec3(1.0f);
                    r.path.pathId = uint(y * width + x) * spi + s;
                    buffer.push(r, config_.rayFormat, roundingBits(r.path, iteration));
                }
        ctx_.stats.cameraRays += buffer.count;
        bins_->add(buffer);
    });
}

void SortedRenderer::renderIteration(uint iteration, Film& film) {
    shading_->beginIteration(iteration);
    generate(iteration, film);
    // With two engine slots, batch k's shading runs while batch k+1 is loaded, traversed and set
    // up; batch k is then finished (its continuation rays binned) before k+2 starts. Batches may
    // be finished in any order: the film and the random numbers do not depend on it.
    const bool overlap = shading_->slots() > 1;
    int pending = -1; // the slot whose batch is being shaded
    int next = 0;
    for (;;) {
        std::optional<RayBatch> batch = queue_->pop(ctx_.stats.stages);
        if (!batch) {
            if (pending >= 0) { // its continuation rays may refill the queue
                finishBatch(pending, iteration, film);
                pending = -1;
                continue;
            }
            if (!bins_->flushLargest()) break; // queue and bins empty: the iteration is done
            continue;
        }
        startBatch(*batch, next);
        if (pending >= 0) finishBatch(pending, iteration, film);
        if (overlap) {
            pending = next;
            next ^= 1;
        } else {
            finishBatch(next, iteration, film);
        }
    }
    publishStats();
}

void SortedRenderer::startBatch(RayBatch& batch, int slot) {
    Scratch& s = *scratch_;
    Scratch::InFlight& flight = s.inFlight[slot];
    StageTimes& times = ctx_.stats.stages;
    const size_t n = batch.count;
    const size_t recordBytes = rayRecordBytes(batch.format);
    ++batchesProcessed_;

    // decompress
    size_t cameraRays = 0;
    {
        StageTimer t(times, "decompress");
        s.rays.resize(n);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t i = r.begin(); i < r.end(); ++i) decodeRay(&batch.bytes[i * recordBytes], batch.format, s.rays[i]);
        });
        cameraRays = parallelCount(n, [&](size_t i) { return s.rays[i].path.bounce == 0; });
        std::vector<std::uint8_t>().swap(batch.bytes);
    }

    // sort rays + traverse
    const RaySortMode mode = policy_.choose(double(cameraRays) / double(std::max<size_t>(n, 1)));
    const auto sortStart = Clock::now();
    if (mode == RaySortMode::Morton || mode == RaySortMode::Median) {
        StageTimer t(times, "sort rays");
        if (mode == RaySortMode::Morton) sortRaysMorton(s.rays, s.keys, s.keyTmp, s.rayTmp);
        else sortRaysMedian(s.rays);
    }
    const bool sorted = mode != RaySortMode::Off;
    {
        StageTimer t(times, "traverse");
        intersectBatch(ctx_.embree, s.rays, sorted, s.hits);
    }
    if (cameraRays * 2 < n) policy_.record(sorted, since(sortStart), n);
    ctx_.stats.bounceRays += n - cameraRays;

    // sort hits by (shader, object, primitive); misses go last and are dropped
    size_t hitCount = 0;
    {
        StageTimer t(times, "sort hits");
        s.keys.resize(n);
        const bool sortHits = config_.sortsHits();
        tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kParallelGrain), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t i = r.begin(); i < r.end(); ++i) {
                const RTCHit& h = s.hits[i].hit;
                std::uint64_t key = kMissKey;
                if (h.geomID != RTC_INVALID_GEOMETRY_ID) {
                    key = sortHits ? hitSortKey(uint(ctx_.scene.meshes[h.geomID].shader), h.geomID, h.primID) : 0;
                }
                s.keys[i] = {key, std::uint32_t(i)};
            }
        });
        hitCount = parallelCount(n, [&](size_t i) { return s.keys[i].key != kMissKey; });
        if (config_.sortsHits()) {
            radixSort(s.keys, s.keyTmp);
        } else {
            // No sort: keep traversal order, just move the misses out.
            std::stable_partition(s.keys.begin(), s.keys.end(), [](const KeyIndex& k) { return k.key != kMissKey; });
        }
    }

    // texture: hit setup and texture lookups in sorted order
    {
        StageTimer t(times, "texture");
        flight.hitCount = hitCount;
        flight.shading = shading_->reserve(slot, hitCount);
        flight.paths.resize(hitCount);
        ShadeInput* inputs = flight.shading.inputs;
        tbb::parallel_for(tbb::blocked_range<size_t>(0, hitCount, 1024), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t i = r.begin(); i < r.end(); ++i) {
                const std::uint32_t k = s.keys[i].index;
                const RTCRayHit& rh = s.hits[k];
                ShadeInput in; // assembled here, stored whole: one sequential write into the slot
                ctx_.embree.surfaceHit(rh.hit.geomID, rh.hit.primID, rh.hit.u, rh.hit.v, rh.ray.tfar, in.hit);
                in.hit.albedo = ctx_.textures.albedo(ctx_.scene.shaders[in.hit.shader],
                                                     ctx_.embree.uvAt(rh.hit.geomID, rh.hit.primID, rh.hit.u, rh.hit.v));
                in.path = s.rays[k].path;
                in.rayDir = s.rays[k].dir;
                in.pad0 = 0.0f;
                inputs[i] = in;
                flight.paths[i] = uvec2(in.path.pathId, in.path.bounce);
            }
        });
    }

    // shade: one range per contiguous shader range (the whole list when hits are unsorted),
    // found from the sort keys, which carry the shader in their top bits
    {
        StageTimer t(times, "shade");
        s.ranges.clear();
        if (config_.sortsHits()) {
            for (const ShaderRun& run : shaderRuns(s.keys, hitCount))
                s.ranges.push_back({ctx_.scene.shaders[run.shader].params.model, run.begin, run.count});
        } else if (hitCount > 0) {
            s.ranges.push_back({kMixedModels, 0, hitCount});
        }
        shading_->submit(slot, s.ranges);
    }
}

void SortedRenderer::finishBatch(int slot, uint iteration, Film& film) {
    Scratch& s = *scratch_;
    StageTimes& times = ctx_.stats.stages;
    const Scratch::InFlight& flight = s.inFlight[slot];
    const size_t hitCount = flight.hitCount;
    const ShadeResult* results = flight.shading.results;
    {
        StageTimer t(times, "shade");
        shading_->finish(slot);
    }

    // shadow rays
    {
        StageTimer t(times, "shadow");
        parallelSelect(hitCount, [&](size_t i) { return (results[i].flags & kShadeShadow) != 0; }, s.shadowOwner);
        s.shadows.resize(s.shadowOwner.size());
        tbb::parallel_for(tbb::blocked_range<size_t>(0, s.shadows.size(), kParallelGrain),
                          [&](const tbb::blocked_range<size_t>& r) {
                              for (size_t j = r.begin(); j < r.end(); ++j) {
                                  const ShadeResult& res = results[s.shadowOwner[j]];
                                  s.shadows[j] = {res.shadowOrigin, res.shadowDir, res.shadowTmax};
                              }
                          });
        occludedBatch(ctx_.embree, s.shadows, false, s.occluded);
        ctx_.stats.shadowRays += s.shadows.size();
    }

    // accumulate
    {
        StageTimer t(times, "accumulate");
        tbb::parallel_for(tbb::blocked_range<size_t>(0, hitCount, 1024), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t i = r.begin(); i < r.end(); ++i)
                if (results[i].flags & kShadeEmitted) {
                    const uvec2 p = flight.paths[i]; // (pathId, bounce)
                    film.splat(filmPosition(p.x, iteration), sampleOf(p.x, iteration), results[i].emitted,
                               filmKey(p.x, p.y, false));
                }
        });
        tbb::parallel_for(tbb::blocked_range<size_t>(0, s.shadows.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t j = r.begin(); j < r.end(); ++j)
                if (!s.occluded[j]) {
                    const size_t i = s.shadowOwner[j];
                    const uvec2 p = flight.paths[i]; // (pathId, bounce)
                    film.splat(filmPosition(p.x, iteration), sampleOf(p.x, iteration),
                               results[i].shadowContribution, filmKey(p.x, p.y, true));
                }
        });
    }

    // bin the continuation rays through thread-local buffers
    {
        StageTimer t(times, "bin");
        const size_t chunk = size_t(ctx_.scene.settings.shadingSize);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, hitCount, chunk), [&](const tbb::blocked_range<size_t>& r) {
            RayBuffer buffer;
            for (size_t i = r.begin(); i < r.end(); ++i) {
                const ShadeResult& res = results[i];
                if (!(res.flags & kShadeContinue)) continue;
                RayState ray;
                ray.origin = res.nextOrigin;
                ray.dir = res.nextDir;
                ray.path = res.next;
                buffer.push(ray, config_.rayFormat, roundingBits(ray.path, iteration));
            }
            bins_->add(buffer);
        });
    }
}

void SortedRenderer::publishStats() {
    const QueueCounters c = queue_->counters();
    nlohmann::json& x = ctx_.stats.extra;
    x["batches_processed"] = batchesProcessed_;
    x["batches_queued"] = c.batchesQueued;
    x["batches_spilled"] = c.batchesSpilled;
    x["bytes_spilled_written"] = c.bytesWritten;
    x["bytes_spilled_read"] = c.bytesRead;
    x["peak_ray_bytes_in_ram"] = c.peakRamBytes;
    x["ray_format"] = config_.rayFormat == RayFormat::Compact ? "compact" : "full";
    x["ray_record_bytes"] = rayRecordBytes(config_.rayFormat);
    x["ray_sort"] = raySortName(config_.raySort);
    x["hit_sort"] = config_.sortsHits();
    x["shading"] = shadingModeName(config_.sortsHits() ? ShadingMode::Sorted : ShadingMode::Megakernel);
    x["batches_ray_sorted"] = policy_.sortedBatches();
    x["batches_ray_unsorted_measured"] = policy_.unsortedBatches();
    shading_->publishStats(ctx_.stats);
}

} // namespace spw
