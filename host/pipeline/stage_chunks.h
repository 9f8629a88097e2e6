// What the pipeline's per-hit stages share (stages.cpp, fused_stages.cpp): the chunk of hits that
// hit setup works on and the film splats gathered a few dozen at a time. Internal to
// host/pipeline/.
#pragma once

#include "host/pipeline/stages.h"
#include "shared/path.h"

#include <cstdint>
#include <vector>

namespace spw {

inline RenderParams paramsAt(const RenderContext& ctx, uint iteration) {
    RenderParams rp = ctx.params;
    rp.iteration = iteration;
    return rp;
}

// Where a path's contributions land on the film.
inline vec2 filmPosition(const RenderContext& ctx, const RenderParams& rp, uint pathId) {
    const uint pixel = pathPixel(rp, pathId), s = pathId % rp.samplesPerIteration;
    const uint width = uint(ctx.scene.image.width);
    const uint x = pixel % width, y = pixel / width;
    // The Box filter needs only the pixel: skip re-deriving the sample's position in it.
    if (ctx.scene.filter.type == FilterType::Box) return vec2(float(x) + 0.5f, float(y) + 0.5f);
    return ctx.camera.filmPosition(x, y, s, pathSample(rp, pathId), rp.seed);
}

// Hits are set up a chunk at a time: a chunk's inputs and results (56 KiB) stay in L2 between
// the fused stages, and its texture lookups go texture by texture. (256 hits measured 2-4 %
// faster than 128 on the Cornell box and the textured scenes: longer runs of one texture.)
constexpr size_t kChunk = 256;
static_assert(kChunk <= 256, "chunk indices are bytes");

// Hit setup of the sorted hits order[0, n), n <= kChunk, into in[0, n): each hit's geometry and
// path, then the albedos (and normal maps), a run of hits of one shader at a time, texture by
// texture (TextureResolver::albedos: the same values as one hit at a time, bit for bit). Hits that
// end their path (max depth) get no albedo: shading never reads it there.
void setUpChunk(const RenderContext& ctx, const std::vector<RayState>& rays,
                const std::vector<HitRecord>& hits, const SortedHit* order, size_t n,
                ShadeInput* in);

// The tiled copies of large images that a batch's hits (order[0, n), or hits[0, n) where order is
// null) will read and that are not made yet, made in parallel before the batch's hit setup
// (TextureResolver::prepare); nothing where none is pending.
void prepareTextures(const RenderContext& ctx, const std::vector<HitRecord>& hits,
                     const SortedHit* order, size_t n);

// Splats gathered a few dozen at a time: each one's film line is prefetched when it joins, and
// the adds wait until the batch is full, so that the lines' cache misses overlap instead of
// stalling one atomic add after another (the sorted order has no pixel locality).
class SplatBatch {
  public:
    explicit SplatBatch(Film& film) : film_(film), sums_(film.sumsSamples()) {}
    ~SplatBatch() { flush(); }
    // A contribution of path `path` (its id) at bounce `bounce`. Field by field into the slot:
    // a Splat assembled and then copied goes through the stack in pieces that the copy's wider
    // loads straddle, a store-forwarding stall.
    void push(const RenderContext& ctx, const RenderParams& rp, uint path, uint bounce, bool shadow,
              vec3 value) {
        // A film that sums samples does not need where the sample lies.
        const vec2 pos = sums_ ? vec2(0.0f) : filmPosition(ctx, rp, path);
        film_.prefetch(path, pos);
        Film::Splat& s = splats_[count_++];
        s.pos = pos;
        s.path = path;
        s.sample = pathSample(rp, path);
        s.key = filmKey(path, bounce, shadow);
        s.value = value;
        if (count_ == kSize) flush();
    }
    // What a hit emitted, or its unoccluded shadow ray brings, for path (pathId, bounce).
    void emitted(const RenderContext& ctx, const RenderParams& rp, const ShadeResult& res,
                 uvec2 path) {
        push(ctx, rp, path.x, path.y, false, res.emitted);
    }
    void shadow(const RenderContext& ctx, const RenderParams& rp, const ShadeResult& res,
                uvec2 path) {
        push(ctx, rp, path.x, path.y, true, res.shadowContribution);
    }
    // In the order pushed: a path's contributions stay in order (Film::splat).
    void flush() {
        film_.splat(splats_, count_);
        count_ = 0;
    }

  private:
    static constexpr size_t kSize = Film::kSplatBatch;
    Film& film_;
    const bool sums_;
    Film::Splat splats_[kSize];
    size_t count_ = 0;
};
} // namespace spw
