// Rows of lanes: the structure-of-arrays blocks the SIMD code (host/simd/, host/cpu/) loads
// whole vectors from. Plain C++, no Highway type: a caller fills and reads them lane by lane.
#pragma once

#include <cstddef>
#include <cstdint>

namespace spw::simd {

// Lanes per block: a multiple of every vector width (16 floats for AVX-512).
constexpr size_t kBlock = 64;
constexpr size_t kMaxLanes = 16;

struct Floats {
    alignas(64) float v[kBlock];
};
struct Uints { // masks (all bits set, or none) and integers
    alignas(64) std::uint32_t v[kBlock];
};
struct Vec2s {
    Floats x, y;
};
struct Vec3s {
    Floats x, y, z;
};

// Lanes [0, count) rounded up to whole vectors of the widest instruction set.
inline size_t wholeVectors(size_t count) {
    return (count + kMaxLanes - 1) / kMaxLanes * kMaxLanes;
}

} // namespace spw::simd
