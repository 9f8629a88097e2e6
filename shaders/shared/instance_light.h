// An emissive prototype's triangles where one instance places them: the light of an instance
// whose prototype is placed too often for a world-space copy of each triangle
// (host/scene_view/lights.cpp, kMostCopiedEmitters). The light tree and the CDF hold the
// instance as one emitter, by its world bounds and power; sampling it picks one of the
// prototype's triangles by its share of the prototype's power (the same for every instance),
// moves it to world space through the instance's transform and samples it as a triangle light.
//
// Its words (shared/types.h's Emitter):
//   p0, e1   the low and high corners of its world bounds (for the light tree's build)
//   area     the offset in the emitter table (EMITTER_CDF) of its transform: 12 words, the
//            columns of the linear map, then the translation
//   e2       the prototype's first triangle emitter (object space, each pickPdf its share of the
//            prototype's power), how many there are, and the table offset of their CDF
//   twoSided where its triangles start in the numbering of all instances' triangles: a hit on
//            its triangle k has emitter index kInstanceTriangle | (twoSided + k)
//   normal.x -1 where the transform mirrors (the front faces stay the file's), else 1
#ifndef SPILLWAY_SHARED_INSTANCE_LIGHT_H
#define SPILLWAY_SHARED_INSTANCE_LIGHT_H
#include "triangle_light.h"

SHARED_BEGIN

// A hit's emitter index (SurfaceHit::emitter) with this bit names an instance's triangle by the
// numbering of all instances' triangles in its low bits, not a table entry.
const uint kInstanceTriangle = 0x80000000u;

SHARED_FN uint instanceTriangles(Emitter e) {
    return floatBitsToUint(e.e2.y);
}

// Triangle k of instance `inst` in world space, its pickPdf its share of the instance's power.
SHARED_FN Emitter instanceTriangle(SCENE_PARAM Emitter inst, uint k) {
    Emitter t = EMITTER(floatBitsToUint(inst.e2.x) + k);
    uint m = floatBitsToUint(inst.area);
    vec3 c0 = vec3(EMITTER_CDF(m), EMITTER_CDF(m + 1u), EMITTER_CDF(m + 2u));
    vec3 c1 = vec3(EMITTER_CDF(m + 3u), EMITTER_CDF(m + 4u), EMITTER_CDF(m + 5u));
    vec3 c2 = vec3(EMITTER_CDF(m + 6u), EMITTER_CDF(m + 7u), EMITTER_CDF(m + 8u));
    vec3 c3 = vec3(EMITTER_CDF(m + 9u), EMITTER_CDF(m + 10u), EMITTER_CDF(m + 11u));
    t.p0 = c0 * t.p0.x + c1 * t.p0.y + c2 * t.p0.z + c3;
    t.e1 = c0 * t.e1.x + c1 * t.e1.y + c2 * t.e1.z;
    t.e2 = c0 * t.e2.x + c1 * t.e2.y + c2 * t.e2.z;
    vec3 n = cross(t.e1, t.e2);
    float len = length(n);
    t.area = 0.5f * len;
    t.normal = len > 0.0f ? n * (inst.normal.x / len) : vec3(0.0f, 0.0f, 1.0f);
    return t;
}

// One of the instance's triangles picked by power with u.x, which is then stretched back over
// [0, 1) for the point on it; pickPdf on entry is the instance's own.
SHARED_FN LightSample instance_lightSample(SCENE_PARAM RenderParams rp, Emitter e, SurfaceHit hit,
                                           vec2 u) {
    uint cdf = floatBitsToUint(e.e2.z);
    uint k = pickInCdf(SCENE_ARG cdf, instanceTriangles(e), u.x);
    float below = k > 0u ? EMITTER_CDF(cdf + k - 1u) : 0.0f;
    float width = EMITTER_CDF(cdf + k) - below;
    if (!(width > 0.0f)) return noLightSample();
    u.x = min((u.x - below) / width, kOneMinusEpsilon);
    Emitter t = instanceTriangle(SCENE_ARG e, k);
    t.pickPdf *= e.pickPdf;
    return triangle_lightSample(SCENE_ARG rp, t, hit, u);
}

// The emitter a ray hit (SurfaceHit::emitter, not kNoEmitter), in world space: a table entry, or
// an instance's triangle. `light` is the entry that next-event estimation picks it through
// (itself, or the instance), and the emitter's pickPdf is its share of that entry's.
SHARED_FN Emitter hitEmitter(SCENE_PARAM RenderParams rp, uint index, OUT(uint) light) {
    light = index;
    if ((index & kInstanceTriangle) == 0u) {
        Emitter e = EMITTER(index);
        e.pickPdf = 1.0f;
        return e;
    }
    // The instance whose triangles' hit indices hold it: the last one starting at or below it.
    uint h = index & ~kInstanceTriangle;
    uint base = rp.instanceLights;
    uint len = rp.instanceLightCount;
    while (len > 1u) {
        uint step = len >> 1u;
        base = EMITTER(base + step).twoSided <= h ? base + step : base;
        len -= step;
    }
    light = base;
    Emitter inst = EMITTER(base);
    return instanceTriangle(SCENE_ARG inst, min(h - inst.twoSided, instanceTriangles(inst) - 1u));
}

SHARED_END
#endif
