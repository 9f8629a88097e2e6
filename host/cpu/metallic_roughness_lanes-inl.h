// MetallicRoughness's SIMD twin (host/cpu/lanes_model-inl.h): shared/metallic_roughness.h's BSDF on
// a vector of hits.
//
// Highway's per-target header convention (host/simd/simd_bsdf-inl.h): compiled once per
// instruction set, through simd_shading.cpp's foreach_target.h.
#if defined(SPILLWAY_CPU_METALLIC_ROUGHNESS_LANES_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef SPILLWAY_CPU_METALLIC_ROUGHNESS_LANES_INL_H_
#undef SPILLWAY_CPU_METALLIC_ROUGHNESS_LANES_INL_H_
#else
#define SPILLWAY_CPU_METALLIC_ROUGHNESS_LANES_INL_H_
#endif

#include "host/cpu/lanes_model-inl.h"

HWY_BEFORE_NAMESPACE();
namespace spw::HWY_NAMESPACE {

struct MetallicRoughnessLanesModel {
    Frame frame;
    V alpha; // max(alpha, kGltfMinAlpha), as metallicRoughnessBsdfEval and
             // metallicRoughnessBsdfSample take it
    explicit MetallicRoughnessLanesModel(const HitVector& h)
        : frame(shadingFrame(h.n)), alpha(gmax(h.alpha, hn::Set(D(), kGltfMinAlpha))) {}
    M delta(const HitVector&) const { return hn::FirstN(D(), 0); }
    V3 eval(const HitVector& h, V3 wi, V& pdf) const {
        return gltfEval(h.albedo, h.metallic, alpha, h.f0d, h.f90d, h.ng, h.ngDotWo, frame, h.wo,
                        wi, pdf);
    }
    BsdfSample sample(const HitVector& h, V ux, V uy, V uz) const {
        return gltfSample(h.albedo, h.metallic, alpha, h.f0d, h.f90d, h.ng, h.ngDotWo, frame, h.wo,
                          ux, uy, uz);
    }
};

} // namespace spw::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif
