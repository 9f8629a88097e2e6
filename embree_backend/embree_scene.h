// The scene as Embree sees it: one triangle geometry per mesh (geometry id = mesh index), built
// with the robust flag, plus the emitter table that next-event estimation samples.
#pragma once

#include "host/scene/scene.h"
#include "host/scene/textures.h"
#include "shared/scene_access.h"

#include <string>
#include <vector>

// Embree's handles, declared as Embree declares them, so that <embree3/rtcore.h> stays inside
// embree_backend/.
struct RTCDeviceTy;
struct RTCSceneTy;

namespace spw {

// A closest hit in Spillway's terms, what traversal hands the rest of the renderer: the mesh
// (Embree's geometry id), the triangle, Embree's barycentric u and v, and the distance.
constexpr uint kNoHit = 0xFFFFFFFFu;
struct HitRecord {
    uint mesh; // kNoHit: the ray missed
    uint prim;
    float u, v, t;
};

class EmbreeScene {
  public:
    // Builds the BVH on Embree's default device. Throws std::runtime_error on a device error.
    explicit EmbreeScene(const Scene& scene);
    ~EmbreeScene();
    EmbreeScene(const EmbreeScene&) = delete;
    EmbreeScene& operator=(const EmbreeScene&) = delete;

    RTCSceneTy* handle() const { return scene_; }
    const Scene& scene() const { return src_; }

    // The shading view: shaders, emitters and their CDF.
    SceneView view() const;
    const std::vector<Emitter>& emitters() const { return emitters_; }
    float brightestEmission() const { return brightest_; }

    // Hit setup, the same on every backend: the world-space hit (position, normals, self-
    // intersection offset, shader, emitter) and the albedo the shader's texture gives there.
    SurfaceHit setUpHit(const HitRecord& h, const TextureResolver& textures) const;
    // Throws if Embree reported an error since the last check.
    void checkError(const char* what) const;

  private:
    const Scene& src_;
    // World-space hit for (mesh, triangle, Embree's u, v) at distance t; albedo left at 0.
    void surfaceHit(uint geomID, uint primID, float u, float v, float t, SurfaceHit& hit) const;
    // Interpolated texture coordinates (0, 0 when the mesh has none).
    vec2 uvAt(uint geomID, uint primID, float u, float v) const;

    RTCDeviceTy* device_ = nullptr;
    RTCSceneTy* scene_ = nullptr;
    std::vector<ShaderParams> shaders_;
    std::vector<Emitter> emitters_;
    std::vector<float> cdf_;
    std::vector<int> emitterBase_; // per mesh: index of its first emitter, or -1
    float brightest_ = 0.0f;
    mutable std::string error_;
};

} // namespace spw
