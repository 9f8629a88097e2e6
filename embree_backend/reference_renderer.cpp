#include "embree_backend/reference_renderer.h"

#include "embree_backend/embree_scene.h"
#include "shared/path.h"

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include <limits>

namespace spw {
namespace {

RTCRayHit makeRay(vec3 o, vec3 d, float tmax) {
    RTCRayHit rh;
    rh.ray.org_x = o.x;
    rh.ray.org_y = o.y;
    rh.ray.org_z = o.z;
    rh.ray.dir_x = d.x;
    rh.ray.dir_y = d.y;
    rh.ray.dir_z = d.z;
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = tmax;
    rh.ray.time = 0.0f;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    return rh;
}

} // namespace

void ReferenceRenderer::renderIteration(uint iteration, Film& film) {
    const Scene& scene = ctx_.scene;
    const EmbreeScene& embree = ctx_.embree;
    const SceneView view = embree.view();
    RenderParams rp = ctx_.params;
    rp.iteration = iteration;
    const int width = scene.image.width, height = scene.image.height;
    const int tile = scene.settings.bucketSize;
    const uint spi = rp.samplesPerIteration;

    StageTimer timer(ctx_.stats.stages, "trace and shade");
    tbb::parallel_for(
        tbb::blocked_range2d<int>(0, height, tile, 0, width, tile), [&](const tbb::blocked_range2d<int>& r) {
            std::uint64_t camera = 0, bounce = 0, shadow = 0;
            RTCIntersectContext ictx;
            for (int y = r.rows().begin(); y < r.rows().end(); ++y)
                for (int x = r.cols().begin(); x < r.cols().end(); ++x)
                    for (uint s = 0; s < spi; ++s) {
                        const uint pixel = uint(y * width + x);
                        const uint sampleIndex = iteration * spi + s;
                        CameraRay cr = ctx_.camera.generate(uint(x), uint(y), s, sampleIndex, rp.seed);
                        film.addSample(cr.filmPos, sampleIndex);
                        PathState st{};
                        st.beta = vec3(1.0f);
                        st.pathId = pixel * spi + s;
                        vec3 org = cr.origin, dir = cr.dir;
                        ++camera;
                        for (;;) {
                            RTCRayHit rh = makeRay(org, dir, std::numeric_limits<float>::infinity());
                            rtcInitIntersectContext(&ictx);
                            rtcIntersect1(embree.handle(), &ictx, &rh);
                            if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) break;
                            SurfaceHit hit;
                            embree.surfaceHit(rh.hit.geomID, rh.hit.primID, rh.hit.u, rh.hit.v, rh.ray.tfar, hit);
                            const Shader& sh = scene.shaders[hit.shader];
                            hit.albedo = ctx_.textures.albedo(sh, embree.uvAt(rh.hit.geomID, rh.hit.primID,
                                                                              rh.hit.u, rh.hit.v));
                            ShadeResult res;
                            shadeSurface(view, rp, hit, dir, st, res);
                            if (res.flags & kShadeEmitted)
                                film.splat(cr.filmPos, sampleIndex, res.emitted, filmKey(st.pathId, st.bounce, false));
                            if (res.flags & kShadeShadow) {
                                ++shadow;
                                RTCRay sr = makeRay(res.shadowOrigin, res.shadowDir, res.shadowTmax).ray;
                                rtcInitIntersectContext(&ictx);
                                rtcOccluded1(embree.handle(), &ictx, &sr);
                                if (sr.tfar >= 0.0f)
                                    film.splat(cr.filmPos, sampleIndex, res.shadowContribution, filmKey(st.pathId, st.bounce, true));
                            }
                            if (!(res.flags & kShadeContinue)) break;
                            ++bounce;
                            org = res.nextOrigin;
                            dir = res.nextDir;
                            st = res.next;
                        }
                    }
            ctx_.stats.cameraRays += camera;
            ctx_.stats.bounceRays += bounce;
            ctx_.stats.shadowRays += shadow;
        });
}

} // namespace spw
