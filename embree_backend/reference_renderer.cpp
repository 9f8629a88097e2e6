#include "embree_backend/reference_renderer.h"

#include "embree_backend/batch_traversal.h"
#include "host/scene_view/denoising_albedo.h"
#include "shared/path.h"

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

namespace spw {
bool ReferenceRenderer::renderIteration(uint iteration, Film& film) {
    const Scene& scene = ctx_.scene;
    const EmbreeScene& embree = ctx_.embree;
    const SceneView view = ctx_.lights.view();
    RenderParams rp = ctx_.params;
    rp.iteration = iteration;
    const int width = scene.image.width, height = scene.image.height;
    const int tile = scene.settings.bucketSize;
    const uint spi = rp.samplesPerIteration;

    StageTimer timer(ctx_.stats.stages, "trace and shade");
    tbb::parallel_for(
        tbb::blocked_range2d<int>(0, height, tile, 0, width, tile),
        [&](const tbb::blocked_range2d<int>& r) {
            if (stopRequested(ctx_.config)) return; // the iteration will be discarded
            std::uint64_t camera = 0, bounce = 0, shadow = 0;
            for (int y = r.rows().begin(); y < r.rows().end(); ++y)
                for (int x = r.cols().begin(); x < r.cols().end(); ++x) {
                    if (!film.sampling(x, y)) continue; // adaptive sampling: converged
                    for (uint s = 0; s < spi; ++s) {
                        const uint pixel = uint(y * width + x);
                        const uint sampleIndex = iteration * spi + s;
                        CameraRay cr =
                            ctx_.camera.generate(uint(x), uint(y), s, sampleIndex, rp.seed);
                        PathState st = cameraPath(rp, pixel, s, ctx_.camera.pixelSpread());
                        film.addSample(st.pathId, cr.filmPos, sampleIndex);
                        vec3 org = cr.origin, dir = cr.dir;
                        ++camera;
                        for (;;) {
                            const HitRecord h = intersectOne(embree, org, dir);
                            if (h.mesh == kNoHit) {
                                if (rp.environment != kNoEmitter)
                                    film.splat(st.pathId, cr.filmPos, sampleIndex,
                                               escapedRadiance(view, rp, dir, st),
                                               filmKey(st.pathId, st.bounce, false));
                                if (ctx_.aovs) recordEscape(*ctx_.aovs, view, rp, st, dir);
                                break;
                            }
                            SurfaceHit hit;
                            ctx_.hitSetup.setUpHit(h, dir, st.cone, ctx_.textures,
                                                   st.bounce < rp.maxDepth, hit);
                            if (ctx_.aovs && st.bounce < rp.maxDepth)
                                recordPasses(*ctx_.aovs, ctx_.scene.shaders[hit.shader].params, st,
                                             dir, hit);
                            ShadeResult res;
                            shadeSurface(view, rp, hit, dir, st, res);
                            if (res.flags & kShadeEmitted)
                                film.splat(st.pathId, cr.filmPos, sampleIndex, res.emitted,
                                           filmKey(st.pathId, st.bounce, false));
                            if (res.flags & kShadeShadow) {
                                ++shadow;
                                if (!occludedOne(embree,
                                                 {res.shadowOrigin, res.shadowDir, res.shadowTmax}))
                                    film.splat(st.pathId, cr.filmPos, sampleIndex,
                                               res.shadowContribution,
                                               filmKey(st.pathId, st.bounce, true));
                            }
                            if (!(res.flags & kShadeContinue)) break;
                            ++bounce;
                            org = res.nextOrigin;
                            dir = res.nextDir;
                            st = res.next;
                        }
                    }
                }
            ctx_.stats.cameraRays += camera;
            ctx_.stats.bounceRays += bounce;
            ctx_.stats.shadowRays += shadow;
        });
    return !stopRequested(ctx_.config);
}

} // namespace spw
