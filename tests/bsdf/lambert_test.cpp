// Lambert (shared/lambert.h): cosine-weighted sampling against its pdf (chi-square), the pdf and
// f |cos| integrated by quadrature, and the shading-normal guard.
#include "bsdf_test_util.h"

namespace spw::test {
namespace {

BsdfUnderTest lambert(vec3 ng, double thetaDeg, vec3 albedo) {
    BsdfUnderTest m;
    m.sh = shaderParams(kModelLambert);
    m.albedo = albedo;
    m.ng = m.ns = ng;
    m.wo = directionAround(ng, thetaDeg, 0.7);
    return m;
}

TEST(Lambert, SampledDirectionsFollowThePdf) {
    const vec3 tilted = glm::normalize(vec3(0.3f, -0.5f, 0.8f));
    struct Case {
        vec3 ng;
        double theta;
        const char* name;
    } cases[] = {{vec3(0, 0, 1), 0.0, "normal incidence"},
                 {vec3(0, 0, 1), 89.5, "grazing incidence"},
                 {tilted, 30.0, "tilted frame"},
                 {-tilted, 150.0, "wo below ng"}};
    const int tests = int(std::size(cases));
    for (const Case& c : cases) {
        BsdfUnderTest m = lambert(c.ng, c.theta, vec3(0.8f, 0.5f, 0.2f));
        SamplingReport r = testSampling(m, ExpectedLobes{}, 200000, 17 + uint(c.theta));
        expectSamplingMatchesPdf(r, tests, std::string("lambert, ") + c.name);
        // No absorption, and the albedo exactly.
        EXPECT_NEAR(r.pdfIntegral, 1.0, 1e-4) << c.name;
        EXPECT_NEAR(r.fcosIntegral, 0.5, 1e-4) << c.name;
        EXPECT_EQ(r.successShare, 1.0) << c.name;
    }
}

// The cosine-hemisphere sample's sin and cos (shared/sampling.h: polynomials, no libm) within
// 2 ulp of the true values over their whole domain [-pi/4, pi/4], and the concentric map exact
// where it has closed forms: a sample's disk radius is max(|2u - 1|), and the points on the
// diagonals and axes land on the rays at 45 degrees and 0 degrees.
TEST(Lambert, HemisphereSampleSinAndCosAreWithin2Ulp) {
    double worst = 0.0;
    for (int i = -100000; i <= 100000; ++i) {
        const float x = float(i) * (kPi / 4.0f) / 100000.0f;
        const double s = std::sin(double(x)), c = std::cos(double(x));
        const double ulpS = std::max(std::abs(s), 1e-30) * std::pow(2.0, -23);
        const double ulpC = std::abs(c) * std::pow(2.0, -23);
        worst = std::max(
            {worst, std::abs(sinQuarterPi(x) - s) / ulpS, std::abs(cosQuarterPi(x) - c) / ulpC});
    }
    EXPECT_LE(worst, 2.0);
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int i = 0; i < 10000; ++i) {
        const vec2 v(u(rng), u(rng));
        const vec3 h = sampleCosineHemisphere(v);
        const float radius = std::max(std::abs(2.0f * v.x - 1.0f), std::abs(2.0f * v.y - 1.0f));
        EXPECT_NEAR(std::hypot(h.x, h.y), radius, 3e-7f * radius + 1e-7f) << v.x << " " << v.y;
        EXPECT_NEAR(glm::length(h), 1.0f, 3e-7f);
    }
    const vec3 diagonal = sampleCosineHemisphere(vec2(1.0f, 1.0f));
    EXPECT_NEAR(diagonal.x, std::sqrt(0.5f), 1e-7f);
    EXPECT_NEAR(diagonal.y, std::sqrt(0.5f), 1e-7f);
    EXPECT_EQ(sampleCosineHemisphere(vec2(0.75f, 0.5f)), vec3(0.5f, 0.0f, std::sqrt(0.75f)));
    EXPECT_EQ(sampleCosineHemisphere(vec2(0.5f, 0.5f)), vec3(0.0f, 0.0f, 1.0f));
}

// A shading normal tilted far from ng: samples below the geometric surface are absorbed and
// eval gives 0 there, so sampling and evaluation still agree and nothing is negative.
TEST(Lambert, TiltedShadingNormalStaysConsistent) {
    BsdfUnderTest m = lambert(vec3(0, 0, 1), 60.0, vec3(1.0f));
    m.ns = glm::normalize(vec3(0.9f, 0.0f, 0.2f));
    SamplingReport r = testSampling(m, ExpectedLobes{}, 200000, 5);
    expectSamplingMatchesPdf(r, 1, "lambert, shading normal 77 degrees off ng");
    EXPECT_LT(r.successShare, 1.0);
    EXPECT_LE(r.fcosIntegral, 1.0 + 1e-4);
}

} // namespace
} // namespace spw::test
