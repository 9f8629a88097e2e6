// The scene file's render-wide entries: `image`, `settings`, `camera`, `filter` and `sampler`,
// each read and range-checked here (scene errors name the file and line). Used by the scene
// loader (scene_loader.cpp) only.
#pragma once

#include "host/loaders/yaml_reader.h"
#include "host/scene/scene.h"

namespace spw::scene_file {

void readImage(const Reader& rd, const YAML::Node& n, ImageSettings& img);
// Every key under `settings:`, read by the one table (host/scene/settings_table.h).
void readSettings(const Reader& rd, const YAML::Node& n, Settings& s);
// Reads the camera and returns its position in the file's coordinates: the scene's origin.
glm::dvec3 readCamera(const Reader& rd, const YAML::Node& n, Camera& c);
void readFilter(const Reader& rd, const YAML::Node& n, Filter& f);
SamplerType readSampler(const Reader& rd, const YAML::Node& n);

} // namespace spw::scene_file
