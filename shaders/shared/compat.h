// The only code both compilers see lives in shaders/shared/. It is written in the common subset
// of GLSL 4.60 and C++17 over glm, so that the BSDFs, light sampling, MIS and the random numbers
// exist once and every backend (reference, cpu, and the Vulkan compute shaders) runs the same
// source. We chose "GLSL-compatible headers compiled as C++ over glm" over generating one language
// from the other: no code generator to maintain, and a compile error on either side points at the
// one true line.
//
// Rules for code in this folder:
//   * float literals carry an `f` suffix (GLSL accepts it; C++ glm refuses float*double);
//   * unsigned literals carry `u`;
//   * no references, pointers, templates or constructors: parameters are `in`, `OUT(T)` or
//     `INOUT(T)`, and structs are filled field by field;
//   * functions are declared `SHARED_FN` (inline in C++, nothing in GLSL);
//   * constant tables are written SHARED_ARRAY_BEGIN(T, name, n) values SHARED_ARRAY_END;
//   * a parameter an interface requires but a function does not read is marked `UNUSED(p);`;
//   * GLSL's `out` parameters are not copied in, and a callee's unwritten `out` overwrites the
//     caller's variable with an undefined value: a function writes every `out` it promises;
//   * buffer reads go through the accessor macros of the file that declares the buffer.
#ifndef SPILLWAY_SHARED_COMPAT_H
#define SPILLWAY_SHARED_COMPAT_H

#ifdef __cplusplus
#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <glm/gtc/packing.hpp>

namespace spw {
using glm::bvec3;
using glm::ivec2;
using glm::mat3;
using glm::mat4;
using glm::uvec2;
using glm::uvec3;
using glm::uvec4;
using glm::vec2;
using glm::vec3;
using glm::vec4;
using uint = std::uint32_t;
// GLSL's abs clears the sign bit; glm's is `x >= 0 ? x : -x`, which GCC compiles to a branch
// (it must keep abs(-0.0) = -0.0) that hit and light geometry makes a coin flip.
inline float abs(float x) {
    return std::fabs(x);
}
inline vec2 abs(vec2 v) {
    return vec2(std::fabs(v.x), std::fabs(v.y));
}
inline vec3 abs(vec3 v) {
    return vec3(std::fabs(v.x), std::fabs(v.y), std::fabs(v.z));
}
inline vec4 abs(vec4 v) {
    return vec4(std::fabs(v.x), std::fabs(v.y), std::fabs(v.z), std::fabs(v.w));
}
using glm::clamp;
using glm::cross;
using glm::dot;
using glm::floatBitsToUint;
using glm::inversesqrt;
using glm::length;
using glm::max;
using glm::min;
using glm::mix;
using glm::normalize;
using glm::packHalf2x16;
using glm::sign;
using glm::uintBitsToFloat;
using glm::unpackHalf2x16;
using std::acos;
using std::atan;
// GLSL's two-argument atan.
inline float atan(float y, float x) {
    return std::atan2(y, x);
}
using std::cos;
using std::exp;
using std::floor;
using std::sin;
using std::sqrt;
// GLSL's bit built-ins, as the compilers' own instructions (glm's are generic loops and masks).
inline uint bitfieldReverse(uint x) {
    x = __builtin_bswap32(x);
    x = ((x >> 4u) & 0x0F0F0F0Fu) | ((x & 0x0F0F0F0Fu) << 4u);
    x = ((x >> 2u) & 0x33333333u) | ((x & 0x33333333u) << 2u);
    return ((x >> 1u) & 0x55555555u) | ((x & 0x55555555u) << 1u);
}
inline int findLSB(uint x) {
    return x != 0u ? __builtin_ctz(x) : -1;
}
} // namespace spw

#define SHARED_FN inline
#define OUT(T) T&
#define INOUT(T) T&
#define SHARED_BEGIN namespace spw {
#define SHARED_END }
#define UNUSED(x) (void)(x)
#define SHARED_ARRAY_BEGIN(T, name, n) constexpr T name[n] = {
#define SHARED_ARRAY_END }
#else
#define SHARED_FN
#define OUT(T) out T
#define INOUT(T) inout T
#define SHARED_BEGIN
#define SHARED_END
#define UNUSED(x)
#define SHARED_ARRAY_BEGIN(T, name, n) const T name[n] = T[n](
#define SHARED_ARRAY_END )
#endif

SHARED_BEGIN
const float kPi = 3.14159265358979323846f;
const float kInvPi = 0.31830988618379067154f;
const float kOneMinusEpsilon = 0.99999994f; // largest float below 1
SHARED_END

#endif
