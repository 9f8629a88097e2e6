// bilinearInTile and blendLayers (wide_texels.h), compiled once per instruction set through
// foreach_target.h. They are TexelReader::bilinear (textures.cpp) and TexelReader::decode for
// 8-bit texels, and the Layered blend of TextureResolver::evaluate, lane by lane, in the same
// operations.
#include "host/textures/wide_texels.h"

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "host/textures/wide_texels.cpp"
#include <hwy/foreach_target.h> // must come before highway.h
#include <hwy/highway.h>

#include "host/simd/simd_math-inl.h" // D, DU, V, VU

#include <cstdint>

HWY_BEFORE_NAMESPACE();
namespace spw::HWY_NAMESPACE {
using DI = hn::RebindToSigned<D>;
using VI = hn::Vec<DI>;
using MI = hn::Mask<DI>;

// A coordinate's fraction (periodic), a NaN's read as 0: s - floor(s), then 0 unless in [0, 1].
HWY_INLINE V fraction(V s) {
    const D d;
    s = hn::Sub(s, hn::Floor(s));
    return hn::IfThenElseZero(hn::And(hn::Ge(s, hn::Zero(d)), hn::Le(s, hn::Set(d, 1.0f))), s);
}

// The texel indices i0 and i1 = i0 + 1 (wrapping to `first`) a bilinear filter reads along one
// axis of a level `size` texels long starting at `first`, and the weight of i1, for fraction f.
HWY_INLINE void axis(V f, int first, int size, VI& i0, VI& i1, V& weight) {
    const D d;
    const DI di;
    const V x = hn::Sub(hn::Mul(f, hn::Set(d, float(size))), hn::Set(d, 0.5f));
    const V floor = hn::Floor(x);
    weight = hn::Sub(x, floor);
    VI i = hn::ConvertTo(di, floor); // exact: an integer in [-1, size)
    i = hn::IfThenElse(hn::Lt(i, hn::Zero(di)), hn::Add(i, hn::Set(di, size)), i);
    i0 = hn::Add(i, hn::Set(di, first));
    const VI next = hn::Add(i0, hn::Set(di, 1));
    i1 = hn::IfThenElse(hn::Eq(next, hn::Set(di, first + size)), hn::Set(di, first), next);
}

HWY_INLINE MI within(VI i, int begin, int end) {
    const DI di;
    return hn::AndNot(hn::Lt(i, hn::Set(di, begin)), hn::Lt(i, hn::Set(di, end)));
}

struct Texel {
    V r, g, b;
};

// The texels at byte offsets `offset` of the tile (each within it), decoded. A texel is read as
// the 32-bit word holding its first byte, moved back where that word would pass the tile's end.
HWY_INLINE Texel fetch(const spw::TexelTile& tile, VI offset) {
    const D d;
    const DI di;
    const DU du;
    const VI start = hn::Min(offset, hn::Set(di, tile.bytes - 4));
    const VU shift = hn::BitCast(du, hn::ShiftLeft<3>(hn::Sub(offset, start)));
    const VU word =
        hn::BitCast(
            du, hn::GatherOffset(di, reinterpret_cast<const std::int32_t*>(tile.pixels), start)) >>
        shift;
    const VU byte = hn::Set(du, 0xFFu);
    auto channel = [&](VU bits) {
        return hn::GatherIndex(d, tile.decode, hn::BitCast(di, hn::And(bits, byte)));
    };
    const V r = channel(word);
    if (tile.channels == 1) return {r, r, r};
    const V g = channel(hn::ShiftRight<8>(word));
    if (tile.channels == 2) return {r, g, hn::Zero(d)};
    return {r, g, channel(hn::ShiftRight<16>(word))};
}

// a + w (b - a), per channel (glm's vec3 operations in its order).
HWY_INLINE Texel lerp(const Texel& a, const Texel& b, V w) {
    return {hn::Add(a.r, hn::Mul(w, hn::Sub(b.r, a.r))),
            hn::Add(a.g, hn::Mul(w, hn::Sub(b.g, a.g))),
            hn::Add(a.b, hn::Mul(w, hn::Sub(b.b, a.b)))};
}

void BilinearInTile(const spw::TexelTile& tile, const spw::TexelLevel& level, size_t count,
                    spw::TexelLanes& lanes) {
    const D d;
    const DI di;
    const DU du;
    for (size_t i = 0; i < count; i += hn::Lanes(d)) {
        VI x0, x1, y0, y1;
        V ax, ay;
        axis(fraction(hn::Load(d, lanes.s.v + i)), level.x, level.width, x0, x1, ax);
        axis(fraction(hn::Load(d, lanes.t.v + i)), level.y, level.height, y0, y1, ay);
        const MI in = hn::And(hn::And(within(x0, tile.x0, tile.x1), within(x1, tile.x0, tile.x1)),
                              hn::And(within(y0, tile.y0, tile.y1), within(y1, tile.y0, tile.y1)));
        hn::Store(hn::BitCast(du, hn::VecFromMask(di, in)), du, lanes.done.v + i);
        if (hn::AllFalse(di, in)) continue;
        // Byte offsets in the tile; lanes outside it read its first texel.
        const VI pixel = hn::Set(di, tile.pixelBytes), row = hn::Set(di, tile.rowBytes);
        const VI c0 = hn::Mul(hn::Sub(x0, hn::Set(di, tile.x0)), pixel),
                 c1 = hn::Mul(hn::Sub(x1, hn::Set(di, tile.x0)), pixel);
        const VI r0 = hn::Mul(hn::Sub(y0, hn::Set(di, tile.y0)), row),
                 r1 = hn::Mul(hn::Sub(y1, hn::Set(di, tile.y0)), row);
        const Texel a = fetch(tile, hn::IfThenElseZero(in, hn::Add(r0, c0)));
        const Texel b = fetch(tile, hn::IfThenElseZero(in, hn::Add(r0, c1)));
        const Texel c = fetch(tile, hn::IfThenElseZero(in, hn::Add(r1, c0)));
        const Texel e = fetch(tile, hn::IfThenElseZero(in, hn::Add(r1, c1)));
        const Texel value = lerp(lerp(a, b, ax), lerp(c, e, ax), ay);
        hn::Store(value.r, d, lanes.r.v + i);
        hn::Store(value.g, d, lanes.g.v + i);
        hn::Store(value.b, d, lanes.b.v + i);
    }
}

void BlendLayers(size_t count, const float* mask, const float* upper, const float* lower,
                 float* out) {
    const D d;
    const V one = hn::Set(d, 1.0f);
    size_t i = 0;
    for (; i + hn::Lanes(d) <= count; i += hn::Lanes(d)) {
        const V m = hn::LoadU(d, mask + i);
        hn::StoreU(hn::Add(hn::Mul(m, hn::LoadU(d, upper + i)),
                           hn::Mul(hn::Sub(one, m), hn::LoadU(d, lower + i))),
                   d, out + i);
    }
    for (; i < count; ++i)
        out[i] = mask[i] * upper[i] + (1.0f - mask[i]) * lower[i];
}

} // namespace spw::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace spw {
HWY_EXPORT(BilinearInTile);
HWY_EXPORT(BlendLayers);

void bilinearInTile(const TexelTile& tile, const TexelLevel& level, size_t count,
                    TexelLanes& lanes) {
    HWY_DYNAMIC_DISPATCH(BilinearInTile)(tile, level, count, lanes);
}

void blendLayers(size_t count, const float* mask, const float* upper, const float* lower,
                 float* out) {
    HWY_DYNAMIC_DISPATCH(BlendLayers)(count, mask, upper, lower, out);
}

} // namespace spw
#endif
