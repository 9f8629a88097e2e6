// The BSDF interface every surface model implements, and the dispatch over models. Directions
// point away from the surface; `fcos` means f(wo, wi) * |cos(ns, wi)|.
//
// Models (one file each, registered in host/scene/surface_models.h):
//   Null       — no response: absorbs everything (emitter-only geometry)
//   Lambert    — lambert.h
//   Conductor  — conductor.h (GGX, Schlick Fresnel; alpha 0: mirror)
//   Dielectric — dielectric.h (GGX, exact Fresnel, refraction; alpha 0: smooth glass)
//
// Delta lobes (smooth Conductor and Dielectric): bsdfEval gives 0 for them, bsdfSample returns
// them with `specular` set, pdf 0 and weight = the lobe's fcos / its discrete probability.
#ifndef SPILLWAY_SHARED_BSDF_H
#define SPILLWAY_SHARED_BSDF_H
#include "conductor.h"
#include "dielectric.h"
#include "lambert.h"
#include "types.h"

SHARED_BEGIN

// True when the shader's BSDF is nothing but delta lobes: light sampling can never hit them,
// so next-event estimation is skipped.
SHARED_FN bool bsdfIsDelta(ShaderParams sh) {
    return (sh.model == kModelConductor || sh.model == kModelDielectric) && ggxIsSmooth(sh.alpha);
}

// f * |cos| and the solid-angle pdf of sampling wi. `albedo`: the hit's reflectance x texture
// (the Conductor's F0).
SHARED_FN vec3 bsdfEval(ShaderParams sh, vec3 albedo, vec3 ng, vec3 ns, vec3 wo, vec3 wi,
                        OUT(float) pdf) {
    pdf = 0.0f;
    if (sh.model == kModelLambert) return lambertEval(albedo, ng, ns, wo, wi, pdf);
    if (sh.model == kModelConductor) return conductorEval(albedo, sh.alpha, ng, ns, wo, wi, pdf);
    if (sh.model == kModelDielectric) return dielectricEval(sh.ior, sh.alpha, ng, ns, wo, wi, pdf);
    return vec3(0.0f);
}

// Samples wi; returns false when the model absorbs. weight = fcos / pdf (for a delta lobe: its
// fcos over the probability of having picked it). u: x, y pick the direction, z the lobe.
SHARED_FN bool bsdfSample(ShaderParams sh, vec3 albedo, vec3 ng, vec3 ns, vec3 wo, vec3 u,
                          OUT(vec3) wi, OUT(vec3) weight, OUT(float) pdf, OUT(bool) specular) {
    specular = false;
    pdf = 0.0f;
    weight = vec3(0.0f);
    wi = vec3(0.0f);
    if (sh.model == kModelLambert)
        return lambertSample(albedo, ng, ns, wo, vec2(u.x, u.y), wi, weight, pdf);
    if (sh.model == kModelConductor)
        return conductorSample(albedo, sh.alpha, ng, ns, wo, vec2(u.x, u.y), wi, weight, pdf,
                               specular);
    if (sh.model == kModelDielectric)
        return dielectricSample(sh.ior, sh.alpha, ng, ns, wo, u, wi, weight, pdf, specular);
    return false;
}

SHARED_END
#endif
