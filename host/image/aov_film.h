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
// Deterministic: each camera sample writes its own slot of the iteration (indexed by its path
// id, as the film's per-sample buffer is), and endIteration() adds the slots pixel by pixel in
// sample order, so the sums do not depend on threads, batches or backend.
#pragma once

#include "shared/types.h"

#include <cstdint>
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

    // Clears the iteration's slots.
    void beginIteration();
    // The first hit of camera path `pathId`: thread-safe for distinct paths.
    void record(uint pathId, const SurfaceHit& hit);
    // Whether camera path `pathId` hit something and its denoising albedo is still to come: its
    // hits so far were specular (host/scene_view/denoising_albedo.h).
    bool albedoPending(uint pathId) const {
        return (passes_ & kAovAlbedo) && size_t(pathId) < state_.size() &&
               (state_[pathId] == kHit || state_[pathId] == kThroughSpecular);
    }
    // A hit of path `pathId` (while albedoPending) and its directional albedo: `passesOn` for a
    // specular hit (the next hit decides, the pass weighted by this one's albedo), else it ends
    // the pass, times the albedos of the specular hits before it.
    void recordAlbedo(uint pathId, vec3 albedo, bool passesOn);
    // Camera path `pathId` escaping with `radiance` from the environment along its ray: where
    // the camera ray itself missed, or its hits so far were specular, the albedo pass takes
    // that radiance (times the specular hits' albedos), as Cycles' "Denoising Albedo" takes the
    // background; the normal and depth of a missed sample stay out of the pixel's means.
    void recordEscape(uint pathId, vec3 radiance);
    // Adds the iteration's slots to the render's sums.
    void endIteration();

    // The EXR channel names of the passes asked for, in the order rows() writes them.
    std::vector<std::string> channelNames() const;
    // Each layer's convention, as EXR header attributes: ("spillway/Normal", "world space, ...").
    std::vector<std::pair<std::string, std::string>> layerNotes() const;
    // Rows y0 .. y1 - 1, channelNames().size() floats a pixel.
    void rows(int y0, int y1, float* out) const;

  private:
    static constexpr int kValues = 7; // albedo rgb, normal xyz, depth
    // A camera sample's state in the iteration.
    enum : std::uint8_t { kMissed = 0, kEscaped, kHit, kThroughSpecular, kAlbedoDone };
    int width_, spi_;
    unsigned passes_;
    mat3 cameraToWorld_;
    vec3 viewAxis_;                   // -cameraToWorld_[2]: depth is along it
    std::vector<float> slots_;        // per camera sample of the iteration: kValues
    std::vector<vec3> chain_;         // per camera sample: its specular hits' albedos, multiplied
    std::vector<std::uint8_t> state_; // per camera sample
    std::vector<double> sums_;        // per pixel: kValues
    std::vector<std::uint32_t> hits_; // per pixel: samples that hit
    std::vector<std::uint32_t> albedoSamples_; // per pixel: samples that hit or saw the environment
};

} // namespace spw
