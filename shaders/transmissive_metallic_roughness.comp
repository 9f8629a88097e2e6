#version 460
#extension GL_GOOGLE_include_directive : require
// TransmissiveMetallicRoughness, glTF's metallic-roughness dielectric that transmits part of the
// light (KHR_materials_transmission below 1), as one homogeneous compute dispatch per shader range.
//   parameters: colour or texture, roughness, ior, absorption, transmission (1). The model's math
//   is shared/transmissive_metallic_roughness.h over shared/metallic_roughness.h and
//   shared/dielectric.h.
//   Papers: the glTF 2.0 specification, appendix B, and KHR_materials_transmission; Walter et al.
//   2007 (GGX, rough refraction), Heitz 2014 (Smith G2), Heitz 2018 (visible normals).
#define SPW_KERNEL_MODEL kModelTransmissiveMetallicRoughness
#include "shade_kernel.glsl"
