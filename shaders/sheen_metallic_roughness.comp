#version 460
#extension GL_GOOGLE_include_directive : require
// SheenMetallicRoughness, glTF's metallic-roughness material under a sheen
// (KHR_materials_sheen), as one homogeneous compute dispatch per shader range.
//   parameters: MetallicRoughness's, and sheen colour ([1, 1, 1]), sheen roughness (0.5). The
//   model's math is shared/sheen_metallic_roughness.h over shared/metallic_roughness.h.
//   Papers: the glTF 2.0 specification, appendix B, and KHR_materials_sheen; Estevez and Kulla
//   2017 (the Charlie sheen and its visibility).
#define SPW_KERNEL_MODEL kModelSheenMetallicRoughness
#include "shade_kernel.glsl"
