// Emitters: every emitting surface is a list of triangles (a Quad light is two), each sampled
// uniformly by area and picked in proportion to its power. pdfs are converted to solid angle at
// the shading point so that MIS compares like with like.
#ifndef SPILLWAY_SHARED_LIGHTS_H
#define SPILLWAY_SHARED_LIGHTS_H
#include "sampling.h"
#include "scene_access.h"

SHARED_BEGIN

// Index of the emitter whose CDF interval holds u (binary search, first cdf > u).
SHARED_FN uint pickEmitter(SCENE_PARAM uint count, float u) {
    uint lo = 0u;
    uint hi = count - 1u;
    while (lo < hi) {
        uint mid = (lo + hi) >> 1u;
        if (EMITTER_CDF(mid) > u)
            hi = mid;
        else
            lo = mid + 1u;
    }
    return lo;
}

// Cosine at the emitter between its normal and the direction back to the receiver, 0 if the
// receiver sees the emitter's back (one-sided emitters).
SHARED_FN float emitterCosine(Emitter e, vec3 towardReceiver) {
    float c = dot(e.normal, towardReceiver);
    if (e.twoSided != 0u) c = abs(c);
    return max(c, 0.0f);
}

// Solid-angle pdf of reaching a point of emitter e at distance `dist` with cosine `cosLight`
// through light sampling.
SHARED_FN float emitterSolidAnglePdf(Emitter e, float dist, float cosLight) {
    if (cosLight <= 0.0f) return 0.0f;
    return e.pickPdf * (dist * dist) / (cosLight * e.area);
}

SHARED_FN vec3 emitterPoint(Emitter e, vec2 u) {
    vec2 b = sampleTriangle(u);
    return e.p0 + b.x * e.e1 + b.y * e.e2;
}

SHARED_END
#endif
