// How shared code reads scene-wide arrays (shaders, emitters, the emitter CDF, the light data:
// the environment's and emitters' maps). In C++ they are
// spans passed as the first argument of every function that needs them; in GLSL they are
// storage buffers declared by the kernel before it includes the shared headers, and the
// SCENE_PARAM / SCENE_ARG (and SCENE_UNUSED) macros vanish.
#ifndef SPILLWAY_SHARED_SCENE_ACCESS_H
#define SPILLWAY_SHARED_SCENE_ACCESS_H
#include "types.h"

#ifdef __cplusplus
namespace spw {
struct SceneView {
    const ShaderParams* shaders = nullptr;
    const Emitter* emitters = nullptr;
    const float* emitterCdf = nullptr; // inclusive prefix sums of pickPdf, last entry 1
    uint emitterCount = 0;
    // The light data, as floats: the environment's lat-long map and its sampling CDFs
    // (shared/environment_light.h) from 0, then the emission maps (shared/emission_map.h); or
    // nothing where there is neither.
    const float* lightData = nullptr;
};
} // namespace spw
#define SCENE_PARAM const SceneView &scene,
#define SCENE_ARG scene,
// In a function that takes the scene for its signature's sake (a light kind's sample reads none).
#define SCENE_UNUSED UNUSED(scene)
#define SHADER(i) scene.shaders[i]
#define EMITTER(i) scene.emitters[i]
#define EMITTER_CDF(i) scene.emitterCdf[i]
#define LIGHT_DATA(i) scene.lightData[i]
#else
#define SCENE_PARAM
#define SCENE_ARG
#define SCENE_UNUSED
#endif

#endif
