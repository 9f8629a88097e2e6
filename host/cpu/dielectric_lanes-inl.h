// Dielectric's SIMD twin (host/cpu/lanes_model-inl.h): shared/dielectric.h's BSDF on a vector of
// hits.
//
// Highway's per-target header convention (host/simd/simd_bsdf-inl.h): compiled once per
// instruction set, through simd_shading.cpp's foreach_target.h.
#if defined(SPILLWAY_CPU_DIELECTRIC_LANES_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef SPILLWAY_CPU_DIELECTRIC_LANES_INL_H_
#undef SPILLWAY_CPU_DIELECTRIC_LANES_INL_H_
#else
#define SPILLWAY_CPU_DIELECTRIC_LANES_INL_H_
#endif

#include "host/cpu/lanes_model-inl.h"

HWY_BEFORE_NAMESPACE();
namespace spw::HWY_NAMESPACE {

struct DielectricLanesModel {
    Frame frame;
    explicit DielectricLanesModel(const HitVector& h) : frame(shadingFrame(h.n)) {}
    M delta(const HitVector& h) const { return ggxIsSmooth(h.alpha); }
    V3 eval(const HitVector& h, V3 wi, V& pdf) const {
        const V3 fcos = dielectricEval(h.ior, h.alpha, h.ng, h.ngDotWo, frame, h.wo, wi, pdf);
        return select(refracts(h, wi), mul(fcos, h.albedo), fcos);
    }
    BsdfSample sample(const HitVector& h, V ux, V uy, V uz) const {
        BsdfSample s = dielectricSample(h.ior, h.alpha, h.ng, h.ngDotWo, frame, h.wo, ux, uy, uz);
        s.weight = select(refracts(h, s.wi), mul(s.weight, h.albedo), s.weight);
        return s;
    }
    // dielectricBsdfEval's and dielectricBsdfSample's test: wi on the other side of ng from wo,
    // where the albedo tints.
    static M refracts(const HitVector& h, V3 wi) {
        return hn::Lt(hn::Mul(h.ngDotWo, dot(h.ng, wi)), hn::Zero(D()));
    }
};

} // namespace spw::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif
