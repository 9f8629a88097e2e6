// Hit sorting: each hit's key packs (shader rank, object, texture order) into 12 + 20 + 32 bits,
// so that a radix sort of the keys groups a batch's hits by surface model and shader, and within
// a shader by object and then by where they fall in texture space (coherent texture reads);
// misses sort last (stages.h: sortHits gives them the rank after the last shader's; kMissKey, the
// all-ones key, where hits are not sorted). The shader's rank (ShaderRanks) puts the shaders
// of one surface model next to each other: each model's hits are one contiguous range, one
// dispatch of its kernel on the vulkan backend, whatever the order of the scene's shaders. Object
// and texture order only pay where textures are read; elsewhere the pipeline keys (shader rank,
// 0, 0) and the hits keep their traversal order within a shader (stages.h: sortHits).
// The loader's kMaxShaders and kMaxObjects keep every hit's key distinct from a miss's.
#pragma once

#include "host/pipeline/radix_sort.h"
#include "host/scene/scene.h"

#include <cstdint>
#include <vector>

namespace spw {

constexpr std::uint64_t kMissKey = ~0ull;

// One entry of the hit sort (MoonRay's SortedEntry): the hit's key, hitSortKey() or kMissKey,
// and the hit's index in its batch. It is the radix sort's own entry type.
using SortedHit = KeyIndex;

inline std::uint64_t hitSortKey(uint shader, uint object, uint order) {
    return std::uint64_t(shader) << 52 | std::uint64_t(object) << 32 | order;
}

// A hit's order within its object: the Morton code of its texture coordinates (wrapped into
// [0, 1), 16 bits each), so that hits reading the same texture tiles sit together; the primitive
// where the mesh has no texture coordinates. Measured against primitive order on the production
// scene (16 models, 1024^2 textures read at the finest level, cache 1/4 of them, 2^14 and 2^17
// batches): 1-3 % fewer tiles read and hit setup up to 20 % faster; a mesh's primitives are
// already in rows of its parametrisation, hence the small gain.
uint textureOrder(const Mesh& mesh, uint primitive, float u, float v);
inline uint shaderOfKey(std::uint64_t key) {
    return uint(key >> 52);
}

// How a batch's hits are ordered before they are shaded: decided once a render, by
// chooseHitOrder() from the engine's rule (ShadingEngine::hitOrder), and followed by the hit
// sort (stages.h: sortHits), the shading ranges (shadeRanges) and --stats.
enum class HitOrder {
    AsTraced,              // traversal order, misses in place: no sort at all
    MissesLast,            // traversal order, the misses moved behind the hits
    ByShader,              // by shader rank (ShaderRanks), traversal order within a shader
    ByShaderObjectTexture, // by shader rank, then object, then textureOrder()
};
// What --stats and the messages call it.
const char* hitOrderName(HitOrder order);
// Whether the hits are sorted by shader: each surface model's hits one contiguous range.
inline bool sortsByShader(HitOrder order) {
    return order == HitOrder::ByShader || order == HitOrder::ByShaderObjectTexture;
}

// What a shading engine wants of the order.
struct HitOrderRule {
    bool byShader;           // its hits sorted by shader (each model's range one dispatch)
    bool textureOrderPays;   // within a shader, object and texture order pay where images are read
    bool takesMissesInPlace; // it can shade unsorted hits with the misses among them
};
// The one decision: by shader where the engine asks for it (with object and texture order where
// the scene reads images and that pays); otherwise traversal order, the misses moved out only
// where an environment gives them something to add (accumulateEscapes reads them behind the
// hits) or the engine cannot leave them in place.
HitOrder chooseHitOrder(const HitOrderRule& rule, bool readsImages, bool hasEnvironment);

// The shaders' places in the hit sort: by surface model, then by index.
struct ShaderRanks {
    explicit ShaderRanks(const Scene& scene);
    std::vector<uint> rank;     // rank[shader]: what the sort key holds
    std::vector<uint> shaderAt; // shaderAt[rank]: the shader
};

// A run of sorted hits that share one shader: [begin, begin + count).
struct ShaderRun {
    uint shader; // what the keys hold: the shader's rank where they were made by ShaderRanks
    size_t begin, count;
};

// The maximal runs of one shader in keys[0, hitCount), which must be sorted by hitSortKey.
std::vector<ShaderRun> shaderRuns(const std::vector<SortedHit>& keys, size_t hitCount);

} // namespace spw
