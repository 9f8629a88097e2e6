// The samplers of shared/rng.h: Sobol's matrices, the stratification a (0,2)-sequence promises
// and Owen scrambling keeps, unbiasedness over scrambles, and padding that decorrelates groups.
#include "shared/rng.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <vector>

namespace spw {
namespace {

// Sobol's direction numbers from Joe & Kuo's recurrence, column b for index bit b (b = 0 the
// lowest), as in Bratley & Fox 1988: v_i = m_i / 2^i for i <= s, then
// v_i = a_1 v_{i-1} ^ ... ^ a_{s-1} v_{i-s+1} ^ v_{i-s} ^ (v_{i-s} >> s).
std::vector<uint> directionNumbers(int s, uint a, std::vector<uint> m) {
    std::vector<uint> v(33, 0);
    for (int i = 1; i <= s; ++i)
        v[size_t(i)] = m[size_t(i - 1)] << (32 - i);
    for (int i = s + 1; i <= 32; ++i) {
        v[size_t(i)] = v[size_t(i - s)] ^ (v[size_t(i - s)] >> s);
        for (int k = 1; k < s; ++k)
            if ((a >> (s - 1 - k)) & 1u) v[size_t(i)] ^= v[size_t(i - k)];
    }
    return std::vector<uint>(v.begin() + 1, v.end());
}

// Unscrambled Sobol point `index`, dimension d in 0..3, from the table rng.h stores.
uint sobol(uint index, int d) {
    if (d == 0) return bitfieldReverse(index);
    uint x = 0;
    for (int b = 0; b < 32; ++b)
        if ((index >> b) & 1u) x ^= bitfieldReverse(kSobolReversed[size_t(d - 1) * 32 + 31 - b]);
    return x;
}

// Whether points (x, y) (32-bit fractions) put exactly one point in every elementary interval
// of area 2^-k: every split of k into k = a + b, cells 2^-a wide and 2^-b high.
bool isNet(const std::vector<uvec2>& pts, int k) {
    if (pts.size() != size_t(1) << k) return false;
    for (int a = 0; a <= k; ++a) {
        std::set<std::pair<uint, uint>> cells;
        for (uvec2 p : pts)
            cells.insert({a == 0 ? 0u : p.x >> (32 - a), k - a == 0 ? 0u : p.y >> (32 - (k - a))});
        if (cells.size() != pts.size()) return false;
    }
    return true;
}

TEST(Sobol, MatricesAreJoeKuosDirectionNumbers) {
    const std::vector<std::vector<uint>> dims = {directionNumbers(1, 0, {1}),
                                                 directionNumbers(2, 1, {1, 3}),
                                                 directionNumbers(3, 1, {1, 3, 1})};
    for (int d = 0; d < 3; ++d)
        for (int b = 0; b < 32; ++b)
            EXPECT_EQ(kSobolReversed[size_t(d) * 32 + 31 - size_t(b)],
                      bitfieldReverse(dims[size_t(d)][size_t(b)]))
                << "dimension " << d + 1 << ", index bit " << b;
}

TEST(Sobol, UnscrambledFirstPointsFillEveryElementaryInterval) {
    for (int k = 1; k <= 10; ++k) {
        std::vector<uvec2> pts;
        for (uint i = 0; i < (1u << k); ++i)
            pts.push_back(uvec2(sobol(i, 0), sobol(i, 1)));
        EXPECT_TRUE(isNet(pts, k)) << "first 2^" << k << " points, dimensions 0 and 1";
        // Every dimension alone: one point in each of 2^k intervals.
        for (int d = 0; d < 4; ++d) {
            std::set<uint> cells;
            for (uint i = 0; i < (1u << k); ++i)
                cells.insert(sobol(i, d) >> (32 - k));
            EXPECT_EQ(cells.size(), size_t(1) << k) << "dimension " << d << ", 2^" << k;
        }
    }
}

TEST(Sobol, ScrambledPointsKeepTheNetsInEveryAlignedBlock) {
    // What a pixel's samples are: any 2^k consecutive sample indices from a multiple of 2^k, under
    // the pixel's own shuffle and scrambles.
    for (uint pixel : {0u, 7u, 123456u})
        for (int k : {2, 5, 8})
            for (uint block : {0u, 3u}) {
                std::vector<uvec2> pts;
                for (uint i = block << k; i < (block + 1) << k; ++i) {
                    uvec4 x = scrambledSobol4(i, uvec4(pixel, 5u, 42u, 0x50B01u));
                    pts.push_back(uvec2(x.x, x.y));
                }
                EXPECT_TRUE(isNet(pts, k))
                    << "pixel " << pixel << ", block " << block << " of 2^" << k;
            }
}

TEST(Sobol, ScramblingIsUnbiased) {
    // E[f] over random scrambles equals the integral: f = x0 x1 + x2^2 x3 over [0,1)^4,
    // integral 1/4 + 1/6. Each seed's 64-point estimate is one sample; the mean over seeds is
    // within 4 standard errors computed from them.
    const int seeds = 4000, n = 64;
    double sum = 0, sum2 = 0;
    for (int s = 0; s < seeds; ++s) {
        double est = 0;
        for (int i = 0; i < n; ++i) {
            vec4 u = rand4(kSamplerSobol, uint(s), 17u, uint(i), 2u, kDimBsdf);
            est += double(u.x) * u.y + double(u.z) * u.z * u.w;
        }
        est /= n;
        sum += est;
        sum2 += est * est;
    }
    const double mean = sum / seeds, var = sum2 / seeds - mean * mean;
    const double se = std::sqrt(var / seeds);
    EXPECT_NEAR(mean, 1.0 / 4 + 1.0 / 6, 4 * se);
    // And it is the point of the exercise: each estimate is far better than independent
    // numbers', whose variance for this f is 7/144 + 1/15 - 1/36 = 0.0875 over n.
    EXPECT_LT(var, 0.0875 / n / 10);
}

TEST(Sobol, PaddingDecorrelatesGroups) {
    // Two groups (the light's and the BSDF's numbers) of one pixel and bounce take the same
    // sample indices. Without the index shuffle their first dimensions would be scrambles of the
    // same van der Corput point, one a function of the other: 16 of the 256 cells of a 16 x 16
    // grid filled. Padded, the pairs are uniform: a chi-square test over the grid.
    const int n = 4096;
    std::vector<int> counts(256, 0);
    for (int i = 0; i < n; ++i) {
        vec4 a = rand4(kSamplerSobol, 9u, 1234u, uint(i), 1u, kDimLight);
        vec4 b = rand4(kSamplerSobol, 9u, 1234u, uint(i), 1u, kDimBsdf);
        ++counts[size_t(int(a.x * 16) * 16 + int(b.x * 16))];
    }
    double chi2 = 0;
    const double expected = n / 256.0;
    for (int c : counts)
        chi2 += (c - expected) * (c - expected) / expected;
    // 255 degrees of freedom: mean 255, sd 22.6; 340 is p ~ 3e-4.
    EXPECT_LT(chi2, 340.0);
}

// The C++ build reads Sobol's matrix columns a byte at a time from tables; the GLSL kernels
// loop over the bits. Both must give the same numbers, or vulkan and cpu would trace different
// paths.
TEST(Sobol, ByteTablesEqualTheBitLoop) {
    uint r = 12345u;
    for (int i = 0; i < 100000; ++i) {
        r = pcg4d(uvec4(r, uint(i), 7u, 9u)).x;
        ASSERT_EQ(sobolReversedColumns(r), sobolReversedColumnsLoop(r)) << "r = " << r;
    }
    for (uint bit = 0; bit < 32; ++bit)
        ASSERT_EQ(sobolReversedColumns(1u << bit), sobolReversedColumnsLoop(1u << bit)) << bit;
}

TEST(Sobol, NumbersArePureFunctionsOfTheirKey) {
    for (uint i = 0; i < 100; ++i) {
        vec4 a = rand4(kSamplerSobol, 3u, i * 7u, i, i % 4u, kDimCamera);
        vec4 b = rand4(kSamplerSobol, 3u, i * 7u, i, i % 4u, kDimCamera);
        EXPECT_EQ(a, b);
        for (int c = 0; c < 4; ++c) {
            EXPECT_GE(a[c], 0.0f);
            EXPECT_LT(a[c], 1.0f);
        }
    }
    // A different seed, bounce or group gives other numbers.
    vec4 base = rand4(kSamplerSobol, 3u, 5u, 6u, 1u, kDimLight);
    EXPECT_NE(base, rand4(kSamplerSobol, 4u, 5u, 6u, 1u, kDimLight));
    EXPECT_NE(base, rand4(kSamplerSobol, 3u, 5u, 6u, 2u, kDimLight));
    EXPECT_NE(base, rand4(kSamplerSobol, 3u, 5u, 6u, 1u, kDimBsdf));
}

} // namespace
} // namespace spw
