#version 460
#extension GL_GOOGLE_include_directive : require
// Conductor, a rough or polished metal, as one homogeneous compute dispatch per shader range.
//   parameters: colour [r, g, b] ([1, 1, 1]) or texture = F0 (Schlick); alpha (0): GGX width,
//   below 1e-4 a mirror. The model's math is shared/conductor.h over shared/ggx.h.
//   Papers: Walter et al. 2007 (GGX), Heitz 2014 (Smith G2), Heitz 2018 (visible normals).
#define SPW_KERNEL_MODEL kModelConductor
#include "shade_kernel.glsl"
