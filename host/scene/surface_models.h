// The C++ view of the surface-model registry (shaders/shared/surface_models.h): each model's
// name as the scene format spells it, its kModel* constant, its kernel (shaders/<stem>.comp,
// embedded as SPIR-V under that name) and the scene keys it takes. Read by the loader (which
// accepts `type: <Name>` and parses the keys), the Vulkan pipeline table (one pipeline per model
// the scene uses) and the tests that check every model is complete.
//
// Adding a model: docs/adding-a-surface-model.md.
#pragma once

#include "shared/types.h"

#include <cstddef>

namespace spw {

// The keys a shader of a model may set beyond `type`, `emission` and `two sided` (which every
// model takes). Each key has one range, checked in one place (scene_loader.cpp's readShader):
enum SurfaceParam : uint {
    kNoParams = 0,
    kTakesReflectance = 1u << 0, // reflectance: albedo scale in [0, 1] (default 1)
    kTakesColour = 1u << 1,      // colour: [r, g, b] in [0, 1] (default [1, 1, 1])
    kTakesTexture = 1u << 2,     // texture: a texture tree for the colour, instead of colour
    kTakesAlpha = 1u << 3,       // alpha: GGX width in [0, 1] (default 0: smooth)
    kTakesIor = 1u << 4,         // ior: index of refraction behind the surface, [1.01, 10] (1.5)
    kTakesMetallic = 1u << 5,    // metallic: glTF's metallic factor in [0, 1] (default 1; 0 on
                                 // TransmissiveMetallicRoughness)
    kTakesRoughness = 1u << 6,   // roughness: glTF's perceptual roughness in [0, 1] (default 1),
                                 // GGX alpha = roughness^2 (shared/metallic_roughness.h)
    kTakesAbsorption = 1u << 7,  // absorption: [r, g, b], each >= 0, per unit length (default 0)
    kTakesCoat =
        1u << 8, // coat (1) in [0, 1] and coat roughness (0) in [0, 1], the clear
                 // coat's weight and perceptual roughness (shared/coated_metallic_roughness.h)
    kTakesSpecular =
        1u << 9, // specular (1) in [0, 1] and specular colour [r, g, b] (each in
                 // [0, 1000], default [1, 1, 1]): the dielectric reflection's
                 // weight and F0 colour (KHR_materials_specular, shared/metallic_roughness.h)
    kTakesTransmission =
        1u << 10, // transmission (1) in [0, 1]: the weight of the glass lobe
                  // against the opaque one (shared/transmissive_metallic_roughness.h)
    kTakesSheen =
        1u
        << 11, // sheen colour [r, g, b] ([1, 1, 1], each in [0, 1]) and sheen
               // roughness (0.5) in [0, 1] (KHR_materials_sheen, shared/sheen_metallic_roughness.h)
    kTakesPrincipled =
        1u << 12, // specular (0.5), specular tint (0), sheen (0) and sheen tint (0.5), each in
                  // [0, 1]: Blender's Principled BSDF's (shared/principled.h); with it the model
                  // takes Blender's defaults for the other keys too
};

struct SurfaceModelInfo {
    const char* name;   // as the scene format spells it
    uint model;         // kModel*
    const char* kernel; // shaders/<kernel>.comp, embedded as SPIR-V under this name
    uint params;        // SurfaceParam bits
};

#define SPW_SURFACE_MODEL_ENTRY(Name, id, stem, fn, params)                                        \
    SurfaceModelInfo{#Name, kModel##Name, #stem, uint(params)},
inline constexpr SurfaceModelInfo kSurfaceModels[] = {SPW_SURFACE_MODELS(SPW_SURFACE_MODEL_ENTRY)};
#undef SPW_SURFACE_MODEL_ENTRY
inline constexpr size_t kSurfaceModelCount = sizeof(kSurfaceModels) / sizeof(kSurfaceModels[0]);
static_assert(kSurfaceModelCount == kModelCount);

// The uber-shader of --shading megakernel: every model, switched per hit.
inline constexpr const char* kMegakernel = "megakernel";

// The registry entry of a model, or nullptr.
inline const SurfaceModelInfo* surfaceModel(uint model) {
    for (const SurfaceModelInfo& m : kSurfaceModels)
        if (m.model == model) return &m;
    return nullptr;
}

} // namespace spw
