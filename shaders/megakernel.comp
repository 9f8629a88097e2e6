#version 460
#extension GL_GOOGLE_include_directive : require
// The megakernel (--shading megakernel): one uber-shader over the unsorted hits that reads each
// hit's surface model and switches on it (shared/bsdf.h's dispatch, unfolded). It exists as the
// ablation against sorted homogeneous shading (Eisenacher et al. 2013): same math, same
// results, measured cost of divergence and of giving up the hit sort.
#define SPW_MEGAKERNEL 1
#include "shade_kernel.glsl"
