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
