// The registry of emitter kinds: one line per kind, and the only list of them there is.
// Everything else that names the kinds is derived from it:
//   * kEmitter<Name> and kEmitterKindCount (shared/types.h), in C++ and GLSL alike;
//   * light sampling: shared/lights.h's sampleEmitter calls the kind's header, <stem>.h, which
//     defines <stem>Sample with the signature lights.h lists (CMake writes the headers' includes
//     into generated/emitter_kind_headers.h and fails to configure without the header);
//   * MIS: emitterIsDelta (shared/lights.h) from the FLAGS: a delta light is never found by BSDF
//     sampling, so its light sample takes the whole weight;
//   * the kernels' specialisation to the one kind a scene has (shade_kernel.glsl), and the
//     kinds the Vulkan backend reports in --stats;
//   * the scene format: a kind with kLightTakesPosition or kLightTakesDirection is a punctual
//     light, `{type: <Scene>, position | direction, intensity, colour}`, read and given its power
//     by the loader and host/scene_view/lights.cpp without any code of its own.
// tests/architecture/emitter_kinds_test.cpp fails for a registered kind without its header, its
// <stem>Sample or its TEST(<Scene>Light, ...) in tests/scene/lights_test.cpp or
// tests/render/reference_test.cpp. How to add one: docs/adding-a-light.md.
//
// X(Name, id, stem, Scene, FLAGS) — id counts up from 0 in this order; Scene is the `type:` a
// scene file names it by; keep each entry on one line (CMake parses them).
//   kLightSurface        triangles of emissive meshes and Quad lights, hit by rays (MIS)
//   kLightAtInfinity     seen by rays that escape the scene (the environment)
//   kLightDelta          a delta light: never hit, never found by BSDF sampling
//   kLightTakesPosition  punctual, at `position`: power 4 pi I
//   kLightTakesDirection punctual, shining along `direction` from infinity: power pi r^2 E
//   kLightInstanced      an emissive prototype's triangles where one instance places them,
//                        made by host/scene_view/lights.cpp; no scene names it
#ifndef SPILLWAY_SHARED_EMITTER_KINDS_H
#define SPILLWAY_SHARED_EMITTER_KINDS_H

#define SPW_EMITTER_KINDS(X)                                                                       \
    X(Triangle, 0u, triangle_light, Quad, kLightSurface)                                           \
    X(Point, 1u, point_light, Point, kLightDelta | kLightTakesPosition)                            \
    X(Environment, 2u, environment_light, Environment, kLightAtInfinity)                           \
    X(Directional, 3u, directional_light, Directional, kLightDelta | kLightTakesDirection)         \
    X(Spot, 4u, spot_light, Spot, kLightDelta | kLightTakesPosition | kLightTakesDirection)        \
    X(Instance, 5u, instance_light, InstancedMesh, kLightInstanced)

#endif
