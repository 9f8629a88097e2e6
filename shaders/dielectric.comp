#version 460
#extension GL_GOOGLE_include_directive : require
// Dielectric, a refracting interface (glass), as one homogeneous compute dispatch per shader range.
//   parameters: ior (1.5) behind the surface; alpha (0): GGX width, below 1e-4 smooth glass.
//   The model's math is shared/dielectric.h over shared/ggx.h: exact Fresnel, total internal
//   reflection, radiance scaled by 1 / eta^2 on refraction.
//   Papers: Walter et al. 2007 (rough refraction), Heitz 2018 (visible normals).
#define SPW_KERNEL_MODEL kModelDielectric
#include "shade_kernel.glsl"
