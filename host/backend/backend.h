// What every backend is handed, and the one call it answers: render an iteration into the film.
// Virtual calls happen per iteration, never per ray.
#pragma once

#include "host/backend/render_config.h"
#include "host/backend/stats.h"
#include "host/image/film.h"
#include "host/scene/camera.h"
#include "host/scene/lights.h"
#include "host/scene/scene.h"
#include "host/scene/textures.h"

namespace spw {

class EmbreeScene;

struct RenderContext {
    const Scene& scene;
    const RenderConfig& config;
    const SceneLights& lights; // shaders and emitters, as shading reads them
    const EmbreeScene& embree;
    const TextureResolver& textures;
    const CameraModel& camera;
    RenderParams params; // the render-wide values; each backend sets `iteration` in its own copy
    int threads;         // resolved thread count
    RenderStats& stats;
};

class Backend {
  public:
    virtual ~Backend() = default;
    virtual void renderIteration(uint iteration, Film& film) = 0;
};

} // namespace spw
