// The scene as Embree sees it, in two levels: one triangle geometry per mesh (geometry id = mesh
// index, whichever scene holds it), the world's meshes in the top scene, each prototype's in a
// scene of its own that instances place (instance i: geometry id instanceBase() + i of the top
// scene), every scene built with the robust flag. Only acceleration lives in embree_backend/: what
// a hit means (hit setup) is the scene's (host/scene_view/hit_setup.h), and so are the shaders and
// emitters (host/scene_view/lights.h).
#pragma once

#include "host/scene/scene.h"

#include <cstddef>
#include <string>

// Embree's handles, declared as Embree declares them, so that <embree3/rtcore.h> stays inside
// embree_backend/.
struct RTCDeviceTy;
struct RTCSceneTy;

namespace spw {

// Which candidate hits count, for meshes with holes in them (an alpha cut-out, or alpha blending
// as stochastic transparency): Embree asks `keeps` for each hit it finds on a mesh that
// `filters`, and traversal goes on past those it does not keep, for closest hits and shadow rays
// alike. Meshes that do not filter get no filter function, and cost nothing.
class HitFilter {
  public:
    virtual ~HitFilter() = default;
    virtual bool filters(uint mesh) const = 0;
    // Whether the hit at Embree's barycentrics (u, v) of triangle `prim` counts, for the ray from
    // `org` along `dir` (as traced: the same ray always gets the same answer). Thread-safe:
    // Embree calls it from every thread that traces.
    virtual bool keeps(uint mesh, uint prim, float u, float v, vec3 org, vec3 dir) const = 0;
};

// The most triangles an Embree scene holds in Embree's fast layout, whose leaves carry copies of
// their triangles' vertices. Past it the scene is built compact (RTC_SCENE_FLAG_COMPACT: leaves
// index the mesh's own vertices): less memory and a faster build for slower traversal, measured
// on 20M triangles in docs/performance.md ("Production scale"). Every other scene of the
// benchmarks is below it.
constexpr size_t kCompactBvhTriangles = size_t(1) << 23;

class EmbreeScene {
  public:
    // Builds the BVH on Embree's default device. Throws std::runtime_error on a device error.
    // `scene` and `filter` (or none) must outlive this: the BVH reads the meshes' vertices and
    // triangles in place where it can (padForSharing).
    // `compactAbove`: the scenes of more triangles are built compact (kCompactBvhTriangles).
    explicit EmbreeScene(const Scene& scene, const HitFilter* filter = nullptr,
                         size_t compactAbove = kCompactBvhTriangles);
    ~EmbreeScene();
    EmbreeScene(const EmbreeScene&) = delete;
    EmbreeScene& operator=(const EmbreeScene&) = delete;

    RTCSceneTy* handle() const { return scene_; }
    // The top scene's geometry id of instance 0 (Scene::instances).
    uint instanceBase() const { return instanceBase_; }
    // Whether the top scene is built compact (kCompactBvhTriangles).
    bool compact() const { return compact_; }

    // Throws if Embree reported an error since the last check.
    void checkError(const char* what) const;

  private:
    RTCDeviceTy* device_ = nullptr;
    RTCSceneTy* scene_ = nullptr;
    mutable std::string error_;
    uint instanceBase_ = 0;
    bool compact_ = false;
};

} // namespace spw
