// A point light at p0: intensity (W/sr) the same in every direction, a delta light (never hit).
#ifndef SPILLWAY_SHARED_POINT_LIGHT_H
#define SPILLWAY_SHARED_POINT_LIGHT_H
#include "light_sample.h"

SHARED_BEGIN

// Radiance is intensity / r^2, the pdf the pick probability alone.
SHARED_FN LightSample point_lightSample(SCENE_PARAM RenderParams rp, Emitter e, SurfaceHit hit,
                                        vec2 u) {
    SCENE_UNUSED;
    UNUSED(rp);
    UNUSED(u);
    LightSample ls = noLightSample();
    vec3 d = e.p0 - hit.p;
    float dist = length(d);
    if (!(dist > 0.0f)) return ls;
    ls.wi = d / dist;
    ls.radiance = e.radiance / (dist * dist);
    ls.pdf = e.pickPdf;
    // Stop short of the point by the origin's own offset: there is no surface at q.
    ls.tmax = shadowRayTmax(dist, hit.offset, 0.0f, 1.0f);
    return ls;
}

SHARED_END
#endif
