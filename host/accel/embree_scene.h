// The scene as Embree sees it: one triangle geometry per mesh (geometry id = mesh index), built
// with the robust flag. Only acceleration lives in host/accel/: what a hit means (hit setup) is
// the scene's (host/scene/hit_setup.h), and so are the shaders and emitters (host/scene/lights.h).
#pragma once

#include "host/scene/scene.h"

#include <string>

// Embree's handles, declared as Embree declares them, so that <embree3/rtcore.h> stays inside
// host/accel/.
struct RTCDeviceTy;
struct RTCSceneTy;

namespace spw {

class EmbreeScene {
  public:
    // Builds the BVH on Embree's default device. Throws std::runtime_error on a device error.
    explicit EmbreeScene(const Scene& scene);
    ~EmbreeScene();
    EmbreeScene(const EmbreeScene&) = delete;
    EmbreeScene& operator=(const EmbreeScene&) = delete;

    RTCSceneTy* handle() const { return scene_; }

    // Throws if Embree reported an error since the last check.
    void checkError(const char* what) const;

  private:
    RTCDeviceTy* device_ = nullptr;
    RTCSceneTy* scene_ = nullptr;
    mutable std::string error_;
};

} // namespace spw
