// The SIMD twins of the shared scalar functions (shaders/shared/), one Highway helper each, for
// the kernels that include this file (the shading kernels, the camera rays, the hit setup, the
// texel filtering, the film's rounding) and for the test that compares each twin with its scalar
// function lane by lane (host/simd/twins.h, tests/simd/twins_test.cpp). Each helper is its scalar
// function to the bit: the same operations in the same order, each rounded once (no fused
// multiply-add). glm's operations are written out in glm's order: dot is (x x' + y y') + z z',
// max(a, b) is (a < b) ? b : a and min(a, b) is (b < a) ? b : a. The scalar side carries the tag
// "// SIMD twin: host/simd/simd_math-inl.h" on the line above its definition. This file holds the
// vector arithmetic, sampling, triangle emitters, Lambert, the random numbers and the light
// tree's descent (checked through the shading kernels, whose light pick is its only caller); the
// surface models built on GGX are simd_bsdf-inl.h's.
//
// Highway's per-target header convention: the includer defines HWY_TARGET_INCLUDE, includes
// <hwy/foreach_target.h>, and this file is compiled once per instruction set.
#if defined(SPILLWAY_SIMD_MATH_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef SPILLWAY_SIMD_MATH_INL_H_
#undef SPILLWAY_SIMD_MATH_INL_H_
#else
#define SPILLWAY_SIMD_MATH_INL_H_
#endif

#include "host/simd/lanes.h"
#include "shared/light_tree.h"
#include "shared/path.h"

#include <hwy/highway.h>

#include <cstdint>

HWY_BEFORE_NAMESPACE();
namespace spw::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;
using D = hn::ScalableTag<float>;
using DU = hn::RebindToUnsigned<D>;
using V = hn::Vec<D>;
using M = hn::Mask<D>;
using VU = hn::Vec<DU>;
using simd::Floats;
using simd::Uints;
using simd::Vec3s;

struct V3 {
    V x, y, z;
};

HWY_INLINE V load(const Floats& a, size_t i) {
    return hn::Load(D(), a.v + i);
}
HWY_INLINE M loadMask(const Uints& a, size_t i) {
    return hn::MaskFromVec(hn::BitCast(D(), hn::Load(DU(), a.v + i)));
}
HWY_INLINE V3 load(const Vec3s& a, size_t i) {
    return {load(a.x, i), load(a.y, i), load(a.z, i)};
}
HWY_INLINE void store(V v, Floats& a, size_t i) {
    hn::Store(v, D(), a.v + i);
}
HWY_INLINE void store(M m, Uints& a, size_t i) {
    hn::Store(hn::BitCast(DU(), hn::VecFromMask(D(), m)), DU(), a.v + i);
}
// The vector where m holds, zero elsewhere (shadeSurface's results start zeroed).
HWY_INLINE void store(M m, V3 v, Vec3s& a, size_t i) {
    store(hn::IfThenElseZero(m, v.x), a.x, i);
    store(hn::IfThenElseZero(m, v.y), a.y, i);
    store(hn::IfThenElseZero(m, v.z), a.z, i);
}

HWY_INLINE V3 add(V3 a, V3 b) {
    return {hn::Add(a.x, b.x), hn::Add(a.y, b.y), hn::Add(a.z, b.z)};
}
HWY_INLINE V3 sub(V3 a, V3 b) {
    return {hn::Sub(a.x, b.x), hn::Sub(a.y, b.y), hn::Sub(a.z, b.z)};
}
HWY_INLINE V3 mul(V3 a, V3 b) {
    return {hn::Mul(a.x, b.x), hn::Mul(a.y, b.y), hn::Mul(a.z, b.z)};
}
HWY_INLINE V3 mul(V3 a, V s) {
    return {hn::Mul(a.x, s), hn::Mul(a.y, s), hn::Mul(a.z, s)};
}
HWY_INLINE V3 div(V3 a, V s) {
    return {hn::Div(a.x, s), hn::Div(a.y, s), hn::Div(a.z, s)};
}
HWY_INLINE V3 neg(V3 a) {
    return {hn::Neg(a.x), hn::Neg(a.y), hn::Neg(a.z)};
}
HWY_INLINE V3 abs(V3 a) {
    return {hn::Abs(a.x), hn::Abs(a.y), hn::Abs(a.z)};
}
HWY_INLINE V3 select(M m, V3 a, V3 b) {
    return {hn::IfThenElse(m, a.x, b.x), hn::IfThenElse(m, a.y, b.y), hn::IfThenElse(m, a.z, b.z)};
}
HWY_INLINE V dot(V3 a, V3 b) {
    return hn::Add(hn::Add(hn::Mul(a.x, b.x), hn::Mul(a.y, b.y)), hn::Mul(a.z, b.z));
}
HWY_INLINE V gmax(V a, V b) { // glm::max
    return hn::IfThenElse(hn::Lt(a, b), b, a);
}
HWY_INLINE V gmin(V a, V b) { // glm::min
    return hn::IfThenElse(hn::Lt(b, a), b, a);
}
HWY_INLINE V3 gmax(V3 a, V3 b) {
    return {gmax(a.x, b.x), gmax(a.y, b.y), gmax(a.z, b.z)};
}
// Twin of maxComponent (shared/sampling.h).
HWY_INLINE V maxComponent(V3 v) {
    return gmax(v.x, gmax(v.y, v.z));
}
HWY_INLINE V clamp01(V x) { // glm::clamp(x, 0, 1)
    return gmin(gmax(x, hn::Zero(D())), hn::Set(D(), 1.0f));
}
HWY_INLINE V sign(M nonNegative) { // x >= 0 ? 1 : -1
    return hn::IfThenElse(nonNegative, hn::Set(D(), 1.0f), hn::Set(D(), -1.0f));
}
// Twin of quantizePdf (shared/sampling.h).
HWY_INLINE V quantizePdf(V pdf) {
    return hn::BitCast(D(), hn::And(hn::BitCast(DU(), pdf), hn::Set(DU(), 0xFFFF0000u)));
}
// Twin of powerHeuristic (shared/sampling.h).
HWY_INLINE V powerHeuristic(V pdfThis, V pdfOther) {
    const V r = hn::Div(pdfOther, pdfThis);
    const V w = hn::Div(hn::Set(D(), 1.0f), hn::Add(hn::Set(D(), 1.0f), hn::Mul(r, r)));
    return hn::IfThenZeroElse(hn::Le(pdfThis, hn::Zero(D())), w);
}
// Twin of facingShadingNormal (shared/sampling.h), given dot(ng, wo): every branch computed, the
// scalar code's early returns as selects in the same order.
HWY_INLINE V3 facingShadingNormal(V3 ns, V3 ng, V3 wo, V ngDotWo) {
    const D d;
    const V zero = hn::Zero(d), one = hn::Set(d, 1.0f), two = hn::Set(d, 2.0f);
    const V side = sign(hn::Ge(ngDotWo, zero));
    const V3 n = mul(ns, side);
    const V3 g = mul(ng, side);
    const V nz = dot(n, g);
    const V wz = dot(wo, g);
    const V clearance = gmin(hn::Mul(hn::Set(d, 0.9f), wz), hn::Set(d, 0.01f));
    const M clears = hn::Ge(hn::Sub(hn::Mul(hn::Mul(two, dot(wo, n)), nz), wz), clearance);
    const V3 xt = sub(n, mul(g, nz));
    const V xl = hn::Sqrt(dot(xt, xt));
    const V3 x = div(xt, xl);
    const V wx = dot(wo, x);
    const V a = hn::Add(hn::Mul(wx, wx), hn::Mul(wz, wz));
    const V root =
        hn::Sqrt(gmax(hn::Mul(hn::Mul(wx, wx), hn::Sub(a, hn::Mul(clearance, clearance))), zero));
    const V mid = hn::Add(hn::Mul(wz, clearance), a);
    const V twoA = hn::Mul(two, a);
    const V cLow = hn::Sqrt(clamp01(hn::Div(hn::Sub(mid, root), twoA)));
    const V cHigh = hn::Sqrt(clamp01(hn::Div(hn::Add(mid, root), twoA)));
    const V sLow = hn::Sqrt(gmax(hn::Sub(one, hn::Mul(cLow, cLow)), zero));
    const V sHigh = hn::Sqrt(gmax(hn::Sub(one, hn::Mul(cHigh, cHigh)), zero));
    const V enough = hn::Mul(hn::Set(d, 0.9f), clearance);
    auto height = [&](V c, V s) {
        return hn::Sub(hn::Mul(hn::Mul(two, c), hn::Add(hn::Mul(s, wx), hn::Mul(c, wz))), wz);
    };
    const M useLow = hn::And(hn::Gt(cLow, nz), hn::Ge(height(cLow, sLow), enough));
    const M useHigh = hn::And(hn::Gt(cHigh, nz), hn::Ge(height(cHigh, sHigh), enough));
    V3 bent = select(useHigh, add(mul(x, sHigh), mul(g, cHigh)), g);
    bent = select(useLow, add(mul(x, sLow), mul(g, cLow)), bent);
    const M degenerate = hn::Not(hn::And(hn::Gt(xl, zero), hn::Gt(a, zero)));
    const V3 valid = select(clears, n, select(degenerate, g, bent));
    return select(hn::Gt(nz, zero), valid, g);
}
// Twin of offsetOrigin (shared/offset.h).
HWY_INLINE V3 offsetOrigin(V3 p, V3 ng, V offset, V3 dir) {
    const V side = sign(hn::Ge(dot(ng, dir), hn::Zero(D())));
    return add(p, mul(ng, hn::Mul(side, offset)));
}
// Twin of shadowLift (shared/offset.h).
HWY_INLINE V shadowLift(V3 ng, V lift, V3 dir, V tmax) {
    const V zero = hn::Zero(D());
    const M up = hn::And(hn::Gt(hn::Mul(dot(ng, dir), lift), zero), hn::Gt(tmax, zero));
    return hn::IfThenElseZero(up, gmin(hn::Abs(lift), hn::Mul(hn::Set(D(), 0.25f), tmax)));
}
// Twin of surfaceOffset (shared/offset.h).
HWY_INLINE V surfaceOffset(V3 p, V3 v0, V3 v1, V3 v2, V3 n) {
    const V3 m = gmax(gmax(abs(v0), abs(v1)), gmax(abs(v2), abs(p)));
    return hn::Add(hn::Mul(dot(m, abs(n)), hn::Set(D(), kOffsetRelative)),
                   hn::Set(D(), kOffsetAbsolute));
}
// Horner's step a z + b.
HWY_INLINE V horner(V a, V z, float b) {
    return hn::Add(hn::Mul(a, z), hn::Set(D(), b));
}
// Twin of sinQuarterPi (shared/sampling.h).
HWY_INLINE V sinQuarterPi(V x) {
    const V z = hn::Mul(x, x);
    const V p = horner(horner(hn::Set(D(), kSinS7), z, kSinS5), z, kSinS3);
    return hn::Add(hn::Mul(hn::Mul(p, z), x), x);
}
// Twin of cosQuarterPi (shared/sampling.h).
HWY_INLINE V cosQuarterPi(V x) {
    const D d;
    const V z = hn::Mul(x, x);
    const V p = horner(horner(hn::Set(d, kCosC8), z, kCosC6), z, kCosC4);
    return hn::Add(hn::Sub(hn::Mul(hn::Mul(p, z), z), hn::Mul(hn::Set(d, 0.5f), z)),
                   hn::Set(d, 1.0f));
}
// Twin of sampleCosineHemisphere (shared/sampling.h).
HWY_INLINE V3 sampleCosineHemisphere(V ux, V uy) {
    const D d;
    const V zero = hn::Zero(d), one = hn::Set(d, 1.0f);
    const V dx = hn::Sub(hn::Mul(hn::Set(d, 2.0f), ux), one);
    const V dy = hn::Sub(hn::Mul(hn::Set(d, 2.0f), uy), one);
    const M xMajor = hn::Gt(hn::Abs(dx), hn::Abs(dy));
    const V r = hn::IfThenElse(xMajor, dx, dy);
    const V theta = hn::Mul(hn::Set(d, kPi / 4.0f), hn::Div(hn::IfThenElse(xMajor, dy, dx), r));
    const V c = cosQuarterPi(theta), s = sinQuarterPi(theta);
    const V x = hn::Mul(r, hn::IfThenElse(xMajor, c, s));
    const V y = hn::Mul(r, hn::IfThenElse(xMajor, s, c));
    const V z = hn::Sqrt(gmax(zero, hn::Sub(hn::Sub(one, hn::Mul(x, x)), hn::Mul(y, y))));
    const M centre = hn::And(hn::Eq(dx, zero), hn::Eq(dy, zero));
    return select(centre, V3{zero, zero, one}, V3{x, y, z});
}
// Twin of makeFrame (shared/sampling.h).
HWY_INLINE void makeFrame(V3 n, V3& t, V3& b) {
    const V one = hn::Set(D(), 1.0f);
    const V s = sign(hn::Ge(n.z, hn::Zero(D())));
    const V a = hn::Div(hn::Set(D(), -1.0f), hn::Add(s, n.z));
    const V c = hn::Mul(hn::Mul(n.x, n.y), a);
    t = {hn::Add(one, hn::Mul(hn::Mul(hn::Mul(s, n.x), n.x), a)), hn::Mul(s, c),
         hn::Mul(hn::Neg(s), n.x)};
    b = {c, hn::Add(s, hn::Mul(hn::Mul(n.y, n.y), a)), hn::Neg(n.y)};
}
// Twin of toWorld (shared/sampling.h).
HWY_INLINE V3 toWorld(V3 local, V3 n) {
    V3 t, b;
    makeFrame(n, t, b);
    return add(add(mul(t, local.x), mul(b, local.y)), mul(n, local.z));
}

// --- triangle emitters (shared/light_sample.h, shared/offset.h) and Lambert (shared/lambert.h)
// -------

// Twin of emitterPoint (shared/light_sample.h) with sampleTriangle (shared/sampling.h) inlined.
HWY_INLINE V3 emitterPoint(V3 p0, V3 e1, V3 e2, V ux, V uy) {
    const V su = hn::Sqrt(ux);
    const V bx = hn::Sub(hn::Set(D(), 1.0f), su);
    const V by = hn::Mul(uy, su);
    return add(add(p0, mul(e1, bx)), mul(e2, by));
}
// Twin of emitterCosine (shared/light_sample.h).
HWY_INLINE V emitterCosine(V3 normal, M twoSided, V3 towardReceiver) {
    const V c = dot(normal, towardReceiver);
    return gmax(hn::IfThenElse(twoSided, hn::Abs(c), c), hn::Zero(D()));
}
// Twin of emitterSolidAnglePdf (shared/light_sample.h).
HWY_INLINE V emitterSolidAnglePdf(V pickPdf, V area, V dist, V cosLight) {
    return hn::IfThenZeroElse(
        hn::Le(cosLight, hn::Zero(D())),
        hn::Div(hn::Mul(pickPdf, hn::Mul(dist, dist)), hn::Mul(cosLight, area)));
}
// Twin of shadowRayTmax (shared/offset.h).
HWY_INLINE V shadowRayTmax(V dist, V offsetP, V offsetQ, V cosQ) {
    return hn::IfThenElseZero(hn::Gt(cosQ, hn::Zero(D())),
                              hn::Sub(hn::Mul(dist, hn::Set(D(), 1.0f - kOffsetRelative)),
                                      hn::Div(hn::Add(offsetP, offsetQ), cosQ)));
}
// Twin of lambertEval (shared/lambert.h), given dot(ng, wo) and facingShadingNormal's n.
HWY_INLINE V3 lambertEval(V3 albedo, V3 ng, V ngDotWo, V3 n, V3 wi, V& pdf) {
    const V zero = hn::Zero(D());
    const V c = dot(n, wi);
    const M evaluated =
        hn::And(hn::Not(hn::Le(hn::Mul(ngDotWo, dot(ng, wi)), zero)), hn::Not(hn::Le(c, zero)));
    const V cosPi = hn::Mul(c, hn::Set(D(), kInvPi));
    pdf = hn::IfThenElseZero(evaluated, cosPi);
    return select(evaluated, mul(albedo, cosPi), V3{zero, zero, zero});
}

// --- vectors as glm computes them, and libm's cos and sin
// -----------------------------------------

HWY_INLINE V3 cross(V3 a, V3 b) { // glm's order
    return {hn::Sub(hn::Mul(a.y, b.z), hn::Mul(b.y, a.z)),
            hn::Sub(hn::Mul(a.z, b.x), hn::Mul(b.z, a.x)),
            hn::Sub(hn::Mul(a.x, b.y), hn::Mul(b.x, a.y))};
}
// glm's normalize, v * inversesqrt(dot(v, v)), inversesqrt being 1 / sqrt.
HWY_INLINE V3 normalize(V3 v) {
    return mul(v, hn::Div(hn::Set(D(), 1.0f), hn::Sqrt(dot(v, v))));
}
HWY_INLINE M selectMask(M m, M a, M b) { // m ? a : b
    return hn::Or(hn::And(m, a), hn::AndNot(m, b));
}
// The scalar code's libm cos and sin, lane by lane: Highway's polynomials round differently.
HWY_INLINE void cosSin(V phi, V& c, V& s) {
    const D d;
    alignas(64) float x[simd::kMaxLanes], cs[simd::kMaxLanes], sn[simd::kMaxLanes];
    hn::Store(phi, d, x);
    for (size_t k = 0; k < hn::Lanes(d); ++k) {
        cs[k] = std::cos(x[k]);
        sn[k] = std::sin(x[k]);
    }
    c = hn::Load(d, cs);
    s = hn::Load(d, sn);
}

// --- rand4 (shared/rng.h) ----------------------------------------------------------------------
struct U4 {
    VU x, y, z, w;
};

HWY_INLINE VU loadU(const Uints& a, size_t i) {
    return hn::Load(DU(), a.v + i);
}
// Twin of pcg4d (shared/rng.h).
HWY_INLINE U4 pcg4d(U4 v) {
    const DU du;
    const VU mul = hn::Set(du, 1664525u), inc = hn::Set(du, 1013904223u);
    v = {hn::Add(hn::Mul(v.x, mul), inc), hn::Add(hn::Mul(v.y, mul), inc),
         hn::Add(hn::Mul(v.z, mul), inc), hn::Add(hn::Mul(v.w, mul), inc)};
    for (int round = 0; round < 2; ++round) {
        v.x = hn::Add(v.x, hn::Mul(v.y, v.w));
        v.y = hn::Add(v.y, hn::Mul(v.z, v.x));
        v.z = hn::Add(v.z, hn::Mul(v.x, v.y));
        v.w = hn::Add(v.w, hn::Mul(v.y, v.z));
        if (round == 0)
            v = {hn::Xor(v.x, hn::ShiftRight<16>(v.x)), hn::Xor(v.y, hn::ShiftRight<16>(v.y)),
                 hn::Xor(v.z, hn::ShiftRight<16>(v.z)), hn::Xor(v.w, hn::ShiftRight<16>(v.w))};
    }
    return v;
}
template <int kShift>
HWY_INLINE VU swapBits(VU x, std::uint32_t low) { // bits in `low` up kShift, the others down
    const DU du;
    return hn::Or(hn::ShiftLeft<kShift>(hn::And(x, hn::Set(du, low))),
                  hn::ShiftRight<kShift>(hn::And(x, hn::Set(du, ~low))));
}
HWY_INLINE VU bitfieldReverse(VU x) {
    x = hn::Or(hn::ShiftLeft<16>(x), hn::ShiftRight<16>(x));
    x = swapBits<8>(x, 0x00FF00FFu);
    x = swapBits<4>(x, 0x0F0F0F0Fu);
    x = swapBits<2>(x, 0x33333333u);
    return swapBits<1>(x, 0x55555555u);
}
// Twin of laineKarrasPermutation (shared/rng.h).
HWY_INLINE VU laineKarrasPermutation(VU x, VU seed) {
    const DU du;
    x = hn::Add(x, seed);
    for (std::uint32_t m : {0x6c50b47cu, 0xb82f1e52u, 0xc7afe638u, 0x8d22f6e6u})
        x = hn::Xor(x, hn::Mul(x, hn::Set(du, m)));
    return x;
}
// sobolReversedColumns (shared/rng.h): the XOR of the byte tables' entries for r's four bytes.
HWY_INLINE void sobolReversedColumns(VU r, VU& x, VU& y, VU& z) {
    const DU du;
    const hn::RebindToSigned<DU> di;
    const std::uint32_t* table = &kSobolByteTables.t[0][0].x;
    x = y = z = hn::Zero(du);
    for (int byte = 0; byte < 4; ++byte) {
        const VU value = hn::And(hn::ShiftRightSame(r, 8 * byte), hn::Set(du, 0xFFu));
        // uvec3 t[4][256]: entry (byte, value) starts at 3 (256 byte + value).
        const auto index = hn::BitCast(
            di, hn::Mul(hn::Add(value, hn::Set(du, 256u * std::uint32_t(byte))), hn::Set(du, 3u)));
        x = hn::Xor(x, hn::GatherIndex(du, table, index));
        y = hn::Xor(y, hn::GatherIndex(du, table + 1, index));
        z = hn::Xor(z, hn::GatherIndex(du, table + 2, index));
    }
}
// Twin of scrambledSobol4 (shared/rng.h).
HWY_INLINE U4 scrambledSobol4(VU sampleIndex, U4 key) {
    const U4 seeds = pcg4d(key);
    const VU shuffleSeed = hn::Xor(hn::Xor(seeds.x, seeds.y), hn::Xor(seeds.z, seeds.w));
    const VU r = laineKarrasPermutation(bitfieldReverse(sampleIndex), shuffleSeed);
    U4 x;
    x.x = bitfieldReverse(r);
    sobolReversedColumns(r, x.y, x.z, x.w);
    return {bitfieldReverse(laineKarrasPermutation(x.x, seeds.x)),
            bitfieldReverse(laineKarrasPermutation(x.y, seeds.y)),
            bitfieldReverse(laineKarrasPermutation(x.z, seeds.z)),
            bitfieldReverse(laineKarrasPermutation(x.w, seeds.w))};
}
// Twin of uintToUnit (shared/rng.h).
HWY_INLINE V uintToUnit(VU x) {
    const D d;
    const hn::RebindToSigned<D> di;
    return hn::Mul(hn::ConvertTo(d, hn::BitCast(di, hn::ShiftRight<8>(x))),
                   hn::Set(d, 1.0f / 16777216.0f));
}
// Twin of rand4 (shared/rng.h), before uintToUnit.
HWY_INLINE U4 rand4(uint sampling, uint seed, VU pixel, VU sampleIndex, VU bounce, uint group) {
    const DU du;
    const VU dimension = hn::Or(hn::ShiftLeft<8>(bounce), hn::Set(du, group));
    if (sampling == kSamplerSobol)
        return scrambledSobol4(
            hn::ShiftRight<1>(sampleIndex),
            {pixel, dimension, hn::Set(du, seed),
             hn::Add(hn::Set(du, 0x50B01u), hn::And(sampleIndex, hn::Set(du, 1u)))});
    return pcg4d({pixel, sampleIndex, dimension, hn::Set(du, seed)});
}

// --- the light tree (shared/light_tree.h) --------------------------------------------------------

// Twin of treeImportance (shared/light_tree.h), for node words gathered from `cdf` at `base`
// (each lane's treeNodeBase): every branch computed, the scalar's choices as masks.
HWY_INLINE V treeImportance(const float* cdf, hn::Vec<hn::RebindToSigned<D>> base, V3 p) {
    const D d;
    const hn::RebindToSigned<D> di;
    auto word = [&](int k) { return hn::GatherIndex(d, cdf, hn::Add(base, hn::Set(di, k))); };
    const V zero = hn::Zero(d), one = hn::Set(d, 1.0f);
    const V power = word(10);
    const V3 dv = sub(p, V3{word(0), word(1), word(2)});
    const V radius = word(3);
    const V r2 = hn::Mul(radius, radius);
    const V d2 = dot(dv, dv);
    const M outside = hn::Gt(d2, r2);
    const V3 axis{word(4), word(5), word(6)};
    const V cosO = word(7);
    const V invD = hn::Div(one, hn::Sqrt(d2)); // glm::inversesqrt
    V cosW = hn::Mul(dot(axis, dv), invD);
    const VU links = hn::BitCast(DU(), word(11));
    const M twoSided =
        hn::RebindMask(d, hn::Ne(hn::And(links, hn::Set(DU(), kTreeTwoSided)), hn::Zero(DU())));
    cosW = hn::IfThenElse(twoSided, hn::Abs(cosW), cosW);
    const M beyondCone = hn::Lt(cosW, cosO);
    const V sinO = word(8);
    const V sinW = hn::Sqrt(gmax(zero, hn::Sub(one, hn::Mul(cosW, cosW))));
    const V cosX = hn::Add(hn::Mul(cosW, cosO), hn::Mul(sinW, sinO));
    const V sinX = gmax(hn::Sub(hn::Mul(sinW, cosO), hn::Mul(cosW, sinO)), zero);
    const V sinB = gmin(hn::Mul(radius, invD), one);
    const V cosB = hn::Sqrt(gmax(zero, hn::Sub(one, hn::Mul(sinB, sinB))));
    const V cosCone =
        hn::IfThenElse(hn::Gt(cosX, cosB), one, hn::Add(hn::Mul(cosX, cosB), hn::Mul(sinX, sinB)));
    const V cosP = hn::IfThenElse(hn::And(outside, beyondCone), cosCone, one);
    const M none =
        hn::Or(hn::Not(hn::Gt(power, zero)), hn::And(outside, hn::Not(hn::Gt(cosP, word(9)))));
    const V importance = hn::Div(hn::Mul(power, cosP), gmax(gmax(d2, r2), hn::Set(d, 1e-30f)));
    return hn::IfThenZeroElse(none, importance);
}

// Twin of treePick's descent (shared/light_tree.h) for the lanes in `active`: from the root to a
// leaf, each lane with its own point p and number u. Out: the leaf reached (node; treeLeafPick
// takes it from there with the u and pmf left), or kTreeRoot where the scalar walk gives up
// (kNoEmitter: no child can reach p, or 64 levels).
HWY_INLINE void treeDescent(const float* cdf, uint nodesAt, V3 p, M active, VU& node, V& u,
                            V& pmf) {
    const D d;
    const DU du;
    const hn::RebindToSigned<D> di;
    const V one = hn::Set(d, 1.0f), last = hn::Set(d, kOneMinusEpsilon);
    auto base = [&](VU n) { // treeNodeBase
        return hn::BitCast(di,
                           hn::Add(hn::Set(du, nodesAt), hn::Mul(n, hn::Set(du, kTreeNodeWords))));
    };
    node = hn::Zero(du);
    pmf = one;
    M running = active;
    M failed = hn::Not(active);
    for (uint depth = 0u; depth < 64u && !hn::AllFalse(d, running); ++depth) {
        const VU links =
            hn::BitCast(du, hn::GatherIndex(d, cdf, hn::Add(base(node), hn::Set(di, 11))));
        const M leaf =
            hn::RebindMask(d, hn::Ne(hn::And(links, hn::Set(du, kTreeLeaf)), hn::Zero(du)));
        running = hn::AndNot(leaf, running);
        if (hn::AllFalse(d, running)) break;
        const VU runningBits = hn::BitCast(du, hn::VecFromMask(d, running));
        // Lanes that have stopped read the root's words: in range, their results unused.
        const VU first = hn::And(hn::Add(node, hn::Set(du, 1u)), runningBits);
        const VU second = hn::And(hn::And(links, hn::Set(du, kTreeIndex)), runningBits);
        const V i0 = treeImportance(cdf, base(first), p);
        const V i1 = treeImportance(cdf, base(second), p);
        const V sum = hn::Add(i0, i1);
        const M stuck = hn::AndNot(hn::Gt(sum, hn::Zero(d)), running);
        failed = hn::Or(failed, stuck);
        running = hn::AndNot(stuck, running);
        const V p0 = hn::Div(i0, sum);
        const M left = hn::Lt(u, p0);
        const V uLeft = gmin(hn::Div(u, p0), last);
        const V uRight = gmin(hn::Div(hn::Sub(u, p0), hn::Sub(one, p0)), last);
        const V pmfLeft = hn::Mul(pmf, p0), pmfRight = hn::Mul(pmf, hn::Div(i1, sum));
        u = hn::IfThenElse(running, hn::IfThenElse(left, uLeft, uRight), u);
        pmf = hn::IfThenElse(running, hn::IfThenElse(left, pmfLeft, pmfRight), pmf);
        const VU next = hn::IfThenElse(hn::RebindMask(du, left), first, second);
        node = hn::IfThenElse(hn::RebindMask(du, running), next, node);
    }
    failed = hn::Or(failed, running); // 64 levels without a leaf
    node = hn::IfThenElse(hn::RebindMask(du, failed), hn::Set(du, kTreeRoot), node);
}

} // namespace spw::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif // SPILLWAY_SIMD_MATH_INL_H_
