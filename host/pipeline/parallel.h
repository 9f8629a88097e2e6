// Small parallel building blocks for the batch stages (TBB underneath).
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstdint>
#include <vector>

namespace spw {

constexpr size_t kParallelGrain = 4096;

// A grain for n items of a batch stage: at most `largest`, at least `smallest`, and otherwise
// small enough for eight tasks per thread, so that a small batch (2^12 rays) still keeps every
// core busy instead of running as one task.
inline size_t batchGrain(size_t n, size_t smallest, size_t largest) {
    const size_t threads = size_t(std::max(1, tbb::this_task_arena::max_concurrency()));
    return std::clamp(n / (8 * threads), smallest, std::max(smallest, largest));
}

// Number of i in [0, n) with pred(i).
template <class Pred> size_t parallelCount(size_t n, Pred pred) {
    return tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, n, kParallelGrain), size_t(0),
        [&](const tbb::blocked_range<size_t>& r, size_t c) {
            for (size_t i = r.begin(); i < r.end(); ++i)
                c += pred(i) ? 1 : 0;
            return c;
        },
        [](size_t a, size_t b) { return a + b; });
}

// The i in [0, n) with pred(i), in increasing order (a stable parallel compaction).
template <class Pred> void parallelSelect(size_t n, Pred pred, std::vector<std::uint32_t>& out) {
    const size_t chunks = (n + kParallelGrain - 1) / kParallelGrain;
    std::vector<size_t> offsets(chunks + 1, 0);
    tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
        size_t count = 0;
        for (size_t i = c * kParallelGrain; i < std::min(n, (c + 1) * kParallelGrain); ++i)
            count += pred(i) ? 1 : 0;
        offsets[c + 1] = count;
    });
    for (size_t c = 0; c < chunks; ++c)
        offsets[c + 1] += offsets[c];
    out.resize(offsets[chunks]);
    tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
        size_t at = offsets[c];
        for (size_t i = c * kParallelGrain; i < std::min(n, (c + 1) * kParallelGrain); ++i)
            if (pred(i)) out[at++] = std::uint32_t(i);
    });
}

} // namespace spw
