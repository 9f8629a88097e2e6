#version 460
#extension GL_GOOGLE_include_directive : require
// CoatedMetallicRoughness, glTF's metallic-roughness material under a clear coat
// (KHR_materials_clearcoat), as one homogeneous compute dispatch per shader range.
//   parameters: MetallicRoughness's, and coat (1), coat roughness (0). The model's math is
//   shared/coated_metallic_roughness.h over shared/metallic_roughness.h and shared/ggx.h.
//   Papers: the glTF 2.0 specification, appendix B, and KHR_materials_clearcoat; Walter et al.
//   2007 (GGX), Heitz 2014 (Smith G2), Heitz 2018 (visible normals).
#define SPW_KERNEL_MODEL kModelCoatedMetallicRoughness
#include "shade_kernel.glsl"
