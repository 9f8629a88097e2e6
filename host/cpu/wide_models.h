// The surface models whose hits the cpu engine shades SIMD-wide, and the only list of them:
// X(Name, stem), the model's registry name and file stem (shaders/shared/surface_models.h), in
// registry order. host/cpu/<stem>_lanes-inl.h defines the model's <Name>LanesModel, the SIMD twins
// of its BSDF functions (host/cpu/lanes_model-inl.h says what it holds). From this list come:
//   * the includes of the lanes files: CMake writes them into generated/wide_model_lanes.h, and
//     configuring stops for a listed model without its file;
//   * its kernel Shade<Name>Lanes (shadeLanes<<Name>LanesModel>, host/cpu/simd_shading.cpp), and
//     its entry in the dispatch table kWideTwins (the function itself; every other model's entry
//     is empty, its hits shaded one at a time by shadeSurfaceWith());
//   * kWideModels, which the tests read: each listed model's hits are compared with
//     shadeSurface() bit for bit (SimdShading.EveryModelsHitsAreShadeSurfaceToTheBit).
// Keep each entry on one line (CMake parses them). Adding one: docs/adding-a-surface-model.md.
#pragma once

#include "shared/types.h"

#define SPW_WIDE_MODELS(X)                                                                         \
    X(Lambert, lambert)                                                                            \
    X(Conductor, conductor)                                                                        \
    X(Dielectric, dielectric)                                                                      \
    X(MetallicRoughness, metallic_roughness)

namespace spw {

#define SPW_WIDE_MODEL_ID(Name, stem) kModel##Name,
inline constexpr uint kWideModels[] = {SPW_WIDE_MODELS(SPW_WIDE_MODEL_ID)};
#undef SPW_WIDE_MODEL_ID

} // namespace spw
