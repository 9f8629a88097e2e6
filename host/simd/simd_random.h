// The path's random numbers (shared/rng.h's rand4) SIMD-wide, a block of pixels and samples at
// a time, in the widest instruction set the processor has (Google Highway's dynamic dispatch):
// the camera's random numbers are made this way, and the scrambled Sobol sequence is most of a
// rand4's cost. The same numbers as rand4(), to the bit (SimdShading.Rand4ManyIsRand4).
#pragma once

#include "shared/types.h"

#include <cstddef>

namespace spw {

// out[i] = rand4(sampling, seed, pixel[i], sampleIndex[i], bounce, group) for i in [0, n).
void rand4Many(uint sampling, uint seed, uint bounce, uint group, const uint* pixel,
               const uint* sampleIndex, size_t n, vec4* out);

// The instruction set the SIMD code runs in on this machine ("AVX3", "AVX2", "SSE4", ...).
const char* simdTarget();

} // namespace spw
