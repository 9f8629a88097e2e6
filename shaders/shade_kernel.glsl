// The body of every shading kernel: one thread shades one hit with shared/path.h's
// shadeSurface(), the very function the cpu and reference backends compile as C++. Which math
// is shared: the whole bounce (path.h), the BSDFs (bsdf.h's dispatch and one header per model of
// the registry, surface_models.h, each named after its model: null.h, lambert.h, conductor.h,
// dielectric.h, metallic_roughness.h, coated_metallic_roughness.h,
// transmissive_metallic_roughness.h and sheen_metallic_roughness.h, over ggx.h), light sampling
// (lights.h), the MIS weight (sampling.h: powerHeuristic), ray offsets (offset.h) and the random numbers (rng.h: pcg4d).
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
//   1 kTextured     false: no shader is textured and no mesh has vertex colours, so the
//                   albedo is the shader's constant colour x reflectance (the same product the
//                   host's TextureResolver computes) and the host-resolved per-hit albedo is
//                   not read;
//   2 kSampling, 3 kStrategy  RenderParams' sampler and MIS strategy, fixed for the render: the
//                   other samplers' and strategies' code is dropped;
//   4 kEmitterKinds bit 1 << kEmitter* for each kind of emitter in the scene (every kind of the
//                   registry, shared/emitter_kinds.h): with one kind, the others' light
//                   sampling (the environment's CDF searches, point lights) is dropped;
//   5 kEmissionMaps false: no emitter has an emission map (glTF's emissiveTexture), so the
//                   lookups of shared/emission_map.h are dropped.
// Why it matters on lavapipe: it runs 8 invocations as the lanes of one vector and executes both
// sides of every if, masked, whatever the lanes decide; code a uniform condition switches off
// still costs its full time there. Constants make the condition known to the compiler instead.
//
// Bindings (set 0): 0 shader table, 1 emitters, 2 emitter CDF, 3 the light data: the
// environment's map and CDFs and the emission maps (4 unread bytes without any), 4 inputs,
// 5 results. 0-4 are uniform texel buffers of 32-bit unsigned words (R32G32B32A32_UINT, or
// R32_UINT for 2 and 3), read with texelFetch and turned back into the shared structs field by
// field; 5 is a storage buffer written as whole uvec4s. Why not storage buffers throughout: on lavapipe (Mesa 22.3) every storage
// buffer access whose address differs between lanes is a loop over the 8 lanes with a branch per
// lane and one scalar load per component, while a texel fetch is a vector gather; the stores are
// fewest as 7 whole uvec4s per record. (Measured: docs/performance-log.md, "Fifth round".) The unpacking below
// follows the byte layout that host/vk/shared_layout.cpp pins for the C++ side.
// 4 and 5 are bound as a window of the batch's buffers (within maxStorageBufferRange and
// maxTexelBufferElements) and ShadePush.offset is relative to it. Dispatches are 1D, or 2D when
// the range needs more than maxComputeWorkGroupCount[0] workgroups; the linear index covers both.
#extension GL_EXT_scalar_block_layout : require
#extension GL_EXT_control_flow_attributes : require

#include "shared/rng.h"
#include "shared/shade_io.h"

layout(local_size_x = kShadeWorkgroupSize, local_size_y = 1, local_size_z = 1) in;

layout(constant_id = 0) const bool kHasEmitters = true;
layout(constant_id = 1) const bool kTextured = true;
layout(constant_id = 2) const uint kSampling = kSamplerIndependent;
layout(constant_id = 3) const uint kStrategy = kStrategyMis;
layout(constant_id = 4) const uint kEmitterKinds = 0xFFFFFFFFu; // every kind
layout(constant_id = 5) const bool kEmissionMaps = true;

layout(set = 0, binding = 0) uniform usamplerBuffer shaderTable; // 8 texels per ShaderParams
layout(set = 0, binding = 1) uniform usamplerBuffer emitterTable; // 5 texels per Emitter
layout(set = 0, binding = 2) uniform usamplerBuffer emitterCdf;
layout(set = 0, binding = 3) uniform usamplerBuffer lightData;
layout(set = 0, binding = 4) uniform usamplerBuffer inputs; // 8 texels per ShadeInput
layout(std430, set = 0, binding = 5) writeonly buffer Results { uvec4 results[]; }; // 7 per ShadeResult
layout(scalar, push_constant) uniform Push { ShadePush pc; };

uvec4 fetch(usamplerBuffer table, uint texel) { return texelFetch(table, int(texel)); }

// Layout twin of the C++ ShaderParams (shared/types.h): tests/vk/kernel_layout_test.cpp checks it field by field.
ShaderParams kernelShader(uint i) {
    uvec4 w0 = fetch(shaderTable, 8u * i), w1 = fetch(shaderTable, 8u * i + 1u),
          w2 = fetch(shaderTable, 8u * i + 2u), w3 = fetch(shaderTable, 8u * i + 3u),
          w4 = fetch(shaderTable, 8u * i + 4u), w5 = fetch(shaderTable, 8u * i + 5u),
          w6 = fetch(shaderTable, 8u * i + 6u), w7 = fetch(shaderTable, 8u * i + 7u);
    ShaderParams s;
    s.emission = uintBitsToFloat(w0.xyz);
    s.model = w0.w;
    s.colour = uintBitsToFloat(w1.xyz);
    s.reflectance = uintBitsToFloat(w1.w);
    s.flags = w2.x;
    s.ior = uintBitsToFloat(w2.y);
    s.alpha = uintBitsToFloat(w2.z);
    s.metallic = uintBitsToFloat(w2.w);
    s.absorption = uintBitsToFloat(w3.xyz);
    s.coat = uintBitsToFloat(w3.w);
    s.coatAlpha = uintBitsToFloat(w4.x);
    s.specularColour = uintBitsToFloat(w4.yzw);
    s.specular = uintBitsToFloat(w5.x);
    s.transmission = uintBitsToFloat(w5.y);
    s.sheenRoughness = uintBitsToFloat(w5.z);
    s.coatNormal = w5.w;
    s.sheenColour = uintBitsToFloat(w6.xyz);
    s.specularTint = uintBitsToFloat(w6.w);
    s.sheen = uintBitsToFloat(w7.x);
    s.sheenTint = uintBitsToFloat(w7.y);
    s.pad1 = w7.z;
    s.pad2 = w7.w;
#ifdef SPW_KERNEL_MODEL
    s.model = SPW_KERNEL_MODEL;
#endif
    return s;
}

// Layout twin of the C++ Emitter (shared/types.h): tests/vk/kernel_layout_test.cpp checks it field by field.
Emitter kernelEmitter(uint i) {
    uvec4 w0 = fetch(emitterTable, 5u * i), w1 = fetch(emitterTable, 5u * i + 1u),
          w2 = fetch(emitterTable, 5u * i + 2u), w3 = fetch(emitterTable, 5u * i + 3u),
          w4 = fetch(emitterTable, 5u * i + 4u);
    Emitter e;
    e.p0 = uintBitsToFloat(w0.xyz);
    e.area = uintBitsToFloat(w0.w);
    e.e1 = uintBitsToFloat(w1.xyz);
    e.pickPdf = uintBitsToFloat(w1.w);
    e.e2 = uintBitsToFloat(w2.xyz);
    e.twoSided = w2.w;
    e.normal = uintBitsToFloat(w3.xyz);
    e.type = w3.w;
    e.radiance = uintBitsToFloat(w4.xyz);
    e.map = w4.w;
    if (!kEmissionMaps) e.map = kNoEmissionMap;
#define SPW_ONLY_KIND(Name, id, stem, Scene, flags)                                                \
    if (kEmitterKinds == (1u << kEmitter##Name)) e.type = kEmitter##Name;
    SPW_EMITTER_KINDS(SPW_ONLY_KIND)
#undef SPW_ONLY_KIND
    return e;
}

// Layout twin of the C++ ShadeInput (shared/shade_io.h): tests/vk/kernel_layout_test.cpp checks it field by field.
ShadeInput loadInput(uint i) {
    uint t = 8u * i;
    uvec4 w[8] = uvec4[8](fetch(inputs, t), fetch(inputs, t + 1u), fetch(inputs, t + 2u),
                          fetch(inputs, t + 3u), fetch(inputs, t + 4u), fetch(inputs, t + 5u),
                          fetch(inputs, t + 6u), fetch(inputs, t + 7u));
    ShadeInput r;
    r.hit.p = uintBitsToFloat(w[0].xyz);
    r.hit.t = uintBitsToFloat(w[0].w);
    r.hit.ng = uintBitsToFloat(w[1].xyz);
    r.hit.shader = w[1].w;
    r.hit.ns = uintBitsToFloat(w[2].xyz);
    r.hit.emitter = w[2].w;
    r.hit.albedo = uintBitsToFloat(w[3].xyz);
    r.hit.offset = uintBitsToFloat(w[3].w);
    r.hit.material = w[4].x;
    r.hit.lift = uintBitsToFloat(w[4].y);
    r.hit.extension = w[4].zw;
    r.path.beta = uintBitsToFloat(w[5].xyz);
    r.path.prevPdf = uintBitsToFloat(w[5].w);
    r.path.pathId = w[6].x;
    r.path.bounce = w[6].y;
    r.path.flags = w[6].z;
    r.path.cone = w[6].w;
    r.rayDir = uintBitsToFloat(w[7].xyz);
    r.pad0 = w[7].w;
    return r;
}

// Layout twin of the C++ ShadeResult (shared/types.h): tests/vk/kernel_layout_test.cpp checks it field by field.
void storeResult(uint i, ShadeResult r) {
    uint o = 7u * i;
    results[o] = uvec4(r.flags, floatBitsToUint(r.emitted));
    results[o + 1u] = uvec4(floatBitsToUint(r.shadowOrigin), floatBitsToUint(r.shadowTmax));
    results[o + 2u] = uvec4(floatBitsToUint(r.shadowDir), floatBitsToUint(r.shadowContribution.x));
    results[o + 3u] = uvec4(floatBitsToUint(r.shadowContribution.yz),
                            floatBitsToUint(r.nextOrigin.xy));
    results[o + 4u] = uvec4(floatBitsToUint(r.nextOrigin.z), floatBitsToUint(r.nextDir));
    results[o + 5u] = uvec4(floatBitsToUint(r.next.beta), floatBitsToUint(r.next.prevPdf));
    results[o + 6u] = uvec4(r.next.pathId, r.next.bounce, r.next.flags, r.next.cone);
}

#define SHADER(i) kernelShader(i)
#define EMITTER(i) kernelEmitter(i)
#define EMITTER_CDF(i) uintBitsToFloat(fetch(emitterCdf, i).x)
#define LIGHT_DATA(i) uintBitsToFloat(fetch(lightData, i).x)
#include "shared/path.h"

void main() {
    uint local = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * kShadeWorkgroupSize +
                 gl_LocalInvocationIndex;
    if (local >= pc.count) return;
    uint i = pc.offset + local;
    ShadeInput record = loadInput(i);
    RenderParams rp = pc.params;
    rp.sampling = kSampling;
    rp.strategy = kStrategy;
    if (!kHasEmitters) {
        record.hit.emitter = kNoEmitter;
        rp.emitterCount = 0u;
    }
    if (!kTextured) {
        ShaderParams s = kernelShader(record.hit.shader);
        record.hit.albedo = s.colour * s.reflectance;
    }
    ShadeResult r;
    shadeSurface(rp, record.hit, record.rayDir, record.path, r);
    storeResult(i, r);
}
