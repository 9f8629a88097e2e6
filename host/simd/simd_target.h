// Which instruction set the SIMD code (Google Highway's dynamic dispatch: the shading kernels,
// the camera rays, the hit setup, the film's rounding) runs in on this machine.
#pragma once

namespace spw {

// "AVX3", "AVX2", "SSE4", ...
const char* simdTarget();

} // namespace spw
