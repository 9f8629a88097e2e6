#include "host/camera.h"

#include "shared/rng.h"
#include "shared/sampling.h"

namespace spw {

CameraModel::CameraModel(const Scene& scene, int sampleBase)
    : cam_(scene.camera), sampler_(scene.sampler), width_(scene.image.width),
      height_(scene.image.height), base_(sampleBase) {
    tanX_ = cam_.tanHalfFovX();
    tanY_ = tanX_ * float(height_) / float(width_);
    rot_ = mat3(cam_.cameraToWorld);
    eye_ = vec3(cam_.cameraToWorld[3]);
}

vec2 CameraModel::filmPosition(uint x, uint y, uint sample, uint sampleIndex, uint seed) const {
    vec2 offset;
    uint cx = sample % uint(base_), cy = sample / uint(base_);
    if (sampler_ == SamplerType::Grid) {
        offset = (vec2(float(cx), float(cy)) + 0.5f) / float(base_);
    } else {
        vec4 u = rand4(seed, y * uint(width_) + x, sampleIndex, kBounceCamera, kDimCamera);
        if (sampler_ == SamplerType::Stratified)
            offset = (vec2(float(cx), float(cy)) + vec2(u.x, u.y)) / float(base_);
        else
            offset = vec2(u.x, u.y);
    }
    offset = glm::min(offset, vec2(kOneMinusEpsilon));
    return vec2(float(x), float(y)) + offset;
}

CameraRay CameraModel::generate(uint x, uint y, uint sample, uint sampleIndex, uint seed) const {
    CameraRay r;
    r.filmPos = filmPosition(x, y, sample, sampleIndex, seed);
    // Film plane at z = -1 in camera space, +Y up, pixel rows going down.
    float sx = (2.0f * r.filmPos.x / float(width_) - 1.0f) * tanX_;
    float sy = (1.0f - 2.0f * r.filmPos.y / float(height_)) * tanY_;
    vec3 d(sx, sy, -1.0f);
    vec3 o(0.0f);
    if (cam_.type == CameraType::ThinLens && cam_.apertureRadius > 0.0f) {
        vec4 u = rand4(seed, y * uint(width_) + x, sampleIndex, kBounceCamera, kDimCamera);
        vec2 lens = sampleConcentricDisk(vec2(u.z, u.w)) * cam_.apertureRadius;
        vec3 focus = d * cam_.focalDistance;
        o = vec3(lens, 0.0f);
        d = focus - o;
    }
    r.origin = eye_ + rot_ * o;
    r.dir = glm::normalize(rot_ * d);
    return r;
}

} // namespace spw
