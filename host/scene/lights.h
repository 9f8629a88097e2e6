// What shading reads of the scene besides the hit: the shader table, and the lights. Every
// triangle of a mesh whose shader emits is an emitter, and so is every punctual light and the
// environment; next-event estimation picks one with probability proportional to its power (the
// CDF), and the film's fixed-point scale reads the brightest emission. Built from the Scene alone,
// apart from the BVH (host/accel/), as pbrt-v4 builds its lights and light sampler apart from
// the aggregate.
#pragma once

#include "host/scene/scene.h"
#include "shared/scene_access.h"

#include <vector>

namespace spw {

class SceneLights {
  public:
    explicit SceneLights(const Scene& scene);

    // The shading view: shaders, emitters and their CDF.
    SceneView view() const;
    const std::vector<Emitter>& emitters() const { return emitters_; }
    // How many emitters next-event estimation picks from (the CDF's length): every emitter but
    // an environment that has no power to be picked by (no geometry to light).
    uint sampledEmitters() const { return uint(cdf_.size()); }
    // The environment's emitter index, or kNoEmitter; its map's size (0 x 0: constant).
    uint environment() const { return environment_; }
    uint environmentWidth() const { return envWidth_; }
    uint environmentHeight() const { return envHeight_; }
    const std::vector<float>& environmentData() const { return environmentData_; }
    float brightestEmission() const { return brightest_; }
    // The emitter index of a mesh's triangle, or kNoEmitter.
    uint emitterOf(uint mesh, uint triangle) const {
        const int base = emitterBase_[mesh];
        return base >= 0 ? uint(base) + triangle : kNoEmitter;
    }

  private:
    void addPunctual(const PunctualLight& p, double radius, std::vector<double>& powers);
    void buildEnvironment(const Environment& env, double radius, std::vector<double>& powers);

    std::vector<ShaderParams> shaders_;
    std::vector<Emitter> emitters_;
    std::vector<float> cdf_;
    std::vector<int> emitterBase_; // per mesh: index of its first emitter, or -1
    float brightest_ = 0.0f;
    uint environment_ = kNoEmitter;
    uint envWidth_ = 0, envHeight_ = 0;
    std::vector<float> environmentData_; // texels, then CDFs (shared/lights.h)
};

} // namespace spw
