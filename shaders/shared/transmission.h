// TransmissiveMetallicRoughness: glTF's metallic-roughness dielectric that transmits part of the
// light (KHR_materials_transmission with 0 < transmissionFactor < 1), as the extension's
// specification composes it: with metallic 0,
//   dielectric_brdf = fresnel_mix(base = mix(diffuse_brdf, specular_btdf, transmission),
//                                 layer = specular_brdf)
// which is, the reflection layer being the same in both terms,
//   f = (1 - transmission) f_opaque + transmission f_glass
// f_opaque the MetallicRoughness model at metallic 0 (shared/gltf.h), f_glass the Dielectric's
// (shared/dielectric.h: the same GGX width, the ior behind the surface, the albedo tinting each
// refraction). Blender's Principled BSDF mixes its glass the same way.
//   parameters: colour [r, g, b] ([1, 1, 1]) or texture: the base colour; roughness (1) in
//   [0, 1]: GGX alpha = roughness^2 for the glass (below kGgxSmoothAlpha, smooth glass), at least
//   kGltfMinAlpha for the opaque part (as MetallicRoughness floors it); ior (1.5) in [1.01, 10];
//   absorption ([0, 0, 0]): the medium behind the surface absorbs per unit length (Beer-Lambert,
//   shared/path.h's throughMedium); transmission (1) in [0, 1].
//   Sampling: the glass's own sampling with probability transmission, the opaque part's
//   otherwise; the pdf and fcos of a sampled direction are the mixture's. A smooth glass's
//   refraction or reflection is a delta sample (specular, pdf 0) of weight the glass's own: its
//   probability and its share of f cancel. A smooth glass contributes nothing to eval, so
//   next-event estimation reaches the opaque part only.
#ifndef SPILLWAY_SHARED_TRANSMISSION_H
#define SPILLWAY_SHARED_TRANSMISSION_H
#include "dielectric.h"
#include "gltf.h"

SHARED_BEGIN

// The opaque part's parameters: MetallicRoughness at metallic 0, its GGX width floored.
SHARED_FN ShaderParams transmissionOpaquePart(ShaderParams sh) {
    sh.metallic = 0.0f;
    sh.alpha = max(sh.alpha, kGltfMinAlpha);
    return sh;
}

// The registry's interface (shared/bsdf.h dispatches here).
SHARED_FN bool transmissionBsdfIsDelta(ShaderParams sh) {
    return sh.transmission >= 1.0f && dielectricBsdfIsDelta(sh);
}
// Where the opaque part has a diffuse lobe, as Lambert's.
SHARED_FN float transmissionBsdfConeSpread(ShaderParams sh) {
    return sh.transmission >= 1.0f ? dielectricBsdfConeSpread(sh) : 1.0f;
}
SHARED_FN vec3 transmissionBsdfEval(ShaderParams sh, vec3 albedo, vec3 ng, vec3 ns, vec3 wo,
                                    vec3 wi, OUT(float) pdf) {
    float t = sh.transmission;
    float pdfOpaque;
    float pdfGlass;
    vec3 opaque = gltfBsdfEval(transmissionOpaquePart(sh), albedo, ng, ns, wo, wi, pdfOpaque);
    vec3 glass = dielectricBsdfEval(sh, albedo, ng, ns, wo, wi, pdfGlass);
    pdf = (1.0f - t) * pdfOpaque + t * pdfGlass;
    return opaque * (1.0f - t) + glass * t;
}
SHARED_FN bool transmissionBsdfSample(ShaderParams sh, vec3 albedo, vec3 ng, vec3 ns, vec3 wo,
                                      vec3 u, OUT(vec3) wi, OUT(vec3) weight, OUT(float) pdf,
                                      OUT(bool) specular) {
    float t = sh.transmission;
    if (u.z < t) {
        vec3 v = vec3(u.x, u.y, u.z / t);
        if (!dielectricBsdfSample(sh, albedo, ng, ns, wo, v, wi, weight, pdf, specular))
            return false;
        if (specular) return true; // a smooth glass's delta lobe
    } else {
        vec3 v = vec3(u.x, u.y, (u.z - t) / (1.0f - t));
        if (!gltfBsdfSample(transmissionOpaquePart(sh), albedo, ng, ns, wo, v, wi, weight, pdf,
                            specular))
            return false;
    }
    specular = false;
    vec3 fcos = transmissionBsdfEval(sh, albedo, ng, ns, wo, wi, pdf);
    if (!(pdf > 0.0f)) return false;
    weight = fcos / pdf;
    return true;
}

SHARED_END
#endif
