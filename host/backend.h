// What every backend is handed, and the one call it answers: render an iteration into the film.
// Virtual calls happen per iteration, never per ray.
#pragma once

#include "host/camera.h"
#include "host/film.h"
#include "host/render_config.h"
#include "host/scene.h"
#include "host/stats.h"
#include "host/textures.h"

namespace spw {

class EmbreeScene;

struct RenderContext {
    const Scene& scene;
    const RenderConfig& config;
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
