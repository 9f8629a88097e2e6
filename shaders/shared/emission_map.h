// Emission maps: an emitting triangle whose radiance varies over it by an image (glTF's
// emissiveTexture), radiance = Emitter::radiance x the image at the point. The host bakes each
// map into the light data (host/scene_view/lights.cpp) as it resolves texture images elsewhere: the
// finest MIP level, decoded to linear RGB, read bilinearly and repeating, as the host's own
// finest-level lookup reads it (host/textures/textures.cpp). The kernels read no texture, so the
// image must be where they can reach it: next-event estimation needs its value at the point it
// picks on the triangle, and a ray that hits the triangle at the point it hit.
//
// An emitter's record, at Emitter::map in LIGHT_DATA, 9 floats:
//   0-1  (s, t) of vertex 0: image coordinates, s = u and t = 1 - v after the texture
//        transform (it is affine, so transforming the vertices' coordinates is exact)
//   2-3  (s, t) of vertex 1 minus vertex 0's
//   4-5  (s, t) of vertex 2 minus vertex 0's
//   6    where the image's texels start in LIGHT_DATA (the bits of a uint)
//   7-8  its width and height (the bits of uints, below 2^30), each with the wrap mode along
//        it (kWrap*, shared/texture_wrap.h: glTF's sampler wrapS, wrapT) in the top two bits
// and each image, 3 w h floats: RGB, row by row from the top.
#ifndef SPILLWAY_SHARED_EMISSION_MAP_H
#define SPILLWAY_SHARED_EMISSION_MAP_H
#include "scene_access.h"
#include "texture_wrap.h"

SHARED_BEGIN

const uint kEmissionMapRecord = 9u;

SHARED_FN vec3 emissionMapTexel(SCENE_PARAM uint image, uint width, uint x, uint y) {
    uint i = image + 3u * (y * width + x);
    return vec3(LIGHT_DATA(i), LIGHT_DATA(i + 1u), LIGHT_DATA(i + 2u));
}

// The map of `record` at barycentric coordinates b (the weights of vertices 1 and 2): bilinear
// between texel centres at ((i + 0.5) / w, (j + 0.5) / h), wrapped as the record says.
SHARED_FN vec3 emissionMapValue(SCENE_PARAM uint record, vec2 b) {
    float s = LIGHT_DATA(record) + b.x * LIGHT_DATA(record + 2u) + b.y * LIGHT_DATA(record + 4u);
    float t =
        LIGHT_DATA(record + 1u) + b.x * LIGHT_DATA(record + 3u) + b.y * LIGHT_DATA(record + 5u);
    uint image = floatBitsToUint(LIGHT_DATA(record + 6u));
    uint wBits = floatBitsToUint(LIGHT_DATA(record + 7u));
    uint hBits = floatBitsToUint(LIGHT_DATA(record + 8u));
    uint w = wBits & 0x3FFFFFFFu;
    uint h = hBits & 0x3FFFFFFFu;
    s = wrapCoordinate(s, wBits >> 30u, w);
    t = wrapCoordinate(t, hBits >> 30u, h);
    // Periodic: only the fraction matters. A NaN coordinate reads the first texel.
    s -= floor(s);
    t -= floor(t);
    if (!(s >= 0.0f && s <= 1.0f)) s = 0.0f;
    if (!(t >= 0.0f && t <= 1.0f)) t = 0.0f;
    float x = s * float(w) - 0.5f;
    float y = t * float(h) - 0.5f;
    float xf = floor(x);
    float yf = floor(y);
    float ax = x - xf;
    float ay = y - yf;
    uint x0 = xf < 0.0f ? w - 1u : min(uint(xf), w - 1u);
    uint y0 = yf < 0.0f ? h - 1u : min(uint(yf), h - 1u);
    uint x1 = x0 + 1u == w ? 0u : x0 + 1u;
    uint y1 = y0 + 1u == h ? 0u : y0 + 1u;
    vec3 a = emissionMapTexel(SCENE_ARG image, w, x0, y0);
    vec3 c = emissionMapTexel(SCENE_ARG image, w, x1, y0);
    vec3 d = emissionMapTexel(SCENE_ARG image, w, x0, y1);
    vec3 f = emissionMapTexel(SCENE_ARG image, w, x1, y1);
    vec3 top = a + ax * (c - a);
    vec3 bottom = d + ax * (f - d);
    return top + ay * (bottom - top);
}

// The barycentric coordinates (weights of vertices 1 and 2) of a point p in a triangle
// emitter's plane, as ratios of areas measured along its unit normal (no product of four edge
// lengths, which tiny and huge scenes would take out of float's range).
SHARED_FN vec2 emitterBarycentrics(Emitter e, vec3 p) {
    vec3 d = p - e.p0;
    float twiceArea = dot(cross(e.e1, e.e2), e.normal);
    return vec2(dot(cross(d, e.e2), e.normal), dot(cross(e.e1, d), e.normal)) / twiceArea;
}

// A triangle emitter's radiance at barycentric coordinates b: its constant radiance, times its
// map's value where it has one.
SHARED_FN vec3 emitterRadiance(SCENE_PARAM Emitter e, vec2 b) {
    if (e.map == kNoEmissionMap) return e.radiance;
    return e.radiance * emissionMapValue(SCENE_ARG e.map, b);
}

// The same at a point p on the emitter (a ray's hit): its barycentric coordinates are found
// only where there is a map to read.
SHARED_FN vec3 emitterRadianceAt(SCENE_PARAM Emitter e, vec3 p) {
    if (e.map == kNoEmissionMap) return e.radiance;
    return e.radiance * emissionMapValue(SCENE_ARG e.map, emitterBarycentrics(e, p));
}

SHARED_END
#endif
