// Principled: Blender 3.4's Principled BSDF (its first version, Burley's "Physically Based Shading
// at Disney", 2012) as Cycles 3.4 renders it with the node's default GGX distribution, reflection
// only: the lobes are added, not layered (none dims another), as Cycles adds its closures.
//   parameters: colour [r, g, b] ([0.8, 0.8, 0.8]) or texture: the base colour c; metallic m (0),
//   roughness r (0.5): GGX alpha = r^2, at least kGltfMinAlpha; specular s (0.5); specular tint
//   (0); sheen (0); sheen tint (0.5); coat (0) and coat roughness (0.03): the clear coat's weight
//   and roughness, alpha_c = coat roughness^2, at least kGltfMinAlpha. Every value in [0, 1],
//   Blender's defaults in brackets.
//   With wo, wi the view and light directions, h their half vector, W(x) = (1 - x)^5:
//   * diffuse (Burley's, with its retro-reflection): c (1 - m) / pi ((1 - W(ci) / 2)(1 - W(co) / 2)
//     + R (W(ci) + W(co) + W(ci) W(co) (R - 1))), R = r (1 + wo.wi) = 2 r (wi.h)^2;
//   * sheen: sheen (1 - m) mix(1, tint_709(c), sheen tint) W(wi.h), no 1 / pi (Cycles' closure);
//     tint_w(c) = c / (w . c), the base colour's hue (1 where c is black), by Rec. 709's
//     luminance for the sheen and by (0.3, 0.6, 0.1) for the specular tint, as Cycles reckons them;
//   * specular: F D G2 / (4 co ci), GGX D and the height-correlated Smith G2 (ggx.h), Cycles'
//     principled Fresnel F = cspec0 (1 - FH) + FH, FH = (Fr(wi.h, eta) - F0) / (1 - F0): Fr the
//     dielectric Fresnel (dielectric.h) at eta = 2 / (1 - sqrt(0.08 s)) - 1, whose F0 = Fr(1, eta)
//     is 0.08 s, cspec0 = min(0.08 s mix(1, tint(c), specular tint) (1 - m) + c m, 1);
//   * clear coat: coat / 4 Fr(wi.h, 1.5) D1 G2' / (4 co ci), D1 Burley's GTR1 of width alpha_c
//     ((a^2 - 1) / (pi ln(a^2) (1 + (a^2 - 1) cos^2))), G2' the Smith G2 of GGX at alpha 0.25
//     (Burley's fixed clear-coat masking), about the same shading normal.
//   Left out (the Blender add-on reports them by name): subsurface, anisotropy, transmission.
//   Sampling: one lobe, chosen by its weight seen from wo much as Cycles weights its closures (the
//   cosine lobe: (1 - m)(mean(c) + sheen W(co) co); the specular one: Schlick's F(co) of the
//   untinted F0; the coat's: coat / 4 Schlick(0.04, co)), cosine-weighted for the diffuse and
//   sheen, GGX's visible normals for the specular, GTR1's normals (Burley's inversion) for the
//   coat; pdf = the mixture's, weight = f cos / pdf, so the estimator is unbiased whatever the
//   choice.
#ifndef SPILLWAY_SHARED_PRINCIPLED_H
#define SPILLWAY_SHARED_PRINCIPLED_H
#include "dielectric.h"
#include "metallic_roughness.h"

SHARED_BEGIN

const float kPrincipledCoatMaskingAlpha = 0.25f;
const float kPrincipledCoatIor = 1.5f;

// Schlick's weight (1 - x)^5, x clamped to [0, 1].
SHARED_FN float principledW(float x) {
    float m = clamp(1.0f - x, 0.0f, 1.0f);
    float m2 = m * m;
    return m2 * m2 * m;
}

// The base colour's hue: c over its luminance by the weights w (1 where c is black).
SHARED_FN vec3 principledTint(vec3 c, vec3 w) {
    float l = dot(c, w);
    return l > 0.0f ? c / l : vec3(1.0f);
}

// The sheen lobe's colour: sheen (1 - m) mix(1, tint(c), sheen tint).
SHARED_FN vec3 principledSheenColour(ShaderParams sh, vec3 c) {
    vec3 tint = principledTint(c, vec3(0.2126f, 0.7152f, 0.0722f));
    return sh.sheen * (1.0f - sh.metallic) * mix(vec3(1.0f), tint, sh.sheenTint);
}

// The specular lobe's colour at normal incidence.
SHARED_FN vec3 principledSpecularF0(ShaderParams sh, vec3 c) {
    vec3 tint = mix(vec3(1.0f), principledTint(c, vec3(0.3f, 0.6f, 0.1f)), sh.specularTint);
    vec3 cspec0 = 0.08f * sh.specular * tint * (1.0f - sh.metallic) + c * sh.metallic;
    return clamp(cspec0, vec3(0.0f), vec3(1.0f));
}

// Cycles' principled Fresnel at cosine cosH between the light and the half vector.
SHARED_FN vec3 principledFresnel(vec3 cspec0, float specular, float cosH) {
    float root = sqrt(0.08f * specular);
    float eta = 2.0f / (1.0f - root) - 1.0f;
    // Fr(1, eta), written out: glslc's optimiser (shaderc 2022.4) crashes on the call with a
    // constant cosine.
    float r0 = (eta - 1.0f) / (eta + 1.0f);
    float f0 = r0 * r0;
    float cosT;
    float fh = f0 < 1.0f ? (fresnelDielectric(cosH, eta, cosT) - f0) / (1.0f - f0) : 0.0f;
    return cspec0 * (1.0f - fh) + vec3(fh);
}

// Burley's GTR1 distribution of half vectors, for a unit local h, width alpha (< 1); written with
// h.x^2 + h.y^2 for 1 - cos^2, as ggxD, so a narrow lobe is resolved in float.
SHARED_FN float principledGtr1D(vec3 h, float alpha) {
    if (h.z <= 0.0f) return 0.0f;
    float a2 = alpha * alpha;
    float t = a2 * h.z * h.z + h.x * h.x + h.y * h.y; // 1 + (a2 - 1) cos^2 for unit h
    return (a2 - 1.0f) / (kPi * log(a2) * t);
}

// A GTR1 half vector, density D1(h) h.z over the hemisphere (Burley 2012, appendix B.2): cos^2 =
// (1 - a2^(1 - u)) / (1 - a2), its sine taken directly from a2^(1 - u) - a2.
SHARED_FN vec3 principledGtr1Sample(float alpha, vec2 u) {
    float a2 = alpha * alpha;
    float power = pow(a2, 1.0f - u.x);
    float sin2 = clamp((power - a2) / (1.0f - a2), 0.0f, 1.0f);
    float sinH = sqrt(sin2);
    float cosH = sqrt(1.0f - sin2);
    float phi = 2.0f * kPi * u.y;
    return vec3(sinH * cos(phi), sinH * sin(phi), cosH);
}

// The probabilities of the cosine, specular and coat lobes seen from wo at cosine cosO: each
// lobe's weight there, by Schlick's approximation of its Fresnel and without the tints (any
// choice that depends on wo alone keeps the estimator unbiased; this one costs no division but
// the last and no square root).
SHARED_FN vec3 principledLobeChoice(ShaderParams sh, vec3 c, float cosO) {
    float w5 = principledW(cosO);
    float mean = (c.x + c.y + c.z) / 3.0f;
    float wCos = (1.0f - sh.metallic) * (mean + sh.sheen * w5 * cosO);
    float f0 = 0.08f * sh.specular * (1.0f - sh.metallic) + mean * sh.metallic;
    float wSpec = sh.specular > 0.0f || sh.metallic > 0.0f ? f0 + (1.0f - f0) * w5 : 0.0f;
    float wCoat = 0.25f * sh.coat * (0.04f + 0.96f * w5);
    float sum = wCos + wSpec + wCoat;
    if (!(sum > 0.0f)) return vec3(1.0f, 0.0f, 0.0f);
    return vec3(wCos, wSpec, wCoat) / sum;
}

// f cos about the shading normal ns, and the pdf of principledSample choosing wi.
SHARED_FN vec3 principledEval(ShaderParams sh, vec3 c, vec3 ng, vec3 ns, vec3 wo, vec3 wi,
                              OUT(float) pdf) {
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
    float alpha = max(sh.alpha, kGltfMinAlpha);
    float coatAlpha = max(sh.coatAlpha, kGltfMinAlpha);
    float ih = dot(li, h);
    // Burley's diffuse, with the retro-reflection of the perceptual roughness.
    float wi5 = principledW(li.z);
    float wo5 = principledW(lo.z);
    float retro = sqrt(alpha) * (1.0f + dot(lo, li));
    float fd = (1.0f - 0.5f * wi5) * (1.0f - 0.5f * wo5) +
               retro * (wi5 + wo5 + wi5 * wo5 * (retro - 1.0f));
    vec3 sum = c * (1.0f - sh.metallic) * (fd * kInvPi * li.z);
    if (sh.sheen > 0.0f) sum += principledSheenColour(sh, c) * (principledW(ih) * li.z);
    float d = ggxD(h, alpha);
    float denom = ggxG2Denominator(lo, li, alpha);
    if (denom > 0.0f)
        sum += principledFresnel(principledSpecularF0(sh, c), sh.specular, ih) *
               (d * li.z / (2.0f * denom));
    float d1 = principledGtr1D(h, coatAlpha);
    float coatPdf = 0.0f;
    if (sh.coat > 0.0f) {
        float cosT;
        float denomC = ggxG2Denominator(lo, li, kPrincipledCoatMaskingAlpha);
        float fc = fresnelDielectric(ih, kPrincipledCoatIor, cosT);
        if (denomC > 0.0f) sum += vec3(0.25f * sh.coat * fc * d1 * li.z / (2.0f * denomC));
        coatPdf = d1 * h.z / (4.0f * dot(lo, h));
    }
    vec3 p = principledLobeChoice(sh, c, lo.z);
    pdf = p.x * li.z * kInvPi + p.y * d / (2.0f * (lo.z + ggxA(lo, alpha))) + p.z * coatPdf;
    return sum;
}

SHARED_FN bool principledSample(ShaderParams sh, vec3 c, vec3 ng, vec3 ns, vec3 wo, vec3 u,
                                OUT(vec3) wi, OUT(vec3) weight, OUT(float) pdf,
                                OUT(bool) specular) {
    wi = vec3(0.0f);
    weight = vec3(0.0f);
    pdf = 0.0f;
    specular = false;
    Frame f = shadingFrame(ns, ng, wo);
    vec3 lo = frameToLocal(f, wo);
    if (lo.z <= 0.0f) return false;
    vec3 p = principledLobeChoice(sh, c, lo.z);
    vec3 li;
    if (u.z < p.x) {
        li = sampleCosineHemisphere(vec2(u.x, u.y));
    } else {
        vec3 h = u.z < p.x + p.y
                     ? ggxSampleVisibleNormal(lo, max(sh.alpha, kGltfMinAlpha), vec2(u.x, u.y))
                     : principledGtr1Sample(max(sh.coatAlpha, kGltfMinAlpha), vec2(u.x, u.y));
        float oh = dot(lo, h);
        if (oh <= 0.0f) return false;
        li = 2.0f * oh * h - lo;
    }
    if (li.z <= 0.0f) return false; // below the surface: absorbed
    wi = frameToWorld(f, li);
    vec3 fcos = principledEval(sh, c, ng, ns, wo, wi, pdf);
    if (!(pdf > 0.0f)) return false;
    weight = fcos / pdf;
    return true;
}

// The registry's interface (shared/bsdf.h dispatches here).
SHARED_FN bool principledBsdfIsDelta(ShaderParams sh) {
    UNUSED(sh);
    return false;
}
SHARED_FN float principledBsdfConeSpread(ShaderParams sh) {
    return metallicRoughnessBsdfConeSpread(sh);
}
SHARED_FN vec3 principledBsdfEval(ShaderParams sh, vec3 albedo, vec3 ng, vec3 ns, vec3 wo, vec3 wi,
                                  OUT(float) pdf) {
    return principledEval(sh, albedo, ng, ns, wo, wi, pdf);
}
SHARED_FN bool principledBsdfSample(ShaderParams sh, vec3 albedo, vec3 ng, vec3 ns, vec3 wo, vec3 u,
                                    OUT(vec3) wi, OUT(vec3) weight, OUT(float) pdf,
                                    OUT(bool) specular) {
    return principledSample(sh, albedo, ng, ns, wo, u, wi, weight, pdf, specular);
}

SHARED_END
#endif
