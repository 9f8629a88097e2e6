// CameraModel::generateMany (camera.h): a block of camera rays SIMD-wide, their random numbers
// included, compiled once per instruction set through foreach_target.h. Each step is
// CameraModel::filmPosition's and generate's, in their order and rounding (no fused
// multiply-add; glm's mat3 * vec3 and normalize written out as glm computes them), so that the
// sorted backends' camera rays are the reference's to the bit
// (CameraModel.GenerateManyIsGenerateToTheBit).
#include "host/scene/camera.h"

#include "host/simd/lanes.h"

#include <algorithm>

#ifndef SPILLWAY_CAMERA_LANES
#define SPILLWAY_CAMERA_LANES
namespace spw::camera_lanes {
using simd::Floats;
using simd::Uints;
using simd::Vec3s;

// The block's samples: the pixel, the render-wide sample index (random numbers), and the
// Grid/Stratified cell, (sample % base, sample / base) as floats.
struct CameraSampleLanes {
    Uints x, y, sampleIndex;
    Floats cellX, cellY;
};
struct CameraRayLanes {
    Vec3s origin, dir;
    Floats filmX, filmY;
};
} // namespace spw::camera_lanes
#endif

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "host/scene/camera_wide.cpp"
#include <hwy/foreach_target.h> // must come before highway.h
#include <hwy/highway.h>

#include "host/simd/simd_math-inl.h"

HWY_BEFORE_NAMESPACE();
namespace spw::HWY_NAMESPACE {

using camera_lanes::CameraRayLanes;
using camera_lanes::CameraSampleLanes;

// glm's m * v: m[0][r] v.x + m[1][r] v.y + m[2][r] v.z, left to right.
HWY_INLINE V3 rotate(const mat3& m, V3 v) {
    const D d;
    auto row = [&](int r) {
        return hn::Add(
            hn::Add(hn::Mul(hn::Set(d, m[0][r]), v.x), hn::Mul(hn::Set(d, m[1][r]), v.y)),
            hn::Mul(hn::Set(d, m[2][r]), v.z));
    };
    return {row(0), row(1), row(2)};
}

// Twin of filmPosition's clamp into the pixel: float(x) + offset, and where that rounds up to
// x + 1, the float below x + 1 (nextafter towards 0 of a float >= 1: its bits minus one).
HWY_INLINE V intoPixel(VU x, V offset) {
    const D d;
    const hn::RebindToSigned<D> di;
    const V p = hn::Add(hn::ConvertTo(d, hn::BitCast(di, x)), offset);
    const V next = hn::ConvertTo(d, hn::BitCast(di, hn::Add(x, hn::Set(DU(), 1u))));
    const V below = hn::BitCast(d, hn::Sub(hn::BitCast(DU(), next), hn::Set(DU(), 1u)));
    return hn::IfThenElse(hn::Ge(p, next), below, p);
}

void GenerateCameraLanes(const CameraNumbers& c, bool random, uint sampling, uint seed,
                         const CameraSampleLanes& in, size_t count, CameraRayLanes& out) {
    const D d;
    const V zero = hn::Zero(d), one = hn::Set(d, 1.0f), two = hn::Set(d, 2.0f);
    const V base = hn::Set(d, float(c.base));
    for (size_t i = 0; i < count; i += hn::Lanes(d)) {
        const VU x = hn::Load(DU(), in.x.v + i), y = hn::Load(DU(), in.y.v + i);
        V ux = zero, uy = zero, uz = zero, uw = zero;
        if (random) {
            const VU pixel = hn::Add(hn::Mul(y, hn::Set(DU(), uint(c.width))), x);
            const U4 u = rand4(sampling, seed, pixel, hn::Load(DU(), in.sampleIndex.v + i),
                               hn::Set(DU(), kBounceCamera), kDimCamera);
            ux = uintToUnit(u.x);
            uy = uintToUnit(u.y);
            uz = uintToUnit(u.z);
            uw = uintToUnit(u.w);
        }
        // filmPosition
        V ox = ux, oy = uy;
        const V cx = load(in.cellX, i), cy = load(in.cellY, i);
        if (c.sampler == SamplerType::Grid) {
            ox = hn::Div(hn::Add(cx, hn::Set(d, 0.5f)), base);
            oy = hn::Div(hn::Add(cy, hn::Set(d, 0.5f)), base);
        } else if (c.sampler == SamplerType::Stratified) {
            ox = hn::Div(hn::Add(cx, ux), base);
            oy = hn::Div(hn::Add(cy, uy), base);
        }
        const V limit = hn::Set(d, kOneMinusEpsilon);
        const V fx = intoPixel(x, gmin(ox, limit)), fy = intoPixel(y, gmin(oy, limit));
        // generate: the film plane at z = -1 in camera space
        const V sx = hn::Mul(hn::Sub(hn::Div(hn::Mul(two, fx), hn::Set(d, float(c.width))), one),
                             hn::Set(d, c.tanX));
        const V sy = hn::Mul(hn::Sub(one, hn::Div(hn::Mul(two, fy), hn::Set(d, float(c.height)))),
                             hn::Set(d, c.tanY));
        V3 dir{sx, sy, hn::Set(d, -1.0f)};
        V3 o{zero, zero, zero};
        if (c.lens) {
            const V3 disk = sampleCosineHemisphere(uz, uw);
            const V aperture = hn::Set(d, c.apertureRadius);
            o = {hn::Mul(disk.x, aperture), hn::Mul(disk.y, aperture), zero};
            dir = sub(mul(dir, hn::Set(d, c.focalDistance)), o);
        }
        const V3 origin = add(V3{hn::Set(d, c.eye.x), hn::Set(d, c.eye.y), hn::Set(d, c.eye.z)},
                              rotate(c.rot, o));
        const V3 unit = normalize(rotate(c.rot, dir));
        store(origin.x, out.origin.x, i);
        store(origin.y, out.origin.y, i);
        store(origin.z, out.origin.z, i);
        store(unit.x, out.dir.x, i);
        store(unit.y, out.dir.y, i);
        store(unit.z, out.dir.z, i);
        store(fx, out.filmX, i);
        store(fy, out.filmY, i);
    }
}

} // namespace spw::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace spw {
HWY_EXPORT(GenerateCameraLanes);

void CameraModel::generateMany(const uint* x, const uint* y, const uint* sample,
                               const uint* sampleIndex, uint seed, size_t n, CameraRay* out) const {
    using simd::kBlock;
    camera_lanes::CameraSampleLanes in;
    camera_lanes::CameraRayLanes rays;
    const bool cells = n_.sampler == SamplerType::Grid || n_.sampler == SamplerType::Stratified;
    const uint base = uint(n_.base);
    for (size_t begin = 0; begin < n; begin += kBlock) {
        const size_t count = std::min(kBlock, n - begin);
        const size_t end = simd::wholeVectors(count);
        for (size_t k = 0; k < end; ++k) { // the padding repeats the last lane
            const size_t i = begin + std::min(k, count - 1);
            in.x.v[k] = x[i];
            in.y.v[k] = y[i];
            in.sampleIndex.v[k] = sampleIndex[i];
            in.cellX.v[k] = cells ? float(sample[i] % base) : 0.0f;
            in.cellY.v[k] = cells ? float(sample[i] / base) : 0.0f;
        }
        HWY_DYNAMIC_DISPATCH(GenerateCameraLanes)
        (n_, usesRandomNumbers(), sampling(), seed, in, end, rays);
        for (size_t k = 0; k < count; ++k) {
            CameraRay& r = out[begin + k];
            r.origin = vec3(rays.origin.x.v[k], rays.origin.y.v[k], rays.origin.z.v[k]);
            r.dir = vec3(rays.dir.x.v[k], rays.dir.y.v[k], rays.dir.z.v[k]);
            r.filmPos = vec2(rays.filmX.v[k], rays.filmY.v[k]);
        }
    }
}

} // namespace spw
#endif
