// The compact ray record's claims (host/pipeline/ray_record.h): the direction within the octahedral
// grid's error bound, the throughput's stochastic rounding unbiased and order-keeping, the MIS
// pdf stored exactly once quantised (so the two MIS weights still sum to one), and the exact
// fields exact. The full record round-trips every bit. The block encoder makes the same bytes.
#include "host/pipeline/ray_record.h"
#include "host/simd/lanes.h"
#include "host/simd/simd_target.h"
#include "shared/sampling.h"

#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <cmath>
#include <cstring>
#include <random>

namespace spw {
namespace {

RayState roundTrip(const RayState& in, RayFormat format, uvec4 rounding) {
    std::uint8_t buf[kFullRayBytes];
    encodeRay(in, format, rounding, buf);
    RayState out;
    decodeRay(buf, format, out);
    return out;
}

RayState someRay(vec3 dir, vec3 beta) {
    RayState r;
    r.origin = vec3(1.5f, -2e7f, 3e-30f);
    r.dir = dir;
    r.path = PathState{};
    r.path.beta = beta;
    r.path.prevPdf = quantizePdf(0.37f);
    r.path.pathId = 0xDEADBEEFu;
    r.path.bounce = 1234;
    r.path.flags = kPathSpecular;
    return r;
}

double angle(vec3 a, vec3 b) {
    const glm::dvec3 x = glm::normalize(glm::dvec3(a)), y = glm::normalize(glm::dvec3(b));
    return std::atan2(glm::length(glm::cross(x, y)), glm::dot(x, y));
}

// 2^24 cells per axis over [-1, 1]: a cell is 1.2e-7 wide, and the octahedral map stretches
// angles by up to about 2.5 (near the fold and the octants' corners). Measured worst over a
// million random directions and the axes, diagonals and fold lines: 2.9e-7 rad. Asserted:
// 3.5e-7 (one fewer bit per axis would double it and fail).
TEST(CompactRay, DirectionWithinTheOctahedralGridBound) {
    std::mt19937 rng(7);
    std::normal_distribution<float> g;
    double worst = 0;
    std::vector<vec3> dirs = {{1, 0, 0},      {-1, 0, 0},     {0, 1, 0},           {0, -1, 0},
                              {0, 0, 1},      {0, 0, -1},     {1, 1, 0},           {1, -1, 0},
                              {0, 1, -1},     {-1, 0, -1},    {1, 1, 1},           {-1, -1, -1},
                              {1e-7f, 0, -1}, {0, 1e-7f, -1}, {0.5f, 0.5f, -1e-7f}};
    for (int i = 0; i < 1000000; ++i)
        dirs.push_back(vec3(g(rng), g(rng), g(rng)));
    for (vec3 d : dirs) {
        d = glm::normalize(d);
        const RayState out = roundTrip(someRay(d, vec3(1)), RayFormat::Compact, uvec4(0));
        worst = std::max(worst, angle(d, out.dir));
        ASSERT_NEAR(glm::length(out.dir), 1.0f, 1e-6f);
    }
    std::printf("worst direction error %.3g rad\n", worst);
    EXPECT_LE(worst, 3.5e-7);
}

// The stored throughput is one of the two bfloat16 neighbours of the value, the upper one with
// probability (value - lower) / step: its mean over a million rounding numbers is the value
// within 4 standard errors of that two-point distribution.
TEST(CompactRay, ThroughputRoundingIsUnbiased) {
    std::mt19937 rng(11);
    for (float x : {0.1f, 0.3337f, 0.999f, 1.0f, 7.77e-20f, 3.1e30f, 1.17549435e-38f}) {
        double sum = 0;
        float lo = INFINITY, hi = 0;
        constexpr int kN = 1000000;
        for (int i = 0; i < kN; ++i) {
            const float v = roundTrip(someRay(vec3(0, 0, 1), vec3(x)), RayFormat::Compact,
                                      uvec4(rng(), 0, 0, 0))
                                .path.beta.x;
            sum += v;
            lo = std::min(lo, v), hi = std::max(hi, v);
        }
        EXPECT_LE(lo, x);
        EXPECT_GE(hi, x);
        EXPECT_LE(double(hi - lo), std::ldexp(double(x), -7))
            << x << ": more than one bfloat16 step";
        const double p = hi > lo ? (double(x) - lo) / (double(hi) - lo) : 0.0;
        const double se = (double(hi) - lo) * std::sqrt(p * (1 - p) / kN);
        std::printf("%.6g: mean %.9g (lower %.9g, upper %.9g, standard error %.3g)\n", x, sum / kN,
                    lo, hi, se);
        EXPECT_NEAR(sum / kN, double(x), 4 * se + 1e-12 * x) << x;
    }
}

// One rounding number rounds the three channels, so their order survives: Russian roulette
// reads the largest channel, and an independent number per channel would bias it up.
TEST(CompactRay, ThroughputRoundingKeepsTheChannelsInOrder) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0.05f, 0.15f);
    for (int i = 0; i < 200000; ++i) {
        const vec3 beta(u(rng), u(rng), u(rng));
        const vec3 out = roundTrip(someRay(vec3(0, 1, 0), beta), RayFormat::Compact,
                                   uvec4(rng(), rng(), rng(), rng()))
                             .path.beta;
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b)
                if (beta[a] >= beta[b]) {
                    ASSERT_GE(out[a], out[b]) << beta[a] << " " << beta[b];
                }
    }
    // Equal channels stay equal: the largest is then exactly as unbiased as each.
    const vec3 out = roundTrip(someRay(vec3(0, 1, 0), vec3(0.1f)), RayFormat::Compact,
                               uvec4(0x8000u, 1, 0xFFFFu, 0))
                         .path.beta;
    EXPECT_EQ(out.x, out.y);
    EXPECT_EQ(out.y, out.z);
}

// shadeSurface() quantises the BSDF pdf before it is stored and before the light side's MIS
// weight reads it, so the record keeps it exactly and the two power-heuristic weights of one
// light path sum to one up to float rounding.
TEST(CompactRay, MisPdfIsStoredExactlySoTheWeightsSumToOne) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> e(-30.0f, 30.0f);
    double worst = 0;
    for (int i = 0; i < 100000; ++i) {
        const float bsdfPdf = quantizePdf(std::exp2(e(rng))), lightPdf = std::exp2(e(rng));
        RayState r = someRay(vec3(0, 0, -1), vec3(1));
        r.path.prevPdf = bsdfPdf;
        const float stored = roundTrip(r, RayFormat::Compact, uvec4(rng())).path.prevPdf;
        ASSERT_EQ(std::memcmp(&stored, &bsdfPdf, 4), 0) << bsdfPdf;
        const double sum = double(powerHeuristic(lightPdf, quantizePdf(bsdfPdf))) +
                           powerHeuristic(stored, lightPdf);
        worst = std::max(worst, std::fabs(sum - 1.0));
    }
    std::printf("worst |light weight + BSDF weight - 1| %.3g\n", worst);
    EXPECT_LE(worst, 4e-7);
}

TEST(CompactRay, ExactFieldsAreExactAndFullRecordsKeepEveryBit) {
    const RayState in = someRay(glm::normalize(vec3(0.3f, -0.2f, 0.9f)), vec3(0.25f, 0.5f, 2.0f));
    const RayState c = roundTrip(in, RayFormat::Compact, uvec4(12345u));
    EXPECT_EQ(std::memcmp(&c.origin, &in.origin, sizeof(vec3)), 0);
    EXPECT_EQ(c.path.pathId, in.path.pathId);
    EXPECT_EQ(c.path.bounce, in.path.bounce);
    EXPECT_EQ(c.path.flags, kPathSpecular);
    EXPECT_EQ(c.path.beta, in.path.beta) << "powers of two are bfloat16 values";
    RayState top = in;
    top.path.bounce = kMaxCompactBounce;
    top.path.flags = 0;
    const RayState t = roundTrip(top, RayFormat::Compact, uvec4(0));
    EXPECT_EQ(t.path.bounce, kMaxCompactBounce);
    EXPECT_EQ(t.path.flags, 0u);

    const RayState f = roundTrip(in, RayFormat::Full, uvec4(0));
    EXPECT_EQ(std::memcmp(&f.origin, &in.origin, sizeof(vec3)), 0);
    EXPECT_EQ(std::memcmp(&f.dir, &in.dir, sizeof(vec3)), 0);
    EXPECT_EQ(std::memcmp(&f.path.beta, &in.path.beta, sizeof(vec3)), 0);
    EXPECT_EQ(f.path.prevPdf, in.path.prevPdf);
    EXPECT_EQ(f.path.bounce, in.path.bounce);
    EXPECT_EQ(f.path.flags, in.path.flags);
}

} // namespace
} // namespace spw

namespace spw {

// The sorted pipeline encodes its continuation rays a block at a time, SIMD-wide
// (encodeCompactBlock): in every instruction set, for ragged block sizes, each record is the bytes
// encodeRay writes with the path's compactRounding, and each bin the direction's cardinalBin.
// The rays include ties, signed zeros, the fold lines, throughputs at the bfloat16 edges
// (the largest finite, denormals, zero, a NaN) and bounces past the field's width.
TEST(CompactRay, BlockEncodingIsEncodeRayByteForByte) {
    std::mt19937 rng(11);
    std::normal_distribution<float> g;
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    // The axes, signed zeros, ties between the largest components (the bin's >=), fold lines.
    const vec3 special[] = {
        {1, 0, 0}, {-1, 0, 0},   {0, 1, 0},       {0, -0.0f, -1}, {-0.0f, 0, 1},
        {1, 1, 0}, {0, 1, 1},    {0.2f, -1, -1},  {-1, 1, 0.5f},  {1, -1, -0.0f},
        {1, 1, 1}, {-1, -1, -1}, {0.6f, 0.8f, 0}, {1e-7f, 0, -1}, {0.5f, -0.5f, -1e-7f}};
    const std::uint32_t nanBits = 0x7FC0FFFFu; // a NaN whose dropped bits would round it
    float nan;
    std::memcpy(&nan, &nanBits, 4);
    const float betas[] = {3.4028235e38f, 1e-40f, 0.0f, 0.999999f, 1.0f, 65504.0f, nan, -2.5f};
    RenderParams rp{};
    rp.samplesPerIteration = 7;
    rp.iteration = 3;
    rp.seed = 99;
    std::vector<ShadeResult> results(203);
    for (size_t i = 0; i < results.size(); ++i) {
        ShadeResult& r = results[i];
        r = ShadeResult{};
        r.flags = kShadeContinue;
        r.nextOrigin = vec3(g(rng) * 1e3f, -g(rng), g(rng) * 1e-20f);
        r.nextDir =
            glm::normalize(i < std::size(special) ? special[i] : vec3(g(rng), g(rng), g(rng)));
        r.next.beta = i < std::size(betas) ? vec3(betas[i], 0.5f, betas[i])
                                           : vec3(unit(rng), unit(rng) * 3.0f, unit(rng));
        r.next.prevPdf = quantizePdf(unit(rng) * 10.0f);
        r.next.pathId = std::uint32_t(rng());
        r.next.bounce = i % 9 == 0 ? kMaxCompactBounce + uint(i) : uint(rng() % 64);
        r.next.flags = i % 3 == 0 ? kPathSpecular : 0u;
        r.next.cone = std::uint32_t(rng() & 0xFFFFu);
    }
    for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
        hwy::SetSupportedTargetsForTest(target);
        SCOPED_TRACE(simdTarget());
        for (size_t n : {size_t(1), size_t(17), size_t(64)})
            for (size_t begin = 0; begin + n <= results.size(); begin += n) {
                const ShadeResult* block[simd::kBlock];
                for (size_t k = 0; k < n; ++k)
                    block[k] = &results[begin + k];
                std::uint8_t records[simd::kBlock * kCompactRayBytes], bins[simd::kBlock];
                encodeCompactBlock(rp, block, n, records, bins);
                for (size_t k = 0; k < n; ++k) {
                    const ShadeResult& r = *block[k];
                    std::uint8_t one[kCompactRayBytes];
                    encodeRay(r.nextOrigin, r.nextDir, r.next, RayFormat::Compact,
                              compactRounding(rp, r.next), one);
                    ASSERT_EQ(std::memcmp(one, records + k * kCompactRayBytes, kCompactRayBytes), 0)
                        << "ray " << begin + k << " of a block of " << n;
                    ASSERT_EQ(bins[k], cardinalBin(r.nextDir)) << "ray " << begin + k;
                }
            }
    }
    hwy::SetSupportedTargetsForTest(0);
}

// And decoded a block at a time (decodeCompactBlock), the same rays as decodeRay makes, to the
// bit: over every cell of the octahedral grid's edges and folds, and random cells.
TEST(CompactRay, BlockDecodingIsDecodeRayBitForBit) {
    std::mt19937 rng(13);
    const uint last = (1u << 24) - 1, mid = last / 2;
    std::vector<uvec2> cells = {{0, 0},      {last, last},       {0, last},
                                {last, 0},   {mid, mid},         {mid + 1, mid},
                                {mid, 0},    {0, mid + 1},       {last, mid},
                                {mid, last}, {mid / 2, mid / 2}, {mid + mid / 2, mid / 2 + 1}};
    while (cells.size() < 20000)
        cells.push_back(uvec2(rng() & last, rng() & last));
    std::vector<std::uint8_t> records(cells.size() * kCompactRayBytes);
    for (size_t i = 0; i < cells.size(); ++i) {
        RayState r = someRay(vec3(0, 0, 1), vec3(0.25f * float(i % 7), 1.0f, 3.0f));
        r.path.pathId = std::uint32_t(rng());
        r.path.bounce = uint(i % 40);
        r.path.flags = i % 2 ? kPathSpecular : 0u;
        r.path.cone = std::uint32_t(i * 257u & 0xFFFFu);
        std::uint8_t* p = &records[i * kCompactRayBytes];
        encodeRay(r, RayFormat::Compact, uvec4(uint(rng())), p);
        for (int b = 0; b < 3; ++b) { // the cell itself, over the encoded direction
            p[16 + b] = std::uint8_t(cells[i].x >> (8 * b));
            p[19 + b] = std::uint8_t(cells[i].y >> (8 * b));
        }
    }
    for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
        hwy::SetSupportedTargetsForTest(target);
        SCOPED_TRACE(simdTarget());
        for (size_t n : {size_t(1), size_t(23), size_t(64)})
            for (size_t begin = 0; begin + n <= cells.size(); begin += n) {
                std::vector<RayState> block(n);
                decodeCompactBlock(&records[begin * kCompactRayBytes], n, block.data());
                for (size_t k = 0; k < n; ++k) {
                    RayState one;
                    decodeRay(&records[(begin + k) * kCompactRayBytes], RayFormat::Compact, one);
                    const RayState& many = block[k];
                    ASSERT_EQ(std::memcmp(&one.origin, &many.origin, sizeof(vec3)), 0);
                    ASSERT_EQ(std::memcmp(&one.dir, &many.dir, sizeof(vec3)), 0)
                        << "cell " << cells[begin + k].x << ", " << cells[begin + k].y;
                    ASSERT_EQ(std::memcmp(&one.path.beta, &many.path.beta, sizeof(vec3)), 0);
                    ASSERT_EQ(std::memcmp(&one.path.prevPdf, &many.path.prevPdf, 4), 0);
                    ASSERT_EQ(one.path.pathId, many.path.pathId);
                    ASSERT_EQ(one.path.bounce, many.path.bounce);
                    ASSERT_EQ(one.path.flags, many.path.flags);
                    ASSERT_EQ(one.path.cone, many.path.cone);
                }
            }
    }
    hwy::SetSupportedTargetsForTest(0);
}

} // namespace spw
