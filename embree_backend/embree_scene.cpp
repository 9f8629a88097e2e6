#include "embree_backend/embree_scene.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace spw {
namespace {
void onEmbreeError(void* user, RTCError code, const char* message) {
    auto* error = static_cast<std::string*>(user);
    if (error->empty())
        *error = "Embree error " + std::to_string(int(code)) + ": " + (message ? message : "");
}
// Embree's filter function for a mesh with holes: candidate hits HitFilter::keeps rejects are
// marked invalid, so traversal goes on past them.
void filterHits(const RTCFilterFunctionNArguments* args) {
    const auto* filter = static_cast<const HitFilter*>(args->geometryUserPtr);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0) continue;
        const uint mesh = RTCHitN_geomID(args->hit, args->N, i);
        const uint prim = RTCHitN_primID(args->hit, args->N, i);
        const float u = RTCHitN_u(args->hit, args->N, i), v = RTCHitN_v(args->hit, args->N, i);
        const vec3 org(RTCRayN_org_x(args->ray, args->N, i), RTCRayN_org_y(args->ray, args->N, i),
                       RTCRayN_org_z(args->ray, args->N, i));
        const vec3 dir(RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i),
                       RTCRayN_dir_z(args->ray, args->N, i));
        if (!filter->keeps(mesh, prim, u, v, org, dir)) args->valid[i] = 0;
    }
}
} // namespace

namespace {
// Mesh `m` as a triangle geometry of `target`, attached under its own index (so that a hit's
// geometry id names the mesh in the scene's list, whichever Embree scene holds it).
void attachMesh(RTCDevice device, RTCScene target, const Scene& scene, size_t m,
                const HitFilter* filter) {
    const Mesh& mesh = scene.meshes[m];
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    // The mesh's own arrays where the vertices have room for Embree's 16-byte load of the last
    // one (padForSharing): the scene's geometry is held once. Else a copy.
    static_assert(sizeof(vec3) == 3 * sizeof(float) && sizeof(uvec3) == 3 * sizeof(unsigned));
    if (mesh.positions.capacity() > mesh.positions.size()) {
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                   mesh.positions.data(), 0, sizeof(vec3), mesh.positions.size());
    } else {
        auto* vb = static_cast<vec3*>(rtcSetNewGeometryBuffer(
            g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, sizeof(vec3), mesh.positions.size()));
        std::copy(mesh.positions.begin(), mesh.positions.end(), vb);
    }
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, mesh.triangles.data(),
                               0, sizeof(uvec3), mesh.triangles.size());
    if (filter && filter->filters(uint(m))) {
        rtcSetGeometryUserData(g, const_cast<HitFilter*>(filter));
        rtcSetGeometryIntersectFilterFunction(g, filterHits);
        rtcSetGeometryOccludedFilterFunction(g, filterHits);
    }
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(target, g, unsigned(m));
    rtcReleaseGeometry(g);
}

// A scene of `triangles` triangles, compact past `compactAbove` (kCompactBvhTriangles).
RTCScene newScene(RTCDevice device, size_t triangles, size_t compactAbove) {
    RTCScene s = rtcNewScene(device);
    const bool compact = triangles > compactAbove;
    rtcSetSceneFlags(s, compact ? RTCSceneFlags(RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_COMPACT)
                                : RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(s, RTC_BUILD_QUALITY_HIGH);
    return s;
}
} // namespace

EmbreeScene::EmbreeScene(const Scene& scene, const HitFilter* filter, size_t compactAbove) {
    device_ = rtcNewDevice(nullptr);
    if (!device_)
        throw std::runtime_error("cannot create the Embree device (error " +
                                 std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
    rtcSetDeviceErrorFunction(device_, onEmbreeError, &error_);
    // Each prototype a scene of its own, built once; the world's meshes in the top scene.
    std::vector<size_t> triangles(scene.prototypes.size() + 1, 0); // the top scene's last
    for (const Mesh& m : scene.meshes)
        triangles[m.prototype >= 0 ? size_t(m.prototype) : scene.prototypes.size()] +=
            m.triangles.size();
    compact_ = triangles.back() > compactAbove;
    scene_ = newScene(device_, triangles.back(), compactAbove);
    std::vector<RTCScene> prototypes;
    for (size_t p = 0; p < scene.prototypes.size(); ++p)
        prototypes.push_back(newScene(device_, triangles[p], compactAbove));
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
        const int proto = scene.meshes[m].prototype;
        attachMesh(device_, proto >= 0 ? prototypes[size_t(proto)] : scene_, scene, m, filter);
    }
    for (RTCScene p : prototypes)
        rtcCommitScene(p);
    // The instances, after the meshes' ids: instance i is geometry meshes.size() + i.
    for (size_t i = 0; i < scene.instances.size(); ++i) {
        const Instance& inst = scene.instances[i];
        RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_INSTANCE);
        rtcSetGeometryInstancedScene(g, prototypes[inst.prototype]);
        rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, &inst.toWorld[0][0]);
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(scene_, g, unsigned(scene.meshes.size() + i));
        rtcReleaseGeometry(g);
    }
    for (RTCScene p : prototypes) // the instances hold them
        rtcReleaseScene(p);
    rtcCommitScene(scene_);
    checkError("building the scene");
    instanceBase_ = uint(scene.meshes.size());
}

EmbreeScene::~EmbreeScene() {
    if (scene_) rtcReleaseScene(scene_);
    if (device_) rtcReleaseDevice(device_);
}

void EmbreeScene::checkError(const char* what) const {
    if (!error_.empty()) throw std::runtime_error(error_ + " (while " + what + ")");
}

} // namespace spw
