// The GGX (Trowbridge-Reitz) microfacet distribution shared by the rough models (conductor.h,
// dielectric.h): isotropic, in a local frame whose +Z is the macro-surface normal on the side
// the light leaves towards (wo.z > 0).
//   D        Walter, Marschner, Li & Torrance 2007, "Microfacet Models for Refraction through
//            Rough Surfaces" (GGX).
//   G1, G2   Smith masking and height-correlated masking-shadowing (Heitz 2014, "Understanding
//            the Masking-Shadowing Function in Microfacet-Based BRDFs").
//   sampling Heitz 2018, "Sampling the GGX Distribution of Visible Normals" (JCGT 7(4)).
//
// Written to stay finite for alpha -> 0 and at grazing angles:
//   * D uses h.x^2 + h.y^2 instead of 1 - cos^2, so a lobe a few 1e-4 wide is still resolved in
//     float, and it is bounded by 1 / (pi alpha^2);
//   * Smith's Lambda appears only through A(w) = sqrt(cos^2 + alpha^2 sin^2) = |cos| (1 + 2
//     Lambda): G1 = 2 |cos| / (|cos| + A), G2 = 2 |co| |ci| / (Ao |ci| + Ai |co|), and the pdf and
//     sample weights are written with these products, so no tan^2 overflows and no 0 / 0 arises
//     at cos = 0;
//   * alpha below kGgxSmoothAlpha is a perfectly smooth surface: the models switch to their delta
//     lobes (eval 0, sampled as specular), and ggx* never sees such an alpha.
#ifndef SPILLWAY_SHARED_GGX_H
#define SPILLWAY_SHARED_GGX_H
#include "sampling.h"

SHARED_BEGIN

// Below this width the surface is smooth: the lobe is narrower than the float resolution of a
// direction around it can sample and evaluate consistently (1e-4 rad).
const float kGgxSmoothAlpha = 1e-4f;

SHARED_FN bool ggxIsSmooth(float alpha) {
    return !(alpha >= kGgxSmoothAlpha);
}

// D(h) for a unit half vector in the local frame (0 below the surface).
// SIMD twin: host/simd/simd_bsdf-inl.h
SHARED_FN float ggxD(vec3 h, float alpha) {
    if (h.z <= 0.0f) return 0.0f;
    float a2 = alpha * alpha;
    float d = h.x * h.x + h.y * h.y + a2 * h.z * h.z; // = cos^4 (alpha^2 + tan^2) for unit h
    return a2 / (kPi * max(d * d, 1e-37f));
}

// A(w) = sqrt(cos^2 + alpha^2 sin^2) = |cos| (1 + 2 Lambda(w)).
// SIMD twin: host/simd/simd_bsdf-inl.h
SHARED_FN float ggxA(vec3 w, float alpha) {
    return sqrt(w.z * w.z + alpha * alpha * (w.x * w.x + w.y * w.y));
}

// Smith's G1 for a local direction.
SHARED_FN float ggxG1(vec3 w, float alpha) {
    float c = abs(w.z);
    float s = c + ggxA(w, alpha);
    return s > 0.0f ? 2.0f * c / s : 0.0f;
}

// ao |ci| + ai |co|, the denominator of the height-correlated G2 = 2 |co| |ci| / (that).
// SIMD twin: host/simd/simd_bsdf-inl.h
SHARED_FN float ggxG2Denominator(vec3 wo, vec3 wi, float alpha) {
    return ggxA(wo, alpha) * abs(wi.z) + ggxA(wi, alpha) * abs(wo.z);
}

// Density of visible normals seen from wo (wo.z > 0): G1(wo) max(0, wo.h) D(h) / wo.z.
SHARED_FN float ggxVisibleNormalPdf(vec3 wo, vec3 h, float alpha) {
    float oh = dot(wo, h);
    if (oh <= 0.0f) return 0.0f;
    return 2.0f * oh * ggxD(h, alpha) / (wo.z + ggxA(wo, alpha));
}

// A microfacet normal sampled from the visible normals seen from wo (wo.z > 0), u in [0, 1)^2
// (Heitz 2018, listing 1, isotropic).
// SIMD twin: host/simd/simd_bsdf-inl.h
SHARED_FN vec3 ggxSampleVisibleNormal(vec3 wo, float alpha, vec2 u) {
    // The view direction in the stretched (alpha = 1) configuration, and a frame around it.
    vec3 vh = normalize(vec3(alpha * wo.x, alpha * wo.y, wo.z));
    float lensq = vh.x * vh.x + vh.y * vh.y;
    vec3 t1 = lensq > 0.0f ? vec3(-vh.y, vh.x, 0.0f) * inversesqrt(lensq) : vec3(1.0f, 0.0f, 0.0f);
    vec3 t2 = cross(vh, t1);
    // A point on the projected hemisphere: a disk whose far half is squashed by vh.z.
    float r = sqrt(u.x);
    float phi = 2.0f * kPi * u.y;
    float p1 = r * cos(phi);
    float p2 = r * sin(phi);
    float s = 0.5f * (1.0f + vh.z);
    p2 = (1.0f - s) * sqrt(max(0.0f, 1.0f - p1 * p1)) + s * p2;
    vec3 nh = p1 * t1 + p2 * t2 + sqrt(max(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
    // Unstretch.
    return normalize(vec3(alpha * nh.x, alpha * nh.y, max(0.0f, nh.z)));
}

// The local frame around n: world direction to local coordinates and back.
SHARED_FN vec3 toLocal(vec3 w, vec3 t, vec3 b, vec3 n) {
    return vec3(dot(w, t), dot(w, b), dot(w, n));
}
SHARED_FN vec3 fromLocal(vec3 l, vec3 t, vec3 b, vec3 n) {
    return normalize(l.x * t + l.y * b + l.z * n);
}

// The frame the microfacet models work in: the shading normal turned to wo's side, and two
// tangents. Built once per eval or sample.
struct Frame {
    vec3 t;
    vec3 b;
    vec3 n;
};
SHARED_FN Frame shadingFrame(vec3 ns, vec3 ng, vec3 wo) {
    Frame f;
    f.n = facingShadingNormal(ns, ng, wo);
    makeFrame(f.n, f.t, f.b);
    return f;
}
SHARED_FN vec3 frameToLocal(Frame f, vec3 w) {
    return toLocal(w, f.t, f.b, f.n);
}
SHARED_FN vec3 frameToWorld(Frame f, vec3 l) {
    return fromLocal(l, f.t, f.b, f.n);
}

SHARED_END
#endif
