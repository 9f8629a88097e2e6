#include "host/pipeline/hit_sort.h"

namespace spw {

std::vector<ShaderRun> shaderRuns(const std::vector<SortedHit>& keys, size_t hitCount) {
    std::vector<ShaderRun> runs;
    size_t begin = 0;
    while (begin < hitCount) {
        const uint shader = shaderOfKey(keys[begin].key);
        size_t end = begin + 1;
        while (end < hitCount && shaderOfKey(keys[end].key) == shader)
            ++end;
        runs.push_back({shader, begin, end - begin});
        begin = end;
    }
    return runs;
}

} // namespace spw
