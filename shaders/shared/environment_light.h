// The environment: radiance at infinity, seen by rays that escape the scene, sampled by its map.
#ifndef SPILLWAY_SHARED_ENVIRONMENT_LIGHT_H
#define SPILLWAY_SHARED_ENVIRONMENT_LIGHT_H
#include "light_sample.h"

SHARED_BEGIN

// A lat-long map of W x H texels covers the sphere of directions: texel column u = phi / 2pi + 1/2
// with phi = atan2(d.x, -d.z) (the map's centre looks along -Z), row v = theta / pi with
// theta = acos(d.y) (row 0 is straight up, +Y). Its radiance is constant over each texel, and so
// is the sampling density in (u, v): texels are picked in proportion to luminance x sin(theta)
// (the solid angle a texel spans), a row from the marginal CDF, then a column from that row's
// conditional CDF (Pharr et al., pbrt 3rd ed., 14.2.4). LIGHT_DATA holds, as floats from 0:
//   3WH   the texels' RGB radiance, row by row
//   H     the rows' CDF (inclusive prefix sums, the last exactly 1)
//   WH    each row's CDF over its columns
//   H-1   cos(theta) of the boundaries between rows, k pi / H for k = 1 .. H-1
//   W-1   cos(phi) of the boundaries between columns, phi = -pi + 2 pi k / W for k = 1 .. W-1
// A direction's texel is found by comparing it with the boundaries, never through acos and
// atan: GLSL lets those be far less exact than C++'s (lavapipe's differ by 1e-6), and a
// direction near a boundary would then read one texel on one backend and its neighbour on
// another. A constant environment has no map: it is sampled uniformly over the sphere.

SHARED_FN vec3 environmentDirection(vec2 uv) {
    float phi = (uv.x - 0.5f) * (2.0f * kPi);
    float theta = uv.y * kPi;
    float s = sin(theta);
    return vec3(s * sin(phi), cos(theta), -s * cos(phi));
}

// Whether direction d's phi = atan2(d.x, -d.z) is at least the k-th column boundary (k >= 1),
// from cos(phi) = -d.z / rho on either half of the circle, without dividing.
SHARED_FN bool environmentPastColumn(SCENE_PARAM RenderParams rp, vec3 d, float rho, uint k) {
    uint w = rp.envWidth;
    float c = LIGHT_DATA(4u * w * rp.envHeight + 2u * rp.envHeight - 1u + k - 1u);
    if (2u * k <= w) return d.x < 0.0f ? -d.z >= c * rho : true; // boundary phi <= 0
    return d.x >= 0.0f && -d.z <= c * rho;                       // boundary phi > 0
}

// The map texel a unit direction falls in (binary searches over the boundaries).
SHARED_FN uvec2 environmentTexel(SCENE_PARAM RenderParams rp, vec3 d) {
    uint rowCos = 4u * rp.envWidth * rp.envHeight + rp.envHeight;
    uint lo = 0u;
    uint hi = rp.envHeight - 1u;
    while (lo < hi) { // the first boundary below d: cos falls as theta grows
        uint mid = (lo + hi) >> 1u;
        if (d.y > LIGHT_DATA(rowCos + mid))
            hi = mid;
        else
            lo = mid + 1u;
    }
    uint row = lo;
    float rho = sqrt(d.x * d.x + d.z * d.z);
    lo = 0u;
    hi = rp.envWidth - 1u;
    while (lo < hi) { // how many column boundaries phi has passed
        uint mid = (lo + hi + 1u) >> 1u;
        if (environmentPastColumn(SCENE_ARG rp, d, rho, mid))
            lo = mid;
        else
            hi = mid - 1u;
    }
    return uvec2(lo, row);
}

SHARED_FN float environmentCdfInterval(SCENE_PARAM uint base, uint i) {
    return LIGHT_DATA(base + i) - (i > 0u ? LIGHT_DATA(base + i - 1u) : 0.0f);
}

// The radiance of map texel t.
SHARED_FN vec3 environmentTexelRadiance(SCENE_PARAM RenderParams rp, uvec2 t) {
    uint i = 3u * (t.y * rp.envWidth + t.x);
    return vec3(LIGHT_DATA(i), LIGHT_DATA(i + 1u), LIGHT_DATA(i + 2u));
}

// Solid-angle density of environmentSample() choosing direction d in map texel t, d's
// sin(theta) sinTheta > 0.
SHARED_FN float environmentTexelPdf(SCENE_PARAM RenderParams rp, uvec2 t, float sinTheta) {
    uint marginal = 3u * rp.envWidth * rp.envHeight;
    uint conditional = marginal + rp.envHeight + t.y * rp.envWidth;
    float p = environmentCdfInterval(SCENE_ARG marginal, t.y) *
              environmentCdfInterval(SCENE_ARG conditional, t.x);
    return p * float(rp.envWidth) * float(rp.envHeight) / (2.0f * kPi * kPi * sinTheta);
}

// Radiance arriving from direction d (unit) out of environment e, and with `withPdf` the
// solid-angle density of environmentSample() choosing d (before the pick probability) in pdf:
// the texel found once for both.
SHARED_FN vec3 environmentLookUp(SCENE_PARAM RenderParams rp, Emitter e, vec3 d, bool withPdf,
                                 OUT(float) pdf) {
    pdf = 0.25f * kInvPi;
    if (rp.envWidth == 0u) return e.radiance;
    uvec2 t = environmentTexel(SCENE_ARG rp, d);
    if (withPdf) {
        float sinTheta = sqrt(max(0.0f, 1.0f - d.y * d.y));
        pdf = sinTheta > 0.0f ? environmentTexelPdf(SCENE_ARG rp, t, sinTheta) : 0.0f;
    }
    return environmentTexelRadiance(SCENE_ARG rp, t);
}

// Solid-angle density of environmentSample() choosing d, before the pick probability.
SHARED_FN float environmentPdf(SCENE_PARAM RenderParams rp, vec3 d) {
    if (rp.envWidth == 0u) return 0.25f * kInvPi;
    float sinTheta = sqrt(max(0.0f, 1.0f - d.y * d.y));
    if (!(sinTheta > 0.0f)) return 0.0f;
    return environmentTexelPdf(SCENE_ARG rp, environmentTexel(SCENE_ARG rp, d), sinTheta);
}

// Index of the first entry of cdf[base .. base + n) above u (binary search), and u rescaled to
// [0, 1) within that entry's interval.
SHARED_FN uint environmentSearch(SCENE_PARAM uint base, uint n, INOUT(float) u) {
    uint lo = 0u;
    uint hi = n - 1u;
    while (lo < hi) {
        uint mid = (lo + hi) >> 1u;
        if (LIGHT_DATA(base + mid) > u)
            hi = mid;
        else
            lo = mid + 1u;
    }
    float below = lo > 0u ? LIGHT_DATA(base + lo - 1u) : 0.0f;
    float width = LIGHT_DATA(base + lo) - below;
    u = width > 0.0f ? min((u - below) / width, kOneMinusEpsilon) : 0.5f;
    return lo;
}

// A direction toward the environment, with importance over its map (or uniform without one),
// and the map texel it was drawn in (0 without a map).
SHARED_FN vec3 environmentSample(SCENE_PARAM RenderParams rp, vec2 u, OUT(uvec2) texel) {
    texel = uvec2(0u);
    if (rp.envWidth == 0u) {
        float z = 1.0f - 2.0f * u.x;
        float r = sqrt(max(0.0f, 1.0f - z * z));
        float phi = 2.0f * kPi * u.y;
        return vec3(r * cos(phi), z, r * sin(phi));
    }
    uint marginal = 3u * rp.envWidth * rp.envHeight;
    uint row = environmentSearch(SCENE_ARG marginal, rp.envHeight, u.y);
    uint column =
        environmentSearch(SCENE_ARG marginal + rp.envHeight + row * rp.envWidth, rp.envWidth, u.x);
    texel = uvec2(column, row);
    return environmentDirection(
        vec2((float(column) + u.x) / float(rp.envWidth), (float(row) + u.y) / float(rp.envHeight)));
}

// A direction toward the environment, by its map; radiance is what arrives along it. The
// radiance and density are the texel's the direction was drawn in, not searched for again: the
// same texel but for a direction that rounding put a hair across its edge, where it is the
// texel whose density drew it.
SHARED_FN LightSample environment_lightSample(SCENE_PARAM RenderParams rp, Emitter e,
                                              SurfaceHit hit, vec2 u) {
    UNUSED(hit);
    LightSample ls;
    uvec2 texel;
    ls.wi = environmentSample(SCENE_ARG rp, u, texel);
    ls.radiance = e.radiance;
    float pdf = 0.25f * kInvPi;
    if (rp.envWidth != 0u) {
        float sinTheta = sqrt(max(0.0f, 1.0f - ls.wi.y * ls.wi.y));
        pdf = sinTheta > 0.0f ? environmentTexelPdf(SCENE_ARG rp, texel, sinTheta) : 0.0f;
        ls.radiance = environmentTexelRadiance(SCENE_ARG rp, texel);
    }
    ls.pdf = e.pickPdf * pdf;
    ls.tmax = kInfiniteDistance;
    return ls;
}

SHARED_END
#endif
