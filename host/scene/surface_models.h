// The registry of surface models: one line per model. From this list come
//   * the shader list of the build: CMakeLists.txt reads the lines below and compiles
//     shaders/<file>.comp for each (configuring fails if a registered model has no kernel);
//   * the Vulkan pipeline table (host/vk/pipelines.cpp): one pipeline per model the scene uses;
//   * the checks of tests/vk/vulkan_test.cpp (every model has its kernel, the count matches
//     kModelCount in shaders/shared/types.h).
// The BSDF dispatch itself is bsdf.h's, shared by every backend.
//
// Adding a model: docs/adding-a-surface-model.md lists every file and what checks each.
//
// X(Name, model constant, kernel file stem) — keep each entry on one line: CMake parses them.
#pragma once

#include "shared/types.h"

#include <cstddef>

#define SPW_SURFACE_MODELS(X)                                                                      \
    X(Null, kModelNull, "null")                                                                    \
    X(Lambert, kModelLambert, "lambert")                                                           \
    X(Conductor, kModelConductor, "conductor")                                                     \
    X(Dielectric, kModelDielectric, "dielectric")

namespace spw {

struct SurfaceModelInfo {
    const char* name;   // as the scene format spells it
    uint model;         // kModel*
    const char* kernel; // shaders/<kernel>.comp, embedded as SPIR-V under this name
};

#define SPW_SURFACE_MODEL_ENTRY(Name, Constant, File) SurfaceModelInfo{#Name, Constant, File},
inline constexpr SurfaceModelInfo kSurfaceModels[] = {SPW_SURFACE_MODELS(SPW_SURFACE_MODEL_ENTRY)};
#undef SPW_SURFACE_MODEL_ENTRY
inline constexpr size_t kSurfaceModelCount = sizeof(kSurfaceModels) / sizeof(kSurfaceModels[0]);

// The uber-shader of --shading megakernel: every model, switched per hit.
inline constexpr const char* kMegakernel = "megakernel";

// The registry entry of a model, or nullptr.
inline const SurfaceModelInfo* surfaceModel(uint model) {
    for (const SurfaceModelInfo& m : kSurfaceModels)
        if (m.model == model) return &m;
    return nullptr;
}

} // namespace spw
