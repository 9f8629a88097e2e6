// setUpHitLanes (wide_hits.h), compiled once per instruction set through foreach_target.h. It is
// HitSetup::surfaceHit's arithmetic, HitSetup::smoothLift and HitSetup::textureQuery
// (hit_setup.cpp), lane by lane, in the same operations.
#include "host/scene_view/wide_hits.h"

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "host/scene_view/wide_hits.cpp"
#include <hwy/foreach_target.h> // must come before highway.h
#include <hwy/highway.h>

#include "host/simd/simd_math-inl.h" // D, V, V3, cross, normalize, surfaceOffset, ...

HWY_BEFORE_NAMESPACE();
namespace spw::HWY_NAMESPACE {

struct V2 {
    V x, y;
};

HWY_INLINE V2 load(const simd::Vec2s& a, size_t i) {
    return {load(a.x, i), load(a.y, i)};
}

// (w a + u b) + v c, per component: glm's w * a + u * b + v * c.
HWY_INLINE V3 interpolate(V w, V u, V v, V3 a, V3 b, V3 c) {
    return add(add(mul(a, w), mul(b, u)), mul(c, v));
}
HWY_INLINE V2 interpolate(V w, V u, V v, V2 a, V2 b, V2 c) {
    return {hn::Add(hn::Add(hn::Mul(a.x, w), hn::Mul(b.x, u)), hn::Mul(c.x, v)),
            hn::Add(hn::Add(hn::Mul(a.y, w), hn::Mul(b.y, u)), hn::Mul(c.y, v))};
}

// Lanes [i, i + Lanes) of the texture lookup's coordinates and the cone's footprint: its width
// at the hit, stretched by the incidence and scaled by the triangle's texture area over its world
// area. `normal`: the triangle's unnormalised normal, ng its unit one.
HWY_INLINE void textureQuery(spw::HitLanes& l, size_t i, V w, V u, V v, V3 normal, V3 ng) {
    const D d;
    const V zero = hn::Zero(d);
    const V2 t0 = load(l.t0, i), t1 = load(l.t1, i), t2 = load(l.t2, i);
    const V worldArea = hn::Sqrt(dot(normal, normal));
    const V ax = hn::Sub(t1.x, t0.x), ay = hn::Sub(t1.y, t0.y);
    const V bx = hn::Sub(t2.x, t0.x), by = hn::Sub(t2.y, t0.y);
    const V uvArea = hn::Abs(hn::Sub(hn::Mul(ax, by), hn::Mul(ay, bx)));
    const V cosine = gmax(hn::Abs(dot(load(l.dir, i), ng)), hn::Set(d, 1e-3f));
    const V width = hn::Add(load(l.coneWidth, i), hn::Mul(load(l.coneSpread, i), load(l.t, i)));
    const V footprint = hn::Mul(hn::Div(width, cosine), hn::Sqrt(hn::Div(uvArea, worldArea)));
    const M uvs = loadMask(l.hasUvs, i);
    store(hn::IfThenElseZero(hn::And(uvs, hn::Gt(worldArea, zero)), footprint), l.footprint, i);
    const V2 uv = interpolate(w, u, v, t0, t1, t2);
    store(hn::IfThenElseZero(uvs, uv.x), l.uv.x, i);
    store(hn::IfThenElseZero(uvs, uv.y), l.uv.y, i);
}

// HitSetup::smoothLift: each vertex's tangent plane lifts p onto it where p lies below it; the
// lift along ng, 0 where it is not finite.
HWY_INLINE V smoothLift(V w, V u, V v, V3 p, V3 p0, V3 p1, V3 p2, V3 n0, V3 n1, V3 n2, V3 ng) {
    const V zero = hn::Zero(D());
    auto toPlane = [&](V3 corner, V3 n) { return mul(n, gmax(zero, dot(sub(corner, p), n))); };
    const V lift = dot(interpolate(w, u, v, toPlane(p0, n0), toPlane(p1, n1), toPlane(p2, n2)), ng);
    return hn::IfThenElseZero(hn::IsFinite(lift), lift);
}

void SetUpHitLanes(size_t count, spw::HitLanes& l) {
    const D d;
    const V zero = hn::Zero(d);
    for (size_t i = 0; i < count; i += hn::Lanes(d)) {
        const V u = load(l.u, i), v = load(l.v, i);
        const V w = hn::Sub(hn::Sub(hn::Set(d, 1.0f), u), v);
        const V3 p0 = load(l.p0, i), p1 = load(l.p1, i), p2 = load(l.p2, i);
        const V3 p = interpolate(w, u, v, p0, p1, p2);
        const V3 normal = cross(sub(p1, p0), sub(p2, p0));
        const V3 ng = normalize(normal);
        // The shading normal: the interpolated vertex normals, where they have a length.
        V3 ns = ng;
        V lift = zero;
        if (l.anyNormals) {
            const V3 n0 = load(l.n0, i), n1 = load(l.n1, i), n2 = load(l.n2, i);
            const V3 n = interpolate(w, u, v, n0, n1, n2);
            const V length = hn::Sqrt(dot(n, n));
            const M has = loadMask(l.hasNormals, i);
            ns = select(hn::And(has, hn::Gt(length, zero)), div(n, length), ng);
            lift = hn::IfThenElseZero(has, smoothLift(w, u, v, p, p0, p1, p2, n0, n1, n2, ng));
        }
        store(p.x, l.p.x, i), store(p.y, l.p.y, i), store(p.z, l.p.z, i);
        store(ng.x, l.ng.x, i), store(ng.y, l.ng.y, i), store(ng.z, l.ng.z, i);
        store(ns.x, l.ns.x, i), store(ns.y, l.ns.y, i), store(ns.z, l.ns.z, i);
        store(surfaceOffset(p, p0, p1, p2, ng), l.offset, i);
        store(lift, l.lift, i);
        if (l.anyUvs) {
            textureQuery(l, i, w, u, v, normal, ng);
        } else {
            store(zero, l.footprint, i), store(zero, l.uv.x, i), store(zero, l.uv.y, i);
        }
    }
}

} // namespace spw::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace spw {
HWY_EXPORT(SetUpHitLanes);

void setUpHitLanes(size_t count, HitLanes& lanes) {
    HWY_DYNAMIC_DISPATCH(SetUpHitLanes)(count, lanes);
}

} // namespace spw
#endif
