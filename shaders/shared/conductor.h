// Conductor: a metal, rough or polished.
//   parameters: colour [r, g, b] ([1, 1, 1]) or texture: F0, the reflectance at normal incidence,
//   through Schlick's Fresnel approximation (Schlick 1994, "An Inexpensive BRDF Model for
//   Physically-based Rendering"); alpha (0): GGX width. alpha < kGgxSmoothAlpha (1e-4) is a
//   perfect mirror.
//   Rough: f = D G2 F / (4 |co| |ci|) (Walter et al. 2007) with GGX D and the height-correlated
//   Smith G2 (ggx.h); sampled through the visible normals (Heitz 2018): pdf = D G1(wo) / (4 co),
//   weight = F G2 / G1(wo). Single scattering only: light that would bounce between microfacets
//   is lost, so an F0 = 1 conductor darkens as alpha grows (tests/extreme measures how much).
//   Smooth: a delta lobe. Eval gives 0, sampling returns the mirror direction as `specular` with
//   weight F(cos) and pdf 0 (never read: MIS is off after a specular bounce).
//   Reflection only: wi on the side of ng that wo is on.
#ifndef SPILLWAY_SHARED_CONDUCTOR_H
#define SPILLWAY_SHARED_CONDUCTOR_H
#include "ggx.h"
#include "types.h"

SHARED_BEGIN

// SIMD twin: host/simd/simd_bsdf-inl.h
SHARED_FN vec3 schlickFresnel(vec3 f0, float cosTheta) {
    float m = clamp(1.0f - cosTheta, 0.0f, 1.0f);
    float m2 = m * m;
    return f0 + (vec3(1.0f) - f0) * (m2 * m2 * m);
}

// SIMD twin: host/simd/simd_bsdf-inl.h
SHARED_FN vec3 conductorEval(vec3 f0, float alpha, vec3 ng, vec3 ns, vec3 wo, vec3 wi,
                             OUT(float) pdf) {
    pdf = 0.0f;
    if (ggxIsSmooth(alpha)) return vec3(0.0f);
    if (dot(ng, wo) * dot(ng, wi) <= 0.0f) return vec3(0.0f);
    Frame f = shadingFrame(ns, ng, wo);
    vec3 lo = frameToLocal(f, wo);
    vec3 li = frameToLocal(f, wi);
    if (lo.z <= 0.0f || li.z <= 0.0f) return vec3(0.0f);
    vec3 h = lo + li;
    float len2 = dot(h, h);
    if (!(len2 > 0.0f)) return vec3(0.0f);
    h = h * inversesqrt(len2);
    float d = ggxD(h, alpha);
    float denom = ggxG2Denominator(lo, li, alpha);
    if (!(denom > 0.0f)) return vec3(0.0f);
    pdf = d / (2.0f * (lo.z + ggxA(lo, alpha)));
    // D G2 F / (4 co) with G2 = 2 co ci / denom.
    return schlickFresnel(f0, dot(lo, h)) * (d * li.z / (2.0f * denom));
}

// SIMD twin: host/simd/simd_bsdf-inl.h
SHARED_FN bool conductorSample(vec3 f0, float alpha, vec3 ng, vec3 ns, vec3 wo, vec2 u,
                               OUT(vec3) wi, OUT(vec3) weight, OUT(float) pdf, OUT(bool) specular) {
    Frame f = shadingFrame(ns, ng, wo);
    vec3 lo = frameToLocal(f, wo);
    if (lo.z <= 0.0f) return false;
    if (ggxIsSmooth(alpha)) {
        wi = normalize(2.0f * lo.z * f.n - wo);
        if (dot(ng, wo) * dot(ng, wi) <= 0.0f) return false;
        specular = true;
        pdf = 0.0f;
        weight = schlickFresnel(f0, lo.z);
        return true;
    }
    vec3 h = ggxSampleVisibleNormal(lo, alpha, u);
    float oh = dot(lo, h);
    vec3 li = 2.0f * oh * h - lo;
    if (oh <= 0.0f || li.z <= 0.0f) return false; // reflected below the surface: absorbed
    wi = frameToWorld(f, li);
    if (dot(ng, wo) * dot(ng, wi) <= 0.0f) return false;
    float ao = ggxA(lo, alpha);
    float denom = ggxG2Denominator(lo, li, alpha);
    pdf = ggxD(h, alpha) / (2.0f * (lo.z + ao));
    // F G2 / G1(wo) = F ci (co + ao) / (ao ci + ai co).
    weight = schlickFresnel(f0, oh) * (li.z * (lo.z + ao) / denom);
    specular = false;
    return pdf > 0.0f;
}

// The registry's interface (shared/bsdf.h dispatches here).
SHARED_FN bool conductorBsdfIsDelta(ShaderParams sh) {
    return ggxIsSmooth(sh.alpha);
}
// GGX's alpha is the tangent of the lobe's angular width: a rough reflection spreads the cone
// by about alpha radians (a mirror, sampled as a delta lobe, by 0: bsdfConeSpread).
SHARED_FN float conductorBsdfConeSpread(ShaderParams sh) {
    return sh.alpha;
}
SHARED_FN vec3 conductorBsdfEval(ShaderParams sh, vec3 albedo, vec3 ng, vec3 ns, vec3 wo, vec3 wi,
                                 OUT(float) pdf) {
    return conductorEval(albedo, sh.alpha, ng, ns, wo, wi, pdf);
}
SHARED_FN bool conductorBsdfSample(ShaderParams sh, vec3 albedo, vec3 ng, vec3 ns, vec3 wo, vec3 u,
                                   OUT(vec3) wi, OUT(vec3) weight, OUT(float) pdf,
                                   OUT(bool) specular) {
    return conductorSample(albedo, sh.alpha, ng, ns, wo, vec2(u.x, u.y), wi, weight, pdf, specular);
}

SHARED_END
#endif
