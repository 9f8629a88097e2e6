// Lambert's SIMD twin (host/cpu/lanes_model-inl.h): shared/lambert.h's BSDF on a vector of hits.
//
// Highway's per-target header convention (host/simd/simd_bsdf-inl.h): compiled once per
// instruction set, through simd_shading.cpp's foreach_target.h.
#if defined(SPILLWAY_CPU_LAMBERT_LANES_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef SPILLWAY_CPU_LAMBERT_LANES_INL_H_
#undef SPILLWAY_CPU_LAMBERT_LANES_INL_H_
#else
#define SPILLWAY_CPU_LAMBERT_LANES_INL_H_
#endif

#include "host/cpu/lanes_model-inl.h"

HWY_BEFORE_NAMESPACE();
namespace spw::HWY_NAMESPACE {

struct LambertLanesModel {
    explicit LambertLanesModel(const HitVector&) {}
    M delta(const HitVector&) const { return hn::FirstN(D(), 0); }
    V3 eval(const HitVector& h, V3 wi, V& pdf) const {
        return lambertEval(h.albedo, h.ng, h.ngDotWo, h.n, wi, pdf);
    }
    BsdfSample sample(const HitVector& h, V ux, V uy, V /*uz*/) const { // lambertSample
        const V zero = hn::Zero(D());
        const V3 local = sampleCosineHemisphere(ux, uy);
        BsdfSample s;
        s.wi = normalize(toWorld(local, h.n));
        s.ok = hn::Not(
            hn::Or(hn::Le(hn::Mul(h.ngDotWo, dot(h.ng, s.wi)), zero), hn::Le(local.z, zero)));
        s.specular = hn::FirstN(D(), 0);
        s.weight = h.albedo;
        s.pdf = hn::Mul(local.z, hn::Set(D(), kInvPi));
        return s;
    }
};

} // namespace spw::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif
