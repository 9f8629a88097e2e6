#include "host/scene/camera.h"

#include "shared/rng.h"
#include "shared/sampling.h"

#include <cmath>

namespace spw {

CameraModel::CameraModel(const Scene& scene, int sampleBase)
    : cam_(scene.camera), sampler_(scene.sampler), width_(scene.image.width),
      height_(scene.image.height), base_(sampleBase) {
    tanX_ = cam_.tanHalfFovX();
    tanY_ = tanX_ * float(height_) / float(width_);
    rot_ = mat3(cam_.cameraToWorld);
    eye_ = vec3(cam_.cameraToWorld[3]);
}

vec4 CameraModel::randomNumbers(uint x, uint y, uint sampleIndex, uint seed) const {
    return rand4(sampling(), seed, y * uint(width_) + x, sampleIndex, kBounceCamera, kDimCamera);
}

vec2 CameraModel::filmPosition(uint x, uint y, uint sample, uint sampleIndex, uint seed) const {
    // The Grid sampler's place in the pixel needs no random number.
    return filmPosition(x, y, sample,
                        sampler_ == SamplerType::Grid ? vec4(0.0f)
                                                      : randomNumbers(x, y, sampleIndex, seed));
}

vec2 CameraModel::filmPosition(uint x, uint y, uint sample, vec4 u) const {
    vec2 offset;
    uint cx = sample % uint(base_), cy = sample / uint(base_);
    if (sampler_ == SamplerType::Grid) {
        offset = (vec2(float(cx), float(cy)) + 0.5f) / float(base_);
    } else {
        if (sampler_ == SamplerType::Stratified)
            offset = (vec2(float(cx), float(cy)) + vec2(u.x, u.y)) / float(base_);
        else
            offset = vec2(u.x, u.y);
    }
    offset = glm::min(offset, vec2(kOneMinusEpsilon));
    // float(x) + offset rounds up to x + 1 when offset is within half an ulp of x + 1 of 1 (for
    // x >= 2, offsets above 1 - 2^-24 x): the sample would land in the next pixel, and the
    // backends would disagree on which pixel's film it belongs to. Keep it in its own pixel.
    vec2 p = vec2(float(x), float(y)) + offset;
    if (p.x >= float(x + 1u)) p.x = std::nextafter(float(x + 1u), 0.0f);
    if (p.y >= float(y + 1u)) p.y = std::nextafter(float(y + 1u), 0.0f);
    return p;
}

bool CameraModel::usesRandomNumbers() const {
    return sampler_ != SamplerType::Grid ||
           (cam_.type == CameraType::ThinLens && cam_.apertureRadius > 0.0f);
}

CameraRay CameraModel::generate(uint x, uint y, uint sample, uint sampleIndex, uint seed) const {
    return generate(x, y, sample,
                    usesRandomNumbers() ? randomNumbers(x, y, sampleIndex, seed) : vec4(0.0f));
}

CameraRay CameraModel::generate(uint x, uint y, uint sample, vec4 u) const {
    CameraRay r;
    r.filmPos = filmPosition(x, y, sample, u);
    // Film plane at z = -1 in camera space, +Y up, pixel rows going down.
    float sx = (2.0f * r.filmPos.x / float(width_) - 1.0f) * tanX_;
    float sy = (1.0f - 2.0f * r.filmPos.y / float(height_)) * tanY_;
    vec3 d(sx, sy, -1.0f);
    vec3 o(0.0f);
    if (cam_.type == CameraType::ThinLens && cam_.apertureRadius > 0.0f) {
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
