// The scene file's lights: Quad (two triangles and an emissive shader of their own), the
// punctual kinds of the emitter registry (Point, Directional: host/scene/emitter_kinds.h) and
// Environment (a constant or a lat-long image, read and range-checked here so that a bad file is
// a scene error).
#pragma once

#include "host/loaders/yaml_reader.h"
#include "host/scene/emitter_kinds.h"
#include "host/scene/scene.h"

#include <filesystem>
#include <vector>

namespace spw::scene_file {

// A quad light becomes two triangles (appended to lightMeshes) and an emissive Null shader of
// its own (returned); both go after the scene's objects and shaders once the file is read.
Shader readQuadLight(const Reader& rd, const YAML::Node& n, const glm::dvec3& origin,
                     std::vector<Mesh>& lightMeshes);
// A punctual light of `kind`: `position` (camera-relative from here on) where the kind takes
// one, `direction` (the way its light travels, normalised here) where it takes one, and
// intensity x colour.
PunctualLight readPunctualLight(const Reader& rd, const YAML::Node& n, const glm::dvec3& origin,
                                const EmitterKindInfo& kind);
// `colour` (a constant) or `string` / `filename` (a lat-long image), times `intensity`.
Environment readEnvironment(const Reader& rd, const YAML::Node& n,
                            const std::filesystem::path& dir);
// The lat-long image at `path` as an environment of `radiance` times its texels, range-checked
// (a YAML scene's Environment light, or --environment FILE). Throws std::runtime_error naming
// the file.
Environment environmentMap(const std::filesystem::path& path, vec3 radiance);

} // namespace spw::scene_file
