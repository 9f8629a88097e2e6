// Emitters: every emitting surface is a list of triangles (a Quad light is two), each sampled
// uniformly by area; punctual lights; and the environment. Next-event estimation picks one in
// proportion to its power. pdfs are converted to solid angle at the shading point so that MIS
// compares like with like. Each kind of emitter is a line of the registry
// (shared/emitter_kinds.h) and a header of its own, <stem>.h, which defines
//   LightSample <stem>Sample(SCENE_PARAM RenderParams rp, Emitter e, SurfaceHit hit, vec2 u)
// (one light sample toward emitter e from the hit, with u uniform in [0, 1)^2); this file
// dispatches on the kind.
#ifndef SPILLWAY_SHARED_LIGHTS_H
#define SPILLWAY_SHARED_LIGHTS_H
#include "emitter_kind_headers.h"
#include "light_sample.h"

SHARED_BEGIN

SHARED_FN LightSample sampleEmitter(SCENE_PARAM RenderParams rp, Emitter e, SurfaceHit hit,
                                    vec2 u) {
#define SPW_SAMPLE_EMITTER(Name, id, stem, Scene, flags)                                           \
    if (e.type == kEmitter##Name) return stem##Sample(SCENE_ARG rp, e, hit, u);
    SPW_EMITTER_KINDS(SPW_SAMPLE_EMITTER)
#undef SPW_SAMPLE_EMITTER
    return noLightSample();
}

// Whether an emitter of this kind is a delta light (its FLAGS in the registry).
SHARED_FN bool emitterIsDelta(uint type) {
#define SPW_EMITTER_IS_DELTA(Name, id, stem, Scene, flags)                                         \
    if (type == kEmitter##Name) return ((flags)&kLightDelta) != 0u;
    SPW_EMITTER_KINDS(SPW_EMITTER_IS_DELTA)
#undef SPW_EMITTER_IS_DELTA
    return false;
}

SHARED_END
#endif
