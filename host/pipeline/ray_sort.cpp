#include "host/pipeline/ray_sort.h"

#include "host/pipeline/parallel.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace spw {
namespace {

// Spreads the low 15 bits of v three apart (bit i -> bit 3i).
std::uint64_t spread3(std::uint64_t v) {
    v &= 0x7FFF;
    v = (v | v << 32) & 0x001F00000000FFFFull;
    v = (v | v << 16) & 0x001F0000FF0000FFull;
    v = (v | v << 8) & 0x100F00F00F00F00Full;
    v = (v | v << 4) & 0x10C30C30C30C30C3ull;
    v = (v | v << 2) & 0x1249249249249249ull;
    return v;
}

struct Bounds {
    vec3 lo{HUGE_VALF}, hi{-HUGE_VALF};
    void add(vec3 p) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    void add(const Bounds& b) {
        lo = glm::min(lo, b.lo);
        hi = glm::max(hi, b.hi);
    }
    int longestAxis() const {
        vec3 e = hi - lo;
        return e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
    }
};

Bounds originBounds(const RayState* r, size_t n) {
    return tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, n, 1 << 14), Bounds(),
        [&](const tbb::blocked_range<size_t>& range, Bounds b) {
            for (size_t i = range.begin(); i < range.end(); ++i)
                b.add(r[i].origin);
            return b;
        },
        [](Bounds a, const Bounds& b) {
            a.add(b);
            return a;
        });
}

template <class Get> void medianSplit(RayState* r, size_t n, size_t leaf, Get get) {
    if (n <= leaf) return;
    Bounds b;
    for (size_t i = 0; i < n; ++i)
        b.add(get(r[i]));
    const int axis = b.longestAxis();
    if (b.hi[axis] <= b.lo[axis]) return; // all equal along every axis: nothing to split
    const size_t mid = n / 2;
    std::nth_element(r, r + mid, r + n, [&](const RayState& a, const RayState& c) {
        return get(a)[axis] < get(c)[axis];
    });
    auto left = [&] { medianSplit(r, mid, leaf, get); };
    auto right = [&] { medianSplit(r + mid, n - mid, leaf, get); };
    if (n > 8192)
        tbb::parallel_invoke(left, right);
    else
        left(), right();
}

void medianByOrigin(RayState* r, size_t n) {
    if (n <= 4096) {
        // Leaf of the origin split: now order by direction down to groups of 64.
        medianSplit(r, n, 64, [](const RayState& s) { return s.dir; });
        return;
    }
    Bounds b;
    for (size_t i = 0; i < n; ++i)
        b.add(r[i].origin);
    const int axis = b.longestAxis();
    const size_t mid = n / 2;
    std::nth_element(r, r + mid, r + n, [&](const RayState& a, const RayState& c) {
        return a.origin[axis] < c.origin[axis];
    });
    tbb::parallel_invoke([&] { medianByOrigin(r, mid); },
                         [&] { medianByOrigin(r + mid, n - mid); });
}

} // namespace

MortonFrame MortonFrame::of(const std::vector<RayState>& rays) {
    const Bounds b = originBounds(rays.data(), rays.size());
    const vec3 extent = b.hi - b.lo;
    return {b.lo, vec3(extent.x > 0 ? 32767.0f / extent.x : 0.0f,
                       extent.y > 0 ? 32767.0f / extent.y : 0.0f,
                       extent.z > 0 ? 32767.0f / extent.z : 0.0f)};
}

std::uint64_t MortonFrame::key(const RayState& r) const {
    vec3 q = glm::clamp((r.origin - lo) * scale, vec3(0.0f), vec3(32767.0f));
    std::uint64_t morton = spread3(std::uint64_t(q.x)) | spread3(std::uint64_t(q.y)) << 1 |
                           spread3(std::uint64_t(q.z)) << 2;
    // 8+8-bit octahedral direction.
    const glm::dvec2 o = octahedralMap(r.dir);
    std::uint64_t du = std::uint64_t(std::clamp((o.x * 0.5 + 0.5) * 255.0, 0.0, 255.0));
    std::uint64_t dv = std::uint64_t(std::clamp((o.y * 0.5 + 0.5) * 255.0, 0.0, 255.0));
    return std::uint64_t(cardinalBin(r.dir)) << 61 | morton << 16 | du << 8 | dv;
}

void sortRaysMorton(std::vector<RayState>& rays, std::vector<KeyIndex>& keys,
                    std::vector<KeyIndex>& scratch, std::vector<RayState>& tmp) {
    const size_t n = rays.size();
    if (n < 2) return;
    const MortonFrame frame = MortonFrame::of(rays);
    keys.resize(n);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, batchGrain(n, 512, 4096)),
                      [&](const tbb::blocked_range<size_t>& range) {
                          for (size_t i = range.begin(); i < range.end(); ++i)
                              keys[i] = {frame.key(rays[i]), std::uint32_t(i)};
                      });
    radixSort(keys, scratch);
    tmp.resize(n);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, batchGrain(n, 512, 4096)),
                      [&](const tbb::blocked_range<size_t>& range) {
                          for (size_t i = range.begin(); i < range.end(); ++i)
                              tmp[i] = rays[keys[i].index];
                      });
    rays.swap(tmp);
}

void sortRaysMedian(std::vector<RayState>& rays) {
    medianByOrigin(rays.data(), rays.size());
}

RaySortMode RaySortPolicy::choose(size_t rays) {
    if (mode_ != RaySortMode::Auto) return mode_;
    if (!measured(rays)) return RaySortMode::Off;
    ++decisions_;
    bool sort;
    if (samples_[0] == 0) {
        sort = false;
    } else if (samples_[1] == 0) {
        sort = true;
    } else {
        const double other = cost_[sorting_ ? 0 : 1], current = cost_[sorting_ ? 1 : 0];
        if (other < 0.9 * current) { // the choice changes: watch it closely again
            sorting_ = !sorting_;
            interval_ = 16;
            nextTry_ = decisions_ + interval_;
        }
        sort = sorting_;
        if (decisions_ >= nextTry_) { // keep the other estimate fresh, ever more rarely
            sort = !sorting_;
            interval_ = std::min<size_t>(interval_ * 2, 256);
            nextTry_ = decisions_ + interval_;
        }
    }
    return sort ? RaySortMode::Morton : RaySortMode::Off;
}

void RaySortPolicy::record(bool sorted, double seconds, size_t rays) {
    (sorted ? sortedBatches_ : unsortedBatches_)++;
    if (mode_ != RaySortMode::Auto || !measured(rays)) return;
    const int k = sorted ? 1 : 0;
    const double perRay = seconds / double(rays);
    // The way taken: a running mean that forgets, the last ~8 batches dominating. The other way,
    // measured again after many batches: its old estimate is stale, the new one replaces it.
    const bool taken = sorted == sorting_;
    cost_[k] = samples_[k] == 0 || !taken ? perRay : 0.875 * cost_[k] + 0.125 * perRay;
    ++samples_[k];
}

} // namespace spw
