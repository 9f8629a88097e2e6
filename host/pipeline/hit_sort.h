// Hit sorting: each hit's key packs (shader, object, primitive) into 12 + 20 + 32 bits, so that
// a radix sort of the keys groups a batch's hits by shader, and within a shader by object and
// primitive (coherent vertex and texture reads); misses take the all-ones key and sort last.
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

inline std::uint64_t hitSortKey(uint shader, uint object, uint primitive) {
    return std::uint64_t(shader) << 52 | std::uint64_t(object) << 32 | primitive;
}
inline uint shaderOfKey(std::uint64_t key) {
    return uint(key >> 52);
}

// A run of sorted hits that share one shader: [begin, begin + count).
struct ShaderRun {
    uint shader;
    size_t begin, count;
};

// The maximal runs of one shader in keys[0, hitCount), which must be sorted by hitSortKey.
std::vector<ShaderRun> shaderRuns(const std::vector<SortedHit>& keys, size_t hitCount);

} // namespace spw
