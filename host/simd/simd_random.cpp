// rand4Many (simd_random.h), compiled once per instruction set through foreach_target.h.
#include "host/simd/simd_random.h"

#include "host/simd/lanes.h"

#include <algorithm>

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "host/simd/simd_random.cpp"
#include <hwy/foreach_target.h> // must come before highway.h
#include <hwy/highway.h>

#include "host/simd/simd_math-inl.h"

HWY_BEFORE_NAMESPACE();
namespace spw::HWY_NAMESPACE {

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

const char* TargetName() {
    return hwy::TargetName(HWY_TARGET);
}

} // namespace spw::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace spw {
HWY_EXPORT(MakeRand4);
HWY_EXPORT(TargetName);

void rand4Many(uint sampling, uint seed, uint bounce, uint group, const uint* pixel,
               const uint* sampleIndex, size_t n, vec4* out) {
    using simd::kBlock;
    simd::Uints pixels, samples;
    simd::Floats x, y, z, w;
    for (size_t begin = 0; begin < n; begin += kBlock) {
        const size_t count = std::min(kBlock, n - begin);
        const size_t end = simd::wholeVectors(count);
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

const char* simdTarget() {
    return HWY_DYNAMIC_DISPATCH(TargetName)();
}

} // namespace spw
#endif
