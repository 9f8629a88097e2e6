// glTF 2.0 files as scenes (docs/scene-format.md, "glTF files"): `.gltf` (JSON, with external or
// embedded buffers) and `.glb` (binary), read with tinygltf. The default scene's meshes become
// triangle meshes with MetallicRoughness shaders (shared/metallic_roughness.h), one per material;
// its first perspective camera is the camera (else one that frames the scene's bounds); its
// KHR_lights_punctual point and directional lights and its emissive materials light it (else a
// uniform environment of radiance 1). What the file holds that Spillway does not render is listed
// in Scene::warnings, once each; an extension the file requires that Spillway cannot honour is an
// error.
#pragma once

#include "host/scene/scene.h"

#include <glm/mat4x4.hpp>

#include <string>
#include <vector>

namespace spw {

// Whether `path` names a glTF file (by its extension: .gltf or .glb, any case).
bool isGltfPath(const std::string& path);

// The Blender add-on's material extension: the Principled BSDF's factors glTF's core lacks
// (shared/principled.h; docs/scene-format.md, "glTF files").
inline constexpr const char* kPrincipledExtension = "SPILLWAY_materials_principled";

// The end of the warning that a glTF file whose emitters are too dim to light it alone is lit by
// a white environment as well: the command line's --environment, which replaces that
// environment, drops the warning (applyOverrides).
inline constexpr const char* kAddedEnvironmentNote = "(--environment chooses another)";

// A glTF scene's sample base (ImageSettings::sampleBase): 4 x 4 = 16 samples a pixel an
// iteration.
constexpr int kGltfSampleBase = 4;

// A glTF scene's Russian roulette (Settings::minDepth, Settings::threshold): from the second
// bounce on, a path goes on with probability min(1, t / 0.3), t its throughput's largest
// channel. The YAML format's defaults (3 and 0.1) keep paths whose throughput is small; ending
// them sooner costs a little variance and saves more time. Time x relMSE at equal samples
// (docs/performance.md): Cornell box -8 to -9 %, textured -4 %, 128 lamps -2 %.
constexpr int kGltfMinDepth = 2;
constexpr float kGltfRouletteThreshold = 0.3f;

// Loads a glTF file as a whole scene. Throws SceneError naming the file, and where in it (a JSON
// pointer such as /meshes/0/primitives/1) the problem is.
Scene loadGltfScene(const std::string& path);

// A glTF file as an object of a YAML scene (`type: Gltf`): its default scene's meshes and lights
// placed by each of `transforms` relative to `scene.origin` (the scene's camera), appended to
// `scene.meshes` (a mesh placed more than once as a prototype, with its instances) and
// `scene.punctualLights`; every mesh takes shader `shader` where it is >= 0, else the file's
// materials, appended to `scene.shaders`. The file's cameras are not used.
void appendGltfObject(const std::string& path, const std::vector<glm::dmat4>& transforms,
                      int shader, Scene& scene);

} // namespace spw
