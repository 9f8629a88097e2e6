// The BSDF interface every surface model implements, and the dispatch over models. Directions
// point away from the surface; `fcos` means f(wo, wi) * |cos(ns, wi)|.
//
// Models (one file each, registered in host/surface_models.h):
//   Null    — no response: absorbs everything (emitter-only geometry)
//   Lambert — lambert.h
#ifndef SPILLWAY_SHARED_BSDF_H
#define SPILLWAY_SHARED_BSDF_H
#include "lambert.h"
#include "types.h"

SHARED_BEGIN

// f * |cos| and the solid-angle pdf of sampling wi.
SHARED_FN vec3 bsdfEval(uint model, vec3 albedo, vec3 ng, vec3 ns, vec3 wo, vec3 wi,
                        OUT(float) pdf) {
    pdf = 0.0f;
    if (model == kModelLambert) return lambertEval(albedo, ng, ns, wo, wi, pdf);
    return vec3(0.0f);
}

// Samples wi; returns false when the model absorbs. weight = fcos / pdf.
SHARED_FN bool bsdfSample(uint model, vec3 albedo, vec3 ng, vec3 ns, vec3 wo, vec3 u,
                          OUT(vec3) wi, OUT(vec3) weight, OUT(float) pdf, OUT(bool) specular) {
    specular = false;
    pdf = 0.0f;
    weight = vec3(0.0f);
    wi = vec3(0.0f);
    if (model == kModelLambert) return lambertSample(albedo, ng, ns, wo, vec2(u.x, u.y), wi, weight, pdf);
    return false;
}

SHARED_END
#endif
