// Emitters: every emitting surface is a list of triangles (a Quad light is two), each sampled
// uniformly by area; punctual lights; and the environment. Next-event estimation picks one in
// proportion to its power, or, among the emitters at a place where a scene has several, by
// what they can send to the shading point (shared/light_tree.h). pdfs are converted to solid angle
// at the shading point so that MIS compares like with like. Each kind of emitter is a line of the
// registry (shared/emitter_kinds.h) and a header of its own, <stem>.h, which defines
//   LightSample <stem>Sample(SCENE_PARAM RenderParams rp, Emitter e, SurfaceHit hit, vec2 u)
// (one light sample toward emitter e from the hit, with u uniform in [0, 1)^2); this file
// dispatches on the kind.
#ifndef SPILLWAY_SHARED_LIGHTS_H
#define SPILLWAY_SHARED_LIGHTS_H
#include "emitter_kind_headers.h"
#include "light_sample.h"
#include "light_tree.h"

SHARED_BEGIN

SHARED_FN LightSample sampleEmitter(SCENE_PARAM RenderParams rp, Emitter e, SurfaceHit hit,
                                    vec2 u) {
#define SPW_SAMPLE_EMITTER(Name, id, stem, Scene, flags)                                           \
    if (e.type == kEmitter##Name) return stem##Sample(SCENE_ARG rp, e, hit, u);
    SPW_EMITTER_KINDS(SPW_SAMPLE_EMITTER)
#undef SPW_SAMPLE_EMITTER
    return noLightSample();
}

// The emitter next-event estimation takes at shading point p for u uniform in [0, 1), and the
// probability of that choice (pmf; kNoEmitter and 0 when nothing can reach p). The CDF picks
// in proportion to power; where the scene has a light tree, the share the CDF gives the tree's
// emitters (0 .. rp.treeEmitters - 1, the CDF's first entries) goes through the tree instead.
SHARED_FN uint pickLight(SCENE_PARAM RenderParams rp, vec3 p, float u, OUT(float) pmf) {
    if (rp.treeEmitters > 0u) {
        float treeShare = EMITTER_CDF(rp.treeEmitters - 1u);
        if (u < treeShare) {
            uint ei = treePick(SCENE_ARG rp, p, min(u / treeShare, kOneMinusEpsilon), pmf);
            pmf *= treeShare;
            return ei;
        }
    }
    uint ei = pickEmitter(SCENE_ARG rp.emitterCount, u);
    pmf = EMITTER(ei).pickPdf;
    return ei;
}

// The probability that pickLight takes emitter ei at shading point p.
SHARED_FN float lightPickPdf(SCENE_PARAM RenderParams rp, uint ei, vec3 p) {
    if (ei < rp.treeEmitters)
        return EMITTER_CDF(rp.treeEmitters - 1u) * treePmf(SCENE_ARG rp, ei, p);
    return EMITTER(ei).pickPdf;
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
