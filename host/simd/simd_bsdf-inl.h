// The SIMD twins of the surface models built on GGX (shared/ggx.h, shared/conductor.h,
// shared/dielectric.h, shared/metallic_roughness.h), one Highway helper each, to the bit as
// simd_math-inl.h's are (its opening comment gives the rules). The scalar side carries the tag
// "// SIMD twin: host/simd/simd_bsdf-inl.h" on the line above its definition.
//
// Highway's per-target header convention: the includer defines HWY_TARGET_INCLUDE, includes
// <hwy/foreach_target.h>, and this file is compiled once per instruction set.
#if defined(SPILLWAY_SIMD_BSDF_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef SPILLWAY_SIMD_BSDF_INL_H_
#undef SPILLWAY_SIMD_BSDF_INL_H_
#else
#define SPILLWAY_SIMD_BSDF_INL_H_
#endif

#include "host/simd/simd_math-inl.h"

#include <hwy/highway.h>

#include <cmath>

HWY_BEFORE_NAMESPACE();
namespace spw::HWY_NAMESPACE {

// --- GGX (shared/ggx.h), Conductor (shared/conductor.h) and Dielectric (shared/dielectric.h) ---

// Twin of Frame and shadingFrame (shared/ggx.h), given facingShadingNormal's n.
struct Frame {
    V3 t, b, n;
};
HWY_INLINE Frame shadingFrame(V3 n) {
    Frame f;
    f.n = n;
    makeFrame(n, f.t, f.b);
    return f;
}
HWY_INLINE V3 frameToLocal(const Frame& f, V3 w) {
    return {dot(w, f.t), dot(w, f.b), dot(w, f.n)};
}
HWY_INLINE V3 frameToWorld(const Frame& f, V3 l) {
    return normalize(add(add(mul(f.t, l.x), mul(f.b, l.y)), mul(f.n, l.z)));
}
// Twin of ggxIsSmooth (shared/ggx.h).
HWY_INLINE M ggxIsSmooth(V alpha) {
    return hn::Not(hn::Ge(alpha, hn::Set(D(), kGgxSmoothAlpha)));
}
// Twin of ggxD (shared/ggx.h).
HWY_INLINE V ggxD(V3 h, V alpha) {
    const D d;
    const V a2 = hn::Mul(alpha, alpha);
    const V q =
        hn::Add(hn::Add(hn::Mul(h.x, h.x), hn::Mul(h.y, h.y)), hn::Mul(hn::Mul(a2, h.z), h.z));
    const V ndf = hn::Div(a2, hn::Mul(hn::Set(d, kPi), gmax(hn::Mul(q, q), hn::Set(d, 1e-37f))));
    return hn::IfThenZeroElse(hn::Le(h.z, hn::Zero(d)), ndf);
}
// Twin of ggxA (shared/ggx.h).
HWY_INLINE V ggxA(V3 w, V alpha) {
    return hn::Sqrt(
        hn::Add(hn::Mul(w.z, w.z),
                hn::Mul(hn::Mul(alpha, alpha), hn::Add(hn::Mul(w.x, w.x), hn::Mul(w.y, w.y)))));
}
// Twin of ggxG2Denominator (shared/ggx.h).
HWY_INLINE V ggxG2Denominator(V3 wo, V3 wi, V alpha) {
    return hn::Add(hn::Mul(ggxA(wo, alpha), hn::Abs(wi.z)),
                   hn::Mul(ggxA(wi, alpha), hn::Abs(wo.z)));
}
// Twin of ggxSampleVisibleNormal (shared/ggx.h).
HWY_INLINE V3 ggxSampleVisibleNormal(V3 wo, V alpha, V ux, V uy) {
    const D d;
    const V zero = hn::Zero(d), one = hn::Set(d, 1.0f);
    const V3 vh = normalize({hn::Mul(alpha, wo.x), hn::Mul(alpha, wo.y), wo.z});
    const V lensq = hn::Add(hn::Mul(vh.x, vh.x), hn::Mul(vh.y, vh.y));
    const M tilted = hn::Gt(lensq, zero);
    const V3 t1 = select(tilted, mul(V3{hn::Neg(vh.y), vh.x, zero}, hn::Div(one, hn::Sqrt(lensq))),
                         V3{one, zero, zero});
    const V3 t2 = cross(vh, t1);
    const V r = hn::Sqrt(ux);
    V c, s;
    cosSin(hn::Mul(hn::Set(d, 2.0f * kPi), uy), c, s);
    const V p1 = hn::Mul(r, c);
    const V h = hn::Mul(hn::Set(d, 0.5f), hn::Add(one, vh.z));
    const V p2 =
        hn::Add(hn::Mul(hn::Sub(one, h), hn::Sqrt(gmax(zero, hn::Sub(one, hn::Mul(p1, p1))))),
                hn::Mul(h, hn::Mul(r, s)));
    const V up = hn::Sqrt(gmax(zero, hn::Sub(hn::Sub(one, hn::Mul(p1, p1)), hn::Mul(p2, p2))));
    const V3 nh = add(add(mul(t1, p1), mul(t2, p2)), mul(vh, up));
    return normalize({hn::Mul(alpha, nh.x), hn::Mul(alpha, nh.y), gmax(zero, nh.z)});
}
// Twin of schlickFresnel (shared/conductor.h).
HWY_INLINE V3 schlickFresnel(V3 f0, V cosTheta) {
    const V one = hn::Set(D(), 1.0f);
    const V m = clamp01(hn::Sub(one, cosTheta));
    const V m2 = hn::Mul(m, m);
    return add(f0, mul(sub(V3{one, one, one}, f0), hn::Mul(hn::Mul(m2, m2), m)));
}
// Twin of conductorEval (shared/conductor.h), given dot(ng, wo) and shadingFrame's frame.
HWY_INLINE V3 conductorEval(V3 f0, V alpha, V3 ng, V ngDotWo, const Frame& f, V3 wo, V3 wi,
                            V& pdf) {
    const D d;
    const V zero = hn::Zero(d), two = hn::Set(d, 2.0f);
    const V3 lo = frameToLocal(f, wo), li = frameToLocal(f, wi);
    V3 h = add(lo, li);
    const V len2 = dot(h, h);
    h = mul(h, hn::Div(hn::Set(d, 1.0f), hn::Sqrt(len2)));
    const V ndf = ggxD(h, alpha);
    const V denom = ggxG2Denominator(lo, li, alpha);
    const M evaluated =
        hn::AndNot(hn::Or(hn::Or(ggxIsSmooth(alpha), hn::Le(hn::Mul(ngDotWo, dot(ng, wi)), zero)),
                          hn::Or(hn::Le(lo.z, zero), hn::Le(li.z, zero))),
                   hn::And(hn::Gt(len2, zero), hn::Gt(denom, zero)));
    pdf = hn::IfThenElseZero(evaluated, hn::Div(ndf, hn::Mul(two, hn::Add(lo.z, ggxA(lo, alpha)))));
    const V3 fcos =
        mul(schlickFresnel(f0, dot(lo, h)), hn::Div(hn::Mul(ndf, li.z), hn::Mul(two, denom)));
    return select(evaluated, fcos, V3{zero, zero, zero});
}
// What a BSDF sample twin gives where `ok` holds (the scalar function's out-parameters).
struct BsdfSample {
    M ok, specular;
    V3 wi, weight;
    V pdf;
};
// Twin of conductorSample (shared/conductor.h), given dot(ng, wo) and shadingFrame's frame.
HWY_INLINE BsdfSample conductorSample(V3 f0, V alpha, V3 ng, V ngDotWo, const Frame& f, V3 wo, V ux,
                                      V uy) {
    const D d;
    const V zero = hn::Zero(d), two = hn::Set(d, 2.0f);
    const V3 lo = frameToLocal(f, wo);
    const M smooth = ggxIsSmooth(alpha);
    BsdfSample s;
    s.specular = smooth;
    // The mirror direction.
    s.wi = normalize(sub(mul(f.n, hn::Mul(two, lo.z)), wo));
    s.weight = schlickFresnel(f0, lo.z);
    s.pdf = zero;
    s.ok = smooth;
    if (!hn::AllTrue(d, smooth)) { // a visible microfacet normal
        const V3 h = ggxSampleVisibleNormal(lo, alpha, ux, uy);
        const V oh = dot(lo, h);
        const V3 li = sub(mul(h, hn::Mul(two, oh)), lo);
        const V3 wi = frameToWorld(f, li);
        const V ao = ggxA(lo, alpha);
        const V denom = ggxG2Denominator(lo, li, alpha);
        const V pdf = hn::Div(ggxD(h, alpha), hn::Mul(two, hn::Add(lo.z, ao)));
        const V3 weight =
            mul(schlickFresnel(f0, oh), hn::Div(hn::Mul(li.z, hn::Add(lo.z, ao)), denom));
        const M rough =
            hn::And(hn::Not(smooth), hn::Not(hn::Or(hn::Le(oh, zero), hn::Le(li.z, zero))));
        s.wi = select(smooth, s.wi, wi);
        s.weight = select(smooth, s.weight, weight);
        s.pdf = hn::IfThenZeroElse(smooth, pdf);
        s.ok = hn::Or(smooth, hn::And(rough, hn::Gt(pdf, zero)));
    }
    s.ok =
        hn::AndNot(hn::Or(hn::Le(lo.z, zero), hn::Le(hn::Mul(ngDotWo, dot(ng, s.wi)), zero)), s.ok);
    return s;
}
// Twin of fresnelDielectric (shared/dielectric.h).
HWY_INLINE V fresnelDielectric(V cosI, V eta, V& cosT) {
    const D d;
    const V one = hn::Set(d, 1.0f);
    const V ci = clamp01(cosI);
    const V sin2T = hn::Div(hn::Sub(one, hn::Mul(ci, ci)), hn::Mul(eta, eta));
    const M total = hn::Ge(sin2T, one);
    const V ct = hn::Sqrt(hn::Sub(one, sin2T));
    const V rs = hn::Div(hn::Sub(ci, hn::Mul(eta, ct)), hn::Add(ci, hn::Mul(eta, ct)));
    const V rp = hn::Div(hn::Sub(hn::Mul(eta, ci), ct), hn::Add(hn::Mul(eta, ci), ct));
    cosT = hn::IfThenZeroElse(total, ct);
    return hn::IfThenElse(total, one,
                          hn::Mul(hn::Set(d, 0.5f), hn::Add(hn::Mul(rs, rs), hn::Mul(rp, rp))));
}
// Twin of dielectricEta (shared/dielectric.h), given dot(ng, wo).
HWY_INLINE V dielectricEta(V ior, V ngDotWo) {
    return hn::IfThenElse(hn::Gt(ngDotWo, hn::Zero(D())), ior, hn::Div(hn::Set(D(), 1.0f), ior));
}
// Twin of dielectricEval (shared/dielectric.h), given dot(ng, wo) and shadingFrame's frame.
HWY_INLINE V3 dielectricEval(V ior, V alpha, V3 ng, V go, const Frame& f, V3 wo, V3 wi, V& pdf) {
    const D d;
    const V zero = hn::Zero(d), one = hn::Set(d, 1.0f), two = hn::Set(d, 2.0f);
    const V gi = dot(ng, wi);
    const M reflection = hn::Gt(hn::Mul(go, gi), zero);
    const V eta = dielectricEta(ior, go);
    const V3 lo = frameToLocal(f, wo), li = frameToLocal(f, wi);
    M evaluated = hn::Not(hn::Or(hn::Or(ggxIsSmooth(alpha), hn::Eq(go, zero)), hn::Eq(gi, zero)));
    const M liUp = hn::Gt(li.z, zero);
    evaluated = hn::AndNot(
        hn::Or(hn::Or(hn::Le(lo.z, zero), hn::Xor(liUp, reflection)), hn::Eq(li.z, zero)),
        evaluated);
    V3 h = select(reflection, add(lo, li), add(lo, mul(li, eta)));
    const V len2 = dot(h, h);
    evaluated = hn::And(evaluated, hn::Gt(len2, zero));
    h = mul(h, hn::Div(one, hn::Sqrt(len2)));
    h = select(hn::Lt(h.z, zero), neg(h), h);
    const V oh = dot(lo, h), ih = dot(li, h);
    evaluated = hn::AndNot(
        hn::Or(hn::Le(oh, zero), selectMask(reflection, hn::Le(ih, zero), hn::Ge(ih, zero))),
        evaluated);
    V cosT;
    const V F = fresnelDielectric(oh, eta, cosT);
    const V ndf = ggxD(h, alpha);
    const V ao = ggxA(lo, alpha);
    const V ci = hn::Abs(li.z);
    const V denomG = ggxG2Denominator(lo, li, alpha);
    evaluated = hn::And(evaluated, hn::Gt(denomG, zero));
    const V reflectPdf = hn::Div(hn::Mul(F, ndf), hn::Mul(two, hn::Add(lo.z, ao)));
    const V reflectF = hn::Div(hn::Mul(hn::Mul(F, ndf), ci), hn::Mul(two, denomG));
    const V s = hn::Add(ih, hn::Div(oh, eta));
    const V s2 = hn::Mul(s, s);
    const V oneF = hn::Sub(one, F);
    const V dv = hn::Div(hn::Mul(hn::Mul(two, oh), ndf), hn::Add(lo.z, ao));
    const V refractPdf = hn::Div(hn::Mul(hn::Mul(oneF, dv), hn::Neg(ih)), s2);
    const V refractF =
        hn::Div(hn::Mul(hn::Mul(hn::Mul(hn::Mul(hn::Mul(oneF, ndf), two), ci), hn::Neg(ih)), oh),
                hn::Mul(hn::Mul(hn::Mul(denomG, s2), eta), eta));
    evaluated = hn::And(evaluated, hn::Or(reflection, hn::Gt(s2, zero)));
    pdf = hn::IfThenElseZero(evaluated, hn::IfThenElse(reflection, reflectPdf, refractPdf));
    const V value = hn::IfThenElseZero(evaluated, hn::IfThenElse(reflection, reflectF, refractF));
    return {value, value, value};
}
// Twin of dielectricSample (shared/dielectric.h), given dot(ng, wo) and shadingFrame's frame.
HWY_INLINE BsdfSample dielectricSample(V ior, V alpha, V3 ng, V go, const Frame& f, V3 wo, V ux,
                                       V uy, V uz) {
    const D d;
    const V zero = hn::Zero(d), one = hn::Set(d, 1.0f), two = hn::Set(d, 2.0f);
    const V eta = dielectricEta(ior, go);
    const V3 lo = frameToLocal(f, wo);
    const M smooth = ggxIsSmooth(alpha);
    V3 h = {zero, zero, one};
    if (!hn::AllTrue(d, smooth)) h = select(smooth, h, ggxSampleVisibleNormal(lo, alpha, ux, uy));
    const V oh = dot(lo, h);
    V cosT;
    const V F = fresnelDielectric(oh, eta, cosT);
    const M reflection = hn::Lt(uz, F);
    const V3 li = select(reflection, sub(mul(h, hn::Mul(two, oh)), lo),
                         sub(mul(h, hn::Sub(hn::Div(oh, eta), cosT)), div(lo, eta)));
    BsdfSample s;
    s.wi = frameToWorld(f, li);
    const V etaScale = hn::IfThenElse(reflection, one, hn::Div(one, hn::Mul(eta, eta)));
    s.ok = hn::Not(hn::Or(hn::Or(hn::Eq(go, zero), hn::Le(lo.z, zero)), hn::Le(oh, zero)));
    s.ok = hn::AndNot(selectMask(reflection, hn::Le(li.z, zero), hn::Ge(li.z, zero)), s.ok);
    s.ok = hn::AndNot(hn::Xor(hn::Gt(hn::Mul(go, dot(ng, s.wi)), zero), reflection), s.ok);
    s.specular = smooth;
    const V ao = ggxA(lo, alpha);
    const V denomG = ggxG2Denominator(lo, li, alpha);
    const V ndf = ggxD(h, alpha);
    const V reflectPdf = hn::Div(hn::Mul(F, ndf), hn::Mul(two, hn::Add(lo.z, ao)));
    const V ih = dot(li, h);
    const V sum = hn::Add(ih, hn::Div(oh, eta));
    const V refractPdf =
        hn::Div(hn::Mul(hn::Mul(hn::Sub(one, F),
                                hn::Div(hn::Mul(hn::Mul(two, oh), ndf), hn::Add(lo.z, ao))),
                        hn::Neg(ih)),
                gmax(hn::Mul(sum, sum), hn::Set(d, 1e-37f)));
    const V pdf = hn::IfThenElse(reflection, reflectPdf, refractPdf);
    const V roughWeight =
        hn::Mul(hn::Div(hn::Mul(hn::Abs(li.z), hn::Add(lo.z, ao)), denomG), etaScale);
    s.pdf = hn::IfThenZeroElse(smooth, pdf);
    const V weight = hn::IfThenElse(smooth, etaScale, roughWeight);
    s.weight = {weight, weight, weight};
    s.ok = hn::And(s.ok, hn::Or(smooth, hn::And(hn::Gt(pdf, zero), hn::Gt(denomG, zero))));
    return s;
}

// --- MetallicRoughness (shared/metallic_roughness.h)
// -----------------------------------------------------------

// glm's mix(vec3(a), b, t): a (1 - t) + b t.
HWY_INLINE V3 mix(V a, V3 b, V t) {
    const V at = hn::Mul(a, hn::Sub(hn::Set(D(), 1.0f), t));
    return {hn::Add(at, hn::Mul(b.x, t)), hn::Add(at, hn::Mul(b.y, t)),
            hn::Add(at, hn::Mul(b.z, t))};
}
// glm's mix(a, b, t) of two vec3: a (1 - t) + b t.
HWY_INLINE V3 mix(V3 a, V3 b, V t) {
    const V s = hn::Sub(hn::Set(D(), 1.0f), t);
    return {hn::Add(hn::Mul(a.x, s), hn::Mul(b.x, t)), hn::Add(hn::Mul(a.y, s), hn::Mul(b.y, t)),
            hn::Add(hn::Mul(a.z, s), hn::Mul(b.z, t))};
}
// Twin of gltfFresnel (shared/metallic_roughness.h).
HWY_INLINE V3 gltfFresnel(V3 f0, V f90, V cosTheta) {
    const V one = hn::Set(D(), 1.0f);
    const V m = clamp01(hn::Sub(one, cosTheta));
    const V m2 = hn::Mul(m, m);
    return add(f0, mul(sub(V3{f90, f90, f90}, f0), hn::Mul(hn::Mul(m2, m2), m)));
}
// gltfF90 (shared/metallic_roughness.h): 1 - (1 - f90d) (1 - metallic).
HWY_INLINE V gltfF90(V f90d, V metallic) {
    const V one = hn::Set(D(), 1.0f);
    return hn::Sub(one, hn::Mul(hn::Sub(one, f90d), hn::Sub(one, metallic)));
}
HWY_INLINE V mean(V3 v) {
    return hn::Div(hn::Add(hn::Add(v.x, v.y), v.z), hn::Set(D(), 3.0f));
}
// Twin of gltfSpecularProbability (shared/metallic_roughness.h).
HWY_INLINE V gltfSpecularProbability(V3 f0, V f90, V3 cDiff, V cosO, V alpha) {
    const D d;
    const V one = hn::Set(d, 1.0f);
    const V3 F = gltfFresnel(f0, f90, cosO);
    const V fs = mean(F);
    const V fd = mean(mul(cDiff, sub(V3{one, one, one}, F)));
    const V open = hn::Sub(one, gmin(alpha, one));
    const V floor = hn::Mul(hn::Mul(hn::Set(d, 0.25f), open), open);
    const V p = gmin(gmax(hn::Div(fs, hn::Add(fs, fd)), floor), hn::Set(d, 0.9f));
    return hn::IfThenElse(hn::Gt(fd, hn::Zero(d)), p, one);
}
// Twin of gltfEval (shared/metallic_roughness.h), given dot(ng, wo) and shadingFrame's frame.
HWY_INLINE V3 gltfEval(V3 colour, V metallic, V alpha, V3 f0d, V f90d, V3 ng, V ngDotWo,
                       const Frame& f, V3 wo, V3 wi, V& pdf) {
    const D d;
    const V zero = hn::Zero(d), one = hn::Set(d, 1.0f), two = hn::Set(d, 2.0f);
    const V invPi = hn::Set(d, kInvPi);
    const V3 lo = frameToLocal(f, wo), li = frameToLocal(f, wi);
    V3 h = add(lo, li);
    const V len2 = dot(h, h);
    const M evaluated = hn::AndNot(hn::Or(hn::Le(hn::Mul(ngDotWo, dot(ng, wi)), zero),
                                          hn::Or(hn::Le(lo.z, zero), hn::Le(li.z, zero))),
                                   hn::Gt(len2, zero));
    h = mul(h, hn::Div(one, hn::Sqrt(len2)));
    const V3 f0 = mix(f0d, colour, metallic);
    const V f90 = gltfF90(f90d, metallic);
    const V3 cDiff = mul(colour, hn::Sub(one, metallic));
    const V3 F = gltfFresnel(f0, f90, dot(lo, h));
    const V ndf = ggxD(h, alpha);
    const V denom = ggxG2Denominator(lo, li, alpha);
    const V3 specular =
        select(hn::Gt(denom, zero), mul(F, hn::Div(hn::Mul(ndf, li.z), hn::Mul(two, denom))),
               V3{zero, zero, zero});
    const V3 diffuse = mul(mul(sub(V3{one, one, one}, F), cDiff), hn::Mul(li.z, invPi));
    const V pSpecular = gltfSpecularProbability(f0, f90, cDiff, lo.z, alpha);
    const V specularPdf = hn::Div(ndf, hn::Mul(two, hn::Add(lo.z, ggxA(lo, alpha))));
    pdf = hn::IfThenElseZero(evaluated,
                             hn::Add(hn::Mul(pSpecular, specularPdf),
                                     hn::Mul(hn::Sub(one, pSpecular), hn::Mul(li.z, invPi))));
    return select(evaluated, add(specular, diffuse), V3{zero, zero, zero});
}
// Twin of gltfSample (shared/metallic_roughness.h), given dot(ng, wo) and shadingFrame's frame.
HWY_INLINE BsdfSample gltfSample(V3 colour, V metallic, V alpha, V3 f0d, V f90d, V3 ng, V ngDotWo,
                                 const Frame& f, V3 wo, V ux, V uy, V uz) {
    const D d;
    const V zero = hn::Zero(d), one = hn::Set(d, 1.0f), two = hn::Set(d, 2.0f);
    const V3 lo = frameToLocal(f, wo);
    const V3 f0 = mix(f0d, colour, metallic);
    const V3 cDiff = mul(colour, hn::Sub(one, metallic));
    const M specularLobe =
        hn::Lt(uz, gltfSpecularProbability(f0, gltfF90(f90d, metallic), cDiff, lo.z, alpha));
    BsdfSample s;
    s.ok = hn::Gt(lo.z, zero);
    V3 li = sampleCosineHemisphere(ux, uy);
    if (!hn::AllFalse(d, specularLobe)) {
        const V3 h = ggxSampleVisibleNormal(lo, alpha, ux, uy);
        const V oh = dot(lo, h);
        s.ok = hn::AndNot(hn::And(specularLobe, hn::Le(oh, zero)), s.ok);
        li = select(specularLobe, sub(mul(h, hn::Mul(two, oh)), lo), li);
    }
    s.ok = hn::And(s.ok, hn::Gt(li.z, zero));
    s.wi = frameToWorld(f, li);
    const V3 fcos = gltfEval(colour, metallic, alpha, f0d, f90d, ng, ngDotWo, f, wo, s.wi, s.pdf);
    s.ok = hn::And(s.ok, hn::Gt(s.pdf, zero));
    s.weight = div(fcos, s.pdf);
    s.specular = hn::FirstN(d, 0);
    return s;
}

} // namespace spw::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif // SPILLWAY_SIMD_BSDF_INL_H_
