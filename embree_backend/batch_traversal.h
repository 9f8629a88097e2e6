// Embree traversal, the only place rays meet Embree: whole batches for the sorted backends
// (closest hits for a batch of rays, occlusion for a batch of shadow rays) and one ray at a time
// for the depth-first reference. The batch calls split the batch into groups traced with
// rtcIntersect1M / rtcOccluded1M, with the coherent context flag only when the batch was sorted
// (Embree's coherent mode halves throughput on incoherent rays). What comes back is Spillway's
// own HitRecord: no Embree type leaves embree_backend/.
//
// Why streams and not packets: on Morton-sorted batches, 8-wide packets (rtcIntersect8 over
// consecutive sorted rays) measured slower than rtcIntersect1M with the coherent flag: traverse
// stage 0.79 s vs 0.67 s on the Cornell box (256x256, 64 spp) and 2.56 s vs 2.52 s on the
// 1M-triangle scene (2-core Zen 3, Embree 3.13.5, `--backend cpu --ray-sort morton`). Embree
// forms its own packets from a coherent stream, so the stream call is kept for both cases.
#pragma once

#include "embree_backend/embree_scene.h"
#include "host/scene_view/hit_setup.h"

#include <cstdint>
#include <vector>

namespace spw {

// A batch's rays as traversal reads them: `count` origins and unit directions, each `stride`
// bytes after the last, so that the pipeline's own ray array is traced where it lies.
struct RayStream {
    const vec3* origin;
    const vec3* dir;
    size_t stride;
    size_t count;
    vec3 originAt(size_t i) const { return at(origin, i); }
    vec3 dirAt(size_t i) const { return at(dir, i); }

  private:
    vec3 at(const vec3* first, size_t i) const {
        return *reinterpret_cast<const vec3*>(reinterpret_cast<const char*>(first) + i * stride);
    }
};

// hits[i]: ray i's closest hit, or mesh == kNoHit.
void intersectBatch(const EmbreeScene& scene, const RayStream& rays, bool coherent,
                    std::vector<HitRecord>& hits);

struct ShadowRay {
    vec3 origin;
    vec3 dir;
    float tmax;
};
// occluded[i] = 1 when something blocks ray i before its tmax.
void occludedBatch(const EmbreeScene& scene, const std::vector<ShadowRay>& rays, bool coherent,
                   std::vector<std::uint8_t>& occluded);
// The same for `count` rays on the calling thread (a fused chunk's shadow rays).
void occludedRange(const EmbreeScene& scene, const ShadowRay* rays, size_t count, bool coherent,
                   std::uint8_t* occluded);

// One ray, for the depth-first reference: the closest hit, and whether a shadow ray is blocked.
HitRecord intersectOne(const EmbreeScene& scene, vec3 origin, vec3 dir);
bool occludedOne(const EmbreeScene& scene, const ShadowRay& ray);

} // namespace spw
