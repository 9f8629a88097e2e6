#version 460
#extension GL_GOOGLE_include_directive : require
// MetallicRoughness, glTF 2.0's metallic-roughness material, as one homogeneous compute dispatch
// per shader range.
//   parameters: colour [r, g, b] ([1, 1, 1]) or texture = the base colour; metallic (1);
//   roughness (1), alpha = roughness^2. The model's math is shared/metallic_roughness.h over
//   shared/ggx.h.
//   Papers: the glTF 2.0 specification, appendix B; Walter et al. 2007 (GGX), Heitz 2014 (Smith
//   G2), Heitz 2018 (visible normals).
#define SPW_KERNEL_MODEL kModelMetallicRoughness
#include "shade_kernel.glsl"
