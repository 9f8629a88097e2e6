// Camera rays: the pixel sampler (Independent, Grid, Stratified, Sobol) picks a point in the pixel,
// the camera (PinHole, ThinLens) turns it into a world-space ray. Both are pure functions of (seed,
// pixel, sample), so the sorted backends can recompute a sample's film position when its
// contribution arrives instead of carrying it in every ray.
#pragma once

#include "host/scene/scene.h"
#include "shared/rng.h"

namespace spw {

struct CameraRay {
    vec3 origin;
    vec3 dir;     // unit
    vec2 filmPos; // continuous pixel coordinates: pixel (x, y) spans [x, x+1) x [y, y+1)
};

// The sampler of every dimension but the camera sample's place in the pixel (kSampler*).
inline uint dimensionSampler(SamplerType s) {
    return s == SamplerType::Sobol ? kSamplerSobol : kSamplerIndependent;
}

class CameraModel {
  public:
    // `sampleBase`: n of the n x n samples per pixel and iteration (after --spp).
    CameraModel(const Scene& scene, int sampleBase);

    // `sample` is the index within the iteration (it picks the Grid/Stratified cell);
    // `sampleIndex` the render-wide one that keys the random numbers.
    CameraRay generate(uint x, uint y, uint sample, uint sampleIndex, uint seed) const;
    vec2 filmPosition(uint x, uint y, uint sample, uint sampleIndex, uint seed) const;
    // The same with the sample's random numbers given: u = randomNumbers(x, y, sampleIndex, seed)
    // (for a caller that makes many at once).
    CameraRay generate(uint x, uint y, uint sample, vec4 u) const;
    vec2 filmPosition(uint x, uint y, uint sample, vec4 u) const;
    // The camera's random numbers: whether it reads any (not a Grid pinhole), and what they are,
    // rand4(sampling(), seed, pixel, sampleIndex, kBounceCamera, kDimCamera).
    bool usesRandomNumbers() const;
    uint sampling() const { return dimensionSampler(sampler_); }
    vec4 randomNumbers(uint x, uint y, uint sampleIndex, uint seed) const;
    // The angle (radians) one pixel subtends at the image centre: camera rays' cone spread
    // (shared/cone.h).
    float pixelSpread() const { return 2.0f * tanX_ / float(width_); }

  private:
    Camera cam_;
    SamplerType sampler_;
    int width_, height_, base_;
    float tanX_, tanY_;
    mat3 rot_;
    vec3 eye_;
};

} // namespace spw
