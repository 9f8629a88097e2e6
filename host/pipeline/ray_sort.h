// Ordering a batch for coherent traversal, two ways:
//  * morton: a parallel radix sort on (cardinal bin, 45-bit Morton code of the origin in the
//    batch's bounds, 8+8-bit octahedral direction);
//  * median: the thesis's recursive median split of the origins along the longest axis down to
//    4096 rays, then of the directions down to 64.
// and the rule that decides whether sorting a batch pays at all (RaySortPolicy).
#pragma once

#include "host/pipeline/radix_sort.h"
#include "host/pipeline/ray_record.h"

#include <cstdint>
#include <string>
#include <vector>

namespace spw {

// The Morton sort's key of a ray in a batch whose origins span [lo, hi]: the cardinal bin (bits
// 61-63), a 45-bit Morton code of the origin quantised to 2^15 steps along each axis of the
// bounds (bits 16-60), and an 8+8-bit octahedral direction (bits 0-15).
struct MortonFrame {
    vec3 lo, scale;
    static MortonFrame of(const std::vector<RayState>& rays);
    std::uint64_t key(const RayState& ray) const;
};

// Sorts by MortonFrame::of(rays).key, stably.
void sortRaysMorton(std::vector<RayState>& rays, std::vector<KeyIndex>& keys,
                    std::vector<KeyIndex>& scratch, std::vector<RayState>& tmp);
// Splits at the median origin along the bounds' longest axis, recursively, down to 4096 rays,
// then at the median direction likewise down to 64.
void sortRaysMedian(std::vector<RayState>& rays);

// The `auto` rule. Sorting costs a fixed time per ray and saves traversal time only when
// traversal is expensive and the rays arrive incoherent, so the rule measures instead of
// guessing. Camera batches never reach it: they are made in tile order, already coherent.
//  * Batches under half the batch size (an iteration's last few) are never sorted and not
//    measured: their fixed costs would blur the estimates.
//  * For full batches it keeps a running mean of the cost per ray with sorting (sort +
//    traverse) and without (traverse), measures each way once, then takes the cheaper way;
//    it changes its choice only when the other way is 10 % cheaper, so noise does not flip it.
//  * It measures the other way again (a fresh estimate, replacing the stale one) after 16 batches,
//  then after twice as many each time the
//    choice stands (up to 256), and after 16 again once it changes: a change of workload is
//    still noticed, while a way that never pays is tried ever more rarely.
class RaySortPolicy {
  public:
    RaySortPolicy(RaySortMode mode, size_t batchRays) : mode_(mode), batchRays_(batchRays) {}
    // The sort to use for a batch of `rays` bounce rays.
    RaySortMode choose(size_t rays);
    // Reports what a batch cost (sorted or not); the estimates ignore the small batches that
    // choose() skips, the counts do not.
    void record(bool sorted, double seconds, size_t rays);
    size_t sortedBatches() const { return sortedBatches_; }
    size_t unsortedBatches() const { return unsortedBatches_; }

  private:
    bool measured(size_t rays) const { return rays * 2 >= batchRays_ && rays > 0; }
    RaySortMode mode_;
    size_t batchRays_;
    double cost_[2] = {0, 0}; // seconds per ray: [unsorted, sorted]
    int samples_[2] = {0, 0};
    size_t decisions_ = 0;
    bool sorting_ = false;                // the current choice
    size_t interval_ = 16, nextTry_ = 16; // when the other way is measured again
    size_t sortedBatches_ = 0, unsortedBatches_ = 0;
};

} // namespace spw
