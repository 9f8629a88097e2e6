// encodeCompactBlock and decodeCompactBlock (ray_record.h): a block of compact records made and
// read with their arithmetic SIMD-wide, compiled once per instruction set through
// foreach_target.h. Each step is the scalar code's (ray_record.cpp: octEncode and octDecode in
// double, toBfloat16, cardinalBin; compactRounding), in the same order and rounding, so the
// bytes and rays are the same (CompactRay.BlockEncodingIsEncodeRayByteForByte,
// CompactRay.BlockDecodingIsDecodeRayBitForBit).
#include "host/pipeline/ray_record.h"

#include "host/pipeline/record_bytes.h"

#include "host/simd/lanes.h"

#include <algorithm>
#include <cstring>

#ifndef SPILLWAY_COMPACT_RAY_LANES
#define SPILLWAY_COMPACT_RAY_LANES
namespace spw::compact_lanes {
using simd::Floats;
using simd::Uints;
using simd::Vec3s;

// The block's rays as the arithmetic reads them, and what it makes of them.
struct CompactLanes {
    Vec3s dir, beta;
    Floats prevPdf;
    Uints pixel, sampleIndex, bounce; // the rounding's key (compactRounding)
    Uints u, v;                       // the octahedral grid cell
    Uints betaX, betaY, betaZ, pdf;   // bfloat16 bits
    Uints bin;                        // cardinalBin
};
// A block of records' octahedral cells, and the directions decoded from them.
struct DirectionLanes {
    Uints u, v;
    Vec3s dir;
};
} // namespace spw::compact_lanes
#endif

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "host/pipeline/ray_record_wide.cpp"
#include <hwy/foreach_target.h> // must come before highway.h
#include <hwy/highway.h>

#include "host/simd/simd_math-inl.h"

HWY_BEFORE_NAMESPACE();
namespace spw::HWY_NAMESPACE {
using compact_lanes::CompactLanes;
using compact_lanes::DirectionLanes;

// Twin of toBfloat16: the top half of f's bits, rounded up with probability (dropped bits /
// 2^16) by `random`, never into Inf/NaN.
HWY_INLINE VU toBfloat16(V f, VU random) {
    const DU du;
    const VU bits = hn::BitCast(du, f);
    const VU hi = hn::ShiftRight<16>(bits), lo = hn::And(bits, hn::Set(du, 0xFFFFu));
    const VU exponent = hn::Set(du, 0x7F80u);
    const auto up = hn::And(hn::Lt(hn::And(random, hn::Set(du, 0xFFFFu)), lo),
                            hn::Ne(hn::And(hi, exponent), exponent));
    return hn::Add(hi, hn::IfThenElseZero(up, hn::Set(du, 1u)));
}

// Twin of cardinalBin (ray_record.h).
HWY_INLINE VU cardinalBin(V3 d) {
    const DU du;
    const V3 a = abs(d);
    const V zero = hn::Zero(D());
    const M x = hn::And(hn::Ge(a.x, a.y), hn::Ge(a.x, a.z));
    const M y = hn::AndNot(x, hn::Ge(a.y, a.z));
    const M z = hn::Not(hn::Or(x, y));
    const M negative = hn::Or(
        hn::Or(hn::And(x, hn::Not(hn::Ge(d.x, zero))), hn::And(y, hn::Not(hn::Ge(d.y, zero)))),
        hn::And(z, hn::Not(hn::Ge(d.z, zero))));
    const VU one = hn::Set(du, 1u);
    const VU yBit = hn::BitCast(du, hn::IfThenElseZero(y, hn::BitCast(D(), one)));
    const VU zBit = hn::BitCast(du, hn::IfThenElseZero(z, hn::BitCast(D(), one)));
    const VU negBit = hn::BitCast(du, hn::IfThenElseZero(negative, hn::BitCast(D(), one)));
    // 2 (y + 2 z) + negative
    return hn::Add(hn::ShiftLeft<1>(hn::Add(yBit, hn::ShiftLeft<1>(zBit))), negBit);
}

// Twin of octEncode (ray_record.cpp), in double, for the rays from i on: a vector of doubles
// holds half as many lanes as one of floats.
HWY_INLINE void octEncodeLanes(CompactLanes& l, size_t i) {
    const hn::ScalableTag<double> dd;
    const hn::Rebind<float, decltype(dd)> df;
    const hn::Rebind<std::int32_t, decltype(dd)> di;
    using VD = hn::Vec<decltype(dd)>;
    const VD x = hn::PromoteTo(dd, hn::Load(df, l.dir.x.v + i));
    const VD y = hn::PromoteTo(dd, hn::Load(df, l.dir.y.v + i));
    const VD z = hn::PromoteTo(dd, hn::Load(df, l.dir.z.v + i));
    const VD zero = hn::Zero(dd), one = hn::Set(dd, 1.0), half = hn::Set(dd, 0.5);
    const VD inv = hn::Div(one, hn::Add(hn::Add(hn::Abs(x), hn::Abs(y)), hn::Abs(z)));
    const VD px = hn::Mul(x, inv), py = hn::Mul(y, inv);
    // octahedralFold: signOf(s, a) flips a's sign where !(s >= 0)
    const VD fx = hn::Sub(one, hn::Abs(py)), fy = hn::Sub(one, hn::Abs(px));
    const VD foldX = hn::IfThenElse(hn::Not(hn::Ge(px, zero)), hn::Neg(fx), fx);
    const VD foldY = hn::IfThenElse(hn::Not(hn::Ge(py, zero)), hn::Neg(fy), fy);
    const auto lower = hn::Lt(z, zero);
    const VD ox = hn::IfThenElse(lower, foldX, px), oy = hn::IfThenElse(lower, foldY, py);
    const VD scale = hn::Set(dd, double((1u << 24) - 1));
    auto cell = [&](VD p) { // uint((p * 0.5 + 0.5) * kOctScale + 0.5), truncated
        return hn::DemoteTo(di, hn::Add(hn::Mul(hn::Add(hn::Mul(p, half), half), scale), half));
    };
    const hn::Rebind<std::uint32_t, decltype(dd)> du;
    hn::Store(hn::BitCast(du, cell(ox)), du, l.u.v + i);
    hn::Store(hn::BitCast(du, cell(oy)), du, l.v.v + i);
}

void EncodeCompactLanes(CompactLanes& l, size_t count, uint seed) {
    const DU du;
    for (size_t i = 0; i < count; i += hn::Lanes(D())) {
        const VU dimension =
            hn::Or(hn::ShiftLeft<8>(loadU(l.bounce, i)), hn::Set(du, kDimRounding));
        const VU random =
            pcg4d({loadU(l.pixel, i), loadU(l.sampleIndex, i), dimension, hn::Set(du, seed)}).x;
        hn::Store(toBfloat16(load(l.beta.x, i), random), du, l.betaX.v + i);
        hn::Store(toBfloat16(load(l.beta.y, i), random), du, l.betaY.v + i);
        hn::Store(toBfloat16(load(l.beta.z, i), random), du, l.betaZ.v + i);
        hn::Store(hn::ShiftRight<16>(hn::BitCast(du, load(l.prevPdf, i))), du, l.pdf.v + i);
        hn::Store(cardinalBin(load(l.dir, i)), du, l.bin.v + i);
    }
    const size_t doubles = hn::Lanes(hn::ScalableTag<double>());
    for (size_t i = 0; i < count; i += doubles)
        octEncodeLanes(l, i);
}

// Twin of octDecode (ray_record.cpp), in double.
void DecodeDirectionLanes(DirectionLanes& l, size_t count) {
    const hn::ScalableTag<double> dd;
    const hn::Rebind<float, decltype(dd)> df;
    const hn::Rebind<std::int32_t, decltype(dd)> di;
    using VD = hn::Vec<decltype(dd)>;
    const VD zero = hn::Zero(dd), one = hn::Set(dd, 1.0);
    const VD toUnit = hn::Set(dd, 2.0 / double((1u << 24) - 1));
    for (size_t i = 0; i < count; i += hn::Lanes(dd)) {
        auto coordinate = [&](const Uints& cell) { // double(cell) * kToUnit - 1.0
            const VD c = hn::PromoteTo(
                dd,
                hn::BitCast(di, hn::Load(hn::Rebind<std::uint32_t, decltype(dd)>(), cell.v + i)));
            return hn::Sub(hn::Mul(c, toUnit), one);
        };
        VD px = coordinate(l.u), py = coordinate(l.v);
        const VD z = hn::Sub(hn::Sub(one, hn::Abs(px)), hn::Abs(py));
        const VD fx = hn::Sub(one, hn::Abs(py)), fy = hn::Sub(one, hn::Abs(px));
        const VD foldX = hn::IfThenElse(hn::Not(hn::Ge(px, zero)), hn::Neg(fx), fx);
        const VD foldY = hn::IfThenElse(hn::Not(hn::Ge(py, zero)), hn::Neg(fy), fy);
        const auto lower = hn::Lt(z, zero);
        px = hn::IfThenElse(lower, foldX, px);
        py = hn::IfThenElse(lower, foldY, py);
        const VD inv = hn::Div(
            one, hn::Sqrt(hn::Add(hn::Add(hn::Mul(px, px), hn::Mul(py, py)), hn::Mul(z, z))));
        hn::Store(hn::DemoteTo(df, hn::Mul(px, inv)), df, l.dir.x.v + i);
        hn::Store(hn::DemoteTo(df, hn::Mul(py, inv)), df, l.dir.y.v + i);
        hn::Store(hn::DemoteTo(df, hn::Mul(z, inv)), df, l.dir.z.v + i);
    }
}

} // namespace spw::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace spw {
HWY_EXPORT(EncodeCompactLanes);
HWY_EXPORT(DecodeDirectionLanes);

using namespace record_bytes;

void encodeCompactBlock(const RenderParams& rp, const ShadeResult* const* res, size_t n,
                        std::uint8_t* out, std::uint8_t* bin) {
    compact_lanes::CompactLanes l;
    const size_t end = simd::wholeVectors(n);
    for (size_t k = 0; k < end; ++k) { // the padding repeats the last ray
        const ShadeResult& r = *res[std::min(k, n - 1)];
        l.dir.x.v[k] = r.nextDir.x, l.dir.y.v[k] = r.nextDir.y, l.dir.z.v[k] = r.nextDir.z;
        l.beta.x.v[k] = r.next.beta.x, l.beta.y.v[k] = r.next.beta.y;
        l.beta.z.v[k] = r.next.beta.z;
        l.prevPdf.v[k] = r.next.prevPdf;
        l.pixel.v[k] = pathPixel(rp, r.next.pathId);
        l.sampleIndex.v[k] = pathSample(rp, r.next.pathId);
        l.bounce.v[k] = r.next.bounce;
    }
    HWY_DYNAMIC_DISPATCH(EncodeCompactLanes)(l, end, rp.seed);
    for (size_t k = 0; k < n; ++k) { // the record's layout: ray_record.h, encodeRay
        const ShadeResult& r = *res[k];
        std::uint8_t* p = out + k * kCompactRayBytes;
        put(p, r.nextOrigin.x), put(p, r.nextOrigin.y), put(p, r.nextOrigin.z);
        put(p, r.next.pathId);
        put24(p, l.u.v[k]);
        put24(p + 3, l.v.v[k]);
        p += 6;
        put(p, std::uint16_t(l.betaX.v[k])), put(p, std::uint16_t(l.betaY.v[k]));
        put(p, std::uint16_t(l.betaZ.v[k])), put(p, std::uint16_t(l.pdf.v[k]));
        put(p, compactBounce(r.next));
        put(p, std::uint16_t(r.next.cone));
        bin[k] = std::uint8_t(l.bin.v[k]);
    }
}

void decodeCompactBlock(const std::uint8_t* in, size_t n, RayState* out) {
    compact_lanes::DirectionLanes l;
    constexpr size_t kCellAt = 16; // origin, pathId, then the two 24-bit cells
    const size_t end = simd::wholeVectors(n);
    for (size_t k = 0; k < end; ++k) { // the padding repeats the last ray
        const std::uint8_t* p = in + std::min(k, n - 1) * kCompactRayBytes + kCellAt;
        l.u.v[k] = get24(p);
        l.v.v[k] = get24(p + 3);
    }
    HWY_DYNAMIC_DISPATCH(DecodeDirectionLanes)(l, end);
    for (size_t k = 0; k < n; ++k) { // the record's layout: ray_record.h, decodeRay
        const std::uint8_t* p = in + k * kCompactRayBytes;
        RayState& r = out[k];
        r.origin.x = get<float>(p), r.origin.y = get<float>(p), r.origin.z = get<float>(p);
        r.path.pathId = get<std::uint32_t>(p);
        p += 6;
        r.dir = vec3(l.dir.x.v[k], l.dir.y.v[k], l.dir.z.v[k]);
        r.path.beta.x = fromBfloat16(get<std::uint16_t>(p));
        r.path.beta.y = fromBfloat16(get<std::uint16_t>(p));
        r.path.beta.z = fromBfloat16(get<std::uint16_t>(p));
        r.path.prevPdf = fromBfloat16(get<std::uint16_t>(p));
        const std::uint16_t bf = get<std::uint16_t>(p);
        r.path.bounce = bf & 0x7FFFu;
        r.path.flags = (bf & 0x8000u) ? kPathSpecular : 0u;
        r.path.cone = get<std::uint16_t>(p);
    }
}

} // namespace spw
#endif
