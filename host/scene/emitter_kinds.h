// The C++ view of the emitter-kind registry (shaders/shared/emitter_kinds.h): each kind's name,
// its kEmitter* constant, its shared header's stem, the `type:` a scene names it by, and its
// flags. Read by the loader (punctual kinds: `{type: <Scene>, position | direction, ...}`), the
// light table's power estimates (host/scene_view/lights.cpp), the Vulkan backend's --stats and the
// tests that check every kind is complete.
//
// Adding a kind: docs/adding-a-light.md.
#pragma once

#include "shared/types.h"

#include <cstddef>
#include <string>
#include <vector>

namespace spw {

struct EmitterKindInfo {
    const char* name;  // kEmitter<name>
    uint kind;         // kEmitter*
    const char* stem;  // shaders/shared/<stem>.h
    const char* scene; // `type:` in a scene file's light
    uint flags;        // kLight*
    bool punctual() const { return (flags & (kLightTakesPosition | kLightTakesDirection)) != 0u; }
};

#define SPW_EMITTER_KIND_ENTRY(Name, id, stem, Scene, flags)                                       \
    EmitterKindInfo{#Name, kEmitter##Name, #stem, #Scene, uint(flags)},
inline constexpr EmitterKindInfo kEmitterKindTable[] = {SPW_EMITTER_KINDS(SPW_EMITTER_KIND_ENTRY)};
#undef SPW_EMITTER_KIND_ENTRY
static_assert(sizeof(kEmitterKindTable) / sizeof(kEmitterKindTable[0]) == kEmitterKindCount);

// The registry entry of a kind, or nullptr.
inline const EmitterKindInfo* emitterKind(uint kind) {
    for (const EmitterKindInfo& k : kEmitterKindTable)
        if (k.kind == kind) return &k;
    return nullptr;
}

// The registry entry a scene's light `type:` names, or nullptr (a kind the lights make for
// instances, kLightInstanced, is named by no scene).
inline const EmitterKindInfo* emitterKindNamed(const std::string& scene) {
    for (const EmitterKindInfo& k : kEmitterKindTable)
        if (scene == k.scene && !(k.flags & kLightInstanced)) return &k;
    return nullptr;
}

// "Quad, Point, Environment or Directional": the light types a scene may name.
inline std::string lightTypeList() {
    std::vector<const char*> named;
    for (const EmitterKindInfo& k : kEmitterKindTable)
        if (!(k.flags & kLightInstanced)) named.push_back(k.scene);
    std::string out;
    for (size_t i = 0; i < named.size(); ++i) {
        if (i > 0) out += i + 1 == named.size() ? " or " : ", ";
        out += named[i];
    }
    return out;
}

} // namespace spw
