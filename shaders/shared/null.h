// Null: no response. The surface absorbs everything that reaches it and scatters nothing; it is
// the model of emitter-only geometry (the scene format's Null and Emissive shaders).
//   parameters: none of its own (emission and two sided are every shader's).
#ifndef SPILLWAY_SHARED_NULL_H
#define SPILLWAY_SHARED_NULL_H
#include "types.h"

SHARED_BEGIN

// The registry's interface (shared/bsdf.h dispatches here).
SHARED_FN float nullBsdfConeSpread(ShaderParams sh) {
    UNUSED(sh);
    return 0.0f;
}
SHARED_FN bool nullBsdfIsDelta(ShaderParams sh) {
    UNUSED(sh);
    return false;
}
SHARED_FN vec3 nullBsdfEval(ShaderParams sh, vec3 albedo, vec3 ng, vec3 ns, vec3 wo, vec3 wi,
                            OUT(float) pdf) {
    UNUSED(sh);
    UNUSED(albedo);
    UNUSED(ng);
    UNUSED(ns);
    UNUSED(wo);
    UNUSED(wi);
    pdf = 0.0f;
    return vec3(0.0f);
}
SHARED_FN bool nullBsdfSample(ShaderParams sh, vec3 albedo, vec3 ng, vec3 ns, vec3 wo, vec3 u,
                              OUT(vec3) wi, OUT(vec3) weight, OUT(float) pdf, OUT(bool) specular) {
    UNUSED(sh);
    UNUSED(albedo);
    UNUSED(ng);
    UNUSED(ns);
    UNUSED(wo);
    UNUSED(u);
    // GLSL's `out` parameters are not copied in: write every one.
    wi = vec3(0.0f);
    weight = vec3(0.0f);
    pdf = 0.0f;
    specular = false;
    return false;
}

SHARED_END
#endif
