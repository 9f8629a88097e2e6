// Conductor's SIMD twin (host/cpu/lanes_model-inl.h): shared/conductor.h's BSDF on a vector of
// hits.
//
// Highway's per-target header convention (host/simd/simd_bsdf-inl.h): compiled once per
// instruction set, through simd_shading.cpp's foreach_target.h.
#if defined(SPILLWAY_CPU_CONDUCTOR_LANES_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef SPILLWAY_CPU_CONDUCTOR_LANES_INL_H_
#undef SPILLWAY_CPU_CONDUCTOR_LANES_INL_H_
#else
#define SPILLWAY_CPU_CONDUCTOR_LANES_INL_H_
#endif

#include "host/cpu/lanes_model-inl.h"

HWY_BEFORE_NAMESPACE();
namespace spw::HWY_NAMESPACE {

struct ConductorLanesModel {
    Frame frame;
    explicit ConductorLanesModel(const HitVector& h) : frame(shadingFrame(h.n)) {}
    M delta(const HitVector& h) const { return ggxIsSmooth(h.alpha); }
    V3 eval(const HitVector& h, V3 wi, V& pdf) const {
        return conductorEval(h.albedo, h.alpha, h.ng, h.ngDotWo, frame, h.wo, wi, pdf);
    }
    BsdfSample sample(const HitVector& h, V ux, V uy, V /*uz*/) const {
        return conductorSample(h.albedo, h.alpha, h.ng, h.ngDotWo, frame, h.wo, ux, uy);
    }
};

} // namespace spw::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif
