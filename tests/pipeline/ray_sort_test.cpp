// The ray sorts themselves, not only the images they leave unchanged: each output is a
// permutation of its input; Morton output is ordered by its key (and stable); median output is
// split at the median along the longest axis at every level its definition names; and the `auto`
// rule decides what its stated rule says for constructed timings.
#include "host/pipeline/ray_sort.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace spw {
namespace {

// Rays with distinct path ids, origins in a 10 x 4 x 1 box (x the longest axis), any direction.
std::vector<RayState> randomRays(size_t n, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<RayState> rays(n);
    for (size_t i = 0; i < n; ++i) {
        RayState& r = rays[i];
        r.origin = vec3(10.0f * u(rng), 4.0f * u(rng), u(rng));
        const float z = 2.0f * u(rng) - 1.0f, phi = 6.2831853f * u(rng),
                    s = std::sqrt(std::max(0.0f, 1 - z * z));
        r.dir = vec3(s * std::cos(phi), s * std::sin(phi), z);
        r.path = PathState{};
        r.path.pathId = uint(i);
    }
    return rays;
}

std::vector<uint> sortedIds(const std::vector<RayState>& rays) {
    std::vector<uint> ids;
    for (const RayState& r : rays)
        ids.push_back(r.path.pathId);
    std::sort(ids.begin(), ids.end());
    return ids;
}

void expectPermutation(const std::vector<RayState>& in, const std::vector<RayState>& out) {
    ASSERT_EQ(in.size(), out.size());
    EXPECT_EQ(sortedIds(in), sortedIds(out));
    // Each ray moved whole: origin and direction still belong to its id.
    for (const RayState& r : out) {
        const RayState& original = in[r.path.pathId];
        EXPECT_EQ(r.origin, original.origin);
        EXPECT_EQ(r.dir, original.dir);
    }
}

TEST(RaySort, MortonIsAStablePermutationOrderedByItsKey) {
    const std::vector<RayState> in = randomRays(20000, 1);
    std::vector<RayState> rays = in, tmp;
    std::vector<KeyIndex> keys, scratch;
    sortRaysMorton(rays, keys, scratch, tmp);
    expectPermutation(in, rays);
    const MortonFrame frame = MortonFrame::of(in);
    size_t ties = 0;
    for (size_t i = 1; i < rays.size(); ++i) {
        const std::uint64_t a = frame.key(rays[i - 1]), b = frame.key(rays[i]);
        ASSERT_LE(a, b) << "out of key order at " << i;
        if (a == b) {
            ++ties;
            EXPECT_LT(rays[i - 1].path.pathId, rays[i].path.pathId) << "not stable at " << i;
        }
    }
    // The keys must order something: an input in id order is far from key order.
    size_t moved = 0;
    for (size_t i = 0; i < rays.size(); ++i)
        moved += rays[i].path.pathId != i;
    EXPECT_GT(moved, rays.size() * 9 / 10);
    std::printf("%zu ties among %zu keys\n", ties, rays.size());
}

TEST(RaySort, MortonKeyPutsTheBinFirstThenOriginThenDirection) {
    const MortonFrame frame{vec3(0.0f), vec3(32767.0f / 8.0f)};
    RayState a{}, b{};
    a.origin = vec3(1, 1, 1), a.dir = vec3(1, 0, 0);
    b.origin = vec3(7, 7, 7), b.dir = vec3(1, 0, 0);
    EXPECT_LT(frame.key(a), frame.key(b)) << "same bin and direction: the origin orders";
    b.origin = a.origin, b.dir = glm::normalize(vec3(1, 0.2f, 0));
    EXPECT_NE(frame.key(a), frame.key(b)) << "same origin: the direction orders";
    EXPECT_EQ(frame.key(a) >> 16, frame.key(b) >> 16) << "the direction only in the low 16 bits";
    b.origin = vec3(7, 7, 7), b.dir = vec3(-1, 0, 0);
    EXPECT_NE(frame.key(a) >> 61, frame.key(b) >> 61) << "the cardinal bin in the top bits";
}

// The median split's definition, checked level by level: at every node of more than `leaf`
// rays, the first half lies at or below the second along the node's longest axis.
template <class Get>
void expectMedianSplit(const RayState* r, size_t n, size_t leaf, Get get, int& nodes) {
    if (n <= leaf) return;
    vec3 lo(HUGE_VALF), hi(-HUGE_VALF);
    for (size_t i = 0; i < n; ++i)
        lo = glm::min(lo, get(r[i])), hi = glm::max(hi, get(r[i]));
    const vec3 e = hi - lo;
    const int axis = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
    if (hi[axis] <= lo[axis]) return;
    const size_t mid = n / 2;
    float below = -HUGE_VALF, above = HUGE_VALF;
    for (size_t i = 0; i < mid; ++i)
        below = std::max(below, get(r[i])[axis]);
    for (size_t i = mid; i < n; ++i)
        above = std::min(above, get(r[i])[axis]);
    ASSERT_LE(below, above) << "a node of " << n << " rays is not split at its median along axis "
                            << axis;
    ++nodes;
    expectMedianSplit(r, mid, leaf, get, nodes);
    expectMedianSplit(r + mid, n - mid, leaf, get, nodes);
}

TEST(RaySort, MedianSplitsAtTheMedianOfOriginsThenOfDirections) {
    const std::vector<RayState> in = randomRays(32768, 2);
    std::vector<RayState> rays = in;
    sortRaysMedian(rays);
    expectPermutation(in, rays);
    int originNodes = 0, directionNodes = 0;
    expectMedianSplit(
        rays.data(), rays.size(), 4096, [](const RayState& s) { return s.origin; }, originNodes);
    EXPECT_EQ(originNodes, 1 + 2 + 4); // 32768 -> 8 leaves of 4096
    for (size_t at = 0; at < rays.size(); at += 4096)
        expectMedianSplit(
            rays.data() + at, 4096, 64, [](const RayState& s) { return s.dir; }, directionNodes);
    EXPECT_EQ(directionNodes, 8 * 63); // each 4096-ray leaf -> 64 groups of 64
}

TEST(RaySortPolicy, FixedModesAreKept) {
    for (RaySortMode m : {RaySortMode::Morton, RaySortMode::Median, RaySortMode::Off}) {
        RaySortPolicy p(m, 1024);
        EXPECT_EQ(p.choose(1024), m);
        EXPECT_EQ(p.choose(3), m);
    }
}

// Feeds the policy `decisions` full batches whose cost per ray is `sorted` or `unsorted`; returns
// the decisions (counted from 1 over the policy's life) at which it sorted.
std::vector<int> run(RaySortPolicy& p, int& decision, int decisions, double sorted,
                     double unsorted) {
    std::vector<int> at;
    for (int k = 0; k < decisions; ++k) {
        const bool sort = p.choose(1024) == RaySortMode::Morton;
        ++decision;
        if (sort) at.push_back(decision);
        p.record(sort, (sort ? sorted : unsorted) * 1024, 1024);
    }
    return at;
}

TEST(RaySortPolicy, AutoMeasuresBothWaysTakesTheCheaperAndReMeasuresEverMoreRarely) {
    RaySortPolicy p(RaySortMode::Auto, 1024);
    // Small batches (an iteration's tail) are neither sorted nor measured.
    for (int k = 0; k < 100; ++k) {
        EXPECT_EQ(p.choose(511), RaySortMode::Off);
        p.record(false, 1e6, 511);
    }
    // First unsorted, then sorted, each measured once; then sorting loses (it doubles the
    // cost) and is measured again at the 16th decision, then 32, 64, 128, 256, 256 later.
    int decision = 0;
    std::vector<int> sorted = run(p, decision, 1000, 2.0, 1.0);
    EXPECT_EQ(sorted, (std::vector<int>{2, 16, 48, 112, 240, 496, 752})) << "sorted at";
    // Noise within 10 % does not flip the choice.
    EXPECT_TRUE(run(p, decision, 200, 0.95, 1.0).size() <= 1u) << "flipped by noise";
    // The workload changes: sorting now halves the cost. The next re-measurement notices it,
    // the running mean (1/8 a batch) turns over, and from then on it sorts, re-measuring the
    // other way after 16, 32, ... batches.
    sorted = run(p, decision, 600, 0.5, 1.0);
    EXPECT_GE(sorted.size(), 600u - 256u - 16u - 32u - 64u - 128u - 10u);
    const std::vector<int> last = run(p, decision, 100, 0.5, 1.0);
    EXPECT_GE(last.size(), 99u) << "not sorting after it became the cheaper way";
    EXPECT_EQ(p.sortedBatches() + p.unsortedBatches(), 100u + 1000u + 200u + 600u + 100u);
}

} // namespace
} // namespace spw
