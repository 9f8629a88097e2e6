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

// What a camera ray is made of besides its sample: CameraModel's numbers, read by generate() and
// by its SIMD twin (camera_wide.cpp) alike.
struct CameraNumbers {
    SamplerType sampler;
    bool lens; // a ThinLens with an aperture
    float apertureRadius, focalDistance;
    int width, height, base;
    float tanX, tanY;
    mat3 rot;
    vec3 eye;
};

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
    // n rays at once, random numbers included, SIMD-wide (camera_wide.cpp): out[i] is
    // generate(x[i], y[i], sample[i], sampleIndex[i], seed) to the bit.
    void generateMany(const uint* x, const uint* y, const uint* sample, const uint* sampleIndex,
                      uint seed, size_t n, CameraRay* out) const;
    // The camera's random numbers: whether it reads any (not a Grid pinhole), and what they are,
    // rand4(sampling(), seed, pixel, sampleIndex, kBounceCamera, kDimCamera).
    bool usesRandomNumbers() const;
    uint sampling() const { return dimensionSampler(n_.sampler); }
    vec4 randomNumbers(uint x, uint y, uint sampleIndex, uint seed) const;
    // The angle (radians) one pixel subtends at the image centre: camera rays' cone spread
    // (shared/cone.h).
    float pixelSpread() const { return 2.0f * n_.tanX / float(n_.width); }

  private:
    CameraNumbers n_;
};

} // namespace spw
