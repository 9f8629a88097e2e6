// SheenMetallicRoughness: glTF's metallic-roughness material under a sheen, the back-scattering of
// cloth and dust, as KHR_materials_sheen defines it (the extension's specification, "Sheen" and
// "Albedo-scaling technique").
//   parameters: those of MetallicRoughness (colour or texture, metallic, roughness, ior,
//   specular, specular colour), and sheen colour [r, g, b] ([1, 1, 1]) in [0, 1], sheen roughness
//   (0.5) in [0, 1]: the sheen's perceptual roughness, alpha = max(sheen roughness,
//   kSheenMinRoughness)^2.
//   f_sheen = sheen colour D(h) V, D the Charlie distribution (2 + 1 / alpha)
//   sin(theta_h)^(1 / alpha) / (2 pi) and V its visibility min(1 / ((1 + L(|co|) + L(|ci|)) 4 |co|
//   |ci|), 1), L the fitted Lambda of Estevez and Kulla 2017 ("Production Friendly Microfacet
//   Sheen BRDF"), as the specification and its sample implementation write them;
//   f = f_sheen + f_base min(1 - s E(|co|), 1 - s E(|ci|)), s the sheen colour's largest channel
//   and E the sheen BRDF's directional albedo (the table sheen_albedo.h, made by
//   scripts/make_sheen_table.py; the specification's albedo scaling, taken at both directions
//   so that it stays reciprocal, as its implementation section does).
//   Sampling: the sheen's lobe cosine-weighted with probability pSheen, the base's own sampling
//   (gltfSample) otherwise; pdf = the mixture's, weight = fcos / pdf. pSheen = sE / (sE + (1 -
//   sE) a), E at wo and a the base's lobes' weight (gltfLobesWeight), within [0.1, 0.9] while the
//   sheen has a colour.
//   Roughness below kSheenMinRoughness (0.1) is rendered as 0.1: the distribution's exponent
//   1 / alpha stays at most 100. Within about 3 degrees of grazing E passes 1 below roughness
//   0.15 (up to 1.3 at 0.1: the fit
//   is the paper's, not energy-conserving there): the base's scale is floored at 0.
#ifndef SPILLWAY_SHARED_SHEEN_H
#define SPILLWAY_SHARED_SHEEN_H
#include "metallic_roughness.h"
#include "sheen_albedo.h"

SHARED_BEGIN

const float kSheenMinRoughness = 0.1f;

SHARED_FN float sheenAlpha(float roughness) {
    float r = max(roughness, kSheenMinRoughness);
    return r * r;
}

// The Charlie distribution at a half vector of cosine cosH to the normal.
SHARED_FN float sheenD(float cosH, float alpha) {
    float sin2 = max(1.0f - cosH * cosH, 0.0f);
    float inv = 1.0f / alpha;
    return (2.0f + inv) * pow(sin2, 0.5f * inv) * (0.5f * kInvPi);
}

// Estevez and Kulla's fitted Lambda for the Charlie distribution (their table: the coefficients
// at roughness 0 and 1, mixed by (1 - alpha)^2), and the visibility it makes.
SHARED_FN float sheenLambdaFit(float x, float alpha) {
    float t = (1.0f - alpha) * (1.0f - alpha);
    float a = mix(21.5473f, 25.3245f, t);
    float b = mix(3.82987f, 3.32435f, t);
    float c = mix(0.19823f, 0.16801f, t);
    float d = mix(-1.97760f, -1.27393f, t);
    float e = mix(-4.32054f, -4.85967f, t);
    return a / (1.0f + b * pow(x, c)) + d * x + e;
}
SHARED_FN float sheenLambda(float cosTheta, float alpha) {
    return cosTheta < 0.5f
               ? exp(sheenLambdaFit(cosTheta, alpha))
               : exp(2.0f * sheenLambdaFit(0.5f, alpha) - sheenLambdaFit(1.0f - cosTheta, alpha));
}
SHARED_FN float sheenV(float cosO, float cosI, float alpha) {
    return min(1.0f / ((1.0f + sheenLambda(cosO, alpha) + sheenLambda(cosI, alpha)) *
                       (4.0f * cosO * cosI)),
               1.0f);
}

// E(cos, roughness): the table's bilinear interpolation, its rows at cos = (i / (rows - 1))^2,
// its columns at roughness = 0.1^(1 - j / (columns - 1)) (kSheenMinRoughness to 1).
SHARED_FN float sheenAlbedo(float cosTheta, float roughness) {
    float x = sqrt(clamp(cosTheta, 0.0f, 1.0f)) * float(kSheenAlbedoCos - 1u);
    float r = clamp(roughness, kSheenMinRoughness, 1.0f);
    float y = (1.0f + log(r) / log(10.0f)) * float(kSheenAlbedoRough - 1u);
    uint i = min(uint(x), kSheenAlbedoCos - 2u);
    uint j = min(uint(y), kSheenAlbedoRough - 2u);
    float fx = x - float(i);
    float fy = y - float(j);
    uint k = i * kSheenAlbedoRough + j;
    float a = mix(sheenAlbedoEntry(k), sheenAlbedoEntry(k + 1u), fy);
    float b = mix(sheenAlbedoEntry(k + kSheenAlbedoRough),
                  sheenAlbedoEntry(k + kSheenAlbedoRough + 1u), fy);
    return mix(a, b, fx);
}

// The probability of sampling the sheen's lobe seen from wo at cosine cosO.
SHARED_FN float sheenProbability(vec3 colour, float metallic, vec3 f0d, float f90d, vec3 sheen,
                                 float roughness, float cosO) {
    float se = maxComponent(sheen) * sheenAlbedo(cosO, roughness);
    if (!(se > 0.0f)) return 0.0f;
    float base = gltfLobesWeight(colour, metallic, f0d, f90d, cosO);
    return clamp(se / (se + (1.0f - se) * base), 0.1f, 0.9f);
}

SHARED_FN vec3 gltfSheenEval(vec3 colour, float metallic, float alpha, vec3 f0d, float f90d,
                             vec3 sheen, float roughness, vec3 ng, vec3 ns, vec3 wo, vec3 wi,
                             OUT(float) pdf) {
    float basePdf;
    vec3 base = gltfEval(colour, metallic, alpha, f0d, f90d, ng, ns, wo, wi, basePdf);
    pdf = 0.0f;
    if (dot(ng, wo) * dot(ng, wi) <= 0.0f) return vec3(0.0f);
    Frame f = shadingFrame(ns, ng, wo);
    vec3 lo = frameToLocal(f, wo);
    vec3 li = frameToLocal(f, wi);
    if (lo.z <= 0.0f || li.z <= 0.0f) return vec3(0.0f);
    vec3 h = lo + li;
    float len2 = dot(h, h);
    if (!(len2 > 0.0f)) return vec3(0.0f);
    float cosH = h.z * inversesqrt(len2);
    float s = maxComponent(sheen);
    float scale =
        max(min(1.0f - s * sheenAlbedo(lo.z, roughness), 1.0f - s * sheenAlbedo(li.z, roughness)),
            0.0f);
    float a = sheenAlpha(roughness);
    vec3 layer = sheen * (sheenD(cosH, a) * sheenV(lo.z, li.z, a) * li.z);
    float pSheen = sheenProbability(colour, metallic, f0d, f90d, sheen, roughness, lo.z);
    pdf = pSheen * (li.z * kInvPi) + (1.0f - pSheen) * basePdf;
    return base * scale + layer;
}

SHARED_FN bool gltfSheenSample(vec3 colour, float metallic, float alpha, vec3 f0d, float f90d,
                               vec3 sheen, float roughness, vec3 ng, vec3 ns, vec3 wo, vec3 u,
                               OUT(vec3) wi, OUT(vec3) weight, OUT(float) pdf, OUT(bool) specular) {
    wi = vec3(0.0f);
    weight = vec3(0.0f);
    pdf = 0.0f;
    specular = false;
    Frame f = shadingFrame(ns, ng, wo);
    vec3 lo = frameToLocal(f, wo);
    if (lo.z <= 0.0f) return false;
    float pSheen = sheenProbability(colour, metallic, f0d, f90d, sheen, roughness, lo.z);
    if (u.z < pSheen) {
        vec3 li = sampleCosineHemisphere(vec2(u.x, u.y));
        if (li.z <= 0.0f) return false;
        wi = frameToWorld(f, li);
    } else {
        vec3 baseWeight;
        float basePdf;
        vec3 v = vec3(u.x, u.y, (u.z - pSheen) / (1.0f - pSheen));
        if (!gltfSample(colour, metallic, alpha, f0d, f90d, ng, ns, wo, v, wi, baseWeight, basePdf,
                        specular))
            return false;
    }
    vec3 fcos =
        gltfSheenEval(colour, metallic, alpha, f0d, f90d, sheen, roughness, ng, ns, wo, wi, pdf);
    if (!(pdf > 0.0f)) return false;
    weight = fcos / pdf;
    return true;
}

// The registry's interface (shared/bsdf.h dispatches here).
SHARED_FN bool sheenMetallicRoughnessBsdfIsDelta(ShaderParams sh) {
    UNUSED(sh);
    return false;
}
// The sheen's lobe is as wide as Lambert's.
SHARED_FN float sheenMetallicRoughnessBsdfConeSpread(ShaderParams sh) {
    UNUSED(sh);
    return 1.0f;
}
SHARED_FN vec3 sheenMetallicRoughnessBsdfEval(ShaderParams sh, vec3 albedo, vec3 ng, vec3 ns,
                                              vec3 wo, vec3 wi, OUT(float) pdf) {
    return gltfSheenEval(albedo, sh.metallic, max(sh.alpha, kGltfMinAlpha),
                         gltfDielectricF0Colour(sh), gltfDielectricF90(sh), sh.sheenColour,
                         sh.sheenRoughness, ng, ns, wo, wi, pdf);
}
SHARED_FN bool sheenMetallicRoughnessBsdfSample(ShaderParams sh, vec3 albedo, vec3 ng, vec3 ns,
                                                vec3 wo, vec3 u, OUT(vec3) wi, OUT(vec3) weight,
                                                OUT(float) pdf, OUT(bool) specular) {
    return gltfSheenSample(albedo, sh.metallic, max(sh.alpha, kGltfMinAlpha),
                           gltfDielectricF0Colour(sh), gltfDielectricF90(sh), sh.sheenColour,
                           sh.sheenRoughness, ng, ns, wo, u, wi, weight, pdf, specular);
}

SHARED_END
#endif
