// The BSDF interface every surface model implements, and the dispatch over models. Directions
// point away from the surface; `fcos` means f(wo, wi) * |cos(ns, wi)|.
//
// The models are the registry's (shared/surface_models.h); each one's header <stem>.h defines
// the four functions dispatched to below (<fn> the registry's function prefix), with these
// signatures:
//   bool <fn>BsdfIsDelta(ShaderParams sh)
//   float <fn>BsdfConeSpread(ShaderParams sh)  the angle (radians) its lobe adds to a ray cone's
//                                              spread (shared/cone.h)
//   vec3 <fn>BsdfEval(ShaderParams sh, vec3 albedo, vec3 ng, vec3 ns, vec3 wo, vec3 wi,
//                     OUT(float) pdf)
//   bool <fn>BsdfSample(ShaderParams sh, vec3 albedo, vec3 ng, vec3 ns, vec3 wo, vec3 u,
//                       OUT(vec3) wi, OUT(vec3) weight, OUT(float) pdf, OUT(bool) specular)
// The headers are included through generated/surface_model_headers.h, which CMake writes from
// the registry.
//
// Delta lobes (smooth Conductor and Dielectric): bsdfEval gives 0 for them, bsdfSample returns
// them with `specular` set, pdf 0 and weight = the lobe's fcos / its discrete probability.
#ifndef SPILLWAY_SHARED_BSDF_H
#define SPILLWAY_SHARED_BSDF_H
#include "surface_model_headers.h"
#include "types.h"

SHARED_BEGIN

// The shader's parameters at a hit: with kShaderHitParams (a MetallicRoughness shader with a
// metallic-roughness image), the metallic and the GGX alpha of the roughness the hit carries;
// with kShaderHitExtension (a glTF material extension's images), the four values the hit carries
// (e0 .. e3) as the model's extension: the clear coat's weight e0 and roughness e1 (and, with
// kShaderCoatNormal, its shading normal in e2 and e3's place), the sheen's
// colour (e0, e1, e2) and roughness e3, the transmission e0, or, on the plain model, the specular
// colour (e0, e1, e2) and specular e3.
SHARED_FN ShaderParams shaderAtHit(ShaderParams sh, SurfaceHit hit) {
    if ((sh.flags & kShaderHitParams) != 0u) {
        sh.metallic = float(hit.material & 0xFFFFu) * (1.0f / 65535.0f);
        sh.alpha = gltfAlpha(float(hit.material >> 16u) * (1.0f / 65535.0f));
    }
    if ((sh.flags & kShaderHitExtension) != 0u) {
        vec2 e01 = unpackHalf2x16(hit.extension.x);
        vec2 e23 = unpackHalf2x16(hit.extension.y);
        if (sh.model == kModelCoatedMetallicRoughness) {
            sh.coat = e01.x;
            sh.coatAlpha = gltfAlpha(e01.y);
            sh.coatNormal = hit.extension.y;
        } else if (sh.model == kModelSheenMetallicRoughness) {
            sh.sheenColour = vec3(e01.x, e01.y, e23.x);
            sh.sheenRoughness = e23.y;
        } else if (sh.model == kModelTransmissiveMetallicRoughness) {
            sh.transmission = e01.x;
        } else {
            sh.specularColour = vec3(e01.x, e01.y, e23.x);
            sh.specular = e23.y;
        }
    }
    return sh;
}

// True when the shader's BSDF is nothing but delta lobes: light sampling can never hit them,
// so next-event estimation is skipped.
SHARED_FN bool bsdfIsDelta(ShaderParams sh) {
#define SPW_BSDF_IS_DELTA(Name, id, stem, fn, params)                                              \
    if (sh.model == kModel##Name) return fn##BsdfIsDelta(sh);
    SPW_SURFACE_MODELS(SPW_BSDF_IS_DELTA)
#undef SPW_BSDF_IS_DELTA
    return false;
}

// What a bounce adds to the ray cone's spread angle: nothing for a delta lobe (`specular`),
// the model's lobe width otherwise (shared/cone.h).
SHARED_FN float bsdfConeSpread(ShaderParams sh, bool specular) {
    if (specular) return 0.0f;
#define SPW_BSDF_CONE_SPREAD(Name, id, stem, fn, params)                                           \
    if (sh.model == kModel##Name) return fn##BsdfConeSpread(sh);
    SPW_SURFACE_MODELS(SPW_BSDF_CONE_SPREAD)
#undef SPW_BSDF_CONE_SPREAD
    return 0.0f;
}

// f * |cos| and the solid-angle pdf of sampling wi. `albedo`: the hit's reflectance x texture
// (the Conductor's F0).
SHARED_FN vec3 bsdfEval(ShaderParams sh, vec3 albedo, vec3 ng, vec3 ns, vec3 wo, vec3 wi,
                        OUT(float) pdf) {
    pdf = 0.0f;
#define SPW_BSDF_EVAL(Name, id, stem, fn, params)                                                  \
    if (sh.model == kModel##Name) return fn##BsdfEval(sh, albedo, ng, ns, wo, wi, pdf);
    SPW_SURFACE_MODELS(SPW_BSDF_EVAL)
#undef SPW_BSDF_EVAL
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
#define SPW_BSDF_SAMPLE(Name, id, stem, fn, params)                                                \
    if (sh.model == kModel##Name)                                                                  \
        return fn##BsdfSample(sh, albedo, ng, ns, wo, u, wi, weight, pdf, specular);
    SPW_SURFACE_MODELS(SPW_BSDF_SAMPLE)
#undef SPW_BSDF_SAMPLE
    return false;
}

SHARED_END
#endif
