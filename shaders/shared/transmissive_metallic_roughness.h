// TransmissiveMetallicRoughness: glTF's metallic-roughness dielectric that transmits part of the
// light (KHR_materials_transmission below 1, or on a metal), as the extension's specification
// composes it:
//   dielectric_brdf = fresnel_mix(base = mix(diffuse_brdf, specular_btdf, transmission),
//                                 layer = specular_brdf)
//   f = mix(dielectric_brdf, metal_brdf, metallic)
// which is, the reflection layer being the same in both terms of the first,
//   f = (1 - t) (1 - m) f_dielectric + t (1 - m) f_glass + m f_metal
//     = (1 - w) f_opaque(m / (1 - w)) + w f_glass,   w = t (1 - m)
// f_opaque(m) the MetallicRoughness model at metallic m (shared/metallic_roughness.h, whose
// dielectric and metal parts are those above, blended by glTF's appendix B as that model blends
// them), f_glass the Dielectric's (shared/dielectric.h: the same GGX width, the ior behind the
// surface, the albedo tinting each refraction). Blender's Principled BSDF mixes its glass the same
// way, its transmission weighted by 1 - metallic too.
//   parameters: colour [r, g, b] ([1, 1, 1]) or texture: the base colour; roughness (1) in
//   [0, 1]: GGX alpha = roughness^2 for the glass (below kGgxSmoothAlpha, smooth glass), at least
//   kGltfMinAlpha for the opaque part (as MetallicRoughness floors it); ior (1.5) in [1.01, 10];
//   absorption ([0, 0, 0]): the medium behind the surface absorbs per unit length (Beer-Lambert,
//   shared/path.h's throughMedium); transmission (1) in [0, 1]; metallic (0) in [0, 1].
//   Sampling: the glass's own sampling with probability w, the opaque part's
//   otherwise; the pdf and fcos of a sampled direction are the mixture's. A smooth glass's
//   refraction or reflection is a delta sample (specular, pdf 0) of weight the glass's own: its
//   probability and its share of f cancel. A smooth glass contributes nothing to eval, so
//   next-event estimation reaches the opaque part only.
#ifndef SPILLWAY_SHARED_TRANSMISSION_H
#define SPILLWAY_SHARED_TRANSMISSION_H
#include "dielectric.h"
#include "metallic_roughness.h"

SHARED_BEGIN

// The glass's weight w = transmission (1 - metallic): the dielectric part's transmission.
SHARED_FN float transmissionGlassWeight(ShaderParams sh) {
    return sh.transmission * (1.0f - sh.metallic);
}

// The opaque part's parameters: MetallicRoughness at metallic m / (1 - w) (0 where w is 1, which
// only metallic 0 gives), its GGX width floored.
SHARED_FN ShaderParams transmissionOpaquePart(ShaderParams sh) {
    float rest = 1.0f - transmissionGlassWeight(sh);
    sh.metallic = rest > 0.0f ? min(sh.metallic / rest, 1.0f) : 0.0f;
    sh.alpha = max(sh.alpha, kGltfMinAlpha);
    return sh;
}

// The registry's interface (shared/bsdf.h dispatches here).
SHARED_FN bool transmissiveMetallicRoughnessBsdfIsDelta(ShaderParams sh) {
    return transmissionGlassWeight(sh) >= 1.0f && dielectricBsdfIsDelta(sh);
}
// Where the opaque part has a diffuse lobe, as Lambert's.
SHARED_FN float transmissiveMetallicRoughnessBsdfConeSpread(ShaderParams sh) {
    return transmissionGlassWeight(sh) >= 1.0f ? dielectricBsdfConeSpread(sh) : 1.0f;
}
SHARED_FN vec3 transmissiveMetallicRoughnessBsdfEval(ShaderParams sh, vec3 albedo, vec3 ng, vec3 ns,
                                                     vec3 wo, vec3 wi, OUT(float) pdf) {
    float t = transmissionGlassWeight(sh);
    float pdfOpaque;
    float pdfGlass;
    vec3 opaque =
        metallicRoughnessBsdfEval(transmissionOpaquePart(sh), albedo, ng, ns, wo, wi, pdfOpaque);
    vec3 glass = dielectricBsdfEval(sh, albedo, ng, ns, wo, wi, pdfGlass);
    pdf = (1.0f - t) * pdfOpaque + t * pdfGlass;
    return opaque * (1.0f - t) + glass * t;
}
SHARED_FN bool transmissiveMetallicRoughnessBsdfSample(ShaderParams sh, vec3 albedo, vec3 ng,
                                                       vec3 ns, vec3 wo, vec3 u, OUT(vec3) wi,
                                                       OUT(vec3) weight, OUT(float) pdf,
                                                       OUT(bool) specular) {
    float t = transmissionGlassWeight(sh);
    if (u.z < t) {
        vec3 v = vec3(u.x, u.y, u.z / t);
        if (!dielectricBsdfSample(sh, albedo, ng, ns, wo, v, wi, weight, pdf, specular))
            return false;
        if (specular) return true; // a smooth glass's delta lobe
    } else {
        vec3 v = vec3(u.x, u.y, (u.z - t) / (1.0f - t));
        if (!metallicRoughnessBsdfSample(transmissionOpaquePart(sh), albedo, ng, ns, wo, v, wi,
                                         weight, pdf, specular))
            return false;
    }
    specular = false;
    vec3 fcos = transmissiveMetallicRoughnessBsdfEval(sh, albedo, ng, ns, wo, wi, pdf);
    if (!(pdf > 0.0f)) return false;
    weight = fcos / pdf;
    return true;
}

SHARED_END
#endif
