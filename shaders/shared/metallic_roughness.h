// MetallicRoughness: glTF 2.0's metallic-roughness material (the glTF 2.0 specification,
// appendix B, "BRDF implementation"), reflection only.
//   parameters: colour [r, g, b] ([1, 1, 1]) or texture: the base colour; metallic (1) in
//   [0, 1]; roughness (1) in [0, 1], the perceptual roughness: GGX alpha = roughness^2, at least
//   kGltfMinAlpha; ior (1.5); specular (1) in [0, 1] and specular colour [r, g, b] ([1, 1, 1]),
//   each at least 0 (KHR_materials_specular). glTF's defaults (metallicFactor and roughnessFactor
//   1).
//   c_diff = colour (1 - metallic), f0 = mix(F0d, colour, metallic), f90 = mix(F90d, 1, metallic),
//   the dielectric's F0d = min(((ior - 1) / (ior + 1))^2 specularColour, 1) specular and
//   F90d = specular: ((ior - 1) / (ior + 1))^2 from the shader's ior (KHR_materials_ior), exactly
//   glTF's 0.04 at ior 1.5 and wherever the ior is unset (below 1); specular and specularColour
//   KHR_materials_specular's weight and F0 colour (1 and (1, 1, 1) without kShaderSpecular, where
//   F0d is the ior's F0 and F90d 1, to the bit), as that extension's implementation section has it,
//   F = f0 + (f90 - f0) (1 - |wo.h|)^5 (Schlick, as conductor.h, with glTF's f90),
//   f = (1 - F) c_diff / pi + F D G2 / (4 |co| |ci|)
//   with GGX D and the height-correlated Smith G2 of ggx.h (the specification's V is
//   G2 / (4 |co| |ci|)). The diffuse term takes (1 - F) with the half vector's F, as the
//   specification's implementation does.
//   Sampling: the specular lobe through GGX's visible normals (as conductor.h) with probability
//   pSpecular, the diffuse one cosine-weighted otherwise; pdf = the mixture's, weight = fcos /
//   pdf. pSpecular = Fs / (Fs + Fd) from the lobes' weights seen from wo (Fs = mean of
//   F(cos wo), Fd = mean of c_diff (1 - F(cos wo))), within [0.25 (1 - alpha)^2, 0.9] while
//   there is a diffuse lobe, 1 without one (a pure metal). Sampled in proportion to its weight,
//   each lobe's sample weight is about the albedo; the floor keeps a narrow lobe, whose peak
//   the ratio underrates, from starving (BSDF sampling is the better strategy for a small light
//   seen in it), and opens to 0 at alpha 1, where the specular lobe is as wide as the diffuse
//   one and a fixed 0.25 only spent samples on the lesser lobe (the Cornell box's walls: 11 %
//   more relMSE at equal samples, docs/performance.md).
//   alpha is floored at kGltfMinAlpha = 0.045^2 (Filament's floor on perceptual roughness): a
//   roughness of 0 is a very narrow GGX lobe, never a delta lobe mixed with a diffuse one.
#ifndef SPILLWAY_SHARED_GLTF_H
#define SPILLWAY_SHARED_GLTF_H
#include "conductor.h"
#include "sampling.h"
#include "types.h"

SHARED_BEGIN

const float kGltfMinAlpha = 0.045f * 0.045f;
const float kGltfDielectricF0 = 0.04f;

// The dielectric part's F0 for an index of refraction (gltfDielectricF0(1.5) is kGltfDielectricF0
// to the bit; an ior below 1, or NaN, is unset and takes it too). The cpu backend's SIMD shading
// calls it per lane (host/cpu/simd_shading.cpp).
SHARED_FN float gltfDielectricF0(float ior) {
    if (!(ior >= 1.0f) || ior == 1.5f) return kGltfDielectricF0;
    float r = (ior - 1.0f) / (ior + 1.0f);
    return r * r;
}

// The dielectric part's F0 colour and F90 (KHR_materials_specular's weight): without
// kShaderSpecular, the ior's F0 and 1.
SHARED_FN vec3 gltfDielectricF0Colour(ShaderParams sh) {
    float f0 = gltfDielectricF0(sh.ior);
    if ((sh.flags & kShaderSpecular) == 0u) return vec3(f0);
    return min(f0 * sh.specularColour, vec3(1.0f)) * sh.specular;
}
SHARED_FN float gltfDielectricF90(ShaderParams sh) {
    return (sh.flags & kShaderSpecular) != 0u ? sh.specular : 1.0f;
}

// Schlick's Fresnel with glTF's f90: f0 + (f90 - f0) (1 - cosTheta)^5 (schlickFresnel at f90 1,
// to the bit).
// SIMD twin: host/simd/simd_bsdf-inl.h
SHARED_FN vec3 gltfFresnel(vec3 f0, float f90, float cosTheta) {
    float m = clamp(1.0f - cosTheta, 0.0f, 1.0f);
    float m2 = m * m;
    return f0 + (vec3(f90) - f0) * (m2 * m2 * m);
}

// f0 and f90 of the dielectric part (f0d, f90d) mixed with the metal's (colour, 1) by metallic.
SHARED_FN vec3 gltfF0(vec3 f0d, vec3 colour, float metallic) {
    return mix(f0d, colour, metallic);
}
SHARED_FN float gltfF90(float f90d, float metallic) {
    return 1.0f - (1.0f - f90d) * (1.0f - metallic);
}

// What the material's lobes reflect in all seen from wo at cosine cosO to the shading normal (the
// channels' mean of F + c_diff (1 - F)): the weight a layer over it (a clear coat, a sheen)
// samples its own lobe against.
SHARED_FN float gltfLobesWeight(vec3 colour, float metallic, vec3 f0d, float f90d, float cosO) {
    vec3 F = gltfFresnel(gltfF0(f0d, colour, metallic), gltfF90(f90d, metallic), cosO);
    vec3 d = colour * (1.0f - metallic) * (vec3(1.0f) - F);
    return (F.x + F.y + F.z + d.x + d.y + d.z) / 3.0f;
}

// GGX alpha from glTF's perceptual roughness.
SHARED_FN float gltfAlpha(float roughness) {
    return max(roughness * roughness, kGltfMinAlpha);
}

// The probability of sampling the specular lobe, seen from wo at cosine cosO to the shading
// normal, for GGX's alpha.
// SIMD twin: host/simd/simd_bsdf-inl.h
SHARED_FN float gltfSpecularProbability(vec3 f0, float f90, vec3 cDiff, float cosO, float alpha) {
    vec3 F = gltfFresnel(f0, f90, cosO);
    float fs = (F.x + F.y + F.z) / 3.0f;
    vec3 d = cDiff * (vec3(1.0f) - F);
    float fd = (d.x + d.y + d.z) / 3.0f;
    if (!(fd > 0.0f)) return 1.0f;
    float open = 1.0f - min(alpha, 1.0f);
    return clamp(fs / (fs + fd), 0.25f * open * open, 0.9f);
}

// SIMD twin: host/simd/simd_bsdf-inl.h
SHARED_FN vec3 gltfEval(vec3 colour, float metallic, float alpha, vec3 f0d, float f90d, vec3 ng,
                        vec3 ns, vec3 wo, vec3 wi, OUT(float) pdf) {
    pdf = 0.0f;
    if (dot(ng, wo) * dot(ng, wi) <= 0.0f) return vec3(0.0f);
    Frame f = shadingFrame(ns, ng, wo);
    vec3 lo = frameToLocal(f, wo);
    vec3 li = frameToLocal(f, wi);
    if (lo.z <= 0.0f || li.z <= 0.0f) return vec3(0.0f);
    vec3 h = lo + li;
    float len2 = dot(h, h);
    if (!(len2 > 0.0f)) return vec3(0.0f);
    h = h * inversesqrt(len2);
    vec3 f0 = gltfF0(f0d, colour, metallic);
    float f90 = gltfF90(f90d, metallic);
    vec3 cDiff = colour * (1.0f - metallic);
    vec3 F = gltfFresnel(f0, f90, dot(lo, h));
    float d = ggxD(h, alpha);
    float denom = ggxG2Denominator(lo, li, alpha);
    vec3 specular = denom > 0.0f ? F * (d * li.z / (2.0f * denom)) : vec3(0.0f);
    vec3 diffuse = (vec3(1.0f) - F) * cDiff * (li.z * kInvPi);
    float pSpecular = gltfSpecularProbability(f0, f90, cDiff, lo.z, alpha);
    pdf =
        pSpecular * (d / (2.0f * (lo.z + ggxA(lo, alpha)))) + (1.0f - pSpecular) * (li.z * kInvPi);
    return specular + diffuse;
}

// SIMD twin: host/simd/simd_bsdf-inl.h
SHARED_FN bool gltfSample(vec3 colour, float metallic, float alpha, vec3 f0d, float f90d, vec3 ng,
                          vec3 ns, vec3 wo, vec3 u, OUT(vec3) wi, OUT(vec3) weight, OUT(float) pdf,
                          OUT(bool) specular) {
    wi = vec3(0.0f);
    weight = vec3(0.0f);
    pdf = 0.0f;
    specular = false;
    Frame f = shadingFrame(ns, ng, wo);
    vec3 lo = frameToLocal(f, wo);
    if (lo.z <= 0.0f) return false;
    vec3 f0 = gltfF0(f0d, colour, metallic);
    vec3 cDiff = colour * (1.0f - metallic);
    vec3 li;
    if (u.z < gltfSpecularProbability(f0, gltfF90(f90d, metallic), cDiff, lo.z, alpha)) {
        vec3 h = ggxSampleVisibleNormal(lo, alpha, vec2(u.x, u.y));
        float oh = dot(lo, h);
        if (oh <= 0.0f) return false;
        li = 2.0f * oh * h - lo;
    } else {
        li = sampleCosineHemisphere(vec2(u.x, u.y));
    }
    if (li.z <= 0.0f) return false; // below the surface: absorbed
    wi = frameToWorld(f, li);
    vec3 fcos = gltfEval(colour, metallic, alpha, f0d, f90d, ng, ns, wo, wi, pdf);
    if (!(pdf > 0.0f)) return false;
    weight = fcos / pdf;
    return true;
}

// The registry's interface (shared/bsdf.h dispatches here).
SHARED_FN bool metallicRoughnessBsdfIsDelta(ShaderParams sh) {
    UNUSED(sh);
    return false;
}
// A pure metal spreads a cone by about alpha, as the conductor; with a diffuse lobe, as Lambert.
SHARED_FN float metallicRoughnessBsdfConeSpread(ShaderParams sh) {
    return sh.metallic >= 1.0f ? max(sh.alpha, kGltfMinAlpha) : 1.0f;
}
SHARED_FN vec3 metallicRoughnessBsdfEval(ShaderParams sh, vec3 albedo, vec3 ng, vec3 ns, vec3 wo,
                                         vec3 wi, OUT(float) pdf) {
    return gltfEval(albedo, sh.metallic, max(sh.alpha, kGltfMinAlpha), gltfDielectricF0Colour(sh),
                    gltfDielectricF90(sh), ng, ns, wo, wi, pdf);
}
SHARED_FN bool metallicRoughnessBsdfSample(ShaderParams sh, vec3 albedo, vec3 ng, vec3 ns, vec3 wo,
                                           vec3 u, OUT(vec3) wi, OUT(vec3) weight, OUT(float) pdf,
                                           OUT(bool) specular) {
    return gltfSample(albedo, sh.metallic, max(sh.alpha, kGltfMinAlpha), gltfDielectricF0Colour(sh),
                      gltfDielectricF90(sh), ng, ns, wo, u, wi, weight, pdf, specular);
}

SHARED_END
#endif
