#version 460
#extension GL_GOOGLE_include_directive : require
// Lambert, the ideal diffuse reflector, as one homogeneous compute dispatch per shader range.
//   parameters: reflectance (1), colour [r, g, b] ([1, 1, 1]) or texture; albedo = reflectance x
//   colour. The model's math is shared/lambert.h (cosine-weighted sampling, pdf = cos / pi).
//   Paper: Lambert 1760, Photometria; sampling by Shirley & Chiu 1997's concentric map.
#define SPW_KERNEL_MODEL kModelLambert
#include "shade_kernel.glsl"
