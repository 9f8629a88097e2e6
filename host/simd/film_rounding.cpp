// roundFootprint (film_rounding.h), compiled once per instruction set through foreach_target.h.
#include "host/simd/film_rounding.h"

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "host/simd/film_rounding.cpp"
#include <hwy/foreach_target.h> // must come before highway.h
#include <hwy/highway.h>

#include "host/simd/simd_math-inl.h"

HWY_BEFORE_NAMESPACE();
namespace spw::HWY_NAMESPACE {

using DD = hn::ScalableTag<double>;
using VD = hn::Vec<DD>;
using DI64 = hn::RebindToSigned<DD>;
using DHalf = hn::Rebind<float, DD>; // as many floats as a vector has doubles

// Film::quantize: v clamped to +-maxAdd (counted), then floor(v) plus one with probability
// frac(v), decided by u (uintToUnit of a hash) against the fraction.
HWY_INLINE void quantize(VD v, VD u, VD maxAdd, std::int64_t* out, size_t& saturated) {
    const DD dd;
    const auto over = hn::Gt(hn::Abs(v), maxAdd);
    saturated += hn::CountTrue(dd, over);
    v = hn::IfThenElse(over, hn::CopySign(maxAdd, v), v);
    const VD floor = hn::Floor(v);
    const DI64 di;
    const auto up = hn::RebindMask(di, hn::Lt(u, hn::Sub(v, floor)));
    hn::Store(hn::Sub(hn::ConvertTo(di, floor), hn::VecFromMask(di, up)), di, out);
}

size_t RoundFootprint(const FootprintLanes& lanes, size_t count, double weightScale, double maxAdd,
                      FootprintAdds& adds) {
    const DU du;
    simd::Floats uw, ur, ug, ub; // the lanes' random numbers in [0, 1)
    const VU c0 = hn::Set(du, 0x5157u), c1 = hn::Set(du, 0x9E3779B9u);
    for (size_t i = 0; i < count; i += hn::Lanes(du)) {
        const VU pixel = loadU(lanes.pixel, i);
        store(uintToUnit(pcg4d({loadU(lanes.weightKey, i), pixel, c0, c1}).w), uw, i);
        const U4 h = pcg4d({loadU(lanes.rgbKey, i), pixel, c0, c1});
        store(uintToUnit(h.x), ur, i);
        store(uintToUnit(h.y), ug, i);
        store(uintToUnit(h.z), ub, i);
    }
    const DD dd;
    const DHalf dh;
    const VD scale = hn::Set(dd, weightScale), limit = hn::Set(dd, maxAdd);
    size_t saturated = 0;
    for (size_t i = 0; i < count; i += hn::Lanes(dd)) {
        auto unit = [&](const simd::Floats& u) { return hn::PromoteTo(dd, hn::Load(dh, u.v + i)); };
        const VD w = hn::PromoteTo(dd, hn::Load(dh, lanes.weight.v + i));
        quantize(hn::Mul(w, scale), unit(uw), limit, adds.w + i, saturated);
        quantize(hn::Mul(hn::Load(dd, lanes.r + i), w), unit(ur), limit, adds.r + i, saturated);
        quantize(hn::Mul(hn::Load(dd, lanes.g + i), w), unit(ug), limit, adds.g + i, saturated);
        quantize(hn::Mul(hn::Load(dd, lanes.b + i), w), unit(ub), limit, adds.b + i, saturated);
    }
    return saturated;
}

} // namespace spw::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace spw {
HWY_EXPORT(RoundFootprint);

size_t roundFootprint(const FootprintLanes& lanes, size_t count, double weightScale, double maxAdd,
                      FootprintAdds& adds) {
    return HWY_DYNAMIC_DISPATCH(RoundFootprint)(lanes, count, weightScale, maxAdd, adds);
}

} // namespace spw
#endif
