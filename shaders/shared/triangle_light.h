// A triangle of an emitting mesh (a Quad light is two), sampled uniformly by area: the
// emitter of every emissive surface, and the only kind a ray can hit.
#ifndef SPILLWAY_SHARED_TRIANGLE_LIGHT_H
#define SPILLWAY_SHARED_TRIANGLE_LIGHT_H
#include "light_sample.h"

SHARED_BEGIN

SHARED_FN LightSample triangle_lightSample(SCENE_PARAM RenderParams rp, Emitter e, SurfaceHit hit,
                                           vec2 u) {
    UNUSED(rp);
    LightSample ls = noLightSample();
    vec3 q = emitterPoint(e, u);
    vec3 d = q - hit.p;
    float dist = length(d);
    if (!(dist > 0.0f)) return ls;
    ls.wi = d / dist;
    float cosLight = emitterCosine(e, -ls.wi);
    ls.pdf = emitterSolidAnglePdf(e, dist, cosLight);
    ls.radiance = emitterRadiance(SCENE_ARG e, sampleTriangle(u));
    // Stop short of the emitter's own surface, whatever the scene's scale.
    float offsetQ = surfaceOffset(q, e.p0, e.p0 + e.e1, e.p0 + e.e2, e.normal);
    ls.tmax = shadowRayTmax(dist, hit.offset, offsetQ, cosLight);
    return ls;
}

SHARED_END
#endif
