// Layout checks for the structs in shaders/shared/types.h and shade_io.h: they cross to GLSL
// (scalar block layout), so their sizes and field offsets are pinned here, in every build type.
#include "shared/shade_io.h"
#include "shared/types.h"

#include <cstddef>

namespace spw {
static_assert(sizeof(vec3) == 12 && alignof(vec3) == 4, "glm must pack vec3 as three floats");
static_assert(sizeof(ShaderParams) == 128, "ShaderParams layout changed");
static_assert(offsetof(ShaderParams, model) == 12 && offsetof(ShaderParams, flags) == 32 &&
                  offsetof(ShaderParams, absorption) == 48 && offsetof(ShaderParams, coat) == 60 &&
                  offsetof(ShaderParams, coatAlpha) == 64 &&
                  offsetof(ShaderParams, specularColour) == 68 &&
                  offsetof(ShaderParams, specular) == 80 &&
                  offsetof(ShaderParams, transmission) == 84 &&
                  offsetof(ShaderParams, sheenRoughness) == 88 &&
                  offsetof(ShaderParams, sheenColour) == 96 &&
                  offsetof(ShaderParams, specularTint) == 108 &&
                  offsetof(ShaderParams, sheen) == 112 && offsetof(ShaderParams, pad2) == 124,
              "ShaderParams layout");
static_assert(sizeof(Emitter) == 80, "Emitter layout changed");
static_assert(offsetof(Emitter, normal) == 48 && offsetof(Emitter, type) == 60 &&
                  offsetof(Emitter, radiance) == 64,
              "Emitter layout");
static_assert(sizeof(SurfaceHit) == 80, "SurfaceHit layout changed");
static_assert(sizeof(PathState) == 32, "PathState layout changed");
static_assert(sizeof(RenderParams) == 60, "RenderParams layout changed");
// What the shading kernels read and write (shaders/shared/shade_io.h, shaders/shade_kernel.glsl).
static_assert(offsetof(SurfaceHit, shader) == 28 && offsetof(SurfaceHit, emitter) == 44 &&
                  offsetof(SurfaceHit, albedo) == 48 && offsetof(SurfaceHit, material) == 64 &&
                  offsetof(SurfaceHit, lift) == 68 && offsetof(SurfaceHit, extension) == 72,
              "SurfaceHit layout");
static_assert(offsetof(PathState, pathId) == 16 && offsetof(PathState, flags) == 24,
              "PathState layout");
static_assert(sizeof(ShadeResult) == 112, "ShadeResult layout changed");
static_assert(offsetof(ShadeResult, emitted) == 4 && offsetof(ShadeResult, shadowTmax) == 28 &&
                  offsetof(ShadeResult, shadowContribution) == 44 &&
                  offsetof(ShadeResult, nextDir) == 68 && offsetof(ShadeResult, next) == 80,
              "ShadeResult layout");
static_assert(sizeof(ShadeInput) == 128, "ShadeInput layout changed");
static_assert(offsetof(ShadeInput, path) == 80 && offsetof(ShadeInput, rayDir) == 112,
              "ShadeInput layout");
static_assert(sizeof(ShadePush) == 72 && offsetof(ShadePush, offset) == 60 &&
                  offsetof(ShadePush, count) == 64,
              "ShadePush layout changed");
static_assert(sizeof(ShadePush) <= 128,
              "push constants beyond the 128 bytes every device guarantees");
} // namespace spw
