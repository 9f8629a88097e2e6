// One bounce of a path, the whole of the integrator: given a ray's hit and the path's state,
// add what the hit emits (MIS-weighted), prepare one next-event-estimation shadow ray with its
// pending contribution, and sample the BSDF for the continuation ray (Russian roulette after
// min depth). The reference backend traces the two rays at once; the sorted backends queue them.
// Either way the arithmetic is this function's, and the random numbers depend only on
// (seed, pixel, sample, bounce, dimension).
#ifndef SPILLWAY_SHARED_PATH_H
#define SPILLWAY_SHARED_PATH_H
#include "bsdf.h"
#include "cone.h"
#include "lights.h"
#include "offset.h"
#include "rng.h"

SHARED_BEGIN

// The pixel and the render-wide sample index of a path.
SHARED_FN uint pathPixel(RenderParams rp, uint pathId) {
    return pathId / rp.samplesPerIteration;
}
SHARED_FN uint pathSample(RenderParams rp, uint pathId) {
    return rp.iteration * rp.samplesPerIteration + pathId % rp.samplesPerIteration;
}

// A camera path's state before its first bounce: throughput 1, sample `s` of `pixel`.
// pixelSpread: the angle one pixel subtends (CameraModel::pixelSpread), the cone's spread.
SHARED_FN PathState cameraPath(RenderParams rp, uint pixel, uint s, float pixelSpread) {
    PathState st;
    st.beta = vec3(1.0f);
    st.prevPdf = 0.0f;
    st.pathId = pixel * rp.samplesPerIteration + s;
    st.bounce = 0u;
    st.flags = 0u;
    st.cone = packCone(0.0f, pixelSpread);
    return st;
}

// What a ray that leaves the scene brings back: the environment's radiance along it, weighted
// against having sampled that direction from the previous vertex (zero without an environment).
SHARED_FN vec3 escapedRadiance(SCENE_PARAM RenderParams rp, vec3 rayDir, PathState st) {
    if (rp.environment == kNoEmitter) return vec3(0.0f);
    Emitter e = EMITTER(rp.environment);
    float w = 1.0f;
    bool sampledByBsdf = st.bounce > 0u && (st.flags & kPathSpecular) == 0u;
    if (sampledByBsdf && rp.strategy == kStrategyLight) w = 0.0f;
    bool weighed = sampledByBsdf && rp.strategy == kStrategyMis;
    float pdf;
    vec3 radiance = environmentLookUp(SCENE_ARG rp, e, rayDir, weighed, pdf);
    if (weighed) w = powerHeuristic(st.prevPdf, e.pickPdf * pdf);
    return st.beta * radiance * w;
}

// Step 1 of shadeSurface: what the hit's emitter sends back along the ray (r.emitted, with
// kShadeEmitted set in r.flags when it counts), weighted against having sampled it from the
// previous vertex. r.emitted and r.flags must be zero on entry.
SHARED_FN void addEmission(SCENE_PARAM RenderParams rp, SurfaceHit hit, vec3 wo, PathState st,
                           INOUT(ShadeResult) r) {
    if (hit.emitter == kNoEmitter) return;
    uint light;
    Emitter e = hitEmitter(SCENE_ARG rp, hit.emitter, light);
    float cosLight = emitterCosine(e, wo);
    if (!(cosLight > 0.0f)) return;
    float w = 1.0f;
    bool sampledByBsdf = st.bounce > 0u && (st.flags & kPathSpecular) == 0u;
    if (sampledByBsdf && rp.strategy == kStrategyLight) w = 0.0f;
    if (sampledByBsdf && rp.strategy == kStrategyMis) {
        // The pick probability from the ray's origin, the previous vertex.
        e.pickPdf *= lightPickPdf(SCENE_ARG rp, light, hit.p + hit.t * wo);
        float lightPdf = emitterSolidAnglePdf(e, hit.t, cosLight);
        w = powerHeuristic(st.prevPdf, lightPdf);
    }
    r.emitted = st.beta * emitterRadianceAt(SCENE_ARG e, hit.p) * w;
    if (w > 0.0f) r.flags |= kShadeEmitted;
}

// Next-event estimation toward a light that the triangle's plane hides but the smooth surface its
// vertex normals describe does not: the light below the triangle on the viewer's side, above
// the interpolated normal, at a hit lifted toward the viewer (SurfaceHit::lift, shared/offset.h).
// The BSDF there as if the interpolated normal were the geometric one, and `toward` set to wo:
// the side the shadow ray leaves from, lifted onto the smooth surface, from where it clears the
// facets next to it on a convex mesh and is caught by them on a concave one (which has no lift).
// Zero elsewhere, `toward` left as it was. The pdf is 0: BSDF sampling never leaves below the
// triangle, so these directions are found by light sampling alone, at MIS weight 1.
// host/cpu/simd_shading.cpp's shadowLanes does the same SIMD-wide.
SHARED_FN vec3 terminatorEval(ShaderParams sh, SurfaceHit hit, vec3 wo, vec3 wi,
                              INOUT(vec3) toward) {
    float side = dot(hit.ng, wo);
    if (!(side * hit.lift > 0.0f) || side * dot(hit.ng, wi) > 0.0f) return vec3(0.0f);
    if (!(dot(hit.ns, wo) > 0.0f) || !(dot(hit.ns, wi) > 0.0f)) return vec3(0.0f);
    float pdf;
    vec3 fcos = bsdfEval(sh, hit.albedo, hit.ns, hit.ns, wo, wi, pdf);
    if (maxComponent(fcos) > 0.0f) toward = wo;
    return fcos;
}

// The path's state at a hit, its throughput attenuated by the medium the ray crossed: a ray that
// reaches a surface with an absorption (a Dielectric, a TransmissiveMetallicRoughness) from behind
// (the side its geometric normal points away from) travelled hit.t inside that surface's medium,
// which passes exp(-absorption t) (Beer-Lambert). A medium is known by the surface that bounds it:
// a surface inside it (nested media) is reached without the attenuation. A clear medium (absorption
// 0) leaves beta as it was, to the bit. host/cpu/simd_shading.cpp's fillLane calls it per lane.
SHARED_FN PathState throughMedium(ShaderParams sh, SurfaceHit hit, vec3 wo, PathState st) {
    if (dot(hit.ng, wo) < 0.0f && maxComponent(sh.absorption) > 0.0f)
        st.beta = st.beta * exp(-sh.absorption * hit.t);
    return st;
}

// Whether the path goes on from a hit of shader sh: it samples a light and its BSDF.
SHARED_FN bool shadeGoesOn(RenderParams rp, ShaderParams sh, PathState st) {
    return st.bounce < rp.maxDepth && sh.model != kModelNull;
}

// Step 2 of shadeSurface: one emitter picked (pickLight, uLight.x), one point on it or direction
// to it (uLight.yz), and the shadow ray toward it with its pending contribution (r.shadow*,
// kShadeShadow in r.flags when there is one to trace).
SHARED_FN void addShadowRay(SCENE_PARAM RenderParams rp, ShaderParams sh, SurfaceHit hit, vec3 wo,
                            PathState st, vec4 uLight, INOUT(ShadeResult) r) {
    float pickPdf;
    uint ei = pickLight(SCENE_ARG rp, hit.p, uLight.x, pickPdf);
    if (ei == kNoEmitter) return;
    Emitter e = EMITTER(ei);
    e.pickPdf = pickPdf;
    LightSample ls = sampleEmitter(SCENE_ARG rp, e, hit, vec2(uLight.y, uLight.z));
    if (!(ls.pdf > 0.0f)) return;
    float bsdfPdf;
    vec3 fcos = bsdfEval(sh, hit.albedo, hit.ng, hit.ns, wo, ls.wi, bsdfPdf);
    vec3 toward = ls.wi; // the side of the surface the shadow ray leaves from
    if (!(maxComponent(fcos) > 0.0f)) {
        fcos = terminatorEval(sh, hit, wo, ls.wi, toward);
        bsdfPdf = 0.0f;
    }
    if (!(maxComponent(fcos) > 0.0f)) return;
    // A delta light (a point, a direction): BSDF sampling cannot find it, no MIS.
    float w = rp.strategy == kStrategyMis && !emitterIsDelta(e.type)
                  ? powerHeuristic(ls.pdf, quantizePdf(bsdfPdf))
                  : 1.0f;
    // Lifted, the origin comes nearer the light by up to `lift` along the ray and moves as far
    // across it: the ray stops twice that much sooner.
    float lift = shadowLift(hit.ng, hit.lift, toward, ls.tmax);
    r.shadowOrigin = offsetOrigin(hit.p, hit.ng, hit.offset + lift, toward);
    r.shadowDir = ls.wi;
    r.shadowTmax = ls.tmax - 2.0f * lift;
    r.shadowContribution = st.beta * fcos * ls.radiance * (w / ls.pdf);
    if (r.shadowTmax > 0.0f) r.flags |= kShadeShadow;
}

// shadeSurface with the path's random numbers for this bounce given: uLight = rand4(kDimLight),
// uBsdf = rand4(kDimBsdf) (read only where shadeGoesOn), so that a caller can make them many at
// a time (host/cpu/simd_shading.cpp).
SHARED_FN void shadeSurfaceWith(SCENE_PARAM RenderParams rp, SurfaceHit hit, vec3 rayDir,
                                PathState st, vec4 uLight, vec4 uBsdf, OUT(ShadeResult) r) {
    r.flags = 0u;
    r.emitted = vec3(0.0f);
    r.shadowContribution = vec3(0.0f);
    r.shadowOrigin = vec3(0.0f);
    r.shadowDir = vec3(0.0f);
    r.shadowTmax = 0.0f;
    r.nextOrigin = vec3(0.0f);
    r.nextDir = vec3(0.0f);
    ShaderParams sh = shaderAtHit(SHADER(hit.shader), hit);
    vec3 wo = -rayDir;
    st = throughMedium(sh, hit, wo, st);
    r.next = st;

    // 1. Emission seen by this ray, weighted against having sampled it from the previous vertex.
    addEmission(SCENE_ARG rp, hit, wo, st, r);

    if (!shadeGoesOn(rp, sh, st)) return;

    // 2. Next-event estimation. A BSDF of delta lobes only can never reach a sampled point.
    if (rp.emitterCount > 0u && rp.strategy != kStrategyBsdf && !bsdfIsDelta(sh))
        addShadowRay(SCENE_ARG rp, sh, hit, wo, st, uLight, r);

    // 3. Continuation: sample the BSDF, then Russian roulette once min depth bounces are done.
    vec3 wi;
    vec3 weight;
    float pdf;
    bool specular;
    if (!bsdfSample(sh, hit.albedo, hit.ng, hit.ns, wo, vec3(uBsdf.x, uBsdf.y, uBsdf.z), wi, weight,
                    pdf, specular))
        return;
    vec3 beta = st.beta * weight;
    if (st.bounce >= rp.minDepth) {
        // Veach's rule as the scene format states it: continue with probability min(1, t / delta).
        float q = min(1.0f, maxComponent(beta) / rp.threshold);
        if (!(uLight.w < q)) return;
        beta = beta / q;
    }
    if (!(maxComponent(beta) > 0.0f)) return;
    r.nextOrigin = offsetOrigin(hit.p, hit.ng, hit.offset, wi);
    r.nextDir = wi;
    r.next.beta = beta;
    r.next.prevPdf = quantizePdf(pdf);
    r.next.bounce = st.bounce + 1u;
    r.next.flags = specular ? kPathSpecular : 0u;
    r.next.cone =
        packCone(coneWidthAt(st.cone, hit.t), coneSpread(st.cone) + bsdfConeSpread(sh, specular));
    r.flags |= kShadeContinue;
}

// One bounce (the comment at the top of this file), its random numbers made here.
SHARED_FN void shadeSurface(SCENE_PARAM RenderParams rp, SurfaceHit hit, vec3 rayDir, PathState st,
                            OUT(ShadeResult) r) {
    vec4 uLight = vec4(0.0f);
    vec4 uBsdf = vec4(0.0f);
    if (shadeGoesOn(rp, SHADER(hit.shader), st)) {
        uint pixel = pathPixel(rp, st.pathId);
        uint sampleIndex = pathSample(rp, st.pathId);
        uLight = rand4(rp.sampling, rp.seed, pixel, sampleIndex, st.bounce, kDimLight);
        uBsdf = rand4(rp.sampling, rp.seed, pixel, sampleIndex, st.bounce, kDimBsdf);
    }
    shadeSurfaceWith(SCENE_ARG rp, hit, rayDir, st, uLight, uBsdf, r);
}

SHARED_END
#endif
