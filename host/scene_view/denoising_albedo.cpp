#include "host/scene_view/denoising_albedo.h"

#include "shared/bsdf.h"
#include "shared/environment_light.h"
#include "shared/sampling.h"

namespace spw {

DenoisingAlbedo denoisingAlbedo(const ShaderParams& sh, const SurfaceHit& hit, vec3 wo) {
    constexpr int kSide = 8; // an 8 x 8 grid of directions, each with its own lobe choice
    static_assert(kSide * kSide == kDenoisingAlbedoSamples);
    vec3 rough(0.0f), specular(0.0f);
    for (int i = 0; i < kDenoisingAlbedoSamples; ++i) {
        // The lobe numbers run through the grid in another order than the directions, so that
        // every lobe sees directions from the whole grid.
        const int lobe = (i * 37) % kDenoisingAlbedoSamples;
        const vec3 u((float(i % kSide) + 0.5f) / float(kSide),
                     (float(i / kSide) + 0.5f) / float(kSide),
                     (float(lobe) + 0.5f) / float(kDenoisingAlbedoSamples));
        vec3 wi, weight;
        float pdf = 0.0f;
        bool delta = false;
        if (!bsdfSample(sh, hit.albedo, hit.ng, hit.ns, wo, u, wi, weight, pdf, delta)) continue;
        (delta ? specular : rough) += weight;
    }
    const float n = float(kDenoisingAlbedoSamples);
    rough /= n, specular /= n;
    // Specular as Cycles counts it for its denoising passes: three quarters of the reflection
    // in delta lobes, or a model whose every lobe is narrower than GGX alpha 0.075 (a polished
    // metal, glTF's roughness 0 among them, whose alpha is kGltfMinAlpha, not a delta).
    constexpr float kSpecularWidth = 0.075f;
    const bool passesOn = luminance(specular) > 3.0f * luminance(rough) ||
                          bsdfConeSpread(sh, false) <= kSpecularWidth;
    return {rough + specular, passesOn};
}

void recordPasses(AovFilm& aovs, const ShaderParams& params, const PathState& path, vec3 rayDir,
                  const SurfaceHit& hit) {
    if (path.bounce == 0) aovs.record(path, hit);
    if (!aovs.albedoPending(path)) return;
    const DenoisingAlbedo a = denoisingAlbedo(shaderAtHit(params, hit), hit, -rayDir);
    aovs.recordAlbedo(path, a.albedo, a.passesOn);
}

void recordEscape(AovFilm& aovs, const SceneView& view, const RenderParams& rp,
                  const PathState& path, vec3 rayDir) {
    if (rp.environment == kNoEmitter) return;
    const SceneView& scene = view; // as EMITTER() names it
    float pdf = 0.0f;
    aovs.recordEscape(path,
                      environmentLookUp(view, rp, EMITTER(rp.environment), rayDir, false, pdf));
}

} // namespace spw
