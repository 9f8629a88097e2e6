// Lambert: the ideal diffuse reflector.
//   parameters: reflectance (1), colour [r, g, b] ([1, 1, 1]) or texture; albedo = reflectance x
//   colour. f = albedo / pi; sampled by the cosine-weighted hemisphere, pdf = cos / pi, so the
//   sample weight is exactly the albedo. Reflection only: wi on the side of ng that wo is on.
#ifndef SPILLWAY_SHARED_LAMBERT_H
#define SPILLWAY_SHARED_LAMBERT_H
#include "sampling.h"
#include "types.h"

SHARED_BEGIN

// SIMD twin: host/simd/simd_math-inl.h
SHARED_FN vec3 lambertEval(vec3 albedo, vec3 ng, vec3 ns, vec3 wo, vec3 wi, OUT(float) pdf) {
    pdf = 0.0f;
    if (dot(ng, wo) * dot(ng, wi) <= 0.0f) return vec3(0.0f);
    vec3 n = facingShadingNormal(ns, ng, wo);
    float c = dot(n, wi);
    if (c <= 0.0f) return vec3(0.0f);
    pdf = c * kInvPi;
    return albedo * (c * kInvPi);
}

SHARED_FN bool lambertSample(vec3 albedo, vec3 ng, vec3 ns, vec3 wo, vec2 u, OUT(vec3) wi,
                             OUT(vec3) weight, OUT(float) pdf) {
    vec3 n = facingShadingNormal(ns, ng, wo);
    vec3 local = sampleCosineHemisphere(u);
    wi = normalize(toWorld(local, n));
    // With a shading normal the sample can fall below the geometric surface: absorb it, as the
    // eval above gives 0 there, so sampling and evaluation stay consistent.
    if (dot(ng, wo) * dot(ng, wi) <= 0.0f || local.z <= 0.0f) return false;
    pdf = local.z * kInvPi;
    weight = albedo;
    return true;
}

// The registry's interface (shared/bsdf.h dispatches here).
// The cosine lobe is about a radian wide (its half-power angle is 60 degrees).
SHARED_FN float lambertBsdfConeSpread(ShaderParams sh) {
    UNUSED(sh);
    return 1.0f;
}
SHARED_FN bool lambertBsdfIsDelta(ShaderParams sh) {
    UNUSED(sh);
    return false;
}
SHARED_FN vec3 lambertBsdfEval(ShaderParams sh, vec3 albedo, vec3 ng, vec3 ns, vec3 wo, vec3 wi,
                               OUT(float) pdf) {
    UNUSED(sh);
    return lambertEval(albedo, ng, ns, wo, wi, pdf);
}
SHARED_FN bool lambertBsdfSample(ShaderParams sh, vec3 albedo, vec3 ng, vec3 ns, vec3 wo, vec3 u,
                                 OUT(vec3) wi, OUT(vec3) weight, OUT(float) pdf,
                                 OUT(bool) specular) {
    UNUSED(sh);
    specular = false; // never a delta lobe (GLSL's `out` is not copied in: set it here)
    return lambertSample(albedo, ng, ns, wo, vec2(u.x, u.y), wi, weight, pdf);
}

SHARED_END
#endif
