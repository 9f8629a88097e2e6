#version 460
#extension GL_GOOGLE_include_directive : require
// Principled, Blender 3.4's Principled BSDF (v1) as Cycles renders it, as one homogeneous compute
// dispatch per shader range. The model's math is shared/principled.h: Burley's diffuse with its
// retro-reflection, his sheen, GGX with Cycles' principled Fresnel and the GTR1 clear coat.
//   Paper: Burley 2012, "Physically Based Shading at Disney".
#define SPW_KERNEL_MODEL kModelPrincipled
#include "shade_kernel.glsl"
