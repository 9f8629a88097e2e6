// Counter-based random numbers: every number a path uses is a pure function of
// (seed, pixel, sample index, bounce, dimension), so an image never depends on the thread
// count, the batch a ray travelled in, or the order batches were processed in. Numbers come in
// groups of four dimensions (one call, one purpose), from one of two samplers:
//
//   Independent  pcg4d (Jarzynski & Olano, "Hash Functions for GPU Rendering", JCGT 2020): four
//                32-bit words in, four well-mixed words out.
//   Sobol        the first four dimensions of the Sobol sequence (Joe & Kuo's direction
//                numbers), Owen-scrambled and shuffled by hashing after Burley 2020, "Practical
//                Hash-based Owen Scrambling" (JCGT 9(4)): the sample index is shuffled by a
//                nested uniform scramble, so every pixel walks its own aligned power-of-two
//                blocks of the sequence, and each dimension is Owen-scrambled with its own seed.
//                Groups are padded: each (pixel, bounce, group) draws its shuffle and scrambles
//                from a hash of those numbers, as pbrt-v4 pads dimensions, so groups are
//                independent of one another while each stays a scrambled (0,2)-sequence in its
//                first two dimensions, and any 2^k consecutive samples from a multiple of 2^k
//                fill every elementary interval of [0,1)^2 once.
#ifndef SPILLWAY_SHARED_RNG_H
#define SPILLWAY_SHARED_RNG_H
#include "compat.h"

SHARED_BEGIN

// Which group of four dimensions a purpose draws from. A bounce uses a handful; the camera
// uses its own pseudo-bounce so that its numbers never collide with bounce 0's.
const uint kDimLight = 0u;    // x: emitter pick, y,z: point on the emitter, w: RR
const uint kDimBsdf = 1u;     // x,y: direction, z: lobe choice, w: spare
const uint kDimRounding = 2u; // stochastic rounding of compact ray fields and the film
const uint kDimCamera = 3u;   // x,y: position in the pixel, z,w: lens
const uint kBounceCamera = 255u;

// Samplers of the path's dimensions (RenderParams::sampling).
const uint kSamplerIndependent = 0u;
const uint kSamplerSobol = 1u;

// SIMD twin: host/simd/simd_math-inl.h
SHARED_FN uvec4 pcg4d(uvec4 v) {
    v = v * 1664525u + 1013904223u;
    v.x += v.y * v.w;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    v.w += v.y * v.z;
    v = v ^ (v >> 16u);
    v.x += v.y * v.w;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    v.w += v.y * v.z;
    return v;
}

// A 32-bit word to a float in [0, 1): the top 24 bits, so every value is exact.
// SIMD twin: host/simd/simd_math-inl.h
SHARED_FN float uintToUnit(uint x) {
    return float(x >> 8u) * (1.0f / 16777216.0f);
}

// Sobol's generator matrices for dimensions 1, 2, 3 (Joe & Kuo's primitive polynomials x + 1,
// x^2 + x + 1, x^3 + x + 1 with initial numbers {1}, {1, 3}, {1, 3, 1}; dimension 0 is the
// index's bits reversed), stored the way the scrambler consumes them: entry p of a dimension is
// the column for index bit 31 - p, bit-reversed. tests/shared/sampler_test.cpp recomputes them.
// clang-format off
SHARED_ARRAY_BEGIN(uint, kSobolReversed, 96)
    // dimension 1
    0xffffffffu, 0x55555555u, 0x33333333u, 0x11111111u,
    0x0f0f0f0fu, 0x05050505u, 0x03030303u, 0x01010101u,
    0x00ff00ffu, 0x00550055u, 0x00330033u, 0x00110011u,
    0x000f000fu, 0x00050005u, 0x00030003u, 0x00010001u,
    0x0000ffffu, 0x00005555u, 0x00003333u, 0x00001111u,
    0x00000f0fu, 0x00000505u, 0x00000303u, 0x00000101u,
    0x000000ffu, 0x00000055u, 0x00000033u, 0x00000011u,
    0x0000000fu, 0x00000005u, 0x00000003u, 0x00000001u,
    // dimension 2
    0xaaaa00a3u, 0x77770071u, 0x3939003au, 0x16160017u,
    0x09a30009u, 0x06710006u, 0x033a0003u, 0x01170001u,
    0x00a3aaaau, 0x00717777u, 0x003a3939u, 0x00171616u,
    0x000909a3u, 0x00060671u, 0x0003033au, 0x00010117u,
    0x0000aa09u, 0x00007706u, 0x00003903u, 0x00001601u,
    0x000009aau, 0x00000677u, 0x00000339u, 0x00000116u,
    0x000000a3u, 0x00000071u, 0x0000003au, 0x00000017u,
    0x00000009u, 0x00000006u, 0x00000003u, 0x00000001u,
    // dimension 3
    0xc900a00au, 0x45004004u, 0x2e003003u, 0x1f001001u,
    0x0a000b6du, 0x0400079eu, 0x030002a7u, 0x0100011au,
    0x00b6dba4u, 0x0079e7dbu, 0x002a7289u, 0x0011a105u,
    0x000c9baeu, 0x000457dfu, 0x0002e28au, 0x0001f104u,
    0x0000a0c3u, 0x00004041u, 0x0000302du, 0x0000101eu,
    0x00000b67u, 0x0000079au, 0x000002a4u, 0x0000011bu,
    0x000000c9u, 0x00000045u, 0x0000002eu, 0x0000001fu,
    0x0000000au, 0x00000004u, 0x00000003u, 0x00000001u
SHARED_ARRAY_END;
// clang-format on

// Dimensions 1, 2, 3 of a Sobol point, reversed: the XOR of the reversed matrix columns that the
// set bits p of r (the reversed index) select.
SHARED_FN uvec3 sobolReversedColumnsLoop(uint r) {
    uvec3 x = uvec3(0u);
    // A loop over r's set bits: no branch on random bits, which would mispredict half the time.
    for (uint bits = r; bits != 0u; bits &= bits - 1u) {
        uint p = uint(findLSB(bits));
        x.x ^= kSobolReversed[p];
        x.y ^= kSobolReversed[32u + p];
        x.z ^= kSobolReversed[64u + p];
    }
    return x;
}

#ifdef __cplusplus
// The same sums a byte of r at a time, from tables of every byte's XOR (12 KiB): four lookups per
// dimension instead of a 16-step loop whose exit the CPU mispredicts: a rand4() of Sobol numbers
// measured 44-49 ns with the loop, 27-33 ns with the tables, on this machine kind (independent
// numbers: 6 ns). GPUs keep the loop (a 12 KiB constant table read at divergent indices is
// slow there). Sobol.ByteTablesEqualTheBitLoop checks that the two agree.
struct SobolByteTables {
    uvec3 t[4][256];
    SobolByteTables() {
        for (uint byte = 0; byte < 4; ++byte)
            for (uint v = 0; v < 256; ++v)
                t[byte][v] = sobolReversedColumnsLoop(v << (8u * byte));
    }
};
inline const SobolByteTables kSobolByteTables;
inline uvec3 sobolReversedColumns(uint r) {
    const SobolByteTables& t = kSobolByteTables;
    return t.t[0][r & 0xFFu] ^ t.t[1][(r >> 8u) & 0xFFu] ^ t.t[2][(r >> 16u) & 0xFFu] ^
           t.t[3][r >> 24u];
}
#else
// The kernels: every column, selected by a mask of its bit. A loop over the set bits would run on
// lavapipe until the lane with the most bits is done, and index the columns per lane; unrolled,
// the indices are constants and the columns immediates (shade_kernel.glsl enables [[unroll]]).
uvec3 sobolReversedColumns(uint r) {
    uvec3 x = uvec3(0u);
    [[unroll]] for (uint p = 0u; p < 32u; ++p) {
        uint m = 0u - ((r >> p) & 1u);
        x ^= uvec3(kSobolReversed[p], kSobolReversed[32u + p], kSobolReversed[64u + p]) & m;
    }
    return x;
}
#endif

// Burley 2020's hash, a Laine-Karras-style permutation: output bit i depends on input bits <= i
// only, so on bit-reversed values it is a random nested uniform (Owen) scramble.
// SIMD twin: host/simd/simd_math-inl.h
SHARED_FN uint laineKarrasPermutation(uint x, uint seed) {
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

// Owen scrambling of a 32-bit fraction: each digit flipped by a hash of the digits above it.
SHARED_FN uint nestedUniformScramble(uint x, uint seed) {
    return bitfieldReverse(laineKarrasPermutation(bitfieldReverse(x), seed));
}

// Four Owen-scrambled Sobol numbers for sample `sampleIndex` of the sequence keyed by `key`:
// index' = nestedUniformScramble(sampleIndex), x_d = nestedUniformScramble(sobol_d(index')).
// Written on reversed bits, where the scramble is laineKarrasPermutation alone: r = reversed
// index', each set bit of r adds a reversed matrix column, and dimension 0's reversed value
// is index' itself. Six bit reversals instead of ten.
// The index's shuffle takes the XOR of the four scrambles' seeds as its own: a fifth seed without a
// second hash (which cost 8 ns a call).
// SIMD twin: host/simd/simd_math-inl.h
SHARED_FN uvec4 scrambledSobol4(uint sampleIndex, uvec4 key) {
    uvec4 seeds = pcg4d(key);
    uint shuffleSeed = seeds.x ^ seeds.y ^ seeds.z ^ seeds.w;
    uint r = laineKarrasPermutation(bitfieldReverse(sampleIndex), shuffleSeed);
    uvec4 x = uvec4(bitfieldReverse(r), sobolReversedColumns(r));
    return uvec4(bitfieldReverse(laineKarrasPermutation(x.x, seeds.x)),
                 bitfieldReverse(laineKarrasPermutation(x.y, seeds.y)),
                 bitfieldReverse(laineKarrasPermutation(x.z, seeds.z)),
                 bitfieldReverse(laineKarrasPermutation(x.w, seeds.w)));
}

// Four uniform numbers for (seed, pixel, sample, bounce, group) from `sampling` (kSampler*).
// `sampleIndex` counts samples of the whole render (iteration * samples per iteration +
// sample), so iterations differ.
// Sobol draws two independent streams: the samples of even index are one scrambled sequence
// (point sampleIndex / 2 of it), those of odd index another, with shuffle and scrambles of its
// own. The film keeps each stream in its own half (Film::Halves::ByStream), so the halves are
// two independent estimates and their difference is an honest error estimate; two halves of
// one scrambled sequence are negatively correlated, and their difference overstated the error
// 2-3x.
// SIMD twin: host/simd/simd_math-inl.h
SHARED_FN vec4 rand4(uint sampling, uint seed, uint pixel, uint sampleIndex, uint bounce,
                     uint group) {
    uvec4 h;
    if (sampling == kSamplerSobol)
        h = scrambledSobol4(sampleIndex >> 1u, uvec4(pixel, (bounce << 8u) | group, seed,
                                                     0x50B01u + (sampleIndex & 1u)));
    else
        h = pcg4d(uvec4(pixel, sampleIndex, (bounce << 8u) | group, seed));
    return vec4(uintToUnit(h.x), uintToUnit(h.y), uintToUnit(h.z), uintToUnit(h.w));
}

SHARED_END
#endif
