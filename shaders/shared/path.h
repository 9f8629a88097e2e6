// One bounce of a path, the whole of the integrator: given a ray's hit and the path's state,
// add what the hit emits (MIS-weighted), prepare one next-event-estimation shadow ray with its
// pending contribution, and sample the BSDF for the continuation ray (Russian roulette after
// min depth). The reference backend traces the two rays at once; the sorted backends queue them.
// Either way the arithmetic is this function's, and the random numbers depend only on
// (seed, pixel, sample, bounce, dimension).
#ifndef SPILLWAY_SHARED_PATH_H
#define SPILLWAY_SHARED_PATH_H
#include "bsdf.h"
#include "lights.h"
#include "rng.h"

SHARED_BEGIN

// How far a new ray's origin moves off a surface: proportional to the floating-point magnitude
// of the hit point (its coordinates' ulp), never a scene-unit epsilon. The hit point comes from
// barycentric interpolation of the vertices, whose rounding error is a few ulps of the largest
// coordinate; 2^-20 relative gives an 8-ulp margin. The tiny absolute term keeps a point at the
// exact origin movable.
SHARED_FN float originOffset(vec3 p) {
    vec3 a = abs(p);
    return max(a.x, max(a.y, a.z)) * (1.0f / 1048576.0f) + 1e-30f;
}

// p moved off its surface to the side of ng that `dir` leaves towards.
SHARED_FN vec3 offsetOrigin(vec3 p, vec3 ng, vec3 dir) {
    float side = dot(ng, dir) >= 0.0f ? 1.0f : -1.0f;
    return p + ng * (side * originOffset(p));
}

// The pixel and the render-wide sample index of a path.
SHARED_FN uint pathPixel(RenderParams rp, uint pathId) { return pathId / rp.samplesPerIteration; }
SHARED_FN uint pathSample(RenderParams rp, uint pathId) {
    return rp.iteration * rp.samplesPerIteration + pathId % rp.samplesPerIteration;
}

SHARED_FN void shadeSurface(SCENE_PARAM RenderParams rp, SurfaceHit hit, vec3 rayDir, PathState st,
                            OUT(ShadeResult) r) {
    r.flags = 0u;
    r.emitted = vec3(0.0f);
    r.shadowContribution = vec3(0.0f);
    r.shadowOrigin = vec3(0.0f);
    r.shadowDir = vec3(0.0f);
    r.shadowTmax = 0.0f;
    r.nextOrigin = vec3(0.0f);
    r.nextDir = vec3(0.0f);
    r.next = st;

    ShaderParams sh = SHADER(hit.shader);
    vec3 wo = -rayDir;
    uint pixel = pathPixel(rp, st.pathId);
    uint sampleIndex = pathSample(rp, st.pathId);

    // 1. Emission seen by this ray, weighted against having sampled it from the previous vertex.
    if (hit.emitter != kNoEmitter) {
        Emitter e = EMITTER(hit.emitter);
        float cosLight = emitterCosine(e, wo);
        if (cosLight > 0.0f) {
            float w = 1.0f;
            bool sampledByBsdf = st.bounce > 0u && (st.flags & kPathSpecular) == 0u;
            if (sampledByBsdf && rp.strategy == kStrategyLight) w = 0.0f;
            if (sampledByBsdf && rp.strategy == kStrategyMis) {
                float lightPdf = emitterSolidAnglePdf(e, hit.t, cosLight);
                w = powerHeuristic(st.prevPdf, lightPdf);
            }
            r.emitted = st.beta * e.radiance * w;
            if (w > 0.0f) r.flags |= kShadeEmitted;
        }
    }

    if (st.bounce >= rp.maxDepth || sh.model == kModelNull) return;

    vec4 uLight = rand4(rp.seed, pixel, sampleIndex, st.bounce, kDimLight);

    // 2. Next-event estimation: one emitter picked by power, one point on it by area.
    if (rp.emitterCount > 0u && rp.strategy != kStrategyBsdf) {
        uint ei = pickEmitter(SCENE_ARG rp.emitterCount, uLight.x);
        Emitter e = EMITTER(ei);
        vec3 q = emitterPoint(e, vec2(uLight.y, uLight.z));
        vec3 d = q - hit.p;
        float dist = length(d);
        if (dist > 0.0f) {
            vec3 wi = d / dist;
            float cosLight = emitterCosine(e, -wi);
            float lightPdf = emitterSolidAnglePdf(e, dist, cosLight);
            float bsdfPdf;
            vec3 fcos = bsdfEval(sh.model, hit.albedo, hit.ng, hit.ns, wo, wi, bsdfPdf);
            if (lightPdf > 0.0f && maxComponent(fcos) > 0.0f) {
                float w = rp.strategy == kStrategyMis ? powerHeuristic(lightPdf, quantizePdf(bsdfPdf)) : 1.0f;
                vec3 origin = offsetOrigin(hit.p, hit.ng, wi);
                r.shadowOrigin = origin;
                r.shadowDir = wi;
                // Stop short of the emitter by its own offset so its surface never occludes.
                r.shadowTmax = dist - originOffset(q) - originOffset(hit.p) * 2.0f;
                r.shadowContribution = st.beta * fcos * e.radiance * (w / lightPdf);
                if (r.shadowTmax > 0.0f) r.flags |= kShadeShadow;
            }
        }
    }

    // 3. Continuation: sample the BSDF, then Russian roulette once min depth bounces are done.
    vec4 uBsdf = rand4(rp.seed, pixel, sampleIndex, st.bounce, kDimBsdf);
    vec3 wi;
    vec3 weight;
    float pdf;
    bool specular;
    if (!bsdfSample(sh.model, hit.albedo, hit.ng, hit.ns, wo, vec3(uBsdf.x, uBsdf.y, uBsdf.z), wi,
                    weight, pdf, specular))
        return;
    vec3 beta = st.beta * weight;
    if (st.bounce >= rp.minDepth) {
        // Veach's rule as the scene format states it: continue with probability min(1, t / delta).
        float q = min(1.0f, maxComponent(beta) / rp.threshold);
        if (!(uLight.w < q)) return;
        beta = beta / q;
    }
    if (!(maxComponent(beta) > 0.0f)) return;
    r.nextOrigin = offsetOrigin(hit.p, hit.ng, wi);
    r.nextDir = wi;
    r.next.beta = beta;
    r.next.prevPdf = quantizePdf(pdf);
    r.next.bounce = st.bounce + 1u;
    r.next.flags = specular ? kPathSpecular : 0u;
    r.flags |= kShadeContinue;
}

SHARED_END
#endif
