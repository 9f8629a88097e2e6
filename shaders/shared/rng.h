// Counter-based random numbers: every number a path uses is a pure function of
// (seed, pixel, sample index, bounce, dimension), so an image never depends on the thread
// count, the batch a ray travelled in, or the order batches were processed in.
//
// The hash is pcg4d (Jarzynski & Olano, "Hash Functions for GPU Rendering", JCGT 2020): four
// 32-bit words in, four well-mixed words out, so one call yields four dimensions.
#ifndef SPILLWAY_SHARED_RNG_H
#define SPILLWAY_SHARED_RNG_H
#include "compat.h"

SHARED_BEGIN

// Which group of four dimensions a purpose draws from. A bounce uses a handful; the camera
// uses its own pseudo-bounce so that its numbers never collide with bounce 0's.
const uint kDimLight = 0u;    // x: emitter pick, y,z: point on the emitter, w: RR
const uint kDimBsdf = 1u;     // x,y: direction, z: lobe choice, w: spare
const uint kDimRounding = 2u; // stochastic rounding of compact ray fields and the film
const uint kDimCamera = 3u;   // x,y: position in the pixel, z,w: lens
const uint kBounceCamera = 255u;

SHARED_FN uvec4 pcg4d(uvec4 v) {
    v = v * 1664525u + 1013904223u;
    v.x += v.y * v.w;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    v.w += v.y * v.z;
    v = v ^ (v >> 16u);
    v.x += v.y * v.w;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    v.w += v.y * v.z;
    return v;
}

// A 32-bit word to a float in [0, 1): the top 24 bits, so every value is exact.
SHARED_FN float uintToUnit(uint x) {
    return float(x >> 8u) * (1.0f / 16777216.0f);
}

// Four uniform numbers for (seed, pixel, sample, bounce, group). `sampleIndex` counts samples of
// the whole render (iteration * samples per iteration + sample), so iterations differ.
SHARED_FN vec4 rand4(uint seed, uint pixel, uint sampleIndex, uint bounce, uint group) {
    uvec4 h = pcg4d(uvec4(pixel, sampleIndex, (bounce << 8u) | group, seed));
    return vec4(uintToUnit(h.x), uintToUnit(h.y), uintToUnit(h.z), uintToUnit(h.w));
}

SHARED_END
#endif
