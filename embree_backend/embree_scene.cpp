#include "embree_backend/embree_scene.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

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

EmbreeScene::EmbreeScene(const Scene& scene, const HitFilter* filter) {
    device_ = rtcNewDevice(nullptr);
    if (!device_)
        throw std::runtime_error("cannot create the Embree device (error " +
                                 std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
    rtcSetDeviceErrorFunction(device_, onEmbreeError, &error_);
    scene_ = rtcNewScene(device_);
    rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);

    for (size_t m = 0; m < scene.meshes.size(); ++m) {
        const Mesh& mesh = scene.meshes[m];
        RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
        auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0,
                                                               RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                               mesh.positions.size()));
        for (size_t i = 0; i < mesh.positions.size(); ++i)
            for (int k = 0; k < 3; ++k)
                vb[3 * i + k] = mesh.positions[i][k];
        auto* ib = static_cast<unsigned*>(
            rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                    3 * sizeof(unsigned), mesh.triangles.size()));
        for (size_t i = 0; i < mesh.triangles.size(); ++i)
            for (int k = 0; k < 3; ++k)
                ib[3 * i + k] = mesh.triangles[i][k];
        if (filter && filter->filters(uint(m))) {
            rtcSetGeometryUserData(g, const_cast<HitFilter*>(filter));
            rtcSetGeometryIntersectFilterFunction(g, filterHits);
            rtcSetGeometryOccludedFilterFunction(g, filterHits);
        }
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(scene_, g, unsigned(m));
        rtcReleaseGeometry(g);
    }
    rtcCommitScene(scene_);
    checkError("building the scene");
}

EmbreeScene::~EmbreeScene() {
    if (scene_) rtcReleaseScene(scene_);
    if (device_) rtcReleaseDevice(device_);
}

void EmbreeScene::checkError(const char* what) const {
    if (!error_.empty()) throw std::runtime_error(error_ + " (while " + what + ")");
}

} // namespace spw
