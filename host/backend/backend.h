// What every backend is handed, and the one call it answers: render an iteration into the film.
// Virtual calls happen per iteration, never per ray.
#pragma once

#include "host/backend/render_config.h"
#include "host/backend/stats.h"
#include "host/image/aov_film.h"
#include "host/image/film.h"
#include "host/scene/camera.h"
#include "host/scene/scene.h"
#include "host/scene_view/hit_setup.h"
#include "host/scene_view/lights.h"
#include "host/textures/textures.h"

namespace spw {

class EmbreeScene;

struct RenderContext {
    const Scene& scene;
    const RenderConfig& config;
    const SceneLights& lights; // shaders and emitters, as shading reads them
    const EmbreeScene& embree; // the BVH (embree_backend/)
    const HitSetup& hitSetup;  // what a hit means
    const TextureResolver& textures;
    const CameraModel& camera;
    RenderParams params; // the render-wide values; each backend sets `iteration` in its own copy
    int threads;         // resolved thread count
    RenderStats& stats;
    AovFilm* aovs = nullptr; // where camera rays' first hits go, with --aov (else none)
};

// Whether a stop was asked for (RenderConfig::stop, set by a signal handler): backends look at
// it between batches (sorted) or tiles (reference).
inline bool stopRequested(const RenderConfig& config) {
    return config.stop != nullptr && config.stop->load(std::memory_order_relaxed) != 0;
}

class Backend {
  public:
    virtual ~Backend() = default;
    // Renders one iteration into the film. Returns false when it stopped early because a stop
    // was requested: the iteration is then incomplete, and the caller discards it.
    virtual bool renderIteration(uint iteration, Film& film) = 0;
};

} // namespace spw
