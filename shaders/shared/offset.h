// Where a new ray starts: off its surface by a distance derived from the floating-point error of
// the hit point, never by a scene-unit epsilon, so that a scene scaled by 1e-4 or 1e4, or moved
// 1e6 units from the origin, is traced the same way.
//
// The error model (after pbrt-v4's error bounds, Pharr et al. 2023, 6.8, and Wächter & Binder,
// "A Fast and Robust Method for Avoiding Self-Intersection", Ray Tracing Gems ch. 6):
//   * the hit point p = w v0 + u v1 + v v2 is interpolated from the triangle's vertices; its
//     error in coordinate i is at most gamma(7) (|w v0_i| + |u v1_i| + |v v2_i|), below
//     2^-21.2 m_i with m_i = max(|v0_i|, |v1_i|, |v2_i|, |p_i|);
//   * the traversal that takes the new ray computes vertex - origin in float, and a plane
//     distance from it, with errors of a few ulps of the same magnitudes m_i;
//   * only the error along the normal matters, so the two add up to c * dot(m, |ng|).
// We offset by 2^-20 dot(m, |ng|): at least 8 ulps of every coordinate the normal leans on. Two
// consequences of taking m per component and from the vertices, not from |p| alone:
//   * a big triangle that straddles the origin (vertices at 1e5, hit point near 0) gets the offset
//     its vertices' magnitude calls for: |p| alone would give almost none, and acne;
//   * an axis-aligned plane is offset by the magnitude of its own coordinate only: a floor at
//     y = 0 is exact in y however far out in x and z it reaches, and so is the traversal's
//     y - origin_y, so no ulps of the large in-plane coordinates are needed. Wächter & Binder's
//     per-component integer offsets fail exactly there: a component whose magnitude is below
//     1/32 (the floor's y = 0) gets their absolute fallback of 1/65536 scene units, an epsilon
//     in disguise (wider than the 1e-5 gap between the Cornell box's light and its ceiling once
//     the box is scaled by 1e-4), and no component is moved for the error of the others.
// The absolute 1e-30 keeps a point on a plane through 0 movable (still a normal float, and the
// products the traversal forms with it stay normal for edges down to 1e-4).
//
// Rounding p + ng * offset to float loses at most half an ulp per component, 1/16 of the offset
// along the normal, so at least 15/16 of it survives.
#ifndef SPILLWAY_SHARED_OFFSET_H
#define SPILLWAY_SHARED_OFFSET_H
#include "compat.h"

SHARED_BEGIN

const float kOffsetRelative = 1.0f / 1048576.0f; // 2^-20
const float kOffsetAbsolute = 1e-30f;
// A shadow ray toward the environment: beyond anything the scene format places (1e15 units).
const float kInfiniteDistance = 1e30f;

// How far rays leave point p of triangle (v0, v1, v2), whose unit geometric normal is n.
// SIMD twin: host/simd/simd_math-inl.h
SHARED_FN float surfaceOffset(vec3 p, vec3 v0, vec3 v1, vec3 v2, vec3 n) {
    vec3 m = max(max(abs(v0), abs(v1)), max(abs(v2), abs(p)));
    return dot(m, abs(n)) * kOffsetRelative + kOffsetAbsolute;
}

// p moved by `offset` off its surface, to the side of ng that `dir` leaves towards.
// SIMD twin: host/simd/simd_math-inl.h
SHARED_FN vec3 offsetOrigin(vec3 p, vec3 ng, float offset, vec3 dir) {
    float side = dot(ng, dir) >= 0.0f ? 1.0f : -1.0f;
    return p + ng * (side * offset);
}

// The largest tmax of a shadow ray from offsetOrigin(p, ...) to a point q at distance `dist`
// from p that cannot reach q's own surface: q's surface lies within offsetQ of q along its normal,
// the origin moved offsetP, and the ray meets that surface at cosine cosQ, so the ray must stop
// (offsetP + offsetQ) / cosQ short of q; the relative 2^-20 covers the rounding of the
// traversal's distance itself. Non-positive when no such ray exists (cosQ ~ 0).
// SIMD twin: host/simd/simd_math-inl.h
SHARED_FN float shadowRayTmax(float dist, float offsetP, float offsetQ, float cosQ) {
    if (!(cosQ > 0.0f)) return 0.0f;
    return dist * (1.0f - kOffsetRelative) - (offsetP + offsetQ) / cosQ;
}

// The shadow terminator of a smooth-shaded mesh (Hanika 2021, "Hacking the Shadow Terminator",
// as Cycles ships it): where the vertex normals say the surface curves, the true surface lies
// above the flat triangle that was hit, and a shadow ray from the triangle toward a grazing light
// is caught by the neighbouring triangles, the terminator drawn in facets. SurfaceHit::lift is
// the height of the smooth surface over the triangle at p: each vertex's tangent plane, where p
// lies below it, lifts p onto it, and the lifts are interpolated with p's barycentrics. A
// shadow ray that leaves toward that side starts this much higher (at most a quarter of the way
// to the light, tmax), one on the other side not at all. The lift is not applied to
// continuation rays: one that left a concave region from above its triangles could escape
// geometry that should have caught it.
// SIMD twin: host/simd/simd_math-inl.h
SHARED_FN float shadowLift(vec3 ng, float lift, vec3 dir, float tmax) {
    return dot(ng, dir) * lift > 0.0f && tmax > 0.0f ? min(abs(lift), 0.25f * tmax) : 0.0f;
}

SHARED_END
#endif
