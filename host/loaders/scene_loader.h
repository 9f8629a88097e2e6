// Loading a scene: the one entry point of host/loaders/, which reads a YAML scene file
// (scene_loader.cpp, docs/scene-format.md) or a glTF 2.0 file (gltf_loader.h) into the
// immutable Scene (host/scene/scene.h).
#pragma once

#include "host/scene/scene.h"

#include <string>

namespace spw {

// Parses and validates a scene file, or a glTF file (.gltf, .glb: host/loaders/gltf_loader.h).
// Throws SceneError (file:line: message) on any problem.
Scene loadScene(const std::string& path);

} // namespace spw
