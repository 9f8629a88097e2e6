// What every emitter kind's header (shared/emitter_kinds.h) builds on: the light sample it
// returns, and the geometry of triangle emitters that MIS also reads when a ray hits one.
#ifndef SPILLWAY_SHARED_LIGHT_SAMPLE_H
#define SPILLWAY_SHARED_LIGHT_SAMPLE_H
#include "emission_map.h"
#include "offset.h"
#include "sampling.h"
#include "scene_access.h"

SHARED_BEGIN

// One light sample from a shading point: the direction, how far the shadow ray may go, the
// radiance (or a point light's intensity / r^2) arriving along it, and its solid-angle pdf
// including the emitter's pick probability (for a point light, the pick probability alone).
struct LightSample {
    vec3 wi;
    float tmax;
    vec3 radiance;
    float pdf;
};

// An empty sample: no light reaches the point (pdf 0).
SHARED_FN LightSample noLightSample() {
    LightSample ls;
    ls.wi = vec3(0.0f, 0.0f, 1.0f);
    ls.tmax = 0.0f;
    ls.radiance = vec3(0.0f);
    ls.pdf = 0.0f;
    return ls;
}

// Index k < count of the interval of the CDF at EMITTER_CDF(first ..) that holds u: the first
// entry > u (the last entry is 1 > u).
// A binary search whose steps depend on the count alone and whose halving is a select, not a
// branch: which half u falls in is a coin flip the CPU would mispredict half the time.
SHARED_FN uint pickInCdf(SCENE_PARAM uint first, uint count, float u) {
    uint base = 0u;
    uint len = count;
    while (len > 1u) {
        uint step = len >> 1u;
        base = EMITTER_CDF(first + base + step) <= u ? base + step : base;
        len -= step;
    }
    return base + uint(EMITTER_CDF(first + base) <= u);
}

// Index of the emitter whose CDF interval holds u.
SHARED_FN uint pickEmitter(SCENE_PARAM uint count, float u) {
    return pickInCdf(SCENE_ARG 0u, count, u);
}

// Cosine at the emitter between its normal and the direction back to the receiver, 0 if the
// receiver sees the emitter's back (one-sided emitters).
// SIMD twin: host/simd/simd_math-inl.h
SHARED_FN float emitterCosine(Emitter e, vec3 towardReceiver) {
    float c = dot(e.normal, towardReceiver);
    if (e.twoSided != 0u) c = abs(c);
    return max(c, 0.0f);
}

// Solid-angle pdf of reaching a point of emitter e at distance `dist` with cosine `cosLight`
// through light sampling.
// SIMD twin: host/simd/simd_math-inl.h
SHARED_FN float emitterSolidAnglePdf(Emitter e, float dist, float cosLight) {
    if (cosLight <= 0.0f) return 0.0f;
    return e.pickPdf * (dist * dist) / (cosLight * e.area);
}

// SIMD twin: host/simd/simd_math-inl.h
SHARED_FN vec3 emitterPoint(Emitter e, vec2 u) {
    vec2 b = sampleTriangle(u);
    return e.p0 + b.x * e.e1 + b.y * e.e2;
}

SHARED_END
#endif
