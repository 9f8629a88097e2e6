// Embree traversal of whole batches for the sorted backends: closest hits for a batch of rays,
// and occlusion for a batch of shadow rays. Both split the batch into groups traced with
// rtcIntersect1M / rtcOccluded1M, with the coherent context flag only when the batch was sorted
// (Embree's coherent mode halves throughput on incoherent rays).
//
// Why streams and not packets: on Morton-sorted batches, 8-wide packets (rtcIntersect8 over
// consecutive sorted rays) measured slower than rtcIntersect1M with the coherent flag: traverse
// stage 0.79 s vs 0.67 s on the Cornell box (256x256, 64 spp) and 2.56 s vs 2.52 s on the
// 1M-triangle scene (2-core Zen 3, Embree 3.13.5, `--backend cpu --ray-sort morton`). Embree
// forms its own packets from a coherent stream, so the stream call is kept for both cases.
#pragma once

#include "embree_backend/embree_scene.h"
#include "host/pipeline/ray_record.h"

#include <vector>

namespace spw {

void intersectBatch(const EmbreeScene& scene, const std::vector<RayState>& rays, bool coherent,
                    std::vector<RTCRayHit>& hits);

struct ShadowRay {
    vec3 origin;
    vec3 dir;
    float tmax;
};
// occluded[i] = 1 when something blocks ray i before its tmax.
void occludedBatch(const EmbreeScene& scene, const std::vector<ShadowRay>& rays, bool coherent,
                   std::vector<std::uint8_t>& occluded);

} // namespace spw
