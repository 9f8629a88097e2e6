// The scene as Embree sees it: one triangle geometry per mesh (geometry id = mesh index), built
// with the robust flag, plus the emitter table that next-event estimation samples.
#pragma once

#include "host/scene/scene.h"
#include "shared/scene_access.h"

#include <embree3/rtcore.h>

#include <string>
#include <vector>

namespace spw {

class EmbreeScene {
  public:
    // Builds the BVH on Embree's default device. Throws std::runtime_error on a device error.
    explicit EmbreeScene(const Scene& scene);
    ~EmbreeScene();
    EmbreeScene(const EmbreeScene&) = delete;
    EmbreeScene& operator=(const EmbreeScene&) = delete;

    RTCScene handle() const { return scene_; }
    const Scene& scene() const { return src_; }

    // The shading view: shaders, emitters and their CDF.
    SceneView view() const;
    const std::vector<Emitter>& emitters() const { return emitters_; }
    float brightestEmission() const { return brightest_; }

    // World-space hit description for (geometry, primitive, Embree's u, v) at distance t.
    // The albedo is left for the texture stage.
    void surfaceHit(uint geomID, uint primID, float u, float v, float t, SurfaceHit& hit) const;
    // Interpolated texture coordinates (0, 0 when the mesh has none).
    vec2 uvAt(uint geomID, uint primID, float u, float v) const;
    // Throws if Embree reported an error since the last check.
    void checkError(const char* what) const;

  private:
    const Scene& src_;
    RTCDevice device_ = nullptr;
    RTCScene scene_ = nullptr;
    std::vector<ShaderParams> shaders_;
    std::vector<Emitter> emitters_;
    std::vector<float> cdf_;
    std::vector<int> emitterBase_; // per mesh: index of its first emitter, or -1
    float brightest_ = 0.0f;
    mutable std::string error_;
};

} // namespace spw
