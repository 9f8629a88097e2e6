// Ray cones (Akenine-Möller, Nilsson, Andersson, Barré-Brisebois, Toth & Karras 2019, "Texture
// Level of Detail Strategies for Real-Time Ray Tracing", Ray Tracing Gems ch. 20; and the 2021
// follow-up, "Improved Shader and Texture Level of Detail Using Ray Cones", JCGT 10(1)): every
// ray carries the cone its pixel subtends, as the cone's width at the ray's origin and its
// spread angle. At a hit at distance t the cone is width + spread * t wide; hit setup divides
// that by |cos| of the incidence and scales it into texture space to get the filter width it
// hands the texture system as derivatives, so a lookup reads the MIP level the pixel needs.
//
// Camera rays start with width 0 and the spread of one pixel at the image centre (a thin lens
// is treated as its pinhole: exact at the focal distance). A bounce keeps the width the cone had
// at the hit and adds the BSDF's own spread (<stem>BsdfConeSpread, bsdf.h): 0 for a delta lobe
// (the surfaces are flat triangles, so a mirror keeps the cone), the lobe's angular width
// otherwise. Shadow rays read no texture and carry no cone.
//
// Packed in 16 bits, in PathState::cone and so in both ray records (host/pipeline/ray_record.h):
// each value a small float, rounded to nearest from float32's bits — the width (high byte) with
// 2 mantissa bits and exponents from 2^-32 (codes up to 3.8e9 world units), the spread (low
// byte) with 3 mantissa bits from 2^-24 (up to 240 radians); code 0 is zero, and values beyond
// a range clamp to its ends. Steps are at most 25 % and 12.5 % apart, finer than LOD needs.
// Integer arithmetic only, so every backend (C++ and GLSL alike) packs a value to the same code;
// shadeSurface() quantises the next ray's cone itself, so every record format carries it exactly.
#ifndef SPILLWAY_SHARED_CONE_H
#define SPILLWAY_SHARED_CONE_H
#include "compat.h"

SHARED_BEGIN

// A value x >= 0 as a byte: float32's exponent and top `mantissaBits` mantissa bits, rounded
// to nearest, counted from 2^minExponent (code 1) up; 0 for x = 0 (or NaN).
SHARED_FN uint coneCode(float x, uint mantissaBits, int minExponent) {
    if (!(x > 0.0f)) return 0u;
    uint q =
        (floatBitsToUint(min(x, 3.0e38f)) + (1u << (22u - mantissaBits))) >> (23u - mantissaBits);
    uint first = uint(minExponent + 127) << mantissaBits;
    return q < first ? 1u : min(q - first + 1u, 255u);
}

SHARED_FN float coneValue(uint code, uint mantissaBits, int minExponent) {
    if (code == 0u) return 0.0f;
    uint first = uint(minExponent + 127) << mantissaBits;
    return uintBitsToFloat((code - 1u + first) << (23u - mantissaBits));
}

SHARED_FN uint packCone(float width, float spread) {
    return coneCode(width, 2u, -32) << 8u | coneCode(spread, 3u, -24);
}

SHARED_FN float coneWidth(uint cone) {
    return coneValue((cone >> 8u) & 0xFFu, 2u, -32);
}

SHARED_FN float coneSpread(uint cone) {
    return coneValue(cone & 0xFFu, 3u, -24);
}

// The cone's width at distance t along its ray.
SHARED_FN float coneWidthAt(uint cone, float t) {
    return coneWidth(cone) + coneSpread(cone) * t;
}

SHARED_END
#endif
