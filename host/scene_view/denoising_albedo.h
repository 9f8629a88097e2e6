// What a hit gives the "Denoising Albedo" pass (--aov albedo) as denoisers take it (Open Image
// Denoise, Blender's Denoise node, OptiX; Cycles' pass of that name): the albedo of what the
// pixel shows. A hit's albedo is its BSDF's directional albedo toward the viewer, the integral of
// f cos over the sphere, so a glossy surface's counts its Fresnel-weighted specular reflection
// beside its diffuse colour; a hit whose reflection is specular (three quarters of it or more in
// delta lobes, or every lobe narrower than GGX alpha 0.075: a mirror, a polished metal, smooth
// glass) passes the pass on to the next hit the path finds, weighted by its own albedo (its
// reflectance, and transmittance), as Cycles waits for the next bounce there.
#pragma once

#include "host/image/aov_film.h"
#include "shared/scene_access.h"
#include "shared/types.h"

namespace spw {

struct DenoisingAlbedo {
    vec3 albedo;   // the directional albedo, every lobe's (a specular hit's: its reflectance)
    bool passesOn; // specular: the pass takes the next hit's albedo instead
};

// `sh` the hit's shader parameters (shaderAtHit's), `wo` the direction back along the ray. The
// integral from kDenoisingAlbedoSamples stratified samples of the BSDF, the same for every hit
// (deterministic, on every backend: the pass is written on the host).
DenoisingAlbedo denoisingAlbedo(const ShaderParams& sh, const SurfaceHit& hit, vec3 wo);

constexpr int kDenoisingAlbedoSamples = 64;

// What a hit of `path` (its ray along `rayDir`) gives the passes: a camera ray's first hit its
// normal and depth, and the albedo while it is pending. `params`: the hit's shader's.
void recordPasses(AovFilm& aovs, const ShaderParams& params, const PathState& path, vec3 rayDir,
                  const SurfaceHit& hit);
// What `path` escaping along `rayDir` gives the albedo pass: the environment's radiance there
// (AovFilm::recordEscape); nothing without an environment.
void recordEscape(AovFilm& aovs, const SceneView& view, const RenderParams& rp,
                  const PathState& path, vec3 rayDir);

} // namespace spw
