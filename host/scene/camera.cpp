#include "host/scene/camera.h"

#include "shared/rng.h"
#include "shared/sampling.h"

#include <cmath>

namespace spw {

CameraModel::CameraModel(const Scene& scene, int sampleBase) {
    const Camera& cam = scene.camera;
    n_.sampler = scene.sampler;
    n_.lens = cam.type == CameraType::ThinLens && cam.apertureRadius > 0.0f;
    n_.apertureRadius = cam.apertureRadius;
    n_.focalDistance = cam.focalDistance;
    n_.width = scene.image.width;
    n_.height = scene.image.height;
    n_.base = sampleBase;
    n_.tanX = cam.tanHalfFovX();
    n_.tanY = n_.tanX * float(n_.height) / float(n_.width);
    n_.rot = mat3(cam.cameraToWorld);
    n_.eye = vec3(cam.cameraToWorld[3]);
}

vec4 CameraModel::randomNumbers(uint x, uint y, uint sampleIndex, uint seed) const {
    return rand4(sampling(), seed, y * uint(n_.width) + x, sampleIndex, kBounceCamera, kDimCamera);
}

vec2 CameraModel::filmPosition(uint x, uint y, uint sample, uint sampleIndex, uint seed) const {
    // The Grid sampler's place in the pixel needs no random number.
    return filmPosition(x, y, sample,
                        n_.sampler == SamplerType::Grid ? vec4(0.0f)
                                                        : randomNumbers(x, y, sampleIndex, seed));
}

// SIMD twin: host/scene/camera_wide.cpp
vec2 CameraModel::filmPosition(uint x, uint y, uint sample, vec4 u) const {
    vec2 offset;
    uint cx = sample % uint(n_.base), cy = sample / uint(n_.base);
    if (n_.sampler == SamplerType::Grid) {
        offset = (vec2(float(cx), float(cy)) + 0.5f) / float(n_.base);
    } else {
        if (n_.sampler == SamplerType::Stratified)
            offset = (vec2(float(cx), float(cy)) + vec2(u.x, u.y)) / float(n_.base);
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
    return n_.sampler != SamplerType::Grid || n_.lens;
}

CameraRay CameraModel::generate(uint x, uint y, uint sample, uint sampleIndex, uint seed) const {
    return generate(x, y, sample,
                    usesRandomNumbers() ? randomNumbers(x, y, sampleIndex, seed) : vec4(0.0f));
}

// SIMD twin: host/scene/camera_wide.cpp
CameraRay CameraModel::generate(uint x, uint y, uint sample, vec4 u) const {
    CameraRay r;
    r.filmPos = filmPosition(x, y, sample, u);
    // Film plane at z = -1 in camera space, +Y up, pixel rows going down.
    float sx = (2.0f * r.filmPos.x / float(n_.width) - 1.0f) * n_.tanX;
    float sy = (1.0f - 2.0f * r.filmPos.y / float(n_.height)) * n_.tanY;
    vec3 d(sx, sy, -1.0f);
    vec3 o(0.0f);
    if (n_.lens) {
        vec2 lens = sampleConcentricDisk(vec2(u.z, u.w)) * n_.apertureRadius;
        vec3 focus = d * n_.focalDistance;
        o = vec3(lens, 0.0f);
        d = focus - o;
    }
    r.origin = n_.eye + n_.rot * o;
    r.dir = glm::normalize(n_.rot * d);
    return r;
}

} // namespace spw
