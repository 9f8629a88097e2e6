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

    // 2. Next-event estimation: one emitter picked by power, one point on it by area. A BSDF of
    //    delta lobes only can never reach the sampled point: no shadow ray.
    if (rp.emitterCount > 0u && rp.strategy != kStrategyBsdf && !bsdfIsDelta(sh)) {
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
            vec3 fcos = bsdfEval(sh, hit.albedo, hit.ng, hit.ns, wo, wi, bsdfPdf);
            if (lightPdf > 0.0f && maxComponent(fcos) > 0.0f) {
                float w = rp.strategy == kStrategyMis
                              ? powerHeuristic(lightPdf, quantizePdf(bsdfPdf))
                              : 1.0f;
                r.shadowOrigin = offsetOrigin(hit.p, hit.ng, hit.offset, wi);
                r.shadowDir = wi;
                // Stop short of the emitter's own surface, whatever the scene's scale.
                float offsetQ = surfaceOffset(q, e.p0, e.p0 + e.e1, e.p0 + e.e2, e.normal);
                r.shadowTmax = shadowRayTmax(dist, hit.offset, offsetQ, cosLight);
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

SHARED_END
#endif
