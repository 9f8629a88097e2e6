// What a surface model's SIMD twin is made of (host/cpu/wide_models.h lists the models that have
// one): a struct <Name>LanesModel, in host/cpu/<stem>_lanes-inl.h, built from a HitVector, with
//   M delta(const HitVector&) const                      bsdfIsDelta's twin, lane by lane
//   V3 eval(const HitVector&, V3 wi, V& pdf) const       bsdfEval's: fcos and its pdf
//   BsdfSample sample(const HitVector&, V ux, V uy, V uz) const   bsdfSample's
// each the same operations in the same order as the model's shared functions (shared/<stem>.h),
// so that simd_shading.cpp's shadeLanes<Model> is shadeSurface() to the bit.
//
// Highway's per-target header convention (host/simd/simd_bsdf-inl.h): compiled once per
// instruction set, through simd_shading.cpp's foreach_target.h.
#if defined(SPILLWAY_CPU_LANES_MODEL_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef SPILLWAY_CPU_LANES_MODEL_INL_H_
#undef SPILLWAY_CPU_LANES_MODEL_INL_H_
#else
#define SPILLWAY_CPU_LANES_MODEL_INL_H_
#endif

#include "host/simd/simd_bsdf-inl.h" // and simd_math-inl.h

#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace spw::HWY_NAMESPACE {

// One vector of hits: what every model's eval and sample read.
struct HitVector {
    V3 ng, albedo, wo;
    V ngDotWo, alpha, ior, metallic;
    V3 f0d; // MetallicRoughness: the dielectric part's F0 colour and F90
    V f90d;
    V3 ns; // the interpolated shading normal
    V3 n;  // facingShadingNormal
};

} // namespace spw::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif
