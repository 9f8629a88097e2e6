// The body of every shading kernel: one thread shades one hit with shared/path.h's
// shadeSurface(), the very function the cpu and reference backends compile as C++. Which math
// is shared: the whole bounce (path.h), the BSDFs (bsdf.h's dispatch and one header per model:
// lambert.h, conductor.h, dielectric.h over ggx.h), light sampling (lights.h), the MIS weight
// (sampling.h: powerHeuristic), ray offsets (offset.h) and the random numbers (rng.h: pcg4d).
// Why: each then exists once, so the Vulkan image can differ from the cpu image only by how the
// two compilers round floats (tests/vk/vulkan_test.cpp measures how much), never by a second
// copy of the math drifting. shared/compat.h gives the rules that let one source compile as
// GLSL 4.60 and as C++17 over glm; only this file and the .comp files are GLSL alone.
//
// A kernel file defines, before including this:
//   SPW_KERNEL_MODEL  the surface model (kModel*) of every hit it shades: the model read from
//                     the shader table is replaced by this constant, so bsdf.h's dispatch folds
//                     to that one model and the other models' code is dropped; or
//   SPW_MEGAKERNEL    nothing fixed: the model is read per hit (the --shading megakernel
//                     ablation over unsorted hits).
//
// Specialisation constants drop what the scene does not need:
//   0 kHasEmitters  false: no emitter anywhere, so no emission weighting and no next-event
//                   estimation (the shadow-ray code is removed);
//   1 kTextured     false: no shader is textured, so the albedo is the shader's constant
//                   colour x reflectance (the same product the host's TextureResolver computes)
//                   and the host-resolved per-hit albedo is not read.
//
// Bindings (set 0): 0 shader table, 1 emitters, 2 emitter CDF, 3 the environment's map and
// CDFs (shared/lights.h; 4 unread bytes without a map), 4 inputs, 5 results; 4 and 5 are bound as a window of the batch's buffers (within maxStorageBufferRange) and
// ShadePush.offset is relative to it. Dispatches are 1D, or 2D when the range needs more than
// maxComputeWorkGroupCount[0] workgroups; the linear index covers both.
#extension GL_EXT_scalar_block_layout : require

#include "shared/shade_io.h"

layout(local_size_x = kShadeWorkgroupSize, local_size_y = 1, local_size_z = 1) in;

layout(constant_id = 0) const bool kHasEmitters = true;
layout(constant_id = 1) const bool kTextured = true;

layout(scalar, set = 0, binding = 0) readonly buffer ShaderTable { ShaderParams shaderTable[]; };
layout(scalar, set = 0, binding = 1) readonly buffer EmitterTable { Emitter emitterTable[]; };
layout(scalar, set = 0, binding = 2) readonly buffer EmitterCdf { float emitterCdf[]; };
layout(scalar, set = 0, binding = 3) readonly buffer EnvironmentData { float environmentData[]; };
layout(scalar, set = 0, binding = 4) readonly buffer Inputs { ShadeInput inputs[]; };
layout(scalar, set = 0, binding = 5) writeonly buffer Results { ShadeResult results[]; };
layout(scalar, push_constant) uniform Push { ShadePush pc; };

ShaderParams kernelShader(uint i) {
    ShaderParams s = shaderTable[i];
#ifdef SPW_KERNEL_MODEL
    s.model = SPW_KERNEL_MODEL;
#endif
    return s;
}

#define SHADER(i) kernelShader(i)
#define EMITTER(i) emitterTable[i]
#define EMITTER_CDF(i) emitterCdf[i]
#define ENVIRONMENT_DATA(i) environmentData[i]
#include "shared/path.h"

void main() {
    uint local = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * kShadeWorkgroupSize +
                 gl_LocalInvocationIndex;
    if (local >= pc.count) return;
    uint i = pc.offset + local;
    ShadeInput record = inputs[i];
    RenderParams rp = pc.params;
    if (!kHasEmitters) {
        record.hit.emitter = kNoEmitter;
        rp.emitterCount = 0u;
    }
    if (!kTextured) {
        ShaderParams s = shaderTable[record.hit.shader];
        record.hit.albedo = s.colour * s.reflectance;
    }
    ShadeResult r;
    shadeSurface(rp, record.hit, record.rayDir, record.path, r);
    results[i] = r;
}
