// The film's stochastic rounding (Film::quantize, host/image/film.cpp) SIMD-wide, for the pass
// that filters each sample's sum into the pixels of its footprint (Film::finishSamples): per
// pixel, a hash of the sample's keys and the pixel, and four values rounded to fixed point.
// Each lane is Film's scalar rounding to the bit: the same hash (pcg4d's twin), the same double
// arithmetic, and the same clamp (Film.FootprintRoundingIsTheScalarRounding).
#pragma once

#include "host/simd/lanes.h"

#include <cstddef>
#include <cstdint>

namespace spw {

// Up to simd::kBlock (pixel, sample) pairs: the pixel, the filter's weight there, the sample's
// two rounding keys and its radiance sum (fixed-point units, as doubles).
struct FootprintLanes {
    simd::Uints pixel, weightKey, rgbKey;
    simd::Floats weight;
    alignas(64) double r[simd::kBlock];
    alignas(64) double g[simd::kBlock];
    alignas(64) double b[simd::kBlock];
};

// What each pair adds to its pixel: the radiance and the weight, rounded.
struct FootprintAdds {
    alignas(64) std::int64_t r[simd::kBlock];
    alignas(64) std::int64_t g[simd::kBlock];
    alignas(64) std::int64_t b[simd::kBlock];
    alignas(64) std::int64_t w[simd::kBlock];
};

// For lanes [0, count) (count a multiple of simd::kMaxLanes): with h = pcg4d(key, pixel, 0x5157,
// 0x9E3779B9), the weight double(weight) * weightScale rounded with the weight key's h.w, and
// each channel c times double(weight) rounded with the radiance key's h.x, h.y, h.z; a value
// beyond maxAdd is clamped to it, and counted in the return value.
size_t roundFootprint(const FootprintLanes& lanes, size_t count, double weightScale, double maxAdd,
                      FootprintAdds& adds);

} // namespace spw
