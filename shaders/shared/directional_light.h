// A directional (distant) light: irradiance E (W/m^2) on a surface facing it, arriving from
// infinity along the unit direction e.normal, the same everywhere (the sun; glTF's
// KHR_lights_punctual "directional"). A delta light: never hit, never found by BSDF sampling.
#ifndef SPILLWAY_SHARED_DIRECTIONAL_LIGHT_H
#define SPILLWAY_SHARED_DIRECTIONAL_LIGHT_H
#include "light_sample.h"

SHARED_BEGIN

// The direction back toward the light; the pdf is the pick probability alone, and the shadow
// ray goes to infinity (the light is outside the scene).
SHARED_FN LightSample directional_lightSample(SCENE_PARAM RenderParams rp, Emitter e,
                                              SurfaceHit hit, vec2 u) {
    SCENE_UNUSED;
    UNUSED(rp);
    UNUSED(hit);
    UNUSED(u);
    LightSample ls;
    ls.wi = -e.normal;
    ls.radiance = e.radiance;
    ls.pdf = e.pickPdf;
    ls.tmax = kInfiniteDistance;
    return ls;
}

SHARED_END
#endif
