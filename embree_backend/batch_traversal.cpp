#include "embree_backend/batch_traversal.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <limits>

namespace spw {
namespace {
// Rays per rtcIntersect1M call: large enough to amortise the call, small enough to balance
// across threads and to keep a group's rays in cache.
constexpr size_t kGroup = 256;

void fillRay(RTCRay& r, vec3 o, vec3 d, float tmax) {
    r.org_x = o.x;
    r.org_y = o.y;
    r.org_z = o.z;
    r.dir_x = d.x;
    r.dir_y = d.y;
    r.dir_z = d.z;
    r.tnear = 0.0f;
    r.tfar = tmax;
    r.time = 0.0f;
    r.mask = 0xFFFFFFFFu;
    r.id = 0;
    r.flags = 0;
}
} // namespace

void intersectBatch(const EmbreeScene& scene, const std::vector<RayState>& rays, bool coherent,
                    std::vector<RTCRayHit>& hits) {
    hits.resize(rays.size());
    const size_t groups = (rays.size() + kGroup - 1) / kGroup;
    tbb::parallel_for(size_t(0), groups, [&](size_t g) {
        const size_t begin = g * kGroup, end = std::min(rays.size(), begin + kGroup);
        for (size_t i = begin; i < end; ++i) {
            fillRay(hits[i].ray, rays[i].origin, rays[i].dir, std::numeric_limits<float>::infinity());
            hits[i].hit.geomID = RTC_INVALID_GEOMETRY_ID;
            hits[i].hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        }
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        ctx.flags = coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
        rtcIntersect1M(scene.handle(), &ctx, &hits[begin], unsigned(end - begin), sizeof(RTCRayHit));
    });
}

void occludedBatch(const EmbreeScene& scene, const std::vector<ShadowRay>& rays, bool coherent,
                   std::vector<std::uint8_t>& occluded) {
    occluded.assign(rays.size(), 0);
    const size_t groups = (rays.size() + kGroup - 1) / kGroup;
    tbb::parallel_for(size_t(0), groups, [&](size_t g) {
        const size_t begin = g * kGroup, end = std::min(rays.size(), begin + kGroup);
        RTCRay buf[kGroup];
        for (size_t i = begin; i < end; ++i) fillRay(buf[i - begin], rays[i].origin, rays[i].dir, rays[i].tmax);
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        ctx.flags = coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
        rtcOccluded1M(scene.handle(), &ctx, buf, unsigned(end - begin), sizeof(RTCRay));
        for (size_t i = begin; i < end; ++i) occluded[i] = buf[i - begin].tfar < 0.0f ? 1 : 0;
    });
}

} // namespace spw
