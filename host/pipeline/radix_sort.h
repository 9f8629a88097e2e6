// A parallel LSD radix sort of 64-bit keys carrying 32-bit payloads (8-bit digits, TBB-parallel
// histograms and scatter, stable). Digits on which every key agrees are skipped, so short keys
// cost only the passes they need.
#pragma once

#include <cstdint>
#include <vector>

namespace spw {

struct KeyIndex {
    std::uint64_t key;
    std::uint32_t index;
};

// Sorts `items` by key, stably. `scratch` is resized as needed and may be reused across calls.
void radixSort(std::vector<KeyIndex>& items, std::vector<KeyIndex>& scratch);

} // namespace spw
