// Structs that every backend's shading step reads and writes. Declared once, here; the C++
// side checks their layout in host/vk/shared_layout.cpp so that a GLSL scalar-block-layout view
// of the same bytes stays in step.
#ifndef SPILLWAY_SHARED_TYPES_H
#define SPILLWAY_SHARED_TYPES_H
#include "compat.h"
#include "emitter_kinds.h"
#include "surface_models.h"

SHARED_BEGIN

// Surface models: kModel<Name> for every line of the registry (shared/surface_models.h), and
// their count.
#define SPW_MODEL_CONSTANT(Name, id, stem, fn, params) const uint kModel##Name = id;
SPW_SURFACE_MODELS(SPW_MODEL_CONSTANT)
#undef SPW_MODEL_CONSTANT
#define SPW_MODEL_ONE(Name, id, stem, fn, params) +1u
const uint kModelCount = 0u SPW_SURFACE_MODELS(SPW_MODEL_ONE);
#undef SPW_MODEL_ONE

const uint kShaderTwoSided = 1u;  // emits from both faces
const uint kShaderTextured = 2u;  // albedo comes from a texture tree, resolved on the host
const uint kShaderHitParams = 4u; // metallic and roughness come from the hit (SurfaceHit.material)
const uint kShaderSpecular = 8u;  // MetallicRoughness models: the dielectric reflection takes
                                  // specular and specularColour (KHR_materials_specular)
const uint kShaderHitExtension = 16u; // the model's extension parameters come from the hit
                                      // (SurfaceHit.extension; bsdf.h's shaderAtHit says which)
const uint kShaderCoatNormal = 32u;   // CoatedMetallicRoughness: the coat has a shading normal of
                                      // its own (ShaderParams.coatNormal, from the hit)

struct ShaderParams {
    vec3 emission;     // radiance leaving the front face (both with kShaderTwoSided)
    uint model;        // kModel*
    vec3 colour;       // constant albedo colour when not textured (Conductor: F0)
    float reflectance; // albedo scale
    uint flags;        // kShader*
    float ior;         // Dielectric: index of refraction of the back (inside) of the surface
    float alpha;     // Conductor, Dielectric, MetallicRoughness: GGX width; below kGgxSmoothAlpha a
                     // delta lobe
    float metallic;  // MetallicRoughness: glTF's metallic factor
    vec3 absorption; // Dielectric: the absorption coefficient of the medium behind the surface,
                     // per unit length (Beer-Lambert); 0: clear
    float coat;      // CoatedMetallicRoughness: the clear coat's weight in [0, 1]
    float coatAlpha; // CoatedMetallicRoughness: the coat's GGX width
    // MetallicRoughness models, with kShaderSpecular: the dielectric reflection's F0 colour
    // factor and its weight (KHR_materials_specular's specularColorFactor and specularFactor);
    // without the flag, (1, 1, 1) and 1.
    vec3 specularColour;
    float specular;
    float transmission;   // TransmissiveMetallicRoughness: the glass lobe's weight in [0, 1]
    float sheenRoughness; // SheenMetallicRoughness: the sheen's perceptual roughness
    // CoatedMetallicRoughness with kShaderCoatNormal: the coat's shading normal at the hit, which
    // shaderAtHit takes from SurfaceHit::extension's last two halves (octahedralEncode's point,
    // packHalf2x16); without the flag the coat shares the base's.
    uint coatNormal;
    vec3 sheenColour;   // SheenMetallicRoughness: the sheen's colour (KHR_materials_sheen)
    float specularTint; // Principled: the specular reflection's tint towards the base colour's hue
    float sheen;        // Principled: the sheen's weight
    float sheenTint;    // Principled: the sheen's tint towards the base colour's hue
    uint pad1;
    uint pad2;
};

// What next-event estimation picks, with probability pickPdf, proportional to its power
// (host/scene_view/lights.cpp says how each kind's power is estimated): kEmitter<Name> for every
// line of the registry (shared/emitter_kinds.h), and their count.
const uint kLightSurface = 1u;
const uint kLightAtInfinity = 2u;
const uint kLightDelta = 4u;
const uint kLightTakesPosition = 8u;
const uint kLightTakesDirection = 16u;
const uint kLightInstanced = 32u; // made by the lights for an instanced mesh, named by no scene
#define SPW_EMITTER_CONSTANT(Name, id, stem, Scene, flags) const uint kEmitter##Name = id;
SPW_EMITTER_KINDS(SPW_EMITTER_CONSTANT)
#undef SPW_EMITTER_CONSTANT
#define SPW_EMITTER_ONE(Name, id, stem, Scene, flags) +1u
const uint kEmitterKindCount = 0u SPW_EMITTER_KINDS(SPW_EMITTER_ONE);
#undef SPW_EMITTER_ONE

// An instance (kEmitterInstance, shared/instance_light.h) keeps its own fields in these words:
// p0 and e1 the low and high corners of its world bounds, area and e2 word offsets and counts
// as float bits, twoSided its triangles' first hit index, normal.x -1 where it mirrors.
struct Emitter {
    vec3 p0; // triangle: vertex 0; point: the position
    float area;
    vec3 e1; // triangle: v1 - v0; spot: (cos outer angle, cos inner angle, 0)
    float pickPdf;
    vec3 e2; // triangle: v2 - v0
    uint twoSided;
    vec3 normal;   // triangle: unit, cross(e1, e2) direction: the front face; directional, spot:
                   // the unit direction its light travels
    uint type;     // kEmitter*
    vec3 radiance; // triangle: radiance; point, spot: intensity (W/sr); environment: radiance
                   // (times the map's texel where it has one); directional: irradiance (W/m^2)
    uint map;      // triangle: its emission map's record in the light data (shared/emission_map.h),
                   // which the radiance is multiplied by; kNoEmissionMap (0) otherwise
};
// No record starts at 0 (the maps' first image is ahead of every record), so a zeroed Emitter has
// no map.
const uint kNoEmissionMap = 0u;

// What the shading step needs to know about a hit, already in world space.
struct SurfaceHit {
    vec3 p;          // position, interpolated from the triangle's vertices (not o + t d)
    float t;         // distance along the unit ray direction
    vec3 ng;         // unit geometric normal, cross(v1 - v0, v2 - v0)
    uint shader;     // index into the scene's shaders
    vec3 ns;         // unit shading normal (interpolated vertex normals, or ng)
    uint emitter;    // index of the emitting triangle hit, or kNoEmitter
    vec3 albedo;     // reflectance x texture, resolved on the host in hit-sorted order
    float offset;    // how far rays leaving p start off the surface (shared/offset.h), set with p
    uint material;   // with kShaderHitParams: the metallic (low 16 bits) and perceptual roughness
                     // (high) that the host's texture lookup gave the hit, as unorm16 (bsdf.h's
                     // shaderAtHit); 0 otherwise
    float lift;      // how far above its flat triangle the smooth surface its vertex normals
                     // describe lies at p, along ng (negative: below), for shadow rays leaving on
                     // that side (shared/offset.h's shadowLift); 0 without vertex normals
    uvec2 extension; // with kShaderHitExtension: four values as halves (packHalf2x16: x holds the
                     // first two, y the last two) that the host's extension maps gave the hit
                     // (KHR_materials_clearcoat's, sheen's, specular's and transmission's
                     // textures times their factors); with kShaderCoatNormal, y is the coat's
                     // shading normal instead (octahedralEncode's point); 0 otherwise
};
const uint kNoEmitter = 0xFFFFFFFFu;

// A path between bounces.
const uint kPathSpecular = 1u; // the last bounce sampled a delta lobe: no MIS on emitter hits

struct PathState {
    vec3 beta;     // throughput
    float prevPdf; // solid-angle pdf of the BSDF sample that made this ray (bfloat16-quantised)
    uint pathId;   // pixel * samplesPerIteration + sample within the iteration
    uint bounce;   // 0 for camera rays
    uint flags;    // kPath*
    uint cone;     // the ray's cone, packed (shared/cone.h)
};

const uint kStrategyMis = 0u;   // light and BSDF sampling, power heuristic
const uint kStrategyLight = 1u; // next-event estimation only (emitter hits after bounce 0 ignored)
const uint kStrategyBsdf = 2u;  // BSDF sampling only (no shadow rays)

struct RenderParams {
    uint seed;
    uint iteration;
    uint samplesPerIteration;
    uint minDepth;
    uint maxDepth;
    float threshold;
    uint strategy;
    uint emitterCount;
    uint sampling;    // kSampler* (shared/rng.h): the numbers of every dimension after the pixel's
    uint environment; // the environment's emitter index, or kNoEmitter
    uint envWidth;    // its lat-long map's size in texels; 0 x 0 for a constant environment
    uint envHeight;
    uint treeEmitters;       // emitters 0 .. treeEmitters - 1 are picked through the light tree
                             // (shared/light_tree.h); 0: no tree
    uint instanceLights;     // the first of the emitters that are instances (kEmitterInstance)
    uint instanceLightCount; // how many there are, one after another; 0: none
};

const uint kShadeEmitted = 1u;
const uint kShadeShadow = 2u;
const uint kShadeContinue = 4u;

struct ShadeResult {
    uint flags;   // kShade*
    vec3 emitted; // beta * Le * MIS weight, for the film now
    vec3 shadowOrigin;
    float shadowTmax;
    vec3 shadowDir;
    vec3 shadowContribution; // added to the film if the shadow ray is unoccluded
    vec3 nextOrigin;
    vec3 nextDir;
    PathState next;
};

SHARED_END
#endif
