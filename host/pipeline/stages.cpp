#include "host/pipeline/stages.h"

#include "host/pipeline/parallel.h"
#include "host/pipeline/radix_sort.h"
#include "host/pipeline/stage_chunks.h"
#include "host/scene_view/denoising_albedo.h"
#include "host/simd/lanes.h"
#include "shared/path.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <memory>

namespace spw {

void CameraRays::begin(const RenderContext& ctx, uint iteration, const Film& film) {
    const Scene& scene = ctx.scene;
    rp_ = paramsAt(ctx, iteration);
    width_ = scene.image.width;
    height_ = scene.image.height;
    tile_ = scene.settings.bucketSize;
    tilesX_ = (width_ + tile_ - 1) / tile_;
    const int tiles = tilesX_ * ((height_ + tile_ - 1) / tile_);
    // Each tile's rays: its sampling pixels times the samples per iteration, then their prefix.
    tileStart_.assign(size_t(tiles) + 1, 0);
    tbb::parallel_for(0, tiles, [&](int t) {
        const int x0 = (t % tilesX_) * tile_, y0 = (t / tilesX_) * tile_;
        std::uint64_t pixels = 0;
        for (int y = y0; y < std::min(height_, y0 + tile_); ++y)
            for (int x = x0; x < std::min(width_, x0 + tile_); ++x)
                pixels += film.sampling(x, y);
        tileStart_[size_t(t) + 1] = pixels * rp_.samplesPerIteration;
    });
    for (size_t t = 1; t < tileStart_.size(); ++t)
        tileStart_[t] += tileStart_[t - 1];
    next_ = 0;
}

size_t CameraRays::remaining() const {
    return tileStart_.empty() ? 0 : size_t(tileStart_.back() - next_);
}

void CameraRays::generate(const RenderContext& ctx, size_t count, Film& film,
                          std::vector<RayState>& rays) {
    const std::uint64_t begin = next_, end = next_ + std::min<std::uint64_t>(count, remaining());
    next_ = end;
    rays.resize(size_t(end - begin));
    if (end == begin) return;
    const uint spi = rp_.samplesPerIteration;
    const float spread = ctx.camera.pixelSpread();
    // The tiles that hold rays [begin, end): the first whose rays end after `begin`, up to the
    // last that starts before `end`.
    const size_t first =
        size_t(std::upper_bound(tileStart_.begin(), tileStart_.end(), begin) - tileStart_.begin()) -
        1;
    const size_t last =
        size_t(std::lower_bound(tileStart_.begin(), tileStart_.end(), end) - tileStart_.begin());
    const CameraModel& camera = ctx.camera;
    tbb::parallel_for(first, last, [&](size_t t) {
        // The tile's rays a block at a time, made SIMD-wide with their random numbers
        // (CameraModel::generateMany).
        constexpr size_t kBlock = 64;
        // (Zeroed: GCC cannot see that flush() reads only the `pending` entries set.)
        uint x[kBlock] = {}, y[kBlock] = {}, pixel[kBlock] = {}, sampleIndex[kBlock] = {},
             sample[kBlock] = {};
        std::uint64_t ray[kBlock];
        CameraRay made[kBlock];
        size_t pending = 0;
        auto flush = [&] {
            camera.generateMany(x, y, sample, sampleIndex, rp_.seed, pending, made);
            for (size_t j = 0; j < pending; ++j) {
                const CameraRay& cr = made[j];
                RayState& r = rays[size_t(ray[j] - begin)];
                r.origin = cr.origin;
                r.dir = cr.dir;
                r.path = cameraPath(rp_, pixel[j], sample[j], spread);
                film.addSample(r.path.pathId, cr.filmPos, sampleIndex[j]);
            }
            pending = 0;
        };
        const int x0 = int(t % size_t(tilesX_)) * tile_, y0 = int(t / size_t(tilesX_)) * tile_;
        std::uint64_t k = tileStart_[t]; // the index of the tile's next ray
        for (int py = y0; py < std::min(height_, y0 + tile_) && k < end; ++py)
            for (int px = x0; px < std::min(width_, x0 + tile_) && k < end; ++px) {
                if (!film.sampling(px, py)) continue; // adaptive sampling: converged
                if (k + spi <= begin) {               // the batch starts after this pixel
                    k += spi;
                    continue;
                }
                for (uint s = 0; s < spi; ++s, ++k) {
                    if (k < begin || k >= end) continue;
                    x[pending] = uint(px);
                    y[pending] = uint(py);
                    pixel[pending] = uint(py * width_ + px);
                    sampleIndex[pending] = rp_.iteration * spi + s;
                    sample[pending] = s;
                    ray[pending] = k;
                    if (++pending == kBlock) flush();
                }
            }
        flush();
    });
    ctx.stats.cameraRays += end - begin;
}

void decompressRays(const RayBatch& batch, std::vector<RayState>& rays) {
    const size_t n = batch.count;
    const size_t recordBytes = rayRecordBytes(batch.format);
    rays.resize(n);
    const bool compact = batch.format == RayFormat::Compact;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, batchGrain(n, 256, 4096)),
                      [&](const tbb::blocked_range<size_t>& r) {
                          if (!compact) {
                              for (size_t i = r.begin(); i < r.end(); ++i)
                                  decodeRay(&batch.bytes[i * recordBytes], batch.format, rays[i]);
                              return;
                          }
                          for (size_t i = r.begin(); i < r.end(); i += simd::kBlock)
                              decodeCompactBlock(&batch.bytes[i * recordBytes],
                                                 std::min(simd::kBlock, r.end() - i), &rays[i]);
                      });
}

void traverse(const EmbreeScene& embree, const std::vector<RayState>& rays, bool coherent,
              std::vector<HitRecord>& hits) {
    if (rays.empty()) {
        hits.clear();
        return;
    }
    intersectBatch(embree, RayStream{&rays[0].origin, &rays[0].dir, sizeof(RayState), rays.size()},
                   coherent, hits);
}

size_t sortHits(const Scene& scene, const ShaderRanks& shaders, const std::vector<HitRecord>& hits,
                HitOrder how, std::vector<SortedHit>& order, std::vector<SortedHit>& scratch) {
    const size_t n = hits.size();
    if (how == HitOrder::AsTraced) {
        order.clear();
        return n;
    }
    const bool byShader = sortsByShader(how);
    const bool inTextureOrder = how == HitOrder::ByShaderObjectTexture;
    order.resize(n);
    // Sorted, the misses take the rank after the last shader's: behind every hit, and varying
    // no byte of the keys that the hits' ranks do not (the all-ones key would make all eight
    // vary, eight radix passes instead of one or a few).
    const std::uint64_t missKey =
        byShader ? hitSortKey(uint(shaders.shaderAt.size()), 0, 0) : kMissKey;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, batchGrain(n, 1024, kParallelGrain)),
                      [&](const tbb::blocked_range<size_t>& r) {
                          for (size_t i = r.begin(); i < r.end(); ++i) {
                              const HitRecord& h = hits[i];
                              std::uint64_t key = missKey;
                              if (h.mesh != kNoHit && byShader) {
                                  const Mesh& mesh = scene.meshes[h.mesh];
                                  key = inTextureOrder
                                            ? hitSortKey(shaders.rank[size_t(mesh.shader)], h.mesh,
                                                         textureOrder(mesh, h.prim, h.u, h.v))
                                            : hitSortKey(shaders.rank[size_t(mesh.shader)], 0, 0);
                              } else if (h.mesh != kNoHit) {
                                  key = 0;
                              }
                              order[i] = {key, std::uint32_t(i)};
                          }
                      });
    const size_t hitCount = parallelCount(n, [&](size_t i) { return order[i].key != missKey; });
    if (byShader) {
        radixSort(order, scratch);
    } else {
        // No sort: keep traversal order, just move the misses out.
        std::stable_partition(order.begin(), order.end(),
                              [](const SortedHit& k) { return k.key != kMissKey; });
    }
    return hitCount;
}

namespace {
// What setUpChunk reads that is likely a miss, asked for a whole chunk ahead (measured faster
// than a fixed distance ahead within the loop): first the hits' rays (in traversal order while
// the hits are in shader order) and triangles, then the triangles' vertices.
void prefetchChunk(const RenderContext& ctx, const std::vector<RayState>& rays,
                   const std::vector<HitRecord>& hits, const SortedHit* order, size_t n) {
    for (size_t i = 0; i < n; ++i) {
        const auto* ray = reinterpret_cast<const char*>(&rays[order[i].index]);
        __builtin_prefetch(ray);
        __builtin_prefetch(ray + sizeof(RayState) - 1);
        ctx.hitSetup.prefetchTriangle(hits[order[i].index]);
    }
    for (size_t i = 0; i < n; ++i)
        ctx.hitSetup.prefetchVertices(hits[order[i].index]);
}

// The geometry of the sorted hits order[0, n), n <= kChunk, into in[0, n) (albedo 0), with their
// paths and ray directions, and each hit's texture coordinates and footprint: SIMD-wide, a block
// of hits at a time (HitSetup::setUpHits).
void setUpGeometry(const RenderContext& ctx, const std::vector<RayState>& rays,
                   const std::vector<HitRecord>& hits, const SortedHit* order, size_t n,
                   ShadeInput* in, vec2* uv, float* footprint) {
    const HitRecord* record[simd::kBlock];
    vec3 dir[simd::kBlock];
    uint cone[simd::kBlock];
    SurfaceHit* out[simd::kBlock];
    for (size_t begin = 0; begin < n; begin += simd::kBlock) {
        const size_t count = std::min(simd::kBlock, n - begin);
        for (size_t j = 0; j < count; ++j) {
            const std::uint32_t k = order[begin + j].index;
            const RayState& ray = rays[k];
            ShadeInput& x = in[begin + j];
            x.path = ray.path;
            x.rayDir = ray.dir;
            record[j] = &hits[k], dir[j] = ray.dir, cone[j] = ray.path.cone, out[j] = &x.hit;
        }
        ctx.hitSetup.setUpHits(count, record, dir, cone, out, uv + begin, footprint + begin);
    }
}

} // namespace

void setUpChunk(const RenderContext& ctx, const std::vector<RayState>& rays,
                const std::vector<HitRecord>& hits, const SortedHit* order, size_t n,
                ShadeInput* in) {
    std::uint8_t slot[kChunk]; // the hits that look textures up, in order
    vec2 uv[kChunk];
    float footprint[kChunk];
    vec3 albedo[kChunk];
    const HitRecord* record[kChunk]; // the hits that look textures up, and their setups
    SurfaceHit* hit[kChunk];
    prefetchChunk(ctx, rays, hits, order, n);
    setUpGeometry(ctx, rays, hits, order, n, in, uv, footprint);
    size_t m = 0;
    for (size_t i = 0; i < n; ++i) {
        ShadeInput& x = in[i];
        if (x.path.bounce >= ctx.params.maxDepth) continue;
        const Shader& shader = ctx.scene.shaders[x.hit.shader];
        if (!shader.looksUpTextures()) {
            x.hit.albedo = ctx.textures.albedo(shader, vec2(0.0f), 0.0f);
            ctx.hitSetup.applyVertexColour(hits[order[i].index], x.hit);
            continue;
        }
        uv[m] = uv[i], footprint[m] = footprint[i]; // m <= i
        slot[m++] = std::uint8_t(i);
    }
    for (size_t a = 0; a < m;) {
        const uint shader = in[slot[a]].hit.shader;
        size_t b = a + 1;
        while (b < m && in[slot[b]].hit.shader == shader)
            ++b;
        const Shader& sh = ctx.scene.shaders[shader];
        ctx.textures.albedos(sh, b - a, uv + a, footprint + a, albedo + a);
        for (size_t j = a; j < b; ++j) {
            in[slot[j]].hit.albedo = albedo[j];
            ctx.hitSetup.applyVertexColour(hits[order[slot[j]].index], in[slot[j]].hit);
        }
        if (sh.hasMaps()) {
            for (size_t j = a; j < b; ++j) {
                record[j] = &hits[order[slot[j]].index];
                hit[j] = &in[slot[j]].hit;
            }
            ctx.hitSetup.applyMaps(sh, ctx.textures, b - a, uv + a, footprint + a, record + a,
                                   hit + a);
        }
        a = b;
    }
    if (ctx.aovs) // the render passes: the camera rays' first hits, and the albedo's
        for (size_t i = 0; i < n; ++i)
            if (in[i].path.bounce < ctx.params.maxDepth)
                recordPasses(*ctx.aovs, ctx.scene.shaders[in[i].hit.shader].params, in[i].path,
                             in[i].rayDir, in[i].hit);
}

void prepareTextures(const RenderContext& ctx, const std::vector<HitRecord>& hits,
                     const SortedHit* order, size_t n) {
    if (!ctx.textures.copiesPending()) return;
    std::vector<bool> shaders(ctx.scene.shaders.size(), false);
    for (size_t i = 0; i < n; ++i) {
        const HitRecord& h = hits[order ? order[i].index : i];
        if (h.mesh != kNoHit) shaders[size_t(ctx.scene.meshes[h.mesh].shader)] = true;
    }
    ctx.textures.prepare(shaders);
}

void setUpHits(const RenderContext& ctx, const std::vector<RayState>& rays,
               const std::vector<HitRecord>& hits, const std::vector<SortedHit>& order,
               size_t hitCount, ShadeInput* inputs, uvec2* paths) {
    prepareTextures(ctx, hits, order.data(), hitCount);
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, hitCount, 1024), [&](const tbb::blocked_range<size_t>& r) {
            ShadeInput chunk[kChunk];
            for (size_t begin = r.begin(); begin < r.end(); begin += kChunk) {
                const size_t n = std::min(kChunk, r.end() - begin);
                setUpChunk(ctx, rays, hits, &order[begin], n, chunk);
                // stored whole, in order: the slots may be write-combined
                // device memory
                for (size_t i = 0; i < n; ++i) {
                    inputs[begin + i] = chunk[i];
                    paths[begin + i] = uvec2(chunk[i].path.pathId, chunk[i].path.bounce);
                }
            }
        });
}

void shadeRanges(const Scene& scene, const ShaderRanks& shaders,
                 const std::vector<SortedHit>& order, size_t hitCount, HitOrder how,
                 std::vector<ShadeRange>& ranges) {
    ranges.clear();
    if (sortsByShader(how)) {
        // The sort keys carry the shader's rank in their top bits, and the ranks put the shaders
        // of one surface model next to each other: their runs make one range.
        for (const ShaderRun& run : shaderRuns(order, hitCount)) {
            const uint model = scene.shaders[shaders.shaderAt[run.shader]].params.model;
            if (!ranges.empty() && ranges.back().model == model)
                ranges.back().count += run.count;
            else
                ranges.push_back({model, run.begin, run.count});
        }
    } else if (hitCount > 0) {
        ranges.push_back({kMixedModels, 0, hitCount});
    }
}

void gatherShadowRays(const ShadeResult* results, size_t hitCount,
                      std::vector<std::uint32_t>& owner, std::vector<ShadowRay>& shadows) {
    parallelSelect(
        hitCount, [&](size_t i) { return (results[i].flags & kShadeShadow) != 0; }, owner);
    shadows.resize(owner.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, shadows.size(), kParallelGrain),
                      [&](const tbb::blocked_range<size_t>& r) {
                          for (size_t j = r.begin(); j < r.end(); ++j) {
                              const ShadeResult& res = results[owner[j]];
                              shadows[j] = {res.shadowOrigin, res.shadowDir, res.shadowTmax};
                          }
                      });
}

void accumulate(const RenderContext& ctx, uint iteration, const ShadeResult* results,
                const uvec2* paths, size_t hitCount, const std::vector<std::uint32_t>& shadowOwner,
                const std::vector<std::uint8_t>& occluded, Film& film) {
    const RenderParams rp = paramsAt(ctx, iteration);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, hitCount, 1024),
                      [&](const tbb::blocked_range<size_t>& r) {
                          SplatBatch splats(film);
                          for (size_t i = r.begin(); i < r.end(); ++i)
                              if (results[i].flags & kShadeEmitted)
                                  splats.emitted(ctx, rp, results[i], paths[i]);
                      });
    tbb::parallel_for(tbb::blocked_range<size_t>(0, shadowOwner.size(), 1024),
                      [&](const tbb::blocked_range<size_t>& r) {
                          SplatBatch splats(film);
                          for (size_t j = r.begin(); j < r.end(); ++j)
                              if (!occluded[j])
                                  splats.shadow(ctx, rp, results[shadowOwner[j]],
                                                paths[shadowOwner[j]]);
                      });
}

void accumulateEscapes(const RenderContext& ctx, uint iteration, const std::vector<RayState>& rays,
                       const std::vector<SortedHit>& order, size_t hitCount, Film& film) {
    const RenderParams rp = paramsAt(ctx, iteration);
    const SceneView view = ctx.lights.view();
    tbb::parallel_for(tbb::blocked_range<size_t>(hitCount, order.size(), 1024),
                      [&](const tbb::blocked_range<size_t>& r) {
                          SplatBatch splats(film);
                          for (size_t i = r.begin(); i < r.end(); ++i) {
                              const RayState& ray = rays[order[i].index];
                              splats.push(ctx, rp, ray.path.pathId, ray.path.bounce, false,
                                          escapedRadiance(view, rp, ray.dir, ray.path));
                              if (ctx.aovs) recordEscape(*ctx.aovs, view, rp, ray.path, ray.dir);
                          }
                      });
}

void binContinuations(const RenderContext& ctx, uint iteration, RayFormat format,
                      const ShadeResult* results, size_t hitCount, DirectionalBins& bins) {
    const RenderParams rp = paramsAt(ctx, iteration);
    const size_t chunk = batchGrain(hitCount, 256, size_t(ctx.scene.settings.shadingSize));
    tbb::parallel_for(tbb::blocked_range<size_t>(0, hitCount, chunk),
                      [&](const tbb::blocked_range<size_t>& r) {
                          RayBuffer buffer;
                          buffer.pushContinuations(rp, format, results + r.begin(), r.size());
                          bins.add(buffer);
                      });
}

} // namespace spw
