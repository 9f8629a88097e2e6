// A parallel LSD radix sort of 64-bit keys carrying 32-bit payloads (8-bit digits, TBB-parallel
// histograms and scatter, stable). Digits on which every key agrees are skipped, so short keys
// cost only the passes they need.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace spw {

struct KeyIndex {
    std::uint64_t key;
    std::uint32_t index;
};

// Sorts items[0, count) by key, stably, and leaves the items after them as they are (count
// defaults to all). `scratch` is resized as needed and may be reused across calls.
void radixSort(std::vector<KeyIndex>& items, std::vector<KeyIndex>& scratch, size_t count);
inline void radixSort(std::vector<KeyIndex>& items, std::vector<KeyIndex>& scratch) {
    radixSort(items, scratch, items.size());
}

} // namespace spw
