// The emitter next-event estimation picks, for a block of shading points at once: pickLight
// (shared/lights.h) with the light tree's descent SIMD-wide, each lane on its own path through
// the tree (host/simd/simd_math-inl.h's treeDescent). The shading kernels' light pick
// (simd_shading.cpp); bit for bit with pickLight
// (SimdShading.HitsUnderALightTreeAreShadeSurfaceToTheBit).
#pragma once

#include "host/simd/lanes.h"
#include "shared/scene_access.h"

#include <cstddef>

namespace spw {

// For the lanes k in [0, count) that `want` (all-ones rows), pickLight(scene, rp, p[k], u[k],
// pickPdf[k]) into picked[k]; kNoEmitter and 0 for the others. The leaf's pick among its members,
// and the binary search of the lights outside the tree, stay one lane at a time.
void pickLights(const SceneView& scene, const RenderParams& rp, const simd::Vec3s& p,
                const simd::Floats& u, const simd::Uints& want, size_t count, uint* picked,
                float* pickPdf);

} // namespace spw
