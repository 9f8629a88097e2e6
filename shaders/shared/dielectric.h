// Dielectric: a refracting interface (glass, water), rough or smooth.
//   parameters: ior (1.5): index of refraction behind the surface (the side its geometric normal
//   points away from; the front is vacuum, index 1), in [1.01, 10]; alpha (0): GGX width, below
//   kGgxSmoothAlpha (1e-4) the interface is smooth; colour ([1, 1, 1]) or texture: the tint of
//   the light it refracts (glTF's base colour on a transmissive material), each crossing
//   multiplied by it, reflection untinted; absorption ([0, 0, 0]): the medium behind the surface
//   absorbs sigma_a per unit length, Beer-Lambert (path.h's throughMedium).
//   Fresnel: the exact unpolarised dielectric reflectance, 1 beyond the critical angle (total
//   internal reflection).
//   Rough: Walter, Marschner, Li & Torrance 2007, "Microfacet Models for Refraction through Rough
//   Surfaces", with GGX D and the height-correlated Smith G2 (ggx.h). A microfacet normal is
//   sampled from the visible normals (Heitz 2018), then reflection with probability F(wo.h),
//   refraction otherwise; a sample that leaves on the wrong side of the macro surface is absorbed
//   (single scattering, as for the conductor). Weights: reflection G2 / G1(wo), refraction
//   G2 / G1(wo) / eta^2.
//   Smooth: two delta lobes, reflection with probability F and weight 1, refraction with
//   probability 1 - F and weight 1 / eta^2; eval gives 0, samples are `specular`.
//   Radiance convention: eta = n_t / n_i with i the side of wo; radiance is scaled by 1 / eta^2
//   across the interface (Veach 1997, 5.2: radiance, not basic radiance L / n^2, is what we
//   carry), so a camera path entering glass carries 1 / 2.25 and leaving it 2.25.
#ifndef SPILLWAY_SHARED_DIELECTRIC_H
#define SPILLWAY_SHARED_DIELECTRIC_H
#include "ggx.h"
#include "types.h"

SHARED_BEGIN

// Fresnel reflectance of unpolarised light arriving at cosine cosI (> 0) on the side of index
// n_i, eta = n_t / n_i. cosT gets the cosine of the refracted direction (0 under total internal
// reflection, where the result is 1).
// SIMD twin: host/simd/simd_bsdf-inl.h
SHARED_FN float fresnelDielectric(float cosI, float eta, OUT(float) cosT) {
    float ci = clamp(cosI, 0.0f, 1.0f);
    float sin2T = (1.0f - ci * ci) / (eta * eta);
    if (sin2T >= 1.0f) {
        cosT = 0.0f;
        return 1.0f;
    }
    cosT = sqrt(1.0f - sin2T);
    float rs = (ci - eta * cosT) / (ci + eta * cosT);
    float rp = (eta * ci - cosT) / (eta * ci + cosT);
    return 0.5f * (rs * rs + rp * rp);
}

// The relative index eta = n_t / n_i for light leaving towards wo on the side of ng it is on.
SHARED_FN float dielectricEta(float ior, vec3 ng, vec3 wo) {
    return dot(ng, wo) > 0.0f ? ior : 1.0f / ior;
}

// SIMD twin: host/simd/simd_bsdf-inl.h
SHARED_FN vec3 dielectricEval(float ior, float alpha, vec3 ng, vec3 ns, vec3 wo, vec3 wi,
                              OUT(float) pdf) {
    pdf = 0.0f;
    if (ggxIsSmooth(alpha)) return vec3(0.0f);
    float go = dot(ng, wo);
    float gi = dot(ng, wi);
    if (go == 0.0f || gi == 0.0f) return vec3(0.0f);
    bool isReflection = go * gi > 0.0f;
    float eta = dielectricEta(ior, ng, wo);
    Frame f = shadingFrame(ns, ng, wo);
    vec3 lo = frameToLocal(f, wo);
    vec3 li = frameToLocal(f, wi);
    // The shading frame must agree with the geometric sides, as sampling requires.
    if (lo.z <= 0.0f || (li.z > 0.0f) != isReflection || li.z == 0.0f) return vec3(0.0f);
    // The (generalised) half vector, on the side of wo.
    vec3 h = isReflection ? lo + li : lo + eta * li;
    float len2 = dot(h, h);
    if (!(len2 > 0.0f)) return vec3(0.0f);
    h = h * inversesqrt(len2);
    if (h.z < 0.0f) h = -h;
    float oh = dot(lo, h);
    float ih = dot(li, h);
    if (oh <= 0.0f || (isReflection ? ih <= 0.0f : ih >= 0.0f))
        return vec3(0.0f); // back-facing microfacet
    float cosT;
    float F = fresnelDielectric(oh, eta, cosT);
    float d = ggxD(h, alpha);
    float ao = ggxA(lo, alpha);
    float ci = abs(li.z);
    float denomG = ggxG2Denominator(lo, li, alpha);
    if (!(denomG > 0.0f)) return vec3(0.0f);
    if (isReflection) {
        pdf = F * d / (2.0f * (lo.z + ao));
        return vec3(F * d * ci / (2.0f * denomG));
    }
    // Refraction: dh/dwi = |wi.h| / (wi.h + wo.h / eta)^2.
    float s = ih + oh / eta;
    float s2 = s * s;
    if (!(s2 > 0.0f)) return vec3(0.0f);
    float dv = 2.0f * oh * d / (lo.z + ao); // visible normal density of h
    pdf = (1.0f - F) * dv * (-ih) / s2;
    // (1 - F) D G2 |wi.h| |wo.h| / (s^2 co) / eta^2, with G2 = 2 co ci / denomG.
    return vec3((1.0f - F) * d * 2.0f * ci * (-ih) * oh / (denomG * s2 * eta * eta));
}

// SIMD twin: host/simd/simd_bsdf-inl.h
SHARED_FN bool dielectricSample(float ior, float alpha, vec3 ng, vec3 ns, vec3 wo, vec3 u,
                                OUT(vec3) wi, OUT(vec3) weight, OUT(float) pdf,
                                OUT(bool) specular) {
    float go = dot(ng, wo);
    if (go == 0.0f) return false;
    float eta = dielectricEta(ior, ng, wo);
    Frame f = shadingFrame(ns, ng, wo);
    vec3 lo = frameToLocal(f, wo);
    if (lo.z <= 0.0f) return false;
    bool isSmooth = ggxIsSmooth(alpha);
    // The facet: the shading normal itself, or a visible microfacet normal.
    vec3 h = isSmooth ? vec3(0.0f, 0.0f, 1.0f) : ggxSampleVisibleNormal(lo, alpha, vec2(u.x, u.y));
    float oh = dot(lo, h);
    if (oh <= 0.0f) return false;
    float cosT;
    float F = fresnelDielectric(oh, eta, cosT);
    bool isReflection = u.z < F;
    vec3 li = isReflection ? 2.0f * oh * h - lo : (oh / eta - cosT) * h - lo / eta;
    if (isReflection ? li.z <= 0.0f : li.z >= 0.0f) return false; // wrong side of the macro surface
    wi = frameToWorld(f, li);
    if ((go * dot(ng, wi) > 0.0f) != isReflection) return false; // the geometric side disagrees
    float etaScale = isReflection ? 1.0f : 1.0f / (eta * eta);
    if (isSmooth) {
        specular = true;
        pdf = 0.0f;
        weight = vec3(etaScale);
        return true;
    }
    float ao = ggxA(lo, alpha);
    float denomG = ggxG2Denominator(lo, li, alpha);
    float d = ggxD(h, alpha);
    if (isReflection) {
        pdf = F * d / (2.0f * (lo.z + ao));
    } else {
        float ih = dot(li, h);
        float s = ih + oh / eta;
        pdf = (1.0f - F) * (2.0f * oh * d / (lo.z + ao)) * (-ih) / max(s * s, 1e-37f);
    }
    // G2 / G1(wo) = ci (co + ao) / denomG, times the radiance scaling on refraction.
    weight = vec3(abs(li.z) * (lo.z + ao) / denomG * etaScale);
    specular = false;
    return pdf > 0.0f && denomG > 0.0f;
}

// The registry's interface (shared/bsdf.h dispatches here). The albedo (reflectance x colour or
// texture) tints refraction; x 1 leaves an untinted interface's values as they are, to the bit.
SHARED_FN bool dielectricBsdfIsDelta(ShaderParams sh) {
    return ggxIsSmooth(sh.alpha);
}
// As the conductor's: about alpha radians for a rough interface.
SHARED_FN float dielectricBsdfConeSpread(ShaderParams sh) {
    return sh.alpha;
}
SHARED_FN vec3 dielectricBsdfEval(ShaderParams sh, vec3 albedo, vec3 ng, vec3 ns, vec3 wo, vec3 wi,
                                  OUT(float) pdf) {
    vec3 fcos = dielectricEval(sh.ior, sh.alpha, ng, ns, wo, wi, pdf);
    return dot(ng, wo) * dot(ng, wi) < 0.0f ? fcos * albedo : fcos;
}
SHARED_FN bool dielectricBsdfSample(ShaderParams sh, vec3 albedo, vec3 ng, vec3 ns, vec3 wo, vec3 u,
                                    OUT(vec3) wi, OUT(vec3) weight, OUT(float) pdf,
                                    OUT(bool) specular) {
    if (!dielectricSample(sh.ior, sh.alpha, ng, ns, wo, u, wi, weight, pdf, specular)) return false;
    if (dot(ng, wo) * dot(ng, wi) < 0.0f) weight = weight * albedo;
    return true;
}

SHARED_END
#endif
