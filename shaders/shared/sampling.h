// Sampling primitives shared by every backend: orthonormal frames, warps from the unit square,
// and the multiple-importance-sampling weight.
#ifndef SPILLWAY_SHARED_SAMPLING_H
#define SPILLWAY_SHARED_SAMPLING_H
#include "compat.h"

SHARED_BEGIN

// Orthonormal basis around a unit vector n (Duff et al. 2017, "Building an Orthonormal Basis,
// Revisited"): branch-free and continuous except at n.z = -0 / +0.
SHARED_FN void makeFrame(vec3 n, OUT(vec3) t, OUT(vec3) b) {
    float s = n.z >= 0.0f ? 1.0f : -1.0f;
    float a = -1.0f / (s + n.z);
    float c = n.x * n.y * a;
    t = vec3(1.0f + s * n.x * n.x * a, s * c, -s * n.x);
    b = vec3(c, s + n.y * n.y * a, -n.y);
}

// A unit vector as a point of [-1, 1]^2, the octahedral map (Cigolle et al. 2014, "A Survey of
// Efficient Representations for Independent Unit Vectors"), and a point back to its unit vector.
// Carried as two halves (SurfaceHit::extension) it comes back within about 1e-3 radians.
SHARED_FN vec2 octahedralEncode(vec3 n) {
    vec2 p = vec2(n.x, n.y) * (1.0f / (abs(n.x) + abs(n.y) + abs(n.z)));
    if (n.z >= 0.0f) return p;
    return vec2((1.0f - abs(p.y)) * (p.x >= 0.0f ? 1.0f : -1.0f),
                (1.0f - abs(p.x)) * (p.y >= 0.0f ? 1.0f : -1.0f));
}
SHARED_FN vec3 octahedralDecode(vec2 p) {
    vec3 n = vec3(p.x, p.y, 1.0f - abs(p.x) - abs(p.y));
    float fold = max(-n.z, 0.0f);
    n.x += n.x >= 0.0f ? -fold : fold;
    n.y += n.y >= 0.0f ? -fold : fold;
    return normalize(n);
}

// SIMD twin: host/simd/simd_math-inl.h
SHARED_FN vec3 toWorld(vec3 local, vec3 n) {
    vec3 t;
    vec3 b;
    makeFrame(n, t, b);
    return local.x * t + local.y * b + local.z * n;
}

// sin and cos of x in [-pi/4, pi/4], as the polynomials of Cephes' sinf and cosf (Moshier
// 1992; within 2 ulp of the true values there): multiplies and adds alone, so that the
// scalar shading, the SIMD kernels (host/cpu/simd_shading.cpp) and the Vulkan kernels
// compute the same thing, without a libm call.
// sin x = x + x z (S3 + z (S5 + z S7)) and cos x = 1 - z / 2 + z^2 (C4 + z (C6 + z C8)),
// z = x^2, evaluated as written below (the SIMD kernel repeats the order).
const float kSinS3 = -1.6666654611e-1f;
const float kSinS5 = 8.3321608736e-3f;
const float kSinS7 = -1.9515295891e-4f;
const float kCosC4 = 4.166664568298827e-2f;
const float kCosC6 = -1.388731625493765e-3f;
const float kCosC8 = 2.443315711809948e-5f;
// SIMD twin: host/simd/simd_math-inl.h
SHARED_FN float sinQuarterPi(float x) {
    float z = x * x;
    return ((kSinS7 * z + kSinS5) * z + kSinS3) * z * x + x;
}
// SIMD twin: host/simd/simd_math-inl.h
SHARED_FN float cosQuarterPi(float x) {
    float z = x * x;
    return ((kCosC8 * z + kCosC6) * z + kCosC4) * z * z - 0.5f * z + 1.0f;
}

// Cosine-weighted hemisphere around +Z through the concentric disk map (Shirley & Chiu 1997).
// SIMD twin: host/simd/simd_math-inl.h
SHARED_FN vec3 sampleCosineHemisphere(vec2 u) {
    vec2 d = 2.0f * u - vec2(1.0f, 1.0f);
    if (d.x == 0.0f && d.y == 0.0f) {
        return vec3(0.0f, 0.0f, 1.0f);
    }
    // The wedge (|x| > |y| or not) is a coin flip per sample: selects, one division, no branch.
    // The angle is theta = pi/4 q in the x-major wedges and pi/2 - theta in the others, where
    // cos and sin trade places: both within [-pi/4, pi/4].
    bool xMajor = abs(d.x) > abs(d.y);
    float r = xMajor ? d.x : d.y;
    float theta = (kPi / 4.0f) * ((xMajor ? d.y : d.x) / r);
    float c = cosQuarterPi(theta);
    float s = sinQuarterPi(theta);
    float x = r * (xMajor ? c : s);
    float y = r * (xMajor ? s : c);
    return vec3(x, y, sqrt(max(0.0f, 1.0f - x * x - y * y)));
}

SHARED_FN vec2 sampleConcentricDisk(vec2 u) {
    vec3 h = sampleCosineHemisphere(u);
    return vec2(h.x, h.y);
}

// Uniform barycentrics on a triangle (Heitz 2019's square-root-free fold would do too; the
// square root form is the classic Turk 1990 map and keeps strata contiguous).
SHARED_FN vec2 sampleTriangle(vec2 u) {
    float su = sqrt(u.x);
    return vec2(1.0f - su, u.y * su);
}

// Power heuristic with beta = 2 (Veach 1997, ch. 9), written to stay finite for any pair of
// non-negative pdfs, including infinite ones.
// SIMD twin: host/simd/simd_math-inl.h
SHARED_FN float powerHeuristic(float pdfThis, float pdfOther) {
    if (pdfThis <= 0.0f) return 0.0f;
    float r = pdfOther / pdfThis;
    return 1.0f / (1.0f + r * r);
}

// The BSDF pdf that MIS compares with the light pdf travels inside the 32-byte compact ray as a
// bfloat16 (the top 16 bits of the float). Quantising it the same way on *both* sides of the
// MIS pair (light sampling and BSDF sampling) keeps the weights an exact partition of unity, so
// the quantisation changes which strategy gets credit, never the expected value.
// SIMD twin: host/simd/simd_math-inl.h
SHARED_FN float quantizePdf(float pdf) {
    return uintBitsToFloat(floatBitsToUint(pdf) & 0xFFFF0000u);
}

// The shading normal turned to the side of the geometric normal that wo is on, and made valid
// for shading there: where wo's mirror reflection about it would point below the geometric
// surface (or not clear it by min(0.9 cos θo, 0.01)), as a normal map or interpolated normals do
// on the rims of bumps and at silhouettes, it is bent toward the geometric normal, in the plane
// of the two, just far enough that the reflection clears it; an unbent normal leaves wo below
// its own hemisphere and the surface black where light reaches it. Cycles and pbrt-v4 make the
// same correction. A normal that needs none comes back unchanged, bit for bit.
// SIMD twin: host/simd/simd_math-inl.h
SHARED_FN vec3 facingShadingNormal(vec3 ns, vec3 ng, vec3 wo) {
    float side = dot(ng, wo) >= 0.0f ? 1.0f : -1.0f;
    vec3 n = ns * side;
    vec3 g = ng * side;
    float nz = dot(n, g);
    // A shading normal on the far side of the geometric one (bad vertex normals) is replaced by
    // the geometric normal, so cosines stay non-negative.
    if (!(nz > 0.0f)) return g;
    float wz = dot(wo, g);
    float clearance = min(0.9f * wz, 0.01f);
    // The reflection's height above the surface: dot(2 dot(wo, n) n - wo, g).
    if (2.0f * dot(wo, n) * nz - wz >= clearance) return n;
    // n' = s x + c g, x the unit direction of n's tangential part. Its reflection's height
    // 2 c (s wx + c wz) - wz equals the clearance where C = c^2 solves
    // a C^2 - (a + wz clearance) C + (wz + clearance)^2 / 4 = 0, a = wx^2 + wz^2.
    vec3 xt = n - g * nz;
    float xl = sqrt(dot(xt, xt));
    if (!(xl > 0.0f)) return g;
    vec3 x = xt / xl;
    float wx = dot(wo, x);
    float a = wx * wx + wz * wz;
    if (!(a > 0.0f)) return g;
    float root = sqrt(max(wx * wx * (a - clearance * clearance), 0.0f));
    float mid = wz * clearance + a;
    // The least bend that clears: the smaller root beyond n's own C, else the larger, else g.
    // Squaring admits a root of the mirrored tilt (-s); its reflection clears by
    // clearance + 4 c s wx, so it is taken only where that is within 10 % of the clearance.
    float cLow = sqrt(clamp((mid - root) / (2.0f * a), 0.0f, 1.0f));
    float cHigh = sqrt(clamp((mid + root) / (2.0f * a), 0.0f, 1.0f));
    float sLow = sqrt(max(1.0f - cLow * cLow, 0.0f));
    float sHigh = sqrt(max(1.0f - cHigh * cHigh, 0.0f));
    float enough = 0.9f * clearance;
    bool useLow = cLow > nz && 2.0f * cLow * (sLow * wx + cLow * wz) - wz >= enough;
    bool useHigh = cHigh > nz && 2.0f * cHigh * (sHigh * wx + cHigh * wz) - wz >= enough;
    if (useLow) return x * sLow + g * cLow;
    if (useHigh) return x * sHigh + g * cHigh;
    return g;
}

// SIMD twin: host/simd/simd_math-inl.h
SHARED_FN float maxComponent(vec3 v) {
    return max(v.x, max(v.y, v.z));
}

SHARED_FN float luminance(vec3 c) {
    return dot(c, vec3(0.2126f, 0.7152f, 0.0722f));
}

SHARED_END
#endif
