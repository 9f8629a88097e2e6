// Shading a run of hits SIMD-wide: the cpu engine's shade step, where the sort has made the work
// homogeneous. Hits of each model with a kernel (host/cpu/wide_models.h: Lambert, Conductor,
// Dielectric and MetallicRoughness) go through a structure-of-arrays kernel that runs
// shadeSurface()'s arithmetic on 4, 8 or 16 hits of that model at once, in the widest
// instruction set the processor has (Google Highway's dynamic dispatch: SSE4, AVX2 or AVX-512); a
// hit of a model without one goes through shadeSurfaceWith(), with its random numbers made
// SIMD-wide too (the scrambled Sobol sequence is most of a rand4's cost). Unsorted hits fill one
// block per model, so interleaved models still make full vectors.
//
// The kernel is shadeSurface() to the bit: the same operations in the same order, each rounded
// once (no fused multiply-add), so an image does not depend on which hits were shaded
// together, on the instruction set, or on whether the kernel ran at all
// (SimdShading.EveryModelsHitsAreShadeSurfaceToTheBit). The emitter pick's walk down the light
// tree runs SIMD-wide too, each lane on its own path through the tree
// (SimdShading.HitsUnderALightTreeAreShadeSurfaceToTheBit). What stays scalar, per hit: the
// pick's last step (among a leaf's members, or the binary search of the lights outside the
// tree), gathering the emitter and the hit into rows, and the emission of an emitter that was
// hit.
#pragma once

#include "shared/scene_access.h"
#include "shared/shade_io.h"

#include <array>
#include <cstddef>

namespace spw {

namespace simd_shading {
struct SurfaceLanes;   // a block of one model's hits, as the kernels read them
struct SurfaceResults; // what they write
} // namespace simd_shading

// Each registered surface model's wide twin in this engine, indexed by kModel*: the kernel that
// shades a run of its hits SIMD-wide (the models host/cpu/wide_models.h lists), or nullptr where
// its hits go through shadeSurfaceWith() one at a time (their random numbers still made
// SIMD-wide). The cpu backend's --stats names the scene's models that have none
// (`scalar_models`), so that a model without one is never silently scalar.
using ShadeLanesFn = void (*)(const simd_shading::SurfaceLanes& in, size_t count, bool nee,
                              bool mis, float threshold, simd_shading::SurfaceResults& out);
struct WideTwin {
    uint model;         // kModel*
    ShadeLanesFn shade; // nullptr: none
};
extern const std::array<WideTwin, kModelCount> kWideTwins;

// out[i] = shadeSurface(view, rp, in[i]) for i in [0, n); `simd` false shades every hit with
// shadeSurface() (--simd-shading off, and to compare). Light samples toward a triangle without
// an emission map are made SIMD-wide; toward any other emitter (a punctual light, the
// environment, a mapped triangle) one lane at a time by sampleEmitter, and the rest of
// next-event estimation SIMD-wide again.
void shadeHits(const SceneView& view, const RenderParams& rp, bool simd, const ShadeInput* in,
               size_t n, ShadeResult* out);

} // namespace spw
