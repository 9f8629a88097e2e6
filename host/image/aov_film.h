// Render passes beside the image (--aov): what the camera rays' first hits were, averaged over
// the samples of each pixel that hit something, for denoisers (Open Image Denoise, Blender's
// Denoise node and OptiX take an albedo and a normal image) and compositors (a depth). Written as
// layers of the output EXR, named as Cycles names its passes: "Denoising Albedo" (R, G, B),
// "Normal" (X, Y, Z) and "Depth" (Z), and "Camera Normal" (X, Y, Z), which Cycles does not have.
//
//   albedo         the albedo of what the pixel shows, as denoisers take it
//                  (host/scene_view/denoising_albedo.h): the first hit's directional albedo
//                  (its diffuse colour and its Fresnel-weighted specular reflection), or through
//                  perfect mirrors and smooth glass the next hit's, times the path's throughput
//                  through them
//   normal         the first hit's shading normal, after any normal map, in world space: the
//                  scene's axes, glTF's +Y up (unit, unaveraged per sample; a pixel's average of
//                  several is shorter than 1 at edges, as Cycles' is)
//   camera-normal  the same in camera space, +X right, +Y up, +Z toward the camera (OpenGL's
//                  and OptiX's convention)
//   depth          the first hit's distance from the camera along its viewing axis (planar, as
//                  Cycles' Z)
//
// Each layer's convention is in the EXR's header too ("spillway/<layer>"). A pixel no sample hit
// reads normal 0 and depth 1e10 (Cycles' background depth), and as its albedo the environment's
// radiance where its rays left the scene (Cycles' background albedo; 0 without an environment),
// as does a sample whose mirror chain ends in the environment. The passes are box-filtered (each
// sample counts in its own pixel) whatever the image's filter.
//
// Accumulated per pixel, as the film is: each sample's values are added, as they are recorded,
// to the pixel's sums of the iteration, 128-bit fixed point with atomic integer adds (exact, so
// the sums do not depend on threads, batches or backend), and endIteration() adds those to the
// render's. What the passes keep a camera sample is one bit: whether its albedo is still to come
// (its hits so far were specular); the weight of the specular hits it went through is the path's
// throughput. Memory: 24 bytes a pixel for each value (3 the albedo, 3 the normals, 1 the depth)
// and 16 for the counts, plus a bit a sample of an iteration (bytes()).
#pragma once

#include "shared/types.h"

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace spw {

enum AovPass : unsigned { kAovAlbedo = 1u, kAovNormal = 2u, kAovDepth = 4u, kAovCameraNormal = 8u };

// The passes named in `list` ("albedo,normal,camera-normal,depth", any subset, any order), or
// throws std::invalid_argument naming the one it does not know.
unsigned parseAovList(const std::string& list);

class AovFilm {
  public:
    // `passes`: kAov* bits; `cameraToWorld`: the camera's axes in the world (columns: right,
    // up, back; the world is camera-relative: the camera stands at the origin).
    AovFilm(int width, int height, int samplesPerIteration, unsigned passes, mat3 cameraToWorld);

    // Clears the iteration's sums (if the last was not ended) and its samples' bits.
    void beginIteration();
    // The first hit of camera path `path` (bounce 0): thread-safe for distinct paths.
    void record(const PathState& path, const SurfaceHit& hit);
    // Whether camera path `path` hit something and its denoising albedo is still to come: this
    // is its first hit, or its hits so far were specular (host/scene_view/denoising_albedo.h).
    bool albedoPending(const PathState& path) const {
        return (passes_ & kAovAlbedo) && size_t(path.pathId) < samples_ &&
               (path.bounce == 0u || (pending_[path.pathId / 64u].load(std::memory_order_relaxed) &
                                      bit(path.pathId)) != 0u);
    }
    // A hit of `path` (while albedoPending) and its directional albedo: `passesOn` for a
    // specular hit (the next hit decides), else it ends the pass with that albedo times the
    // path's throughput through the specular hits before it.
    void recordAlbedo(const PathState& path, vec3 albedo, bool passesOn);
    // Camera path `path` escaping with `radiance` from the environment along its ray: where
    // the camera ray itself missed, or its hits so far were specular, the albedo pass takes
    // that radiance (times the path's throughput), as Cycles' "Denoising Albedo" takes the
    // background; the normal and depth of a missed sample stay out of the pixel's means.
    void recordEscape(const PathState& path, vec3 radiance);
    // Adds the iteration's sums to the render's.
    void endIteration();

    // The EXR channel names of the passes asked for, in the order rows() writes them.
    std::vector<std::string> channelNames() const;
    // Each layer's convention, as EXR header attributes: ("spillway/Normal", "world space, ...").
    std::vector<std::pair<std::string, std::string>> layerNotes() const;
    // Rows y0 .. y1 - 1, channelNames().size() floats a pixel.
    void rows(int y0, int y1, float* out) const;
    // The bytes the passes hold.
    size_t bytes() const;

  private:
    static std::uint64_t bit(uint pathId) { return std::uint64_t(1) << (pathId % 64u); }
    size_t pixelOf(uint pathId) const { return size_t(pathId) / size_t(spi_); }
    // Adds v, clamped to the value's bound, to value k of the pixel's iteration sums.
    void add(size_t pixel, int k, float v);
    void addAlbedo(size_t pixel, vec3 albedo);
    void count(size_t pixel, int which) { iterCounts_[pixel * 2 + size_t(which)].fetch_add(1); }
    enum { kHitCount = 0, kAlbedoCount = 1 };

    int width_, spi_;
    size_t pixels_, samples_;
    unsigned passes_;
    mat3 cameraToWorld_;
    vec3 viewAxis_; // -cameraToWorld_[2]: depth is along it
    // Where each value sits among a pixel's (-1: not asked for), how many there are, and each
    // value's fixed point: q = v x 2^exponent_, |v| <= 2^bound_ (the scene format's limits).
    int albedoAt_ = -1, normalAt_ = -1, depthAt_ = -1, values_ = 0;
    int exponent_[7] = {}, bound_[7] = {};
    // The iteration's sums: two words a value (the low 64 bits, then the high, two's
    // complement), and two counts a pixel (samples that hit, samples that give an albedo).
    std::unique_ptr<std::atomic<std::uint64_t>[]> iter_;
    std::unique_ptr<std::atomic<std::uint32_t>[]> iterCounts_;
    bool iterDirty_ = false; // the sums may hold values: new, or an iteration that did not end
    // Per camera sample of the iteration, with the albedo pass: its albedo is still to come.
    std::unique_ptr<std::atomic<std::uint64_t>[]> pending_;
    size_t pendingWords_ = 0;
    std::vector<double> sums_;                 // the render's, per pixel: values_
    std::vector<std::uint32_t> hits_;          // per pixel: samples that hit
    std::vector<std::uint32_t> albedoSamples_; // per pixel: samples that hit or saw the environment
};

} // namespace spw
