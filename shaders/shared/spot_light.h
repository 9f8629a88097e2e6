// A spot light at p0 shining along the unit direction `normal`: intensity (W/sr) `radiance` on
// its axis, falling off with the angle theta to it as glTF's KHR_lights_punctual recommends,
//   I(theta) = I t^2, t = clamp((cos theta - cos outer) / (cos inner - cos outer), 0, 1),
// full inside the inner cone, nothing outside the outer one; e1.x holds cos(outer), e1.y
// cos(inner). A delta light: never hit, never found by BSDF sampling.
#ifndef SPILLWAY_SHARED_SPOT_LIGHT_H
#define SPILLWAY_SHARED_SPOT_LIGHT_H
#include "light_sample.h"

SHARED_BEGIN

// The falloff t^2 at cosine `cosTheta` to the axis.
SHARED_FN float spotFalloff(Emitter e, float cosTheta) {
    float t = clamp((cosTheta - e.e1.x) / max(e.e1.y - e.e1.x, 1e-3f), 0.0f, 1.0f);
    return t * t;
}

// Radiance is I(theta) / r^2, the pdf the pick probability alone.
SHARED_FN LightSample spot_lightSample(SCENE_PARAM RenderParams rp, Emitter e, SurfaceHit hit,
                                       vec2 u) {
    SCENE_UNUSED;
    UNUSED(rp);
    UNUSED(u);
    LightSample ls = noLightSample();
    vec3 d = e.p0 - hit.p;
    float dist = length(d);
    if (!(dist > 0.0f)) return ls;
    vec3 wi = d / dist;
    float falloff = spotFalloff(e, -dot(wi, e.normal));
    if (!(falloff > 0.0f)) return ls;
    ls.wi = wi;
    ls.radiance = e.radiance * (falloff / (dist * dist));
    ls.pdf = e.pickPdf;
    // Stop short of the point by the origin's own offset: there is no surface at q.
    ls.tmax = shadowRayTmax(dist, hit.offset, 0.0f, 1.0f);
    return ls;
}

SHARED_END
#endif
