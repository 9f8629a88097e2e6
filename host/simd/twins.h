// The registry of SIMD twins: every scalar function of shaders/shared/ that has a SIMD twin in
// host/simd/simd_math-inl.h or simd_bsdf-inl.h, one line each, and a way to run each twin on lanes
// of inputs, so that tests/simd/twins_test.cpp compares it with its scalar function lane by lane,
// bit for bit, on random inputs: a change to either side fails at the function that drifted, not at
// the end of a render. The scalar side carries the tag "// SIMD twin: host/simd/simd_math-inl.h"
// (or simd_bsdf-inl.h, the one that holds the twin) on the line above its definition; the test
// checks that the tags and this list are the same set.
//
// X(name, header): the function's name on both sides, and its shared header.
#pragma once

#include "host/simd/lanes.h"

#include <cstddef>

#define SPW_SIMD_TWINS(X)                                                                          \
    X(maxComponent, "sampling.h")                                                                  \
    X(quantizePdf, "sampling.h")                                                                   \
    X(powerHeuristic, "sampling.h")                                                                \
    X(facingShadingNormal, "sampling.h")                                                           \
    X(sinQuarterPi, "sampling.h")                                                                  \
    X(cosQuarterPi, "sampling.h")                                                                  \
    X(sampleCosineHemisphere, "sampling.h")                                                        \
    X(toWorld, "sampling.h")                                                                       \
    X(surfaceOffset, "offset.h")                                                                   \
    X(offsetOrigin, "offset.h")                                                                    \
    X(shadowRayTmax, "offset.h")                                                                   \
    X(shadowLift, "offset.h")                                                                      \
    X(emitterPoint, "light_sample.h")                                                              \
    X(emitterCosine, "light_sample.h")                                                             \
    X(emitterSolidAnglePdf, "light_sample.h")                                                      \
    X(lambertEval, "lambert.h")                                                                    \
    X(ggxD, "ggx.h")                                                                               \
    X(ggxA, "ggx.h")                                                                               \
    X(ggxG2Denominator, "ggx.h")                                                                   \
    X(ggxSampleVisibleNormal, "ggx.h")                                                             \
    X(schlickFresnel, "conductor.h")                                                               \
    X(conductorEval, "conductor.h")                                                                \
    X(conductorSample, "conductor.h")                                                              \
    X(fresnelDielectric, "dielectric.h")                                                           \
    X(dielectricEval, "dielectric.h")                                                              \
    X(dielectricSample, "dielectric.h")                                                            \
    X(gltfFresnel, "metallic_roughness.h")                                                         \
    X(gltfSpecularProbability, "metallic_roughness.h")                                             \
    X(gltfEval, "metallic_roughness.h")                                                            \
    X(gltfSample, "metallic_roughness.h")                                                          \
    X(pcg4d, "rng.h")                                                                              \
    X(laineKarrasPermutation, "rng.h")                                                             \
    X(scrambledSobol4, "rng.h")                                                                    \
    X(uintToUnit, "rng.h")                                                                         \
    X(rand4, "rng.h")

namespace spw::simd {

enum class Twin {
#define SPW_TWIN_ENUM(name, header) name,
    SPW_SIMD_TWINS(SPW_TWIN_ENUM)
#undef SPW_TWIN_ENUM
};

struct TwinInfo {
    Twin twin;
    const char* name;
    const char* header; // in shaders/shared/
};
inline constexpr TwinInfo kTwins[] = {
#define SPW_TWIN_INFO(name, header) TwinInfo{Twin::name, #name, header},
    SPW_SIMD_TWINS(SPW_TWIN_INFO)
#undef SPW_TWIN_INFO
};

// A twin's arguments and results as rows of lanes: f[k] and u[k] are the k-th float and uint
// argument (a vec3 takes three rows, x y z), in the order of the scalar function's parameters;
// results the same way (a returned value first, then out-parameters; a BSDF sample's `ok` and
// `specular` as masks u0 and u1, its out-parameters zero where it fails). twins.cpp says per twin
// which rows it reads; `uniform` holds the arguments that are one value for every lane.
struct TwinLanes {
    Floats f[21];
    Uints u[5];
    std::uint32_t uniform[3];
};
struct TwinResults {
    Floats f[8];
    Uints u[4];
};

// Runs the twin on lanes [0, count) (count a multiple of kMaxLanes) in the instruction set the
// dispatch picks (hwy::SetSupportedTargetsForTest narrows it, to try each in turn).
void runTwin(Twin twin, const TwinLanes& in, size_t count, TwinResults& out);

} // namespace spw::simd
