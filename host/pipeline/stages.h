// The sorted deferred pipeline's stages (Eisenacher et al. 2013, as the thesis builds it), in the
// order docs/design.md draws the data flow. SortedRenderer (sorted_renderer.cpp) calls them one a
// line; each is timed in --stats under the name given here.
//
//   generate      camera rays, a batch at a time, when no bounce batch is waiting
//   load          the next batch from RAM or the spill file      BatchQueue::pop (batch_queue.h)
//   decompress    34- or 50-byte records -> RayState
//   sort rays     Morton radix sort, median split, or none        ray_sort.h; RaySortPolicy decides
//   traverse      closest hits of the whole batch                 intersectBatch (embree_backend/)
//   sort hits     by (shader, object, texture order), misses last
//   escape        misses see the environment (scenes with one)
//   hit setup     world-space hit and texture albedo, in sorted order, into the engine's inputs
//   shade         one pass per shader range                       ShadingEngine (shading_engine.h)
//   shade wait    until the engine's results are complete
//   shadow        next-event rays, traced with Embree's occlusion call
//   accumulate    emitted and unoccluded contributions into the film
//   bin           continuation rays -> thread-local ray buffers -> bins
#pragma once

#include "embree_backend/batch_traversal.h"
#include "host/backend/backend.h"
#include "host/pipeline/batch_queue.h"
#include "host/pipeline/directional_bins.h"
#include "host/pipeline/hit_sort.h"
#include "host/pipeline/ray_record.h"
#include "host/pipeline/shading_engine.h"

#include <cstdint>
#include <functional>
#include <vector>

namespace spw {

// generate: the iteration's camera rays, made straight into batches when the pipeline asks for
// them (no record, no bin, no decompress: a camera ray is a function of its pixel and sample).
// Their order is the bucket tiles', row by row within a tile, a pixel's samples together, which
// is what makes a camera batch coherent. Each sample is counted in the film (its filter weight)
// as its ray is made.
class CameraRays {
  public:
    // Lays out the iteration: the rays of every pixel `film` is sampling.
    void begin(const RenderContext& ctx, uint iteration, const Film& film);
    size_t remaining() const;
    // The next min(count, remaining()) rays into `rays` (resized to them).
    void generate(const RenderContext& ctx, size_t count, Film& film, std::vector<RayState>& rays);

  private:
    RenderParams rp_{};
    int width_ = 0, height_ = 0, tile_ = 1, tilesX_ = 0;
    std::vector<std::uint64_t> tileStart_; // the index of each tile's first ray, then the total
    std::uint64_t next_ = 0;
};

// decompress: the batch's records into `rays` (the records are left for the caller to recycle).
void decompressRays(const RayBatch& batch, std::vector<RayState>& rays);

// traverse: the rays' closest hits.
void traverse(const EmbreeScene& embree, const std::vector<RayState>& rays, bool coherent,
              std::vector<HitRecord>& hits);

// sort hits: the hits in `how` (hit_sort.h: HitOrder), one SortedHit per ray, the hits first,
// the misses after them; with HitOrder::AsTraced, `order` empty (no sort). Returns the number of
// hits.
size_t sortHits(const Scene& scene, const ShaderRanks& shaders, const std::vector<HitRecord>& hits,
                HitOrder how, std::vector<SortedHit>& order, std::vector<SortedHit>& scratch);

// hit setup: inputs[i] and paths[i] (pathId, bounce) for the i-th hit in `order`. Chunk by
// chunk of kChunk (256) hits; within a chunk, each run of one shader's hits looks its textures up
// texture by texture (TextureResolver::albedos).
void setUpHits(const RenderContext& ctx, const std::vector<RayState>& rays,
               const std::vector<HitRecord>& hits, const std::vector<SortedHit>& order,
               size_t hitCount, ShadeInput* inputs, uvec2* paths);

// shade: the ranges the engine shades, one per surface model (hits sorted by shader) or one over
// every hit.
void shadeRanges(const Scene& scene, const ShaderRanks& shaders,
                 const std::vector<SortedHit>& order, size_t hitCount, HitOrder how,
                 std::vector<ShadeRange>& ranges);

// shadow: the shadow rays the shading made, and for each the hit it belongs to.
void gatherShadowRays(const ShadeResult* results, size_t hitCount,
                      std::vector<std::uint32_t>& owner, std::vector<ShadowRay>& shadows);

// accumulate: what each hit emitted, and each unoccluded shadow ray's contribution, into the film.
void accumulate(const RenderContext& ctx, uint iteration, const ShadeResult* results,
                const uvec2* paths, size_t hitCount, const std::vector<std::uint32_t>& shadowOwner,
                const std::vector<std::uint8_t>& occluded, Film& film);

// escape: what the environment gives each ray that missed (the sorted order's tail, from
// hitCount), into the film. Only for a scene with an environment.
void accumulateEscapes(const RenderContext& ctx, uint iteration, const std::vector<RayState>& rays,
                       const std::vector<SortedHit>& order, size_t hitCount, Film& film);

// bin: the continuation rays, encoded, into the bins.
void binContinuations(const RenderContext& ctx, uint iteration, RayFormat format,
                      const ShadeResult* results, size_t hitCount, DirectionalBins& bins);

// The per-hit stages fused, for an engine that shades on the host's own threads (cpu): hit setup,
// shade, shadow, accumulate and bin run one after another on chunks of kChunk sorted hits, so that
// a chunk's inputs and results stay in L1/L2 between stages instead of streaming through RAM
// (the staged path writes and reads 224 bytes per hit). Same per-hit functions, same arithmetic,
// same image bit for bit. Each stage's --stats seconds: the loop's wall time shared in
// proportion to the thread time the stage took.
// With an empty `order` (the hit sort skipped: no shader sort and no environment for the misses
// to see), the hits are taken in traversal order from all `hitCount` = rays.size() rays, each
// chunk leaving out its misses itself. `shade` shades a chunk: out[i] for in[i], i < n (the cpu
// engine's shadeHits, host/cpu/simd_shading.h).
using ShadeChunk =
    std::function<void(const RenderParams& rp, const ShadeInput* in, size_t n, ShadeResult* out)>;
void shadeFused(const RenderContext& ctx, uint iteration, RayFormat format, const ShadeChunk& shade,
                const std::vector<RayState>& rays, const std::vector<HitRecord>& hits,
                const std::vector<SortedHit>& order, size_t hitCount, Film& film,
                DirectionalBins& bins);

// The stages after shading fused, for an engine that shades elsewhere (vulkan): shadow, accumulate
// and bin run one after another on chunks of kChunk results, as in shadeFused, instead of each
// stage streaming over the whole batch (gatherShadowRays, accumulate, binContinuations: the
// staged path, kept for --stages separate). Same image bit for bit.
void finishFused(const RenderContext& ctx, uint iteration, RayFormat format,
                 const ShadeResult* results, const uvec2* paths, size_t hitCount, Film& film,
                 DirectionalBins& bins);

} // namespace spw
