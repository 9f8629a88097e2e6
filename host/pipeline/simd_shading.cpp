// The SIMD Lambert kernel and the SIMD random numbers (simd_shading.h). Highway compiles the part
// between HWY_BEFORE_NAMESPACE and HWY_AFTER_NAMESPACE once per instruction set (this file includes
// itself through foreach_target.h) and picks the best the processor has at the first call.
//
// The kernel mirrors shadeSurface() (shared/path.h) for the Lambert model (shared/lambert.h)
// and triangle emitters line by line; each helper below names the shared function it stands for.
// glm's operations are written out in glm's order: dot is (x x' + y y') + z z', normalize is
// v * (1 / sqrt(dot(v, v))), max(a, b) is (a < b) ? b : a and min(a, b) is (b < a) ? b : a.
#include "host/pipeline/simd_shading.h"

#include "shared/path.h"

#include <algorithm>
#include <cstdint>
#include <cstring>

#ifndef SPILLWAY_SIMD_SHADING_LANES
#define SPILLWAY_SIMD_SHADING_LANES
namespace spw::simd_shading {

// Hits per pass through the kernel: a multiple of every vector width (16 floats for AVX-512).
constexpr size_t kBlock = 64;
constexpr size_t kMaxLanes = 16;

struct Floats {
    alignas(64) float v[kBlock];
};
struct Uints { // masks (all bits set, or none) and integers
    alignas(64) std::uint32_t v[kBlock];
};
struct Vec3s {
    Floats x, y, z;
};

// Every struct of lanes below is rows of kBlock 4-byte values and nothing else, so padding a
// block copies rows (padLanes).

// The random numbers of up to kBlock hits: what they are a function of, and what
// MakeRandomNumbers makes of it.
struct RandomLanes {
    Uints pixel, sampleIndex, bounce;
    Floats uLightX, uLightY, uLightZ, uLightW; // rand4(kDimLight)
    Floats uBsdfX, uBsdfY, uBsdfZ;             // rand4(kDimBsdf).xyz
};

// The kernel's inputs for up to kBlock Lambert hits.
struct LambertLanes {
    Vec3s p, ng, ns, albedo, wo, beta; // the hit, -rayDir, the path's throughput
    Floats offset;
    Uints live;     // bounce < max depth: the path goes on from here
    Uints roulette; // bounce >= min depth
    RandomLanes random;
    Vec3s e0, e1, e2, eNormal, eRadiance; // the picked emitter (a triangle)
    Floats ePickPdf, eArea;
    Uints eTwoSided;
};
static_assert(sizeof(LambertLanes) % sizeof(Floats) == 0, "rows only");
static_assert(sizeof(RandomLanes) % sizeof(Floats) == 0, "rows only");

// What the kernel writes; shadeHits() puts it into the ShadeResults.
struct LambertResults {
    Uints shadow, next; // kShadeShadow, kShadeContinue
    Vec3s shadowOrigin, shadowDir, shadowContribution, nextOrigin, nextDir, nextBeta;
    Floats shadowTmax, nextPdf;
};

} // namespace spw::simd_shading
#endif

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "host/pipeline/simd_shading.cpp"
#include <hwy/foreach_target.h> // must come before highway.h
#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace spw::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;
using D = hn::ScalableTag<float>;
using DU = hn::RebindToUnsigned<D>;
using V = hn::Vec<D>;
using M = hn::Mask<D>;
using simd_shading::Floats;
using simd_shading::Uints;
using simd_shading::Vec3s;

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
HWY_INLINE V maxComponent(V3 v) {
    return gmax(v.x, gmax(v.y, v.z));
}
HWY_INLINE V sign(M nonNegative) { // x >= 0 ? 1 : -1
    return hn::IfThenElse(nonNegative, hn::Set(D(), 1.0f), hn::Set(D(), -1.0f));
}
HWY_INLINE V quantizePdf(V pdf) {
    return hn::BitCast(D(), hn::And(hn::BitCast(DU(), pdf), hn::Set(DU(), 0xFFFF0000u)));
}
HWY_INLINE V powerHeuristic(V pdfThis, V pdfOther) {
    const V r = hn::Div(pdfOther, pdfThis);
    const V w = hn::Div(hn::Set(D(), 1.0f), hn::Add(hn::Set(D(), 1.0f), hn::Mul(r, r)));
    return hn::IfThenZeroElse(hn::Le(pdfThis, hn::Zero(D())), w);
}
HWY_INLINE V3 facingShadingNormal(V3 ns, V3 ng, V ngDotWo) {
    const V side = sign(hn::Ge(ngDotWo, hn::Zero(D())));
    const V3 n = mul(ns, side);
    const V3 g = mul(ng, side);
    return select(hn::Gt(dot(n, g), hn::Zero(D())), n, g);
}
HWY_INLINE V3 offsetOrigin(V3 p, V3 ng, V offset, V3 dir) {
    const V side = sign(hn::Ge(dot(ng, dir), hn::Zero(D())));
    return add(p, mul(ng, hn::Mul(side, offset)));
}
HWY_INLINE V surfaceOffset(V3 p, V3 v0, V3 v1, V3 v2, V3 n) {
    const V3 m = gmax(gmax(abs(v0), abs(v1)), gmax(abs(v2), abs(p)));
    return hn::Add(hn::Mul(dot(m, abs(n)), hn::Set(D(), kOffsetRelative)),
                   hn::Set(D(), kOffsetAbsolute));
}
// Horner's step a z + b.
HWY_INLINE V horner(V a, V z, float b) {
    return hn::Add(hn::Mul(a, z), hn::Set(D(), b));
}
HWY_INLINE V sinQuarterPi(V x) {
    const V z = hn::Mul(x, x);
    const V p = horner(horner(hn::Set(D(), kSinS7), z, kSinS5), z, kSinS3);
    return hn::Add(hn::Mul(hn::Mul(p, z), x), x);
}
HWY_INLINE V cosQuarterPi(V x) {
    const D d;
    const V z = hn::Mul(x, x);
    const V p = horner(horner(hn::Set(d, kCosC8), z, kCosC6), z, kCosC4);
    return hn::Add(hn::Sub(hn::Mul(hn::Mul(p, z), z), hn::Mul(hn::Set(d, 0.5f), z)),
                   hn::Set(d, 1.0f));
}
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
HWY_INLINE V3 toWorld(V3 local, V3 n) { // makeFrame, then local.x t + local.y b + local.z n
    const V one = hn::Set(D(), 1.0f);
    const V s = sign(hn::Ge(n.z, hn::Zero(D())));
    const V a = hn::Div(hn::Set(D(), -1.0f), hn::Add(s, n.z));
    const V c = hn::Mul(hn::Mul(n.x, n.y), a);
    const V3 t = {hn::Add(one, hn::Mul(hn::Mul(hn::Mul(s, n.x), n.x), a)), hn::Mul(s, c),
                  hn::Mul(hn::Neg(s), n.x)};
    const V3 b = {c, hn::Add(s, hn::Mul(hn::Mul(n.y, n.y), a)), hn::Neg(n.y)};
    return add(add(mul(t, local.x), mul(b, local.y)), mul(n, local.z));
}

// --- rand4 (shared/rng.h) ----------------------------------------------------------------------
using VU = hn::Vec<DU>;
struct U4 {
    VU x, y, z, w;
};

HWY_INLINE VU loadU(const Uints& a, size_t i) {
    return hn::Load(DU(), a.v + i);
}
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
HWY_INLINE VU laineKarrasPermutation(VU x, VU seed) {
    const DU du;
    x = hn::Add(x, seed);
    for (std::uint32_t m : {0x6c50b47cu, 0xb82f1e52u, 0xc7afe638u, 0x8d22f6e6u})
        x = hn::Xor(x, hn::Mul(x, hn::Set(du, m)));
    return x;
}
// sobolReversedColumns: the XOR of the byte tables' entries for r's four bytes.
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
HWY_INLINE V uintToUnit(VU x) {
    const D d;
    const hn::RebindToSigned<D> di;
    return hn::Mul(hn::ConvertTo(d, hn::BitCast(di, hn::ShiftRight<8>(x))),
                   hn::Set(d, 1.0f / 16777216.0f));
}
HWY_INLINE U4 rand4(uint sampling, uint seed, VU pixel, VU sampleIndex, VU bounce, uint group) {
    const DU du;
    const VU dimension = hn::Or(hn::ShiftLeft<8>(bounce), hn::Set(du, group));
    if (sampling == kSamplerSobol)
        return scrambledSobol4(sampleIndex,
                               {pixel, dimension, hn::Set(du, seed), hn::Set(du, 0x50B01u)});
    return pcg4d({pixel, sampleIndex, dimension, hn::Set(du, seed)});
}

// The lanes' rand4(kDimLight) and rand4(kDimBsdf).xyz, for lanes [0, count).
void MakeRandomNumbers(simd_shading::RandomLanes& lanes, size_t count, uint sampling, uint seed) {
    for (size_t i = 0; i < count; i += hn::Lanes(D())) {
        const VU pixel = loadU(lanes.pixel, i), sampleIndex = loadU(lanes.sampleIndex, i);
        const VU bounce = loadU(lanes.bounce, i);
        const U4 light = rand4(sampling, seed, pixel, sampleIndex, bounce, kDimLight);
        store(uintToUnit(light.x), lanes.uLightX, i);
        store(uintToUnit(light.y), lanes.uLightY, i);
        store(uintToUnit(light.z), lanes.uLightZ, i);
        store(uintToUnit(light.w), lanes.uLightW, i);
        const U4 bsdf = rand4(sampling, seed, pixel, sampleIndex, bounce, kDimBsdf);
        store(uintToUnit(bsdf.x), lanes.uBsdfX, i);
        store(uintToUnit(bsdf.y), lanes.uBsdfY, i);
        store(uintToUnit(bsdf.z), lanes.uBsdfZ, i);
    }
}

// rand4(sampling, seed, pixel[i], sampleIndex[i], bounce, group) for lanes [0, count).
void MakeRand4(const Uints& pixel, const Uints& sampleIndex, size_t count, uint sampling, uint seed,
               uint bounce, uint group, Floats& x, Floats& y, Floats& z, Floats& w) {
    const VU bounces = hn::Set(DU(), bounce);
    for (size_t i = 0; i < count; i += hn::Lanes(D())) {
        const U4 u = rand4(sampling, seed, loadU(pixel, i), loadU(sampleIndex, i), bounces, group);
        store(uintToUnit(u.x), x, i);
        store(uintToUnit(u.y), y, i);
        store(uintToUnit(u.z), z, i);
        store(uintToUnit(u.w), w, i);
    }
}

// Steps 2 and 3 of shadeSurface for lanes [0, count), count a multiple of the vector width.
void ShadeLambertLanes(const simd_shading::LambertLanes& in, size_t count, bool nee, bool mis,
                       float threshold, simd_shading::LambertResults& out) {
    const D d;
    const V zero = hn::Zero(d);
    const V one = hn::Set(d, 1.0f);
    const V invPi = hn::Set(d, kInvPi);
    for (size_t i = 0; i < count; i += hn::Lanes(d)) {
        const V3 p = load(in.p, i), ng = load(in.ng, i), ns = load(in.ns, i);
        const V3 albedo = load(in.albedo, i), wo = load(in.wo, i), beta = load(in.beta, i);
        const V offset = load(in.offset, i);
        const M live = loadMask(in.live, i);
        const V ngDotWo = dot(ng, wo);
        const V3 n = facingShadingNormal(ns, ng, ngDotWo);

        // 2. Next-event estimation toward a point of the picked triangle (sampleEmitter).
        M shadowing = hn::And(live, hn::MaskFromVec(nee ? hn::Not(zero) : zero));
        if (!hn::AllFalse(d, shadowing)) {
            const V3 e0 = load(in.e0, i), e1 = load(in.e1, i), e2 = load(in.e2, i);
            const V3 eNormal = load(in.eNormal, i);
            const V su = hn::Sqrt(load(in.random.uLightY, i)); // sampleTriangle
            const V bx = hn::Sub(one, su);
            const V by = hn::Mul(load(in.random.uLightZ, i), su);
            const V3 q = add(add(e0, mul(e1, bx)), mul(e2, by)); // emitterPoint
            const V3 dq = sub(q, p);
            const V dist = hn::Sqrt(dot(dq, dq));
            const V3 wi = div(dq, dist);
            V c = dot(eNormal, neg(wi)); // emitterCosine
            c = hn::IfThenElse(loadMask(in.eTwoSided, i), hn::Abs(c), c);
            const V cosLight = gmax(c, zero);
            const M facing = hn::Gt(cosLight, zero);
            const V pdf = hn::IfThenElseZero( // emitterSolidAnglePdf
                facing, hn::Div(hn::Mul(load(in.ePickPdf, i), hn::Mul(dist, dist)),
                                hn::Mul(cosLight, load(in.eArea, i))));
            const V offsetQ = surfaceOffset(q, e0, add(e0, e1), add(e0, e2), eNormal);
            const V tmax = hn::IfThenElseZero( // shadowRayTmax
                facing, hn::Sub(hn::Mul(dist, hn::Set(d, 1.0f - kOffsetRelative)),
                                hn::Div(hn::Add(offset, offsetQ), cosLight)));
            shadowing = hn::And(shadowing, hn::And(hn::Gt(dist, zero), hn::Gt(pdf, zero)));

            // lambertEval
            const V c2 = dot(n, wi);
            const M evaluated = hn::And(hn::Not(hn::Le(hn::Mul(ngDotWo, dot(ng, wi)), zero)),
                                        hn::Not(hn::Le(c2, zero)));
            const V cosPi = hn::Mul(c2, invPi);
            const V bsdfPdf = hn::IfThenElseZero(evaluated, cosPi);
            const V3 fcos = select(evaluated, mul(albedo, cosPi), V3{zero, zero, zero});
            shadowing = hn::And(shadowing, hn::Gt(maxComponent(fcos), zero));

            const V w = mis ? powerHeuristic(pdf, quantizePdf(bsdfPdf)) : one;
            const V3 radiance = load(in.eRadiance, i);
            store(shadowing, offsetOrigin(p, ng, offset, wi), out.shadowOrigin, i);
            store(shadowing, wi, out.shadowDir, i);
            store(hn::IfThenElseZero(shadowing, tmax), out.shadowTmax, i);
            store(shadowing, mul(mul(mul(beta, fcos), radiance), hn::Div(w, pdf)),
                  out.shadowContribution, i);
            shadowing = hn::And(shadowing, hn::Gt(tmax, zero));
        } else {
            const V3 none = {zero, zero, zero};
            store(shadowing, none, out.shadowOrigin, i);
            store(shadowing, none, out.shadowDir, i);
            store(zero, out.shadowTmax, i);
            store(shadowing, none, out.shadowContribution, i);
        }
        store(shadowing, out.shadow, i);

        // 3. Continuation: lambertSample, then Russian roulette.
        const V3 local =
            sampleCosineHemisphere(load(in.random.uBsdfX, i), load(in.random.uBsdfY, i));
        const V3 world = toWorld(local, n);
        const V3 wi = mul(world, hn::Div(one, hn::Sqrt(dot(world, world))));
        M next = hn::And(live, hn::Not(hn::Or(hn::Le(hn::Mul(ngDotWo, dot(ng, wi)), zero),
                                              hn::Le(local.z, zero))));
        V3 nextBeta = mul(beta, albedo);
        const V q = gmin(one, hn::Div(maxComponent(nextBeta), hn::Set(d, threshold)));
        const M roulette = loadMask(in.roulette, i);
        next = hn::And(next, hn::Or(hn::Not(roulette), hn::Lt(load(in.random.uLightW, i), q)));
        nextBeta = select(roulette, div(nextBeta, q), nextBeta);
        next = hn::And(next, hn::Gt(maxComponent(nextBeta), zero));
        store(next, out.next, i);
        store(next, offsetOrigin(p, ng, offset, wi), out.nextOrigin, i);
        store(next, wi, out.nextDir, i);
        store(next, nextBeta, out.nextBeta, i);
        store(hn::IfThenElseZero(next, quantizePdf(hn::Mul(local.z, invPi))), out.nextPdf, i);
    }
}

const char* TargetName() {
    return hwy::TargetName(HWY_TARGET);
}

} // namespace spw::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace spw {
HWY_EXPORT(ShadeLambertLanes);
HWY_EXPORT(MakeRandomNumbers);
HWY_EXPORT(MakeRand4);
HWY_EXPORT(TargetName);

using simd_shading::kBlock;
using simd_shading::kMaxLanes;
using simd_shading::LambertLanes;
using simd_shading::LambertResults;

namespace {

void set(simd_shading::Vec3s& a, size_t k, vec3 v) {
    a.x.v[k] = v.x;
    a.y.v[k] = v.y;
    a.z.v[k] = v.z;
}
vec3 get(const simd_shading::Vec3s& a, size_t k) {
    return vec3(a.x.v[k], a.y.v[k], a.z.v[k]);
}
std::uint32_t mask(bool b) {
    return b ? ~0u : 0u;
}
// Lanes [0, count) rounded up to whole vectors of the widest instruction set.
size_t wholeVectors(size_t count) {
    return (count + kMaxLanes - 1) / kMaxLanes * kMaxLanes;
}

// Lane k of `lanes`: what path st's random numbers at this bounce are a function of.
void setRandomLane(const RenderParams& rp, const PathState& st, simd_shading::RandomLanes& lanes,
                   size_t k) {
    lanes.pixel.v[k] = pathPixel(rp, st.pathId);
    lanes.sampleIndex.v[k] = pathSample(rp, st.pathId);
    lanes.bounce.v[k] = st.bounce;
}

// Lane k from hit `in`: what the kernel reads, and (scalar) the emission into `out`.
void fillLane(const SceneView& scene, const RenderParams& rp, const ShadeInput& in,
              LambertLanes& lanes, size_t k, ShadeResult& out) {
    const SurfaceHit& hit = in.hit;
    const PathState& st = in.path;
    const vec3 wo = -in.rayDir;
    out.flags = 0u;
    out.emitted = vec3(0.0f);
    addEmission(scene, rp, hit, wo, st, out);
    set(lanes.p, k, hit.p);
    set(lanes.ng, k, hit.ng);
    set(lanes.ns, k, hit.ns);
    set(lanes.albedo, k, hit.albedo);
    set(lanes.wo, k, wo);
    set(lanes.beta, k, st.beta);
    lanes.offset.v[k] = hit.offset;
    const bool live = st.bounce < rp.maxDepth;
    lanes.live.v[k] = mask(live);
    lanes.roulette.v[k] = mask(st.bounce >= rp.minDepth);
    setRandomLane(rp, st, lanes.random, k);
}

// Lane k's emitter, picked with the random number MakeRandomNumbers made (zeros where the path ends
// here or nothing is sampled, so that the kernel reads defined values).
void pickLaneEmitter(const SceneView& scene, const RenderParams& rp, bool nee, LambertLanes& lanes,
                     size_t k) {
    static const Emitter kNone{};
    const Emitter& e =
        nee && lanes.live.v[k] != 0u
            ? scene.emitters[pickEmitter(scene, rp.emitterCount, lanes.random.uLightX.v[k])]
            : kNone;
    set(lanes.e0, k, e.p0);
    set(lanes.e1, k, e.e1);
    set(lanes.e2, k, e.e2);
    set(lanes.eNormal, k, e.normal);
    set(lanes.eRadiance, k, e.radiance);
    lanes.ePickPdf.v[k] = e.pickPdf;
    lanes.eArea.v[k] = e.area;
    lanes.eTwoSided.v[k] = mask(e.twoSided != 0u);
}

// Lanes [count, end) copies of lane 0, so that whole vectors read defined values.
template <class Lanes> void padLanes(Lanes& lanes, size_t count, size_t end) {
    auto* rows = reinterpret_cast<unsigned char*>(&lanes);
    for (size_t row = 0; row < sizeof(Lanes); row += sizeof(simd_shading::Floats))
        for (size_t k = count; k < end; ++k)
            std::memcpy(rows + row + 4 * k, rows + row, 4);
}

// The kernel's results for lane k into `out` (whose emission fillLane wrote).
void takeLane(const ShaderParams& sh, const LambertResults& res, size_t k, const ShadeInput& in,
              ShadeResult& out) {
    const PathState& st = in.path;
    out.shadowOrigin = get(res.shadowOrigin, k);
    out.shadowDir = get(res.shadowDir, k);
    out.shadowTmax = res.shadowTmax.v[k];
    out.shadowContribution = get(res.shadowContribution, k);
    out.nextOrigin = get(res.nextOrigin, k);
    out.nextDir = get(res.nextDir, k);
    out.next = st;
    if (res.shadow.v[k]) out.flags |= kShadeShadow;
    if (!res.next.v[k]) return;
    out.next.beta = get(res.nextBeta, k);
    out.next.prevPdf = res.nextPdf.v[k];
    out.next.bounce = st.bounce + 1u;
    out.next.flags = 0u;
    out.next.cone =
        packCone(coneWidthAt(st.cone, in.hit.t), coneSpread(st.cone) + bsdfConeSpread(sh, false));
    out.flags |= kShadeContinue;
}

} // namespace

bool simdShadingApplies(const SceneView& view) {
    for (uint i = 0; i < view.emitterCount; ++i)
        if (view.emitters[i].type != kEmitterTriangle) return false;
    return true;
}

void shadeHits(const SceneView& view, const RenderParams& rp, bool simd, const ShadeInput* in,
               size_t n, ShadeResult* out) {
    if (!simd) {
        for (size_t i = 0; i < n; ++i)
            shadeSurface(view, rp, in[i].hit, in[i].rayDir, in[i].path, out[i]);
        return;
    }
    const bool nee = rp.emitterCount > 0u && rp.strategy != kStrategyBsdf;
    const bool mis = rp.strategy == kStrategyMis;
    // The other models' hits that go on: shadeSurface with their random numbers made here.
    simd_shading::RandomLanes others;
    std::uint32_t otherOf[kBlock];
    size_t otherCount = 0;
    auto runOthers = [&] {
        const size_t end = wholeVectors(otherCount);
        padLanes(others, otherCount, end);
        HWY_DYNAMIC_DISPATCH(MakeRandomNumbers)(others, end, rp.sampling, rp.seed);
        for (size_t k = 0; k < otherCount; ++k) {
            const ShadeInput& hit = in[otherOf[k]];
            const vec4 uLight(others.uLightX.v[k], others.uLightY.v[k], others.uLightZ.v[k],
                              others.uLightW.v[k]);
            const vec4 uBsdf(others.uBsdfX.v[k], others.uBsdfY.v[k], others.uBsdfZ.v[k], 0.0f);
            shadeSurfaceWith(view, rp, hit.hit, hit.rayDir, hit.path, uLight, uBsdf,
                             out[otherOf[k]]);
        }
        otherCount = 0;
    };
    LambertLanes lanes;
    LambertResults results;
    std::uint32_t hitOf[kBlock];
    size_t count = 0;
    auto run = [&] {
        const size_t end = wholeVectors(count);
        padLanes(lanes, count, end);
        HWY_DYNAMIC_DISPATCH(MakeRandomNumbers)(lanes.random, end, rp.sampling, rp.seed);
        for (size_t k = 0; k < end; ++k)
            pickLaneEmitter(view, rp, nee, lanes, k);
        HWY_DYNAMIC_DISPATCH(ShadeLambertLanes)(lanes, end, nee, mis, rp.threshold, results);
        for (size_t k = 0; k < count; ++k) {
            const ShadeInput& hit = in[hitOf[k]];
            takeLane(view.shaders[hit.hit.shader], results, k, hit, out[hitOf[k]]);
        }
        count = 0;
    };
    for (size_t i = 0; i < n; ++i) {
        const ShaderParams& sh = view.shaders[in[i].hit.shader];
        if (sh.model != kModelLambert) {
            if (!shadeGoesOn(rp, sh, in[i].path)) {
                shadeSurfaceWith(view, rp, in[i].hit, in[i].rayDir, in[i].path, vec4(0.0f),
                                 vec4(0.0f), out[i]);
                continue;
            }
            setRandomLane(rp, in[i].path, others, otherCount);
            otherOf[otherCount++] = std::uint32_t(i);
            if (otherCount == kBlock) runOthers();
            continue;
        }
        fillLane(view, rp, in[i], lanes, count, out[i]);
        hitOf[count++] = std::uint32_t(i);
        if (count == kBlock) run();
    }
    if (count > 0) run();
    if (otherCount > 0) runOthers();
}

void rand4Many(uint sampling, uint seed, uint bounce, uint group, const uint* pixel,
               const uint* sampleIndex, size_t n, vec4* out) {
    simd_shading::Uints pixels, samples;
    simd_shading::Floats x, y, z, w;
    for (size_t begin = 0; begin < n; begin += kBlock) {
        const size_t count = std::min(kBlock, n - begin);
        const size_t end = wholeVectors(count);
        for (size_t k = 0; k < end; ++k) { // the padding repeats the last lane
            pixels.v[k] = pixel[begin + std::min(k, count - 1)];
            samples.v[k] = sampleIndex[begin + std::min(k, count - 1)];
        }
        HWY_DYNAMIC_DISPATCH(MakeRand4)
        (pixels, samples, end, sampling, seed, bounce, group, x, y, z, w);
        for (size_t k = 0; k < count; ++k)
            out[begin + k] = vec4(x.v[k], y.v[k], z.v[k], w.v[k]);
    }
}

const char* simdShadingTarget() {
    return HWY_DYNAMIC_DISPATCH(TargetName)();
}

} // namespace spw
#endif
