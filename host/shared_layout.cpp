// Layout checks for the structs in shaders/shared/types.h: they cross to GLSL (scalar block
// layout), so their sizes and field offsets are pinned here, in every build type.
#include "shared/types.h"

#include <cstddef>

namespace spw {
static_assert(sizeof(vec3) == 12 && alignof(vec3) == 4, "glm must pack vec3 as three floats");
static_assert(sizeof(ShaderParams) == 48, "ShaderParams layout changed");
static_assert(offsetof(ShaderParams, model) == 12 && offsetof(ShaderParams, flags) == 32, "ShaderParams layout");
static_assert(sizeof(Emitter) == 80, "Emitter layout changed");
static_assert(offsetof(Emitter, normal) == 48 && offsetof(Emitter, radiance) == 64, "Emitter layout");
static_assert(sizeof(SurfaceHit) == 64, "SurfaceHit layout changed");
static_assert(sizeof(PathState) == 32, "PathState layout changed");
static_assert(sizeof(RenderParams) == 32, "RenderParams layout changed");
} // namespace spw
