// CoatedMetallicRoughness: glTF's metallic-roughness material (shared/metallic_roughness.h) under a
// clear coat, as KHR_materials_clearcoat defines it (the extension's specification, "Clearcoat" and
// "Implementation").
//   parameters: those of MetallicRoughness (colour or texture, metallic, roughness, ior,
//   specular, specular colour), and
//   coat (1) in [0, 1], the coat's weight; coat roughness (0) in [0, 1], its perceptual
//   roughness (GGX alpha = coat roughness^2, at least kGltfMinAlpha).
//   The coat is a dielectric of ior 1.5 (F0 = 0.04) over the base, about its own shading normal
//   nc (clearcoatNormalTexture's; without it the interpolated normal, not the base's normal map,
//   as the specification says; with neither, the base's ns):
//     Fc = coat (0.04 + 0.96 (1 - |n.wo|)^5)
//     f = (1 - Fc) f_base + Fc D_c G2_c / (4 |co| |ci|)
//   the specification's fresnel_coat: the coat's Fresnel term is taken once, from the view
//   direction, and the base is dimmed by what the coat reflects. The coat lobe is GGX with the
//   height-correlated Smith G2 (ggx.h), as the base's specular lobe.
//   Sampling: the coat's lobe through GGX's visible normals with probability pCoat, the base's
//   own sampling (gltfSample) otherwise; pdf = the mixture's, weight = fcos / pdf. pCoat = Fc /
//   (Fc + (1 - Fc) a), a the base's lobes' weights seen from wo (as gltfSpecularProbability
//   reckons them), within [0.1, 0.9] while the coat has weight.
//   Each lobe's cosine is to its own normal; the coat's Fresnel and lobe are taken in the frame
//   of nc (made valid for wo as ns is: sampling.h's facingShadingNormal), the base's in ns's.
//   Not rendered: the coat dims nothing the surface emits.
#ifndef SPILLWAY_SHARED_CLEARCOAT_H
#define SPILLWAY_SHARED_CLEARCOAT_H
#include "metallic_roughness.h"

SHARED_BEGIN

// The coat's reflectance seen from wo at cosine cosO to the shading normal, times its weight.
SHARED_FN float gltfCoatFresnel(float coat, float cosO) {
    return coat * schlickFresnel(vec3(kGltfDielectricF0), cosO).x;
}

// The probability of sampling the coat's lobe: its reflectance fc against the base's lobes'.
SHARED_FN float gltfCoatProbability(vec3 colour, float metallic, vec3 f0d, float f90d, float fc,
                                    float cosO) {
    if (!(fc > 0.0f)) return 0.0f;
    float base = gltfLobesWeight(colour, metallic, f0d, f90d, cosO);
    return clamp(fc / (fc + (1.0f - fc) * base), 0.1f, 0.9f);
}

// The coat's shading normal: its own with kShaderCoatNormal (KHR_materials_clearcoat's
// clearcoatNormalTexture, or the interpolated normal where only the base is normal-mapped),
// the base's `ns` otherwise.
SHARED_FN vec3 gltfCoatNormal(ShaderParams sh, vec3 ns) {
    if ((sh.flags & kShaderCoatNormal) == 0u) return ns;
    return octahedralDecode(unpackHalf2x16(sh.coatNormal));
}

// f * cos and the pdf, the base about its shading normal ns, the coat about its own, nc (the
// two the same: one frame, as the specification draws it).
SHARED_FN vec3 gltfCoatEval(vec3 colour, float metallic, float alpha, vec3 f0d, float f90d,
                            float coat, float coatAlpha, vec3 ng, vec3 ns, vec3 nc, vec3 wo,
                            vec3 wi, OUT(float) pdf) {
    float basePdf;
    vec3 base = gltfEval(colour, metallic, alpha, f0d, f90d, ng, ns, wo, wi, basePdf);
    pdf = 0.0f;
    if (dot(ng, wo) * dot(ng, wi) <= 0.0f) return vec3(0.0f);
    Frame f = shadingFrame(nc, ng, wo);
    vec3 lo = frameToLocal(f, wo);
    vec3 li = frameToLocal(f, wi);
    if (lo.z <= 0.0f) return vec3(0.0f);
    float fc = gltfCoatFresnel(coat, lo.z);
    // The base's lobes' weight is reckoned from wo's cosine to the base's own normal.
    float cosBase = lo.z;
    if (nc != ns) cosBase = dot(facingShadingNormal(ns, ng, wo), wo);
    float pCoat = gltfCoatProbability(colour, metallic, f0d, f90d, fc, cosBase);
    float layer = 0.0f;
    float coatPdf = 0.0f;
    if (li.z > 0.0f) {
        vec3 h = lo + li; // li.z > 0 and lo.z > 0: never 0
        h = h * inversesqrt(dot(h, h));
        float d = ggxD(h, coatAlpha);
        float denom = ggxG2Denominator(lo, li, coatAlpha);
        layer = denom > 0.0f ? fc * d * li.z / (2.0f * denom) : 0.0f;
        coatPdf = d / (2.0f * (lo.z + ggxA(lo, coatAlpha)));
    }
    pdf = pCoat * coatPdf + (1.0f - pCoat) * basePdf;
    return base * (1.0f - fc) + vec3(layer);
}

SHARED_FN bool gltfCoatSample(vec3 colour, float metallic, float alpha, vec3 f0d, float f90d,
                              float coat, float coatAlpha, vec3 ng, vec3 ns, vec3 nc, vec3 wo,
                              vec3 u, OUT(vec3) wi, OUT(vec3) weight, OUT(float) pdf,
                              OUT(bool) specular) {
    wi = vec3(0.0f);
    weight = vec3(0.0f);
    pdf = 0.0f;
    specular = false;
    Frame f = shadingFrame(nc, ng, wo);
    vec3 lo = frameToLocal(f, wo);
    if (lo.z <= 0.0f) return false;
    float fc = gltfCoatFresnel(coat, lo.z);
    float cosBase = lo.z;
    if (nc != ns) cosBase = dot(facingShadingNormal(ns, ng, wo), wo);
    float pCoat = gltfCoatProbability(colour, metallic, f0d, f90d, fc, cosBase);
    if (u.z < pCoat) {
        vec3 h = ggxSampleVisibleNormal(lo, coatAlpha, vec2(u.x, u.y));
        float oh = dot(lo, h);
        if (oh <= 0.0f) return false;
        vec3 li = 2.0f * oh * h - lo;
        if (li.z <= 0.0f) return false;
        wi = frameToWorld(f, li);
    } else {
        vec3 baseWeight;
        float basePdf;
        vec3 v = vec3(u.x, u.y, (u.z - pCoat) / (1.0f - pCoat));
        if (!gltfSample(colour, metallic, alpha, f0d, f90d, ng, ns, wo, v, wi, baseWeight, basePdf,
                        specular))
            return false;
    }
    vec3 fcos =
        gltfCoatEval(colour, metallic, alpha, f0d, f90d, coat, coatAlpha, ng, ns, nc, wo, wi, pdf);
    if (!(pdf > 0.0f)) return false;
    weight = fcos / pdf;
    return true;
}

// The registry's interface (shared/bsdf.h dispatches here).
SHARED_FN bool coatedMetallicRoughnessBsdfIsDelta(ShaderParams sh) {
    UNUSED(sh);
    return false;
}
SHARED_FN float coatedMetallicRoughnessBsdfConeSpread(ShaderParams sh) {
    return metallicRoughnessBsdfConeSpread(sh);
}
SHARED_FN vec3 coatedMetallicRoughnessBsdfEval(ShaderParams sh, vec3 albedo, vec3 ng, vec3 ns,
                                               vec3 wo, vec3 wi, OUT(float) pdf) {
    return gltfCoatEval(albedo, sh.metallic, max(sh.alpha, kGltfMinAlpha),
                        gltfDielectricF0Colour(sh), gltfDielectricF90(sh), sh.coat,
                        max(sh.coatAlpha, kGltfMinAlpha), ng, ns, gltfCoatNormal(sh, ns), wo, wi,
                        pdf);
}
SHARED_FN bool coatedMetallicRoughnessBsdfSample(ShaderParams sh, vec3 albedo, vec3 ng, vec3 ns,
                                                 vec3 wo, vec3 u, OUT(vec3) wi, OUT(vec3) weight,
                                                 OUT(float) pdf, OUT(bool) specular) {
    return gltfCoatSample(albedo, sh.metallic, max(sh.alpha, kGltfMinAlpha),
                          gltfDielectricF0Colour(sh), gltfDielectricF90(sh), sh.coat,
                          max(sh.coatAlpha, kGltfMinAlpha), ng, ns, gltfCoatNormal(sh, ns), wo, u,
                          wi, weight, pdf, specular);
}

SHARED_END
#endif
