#include "embree_backend/batch_traversal.h"

#include <embree3/rtcore.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <limits>

namespace spw {
namespace {
// Rays per rtcIntersect1M call: large enough to amortise the call, small enough to balance
// across threads and to keep a group's rays in cache.
constexpr size_t kGroup = 256;
constexpr float kInfinity = std::numeric_limits<float>::infinity();

// Every ray Spillway traces is filled here: from 0 to tmax, no motion, every geometry.
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

void fillRayHit(RTCRayHit& rh, vec3 o, vec3 d) {
    fillRay(rh.ray, o, d, kInfinity);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

HitRecord toHitRecord(const RTCRayHit& rh, uint instanceBase) {
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return HitRecord{kNoHit, 0, 0.0f, 0.0f, 0.0f};
    const uint instance =
        rh.hit.instID[0] == RTC_INVALID_GEOMETRY_ID ? kNoInstance : rh.hit.instID[0] - instanceBase;
    return HitRecord{rh.hit.geomID, rh.hit.primID, rh.hit.u, rh.hit.v, rh.ray.tfar, instance};
}

RTCIntersectContext context(bool coherent) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags =
        coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    return ctx;
}
} // namespace

void intersectBatch(const EmbreeScene& scene, const RayStream& rays, bool coherent,
                    std::vector<HitRecord>& hits) {
    hits.resize(rays.count);
    const size_t groups = (rays.count + kGroup - 1) / kGroup;
    tbb::parallel_for(size_t(0), groups, [&](size_t g) {
        const size_t begin = g * kGroup, end = std::min(rays.count, begin + kGroup);
        RTCRayHit buf[kGroup];
        for (size_t i = begin; i < end; ++i)
            fillRayHit(buf[i - begin], rays.originAt(i), rays.dirAt(i));
        RTCIntersectContext ctx = context(coherent);
        rtcIntersect1M(scene.handle(), &ctx, buf, unsigned(end - begin), sizeof(RTCRayHit));
        for (size_t i = begin; i < end; ++i)
            hits[i] = toHitRecord(buf[i - begin], scene.instanceBase());
    });
}

void occludedRange(const EmbreeScene& scene, const ShadowRay* rays, size_t count, bool coherent,
                   std::uint8_t* occluded) {
    RTCIntersectContext ctx = context(coherent);
    RTCRay buf[kGroup];
    for (size_t begin = 0; begin < count; begin += kGroup) {
        const size_t n = std::min(count - begin, kGroup);
        for (size_t i = 0; i < n; ++i)
            fillRay(buf[i], rays[begin + i].origin, rays[begin + i].dir, rays[begin + i].tmax);
        rtcOccluded1M(scene.handle(), &ctx, buf, unsigned(n), sizeof(RTCRay));
        for (size_t i = 0; i < n; ++i)
            occluded[begin + i] = buf[i].tfar < 0.0f ? 1 : 0;
    }
}

void occludedBatch(const EmbreeScene& scene, const std::vector<ShadowRay>& rays, bool coherent,
                   std::vector<std::uint8_t>& occluded) {
    occluded.assign(rays.size(), 0);
    const size_t groups = (rays.size() + kGroup - 1) / kGroup;
    tbb::parallel_for(size_t(0), groups, [&](size_t g) {
        const size_t begin = g * kGroup, end = std::min(rays.size(), begin + kGroup);
        occludedRange(scene, &rays[begin], end - begin, coherent, &occluded[begin]);
    });
}

HitRecord intersectOne(const EmbreeScene& scene, vec3 origin, vec3 dir) {
    RTCRayHit rh;
    fillRayHit(rh, origin, dir);
    RTCIntersectContext ctx = context(false);
    rtcIntersect1(scene.handle(), &ctx, &rh);
    return toHitRecord(rh, scene.instanceBase());
}

bool occludedOne(const EmbreeScene& scene, const ShadowRay& ray) {
    RTCRay r;
    fillRay(r, ray.origin, ray.dir, ray.tmax);
    RTCIntersectContext ctx = context(false);
    rtcOccluded1(scene.handle(), &ctx, &r);
    return r.tfar < 0.0f;
}

} // namespace spw
