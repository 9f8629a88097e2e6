// simdTarget (simd_target.h): the name of the target Highway's dynamic dispatch picks, compiled
// once per instruction set through foreach_target.h.
#include "host/simd/simd_target.h"

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "host/simd/simd_target.cpp"
#include <hwy/foreach_target.h> // must come before highway.h
#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace spw::HWY_NAMESPACE {

const char* TargetName() {
    return hwy::TargetName(HWY_TARGET);
}

} // namespace spw::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace spw {
HWY_EXPORT(TargetName);

const char* simdTarget() {
    return HWY_DYNAMIC_DISPATCH(TargetName)();
}

} // namespace spw
#endif
