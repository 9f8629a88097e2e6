#version 460
#extension GL_GOOGLE_include_directive : require
// Null: no surface response. Emitter-only geometry (quad lights, Emissive shaders): the kernel
// adds the MIS-weighted emission the ray sees and ends the path.
//   parameters: emission [r, g, b] ([0, 0, 0]), two sided (false).
#define SPW_KERNEL_MODEL kModelNull
#include "shade_kernel.glsl"
