// Rays between bounces, as they wait in bins, batches and spill files.
//
// RayState is the working form (56 bytes). On the way into a bin it is encoded into one of two
// records; `compact` is the default, `full` keeps every bit and exists to prove that compaction
// does not change the image (a test renders both).
//
// Compact record, 34 bytes:
//   origin      3 x float32  12 B  exact: the origin decides self-intersection, so it keeps
//                                  every bit.
//   pathId      uint32        4 B  exact: pixel * samples per iteration + sample. The iteration
//                                  is global to all rays in flight, so it is not stored.
//   direction   2 x 24 bits   6 B  octahedral map (Cigolle et al. 2014) on a 2^24 grid: cells
//                                  1.2e-7 wide, 2.9e-7 rad worst case measured over a million
//                                  directions (CompactRay.DirectionWithinTheOctahedralGridBound),
//                                  a few times a float32 unit vector's own rounding (6e-8). The
//                                  direction traced is the decoded one.
//   throughput  3 x bfloat16  6 B  stochastically rounded with the path's own random number
//                                  (dimension kDimRounding): E[stored] = exact, so the estimator
//                                  stays unbiased; the added noise is < 2^-8 relative. One number
//                                  rounds all three channels, which keeps their order: Russian
//                                  roulette reads the largest, and with a number per channel the
//                                  largest rounded channel would be biased up (E[max] > max E),
//                                  paths surviving longer than the rule says (+4.3 % at albedo
//                                  0.999).
//   prevPdf     bfloat16      2 B  exact: shadeSurface() already quantises it, and MIS uses the
//                                  same quantised value on both sides (shared/sampling.h).
//   bounce      15 bits      2 B  exact up to 32767 bounces; the top bit is the specular flag.
//   cone        2 x 8 bits   2 B  exact: the ray cone's width and spread, which shadeSurface()
//                                  already quantises to a byte each on a log2 scale
//                                  (shared/cone.h), for the texture filter width at the next hit.
//
// Full record, 50 bytes: float32 origin, direction, throughput, prevPdf; uint32 pathId and
// bounce | flags << 16; the 16-bit cone.
#pragma once

#include "host/backend/render_config.h"
#include "shared/path.h"
#include "shared/types.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>

namespace spw {

struct RayState {
    vec3 origin;
    vec3 dir; // unit
    PathState path;
};

constexpr size_t kCompactRayBytes = 34;
constexpr size_t kFullRayBytes = 50;
constexpr uint kMaxCompactBounce = 0x7FFF;

inline size_t rayRecordBytes(RayFormat f) {
    return f == RayFormat::Compact ? kCompactRayBytes : kFullRayBytes;
}

// `rounding`: four uniform 32-bit words for the stochastic rounding (compact only).
void encodeRay(vec3 origin, vec3 dir, const PathState& path, RayFormat format, uvec4 rounding,
               std::uint8_t* out);
inline void encodeRay(const RayState& ray, RayFormat format, uvec4 rounding, std::uint8_t* out) {
    encodeRay(ray.origin, ray.dir, ray.path, format, rounding, out);
}
void decodeRay(const std::uint8_t* in, RayFormat format, RayState& ray);

// The random numbers that round a ray's compact record: the path's own (dimension kDimRounding).
inline uvec4 compactRounding(const RenderParams& rp, const PathState& path) {
    return pcg4d(uvec4(pathPixel(rp, path.pathId), pathSample(rp, path.pathId),
                       (path.bounce << 8u) | kDimRounding, rp.seed));
}
// The compact record's bounce field: the bounce (at most kMaxCompactBounce), the specular flag
// in the top bit.
inline std::uint16_t compactBounce(const PathState& path) {
    return std::uint16_t(std::min(path.bounce, kMaxCompactBounce) |
                         ((path.flags & kPathSpecular) ? 0x8000u : 0u));
}

// The compact records of the continuation rays of n <= simd::kBlock shading results, their
// arithmetic SIMD-wide (ray_record_wide.cpp): record i, at out + i * kCompactRayBytes, is the
// bytes encodeRay(res[i]->nextOrigin, res[i]->nextDir, res[i]->next, RayFormat::Compact,
// compactRounding(rp, res[i]->next), ...) writes, and bin[i] is cardinalBin(res[i]->nextDir).
void encodeCompactBlock(const RenderParams& rp, const ShadeResult* const* res, size_t n,
                        std::uint8_t* out, std::uint8_t* bin);
// n compact records at `in` decoded, their directions SIMD-wide (ray_record_wide.cpp): out[i] is
// what decodeRay makes of record i.
void decodeCompactBlock(const std::uint8_t* in, size_t n, RayState* out);

// The octahedral map (Cigolle et al. 2014) of a direction to [-1, 1]^2, in double so that the
// compact record's 2^24 grid is its only rounding; the Morton key (ray_sort.cpp) quantises the
// same map to 8 bits. octahedralFold is the lower hemisphere's fold, its own inverse.
glm::dvec2 octahedralMap(vec3 d);
glm::dvec2 octahedralFold(glm::dvec2 p);

// The cardinal direction bin of a direction: 0..5 for +X, -X, +Y, -Y, +Z, -Z (dominant axis).
// In integer arithmetic on the comparisons: bounce directions are random, and mispredicted
// branches here cost more than the arithmetic (GCC made branches of the ternaries this was).
// abs is the shared code's (shared/compat.h), a sign-bit clear, not glm's branch.
inline uint cardinalBin(vec3 d) {
    const vec3 a = spw::abs(d);
    const uint x = uint(a.x >= a.y) & uint(a.x >= a.z);
    const uint y = (x ^ 1u) & uint(a.y >= a.z);
    const uint z = (x | y) ^ 1u;
    const uint negative =
        (x & uint(!(d.x >= 0.0f))) | (y & uint(!(d.y >= 0.0f))) | (z & uint(!(d.z >= 0.0f)));
    return 2u * (y + 2u * z) + negative;
}

} // namespace spw
