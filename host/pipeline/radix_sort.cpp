#include "host/pipeline/radix_sort.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>

namespace spw {

void radixSort(std::vector<KeyIndex>& items, std::vector<KeyIndex>& scratch) {
    const size_t n = items.size();
    if (n < 2) return;
    scratch.resize(n);
    // Below this size one thread sorts faster than the task overhead of splitting.
    const size_t chunk = std::max<size_t>(1 << 14, (n + 31) / 32);
    const size_t chunks = (n + chunk - 1) / chunk;
    std::uint64_t all_or = 0, all_and = ~0ull;
    for (const KeyIndex& k : items)
        all_or |= k.key, all_and &= k.key;
    const std::uint64_t varying = all_or ^ all_and;
    std::vector<std::array<size_t, 256>> hist(chunks);
    for (int shift = 0; shift < 64; shift += 8) {
        if (((varying >> shift) & 0xFF) == 0) continue;
        tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
            hist[c].fill(0);
            const size_t end = std::min(n, (c + 1) * chunk);
            for (size_t i = c * chunk; i < end; ++i)
                ++hist[c][(items[i].key >> shift) & 0xFF];
        });
        // Exclusive prefix over (digit, chunk) so every chunk scatters to its own slots: stable.
        size_t sum = 0;
        for (int d = 0; d < 256; ++d)
            for (size_t c = 0; c < chunks; ++c) {
                size_t h = hist[c][size_t(d)];
                hist[c][size_t(d)] = sum;
                sum += h;
            }
        tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
            std::array<size_t, 256>& offs = hist[c];
            const size_t end = std::min(n, (c + 1) * chunk);
            for (size_t i = c * chunk; i < end; ++i)
                scratch[offs[(items[i].key >> shift) & 0xFF]++] = items[i];
        });
        items.swap(scratch);
    }
}

} // namespace spw
