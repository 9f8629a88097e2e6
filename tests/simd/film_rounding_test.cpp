// The film's rounding SIMD-wide (host/simd/film_rounding.h) against the film's scalar rounding
// written out from its definition (Film::quantize, roundingKey's hash), lane by lane and bit for
// bit, in every instruction set this machine has: ordinary, negative, zero, tiny and clamped
// values, and the count of clamped ones.
#include "host/simd/film_rounding.h"
#include "host/simd/simd_target.h"

#include "shared/rng.h"

#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <cmath>
#include <random>

namespace spw {
namespace {

// Film::quantize: clamped to +-maxAdd (counted), then rounded up with probability frac(v).
std::int64_t quantize(double v, uint u, double maxAdd, size_t& saturated) {
    if (std::fabs(v) > maxAdd) {
        ++saturated;
        v = std::copysign(maxAdd, v);
    }
    const double fl = std::floor(v);
    return std::int64_t(fl) + (double(uintToUnit(u)) < v - fl ? 1 : 0);
}

TEST(SimdFilm, RoundFootprintIsTheScalarRoundingInEveryInstructionSet) {
    const double weightScale = 1048576.0, maxAdd = 1e12;
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> weight(0.0f, 1.0f);
    std::uniform_real_distribution<double> value(-3e12, 3e12), small(-10.0, 10.0);
    const std::vector<std::int64_t> targets = hwy::SupportedAndGeneratedTargets();
    ASSERT_FALSE(targets.empty());
    for (std::int64_t target : targets) {
        hwy::SetSupportedTargetsForTest(target);
        SCOPED_TRACE(simdTarget());
        for (int round = 0; round < 200; ++round) {
            FootprintLanes lanes;
            for (size_t k = 0; k < simd::kBlock; ++k) {
                lanes.pixel.v[k] = uint(rng());
                lanes.weightKey.v[k] = uint(rng());
                lanes.rgbKey.v[k] = uint(rng());
                lanes.weight.v[k] = k % 7 == 0 ? 1e-30f : weight(rng);
                double* channel[3] = {&lanes.r[k], &lanes.g[k], &lanes.b[k]};
                for (double* c : channel)
                    *c = k % 5 == 0 ? 0.0 : k % 3 == 0 ? small(rng) : std::round(value(rng));
            }
            FootprintAdds adds;
            const size_t saturated = roundFootprint(lanes, simd::kBlock, weightScale, maxAdd, adds);
            size_t expectedSaturated = 0;
            for (size_t k = 0; k < simd::kBlock; ++k) {
                const uvec4 key(lanes.weightKey.v[k], lanes.pixel.v[k], 0x5157u, 0x9E3779B9u);
                const uvec4 hw = pcg4d(key);
                const uvec4 h = pcg4d(uvec4(lanes.rgbKey.v[k], key.y, key.z, key.w));
                const double w = double(lanes.weight.v[k]);
                ASSERT_EQ(adds.w[k], quantize(w * weightScale, hw.w, maxAdd, expectedSaturated));
                ASSERT_EQ(adds.r[k], quantize(lanes.r[k] * w, h.x, maxAdd, expectedSaturated));
                ASSERT_EQ(adds.g[k], quantize(lanes.g[k] * w, h.y, maxAdd, expectedSaturated));
                ASSERT_EQ(adds.b[k], quantize(lanes.b[k] * w, h.z, maxAdd, expectedSaturated));
            }
            ASSERT_EQ(saturated, expectedSaturated);
        }
    }
    hwy::SetSupportedTargetsForTest(0);
}

} // namespace
} // namespace spw
