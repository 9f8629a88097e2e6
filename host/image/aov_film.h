// Render passes beside the image (--aov): what the camera rays' first hits were, averaged over
// the samples of each pixel that hit something, for denoisers (Open Image Denoise takes an albedo
// and a normal image) and compositors (a depth). Written as layers of the output EXR, named as
// Cycles names its passes: "Denoising Albedo" (R, G, B), "Normal" (X, Y, Z) and "Depth" (Z).
//
//   albedo  the hit's albedo as shading reads it: reflectance x colour or texture x vertex colour
//           (a MetallicRoughness hit's base colour, a Conductor's F0)
//   normal  the hit's shading normal, after any normal map, in world space (unit, unaveraged per
//           sample; a pixel's average of several is shorter than 1 at edges, as Cycles' is)
//   depth   the hit's distance from the camera along its viewing axis (planar, as Cycles' Z)
//
// A pixel no sample hit reads albedo 0, normal 0 and depth 1e10 (Cycles' background depth). The
// passes are box-filtered (each sample counts in its own pixel) whatever the image's filter.
//
// Deterministic: each camera sample writes its own slot of the iteration (indexed by its path
// id, as the film's per-sample buffer is), and endIteration() adds the slots pixel by pixel in
// sample order, so the sums do not depend on threads, batches or backend.
#pragma once

#include "shared/types.h"

#include <cstdint>
#include <string>
#include <vector>

namespace spw {

enum AovPass : unsigned { kAovAlbedo = 1u, kAovNormal = 2u, kAovDepth = 4u };

// The passes named in `list` ("albedo,normal,depth", any subset, any order), or throws
// std::invalid_argument naming the one it does not know.
unsigned parseAovList(const std::string& list);

class AovFilm {
  public:
    // `passes`: kAov* bits; `viewAxis`: the camera's unit viewing direction in the world (which is
    // camera-relative: the camera stands at the origin).
    AovFilm(int width, int height, int samplesPerIteration, unsigned passes, vec3 viewAxis);

    // Clears the iteration's slots.
    void beginIteration();
    // The first hit of camera path `pathId`: thread-safe for distinct paths.
    void record(uint pathId, const SurfaceHit& hit);
    // Adds the iteration's slots to the render's sums.
    void endIteration();

    // The EXR channel names of the passes asked for, in the order rows() writes them.
    std::vector<std::string> channelNames() const;
    // Rows y0 .. y1 - 1, channelNames().size() floats a pixel.
    void rows(int y0, int y1, float* out) const;

  private:
    static constexpr int kValues = 7; // albedo rgb, normal xyz, depth
    int width_, height_, spi_;
    unsigned passes_;
    vec3 viewAxis_;
    std::vector<float> slots_;        // per camera sample of the iteration: kValues
    std::vector<std::uint8_t> hit_;   // per camera sample: whether it hit
    std::vector<double> sums_;        // per pixel: kValues
    std::vector<std::uint32_t> hits_; // per pixel: samples that hit
};

} // namespace spw
