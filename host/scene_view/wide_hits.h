// Hit setup's arithmetic SIMD-wide, for a block of closest hits (Google Highway, dynamic
// dispatch, as the shading kernels and the texture filter): the interpolated position and
// shading normal, the geometric normal, the self-intersection offset, the texture coordinates
// and the ray cone's footprint in texture space. HitSetup (hit_setup.h) gathers each hit's
// triangle into the lanes and scatters the results; this file only computes. Each lane is
// HitSetup::setUpGeometry and HitSetup::textureQuery to the bit: the same operations in the same
// order, each rounded once (no fused multiply-add), glm's vector operations written out in
// glm's order (HitSetup.WideSetupIsTheScalarSetupBitForBit).
#pragma once

#include "host/simd/lanes.h"

#include <cstddef>

namespace spw {

// A block of hits, a row of lanes per value (host/simd/lanes.h).
struct HitLanes {
    // In: Embree's barycentrics and distance, the triangle's vertices, vertex normals and
    // texture coordinates (each 0 where the mesh has none, and the masks 0), the ray's unit
    // direction and its cone's width and spread (shared/cone.h, unpacked).
    simd::Floats u, v, t;
    simd::Vec3s p0, p1, p2, n0, n1, n2, dir;
    simd::Vec2s t0, t1, t2;
    simd::Uints hasNormals, hasUvs; // all ones where the mesh has them
    // false: those rows and masks are not read (with anyUvs, nor dir and the cone's)
    bool anyNormals = false, anyUvs = false;
    simd::Floats coneWidth, coneSpread;
    // Out: what SurfaceHit takes (p, ng, ns, offset, lift: 0 without vertex normals), and the
    // texture lookup's coordinates and filter footprint (HitSetup::textureQuery).
    simd::Vec3s p, ng, ns;
    simd::Floats offset, lift, footprint;
    simd::Vec2s uv;
};

// The results of lanes [0, count) (count a multiple of simd::kMaxLanes, at most simd::kBlock).
void setUpHitLanes(size_t count, HitLanes& lanes);

} // namespace spw
