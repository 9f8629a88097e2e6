// Conductor (shared/conductor.h): GGX visible-normal sampling against the pdf (chi-square) for
// alpha from 1e-3 to 1 at normal, oblique and grazing incidence; the pdf and f |cos| integrated
// by quadrature; the smooth mirror as a delta lobe; finiteness as alpha -> 0.
#include "bsdf_test_util.h"

namespace spw::test {
namespace {

const vec3 kF0(1.0f, 0.78f, 0.34f); // gold-ish

BsdfUnderTest conductor(float alpha, double thetaDeg, vec3 ng = vec3(0, 0, 1)) {
    BsdfUnderTest m;
    m.sh = shaderParams(kModelConductor, alpha);
    m.albedo = kF0;
    m.ng = m.ns = ng;
    m.wo = directionAround(ng, thetaDeg, 0.4);
    return m;
}

ExpectedLobes mirrorLobe(const BsdfUnderTest& m) {
    ExpectedLobes l;
    vec3 r = glm::normalize(2.0f * glm::dot(m.wo, m.ng) * m.ng - m.wo);
    (glm::dot(r, m.ng) > 0 ? l.upper : l.lower) = r;
    l.width = std::max(2.0 * m.sh.alpha, 1e-4);
    return l;
}

const float kAlphas[] = {1e-3f, 1e-2f, 0.1f, 0.5f, 1.0f};
const double kThetas[] = {0.0, 45.0, 89.0};

TEST(Conductor, SampledDirectionsFollowThePdf) {
    const int tests = int(std::size(kAlphas) * std::size(kThetas)) + 1;
    for (float alpha : kAlphas)
        for (double theta : kThetas) {
            BsdfUnderTest m = conductor(alpha, theta);
            char name[96];
            std::snprintf(name, sizeof name, "conductor alpha %g, theta %g", alpha, theta);
            expectSamplingMatchesPdf(testSampling(m, mirrorLobe(m), 200000, 1000 + uint(theta)),
                                     tests, name);
        }
    // In a tilted frame, wo on the back of ng (the model turns to wo's side).
    BsdfUnderTest m = conductor(0.3f, 130.0, glm::normalize(vec3(-0.2f, 0.7f, 0.4f)));
    expectSamplingMatchesPdf(testSampling(m, mirrorLobe(m), 200000, 3), tests,
                             "conductor alpha 0.3, back side, tilted");
}

// Schlick's approximation at values worked by hand: F0 = 0.04 (glass-like) at 60 degrees is
// 0.04 + 0.96 / 32 = 0.07; at normal incidence F0 itself; at grazing incidence 1.
TEST(Conductor, SchlickFresnelMatchesHandWorkedValues) {
    const vec3 f0(0.04f, 0.5f, 0.9f);
    const vec3 at60 = schlickFresnel(f0, 0.5f);
    EXPECT_NEAR(at60.x, 0.07, 1e-7);
    EXPECT_NEAR(at60.y, 0.5 + 0.5 / 32.0, 1e-7);
    EXPECT_NEAR(at60.z, 0.9 + 0.1 / 32.0, 1e-7);
    EXPECT_EQ(schlickFresnel(f0, 1.0f), f0);
    for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(schlickFresnel(f0, 0.0f)[k], 1.0, 1e-7);
}

// With F0 = 1 and a vanishing alpha the rough model becomes the mirror: it keeps all energy.
TEST(Conductor, NarrowLobeWithUnitF0KeepsAllEnergy) {
    for (double theta : {0.0, 60.0}) {
        BsdfUnderTest m = conductor(1e-3f, theta);
        m.albedo = vec3(1.0f);
        SamplingReport r = testSampling(m, mirrorLobe(m), 100000, 9);
        EXPECT_NEAR(r.fcosIntegral, 1.0, 2e-3) << theta;
        EXPECT_NEAR(r.meanWeight, 1.0, 2e-3) << theta;
    }
}

TEST(Conductor, SmoothIsADeltaLobe) {
    for (float alpha : {0.0f, 0.5f * kGgxSmoothAlpha})
        for (double theta : {0.0, 40.0, 89.9}) {
            BsdfUnderTest m = conductor(alpha, theta);
            EXPECT_TRUE(bsdfIsDelta(m.sh));
            Uniform u(4);
            vec3 wi, weight;
            float pdf;
            bool specular;
            ASSERT_TRUE(
                bsdfSample(m.sh, m.albedo, m.ng, m.ns, m.wo, u.next3(), wi, weight, pdf, specular));
            EXPECT_TRUE(specular);
            const vec3 mirror = 2.0f * glm::dot(m.wo, m.ng) * m.ng - m.wo;
            EXPECT_LT(glm::length(wi - mirror), 1e-6f);
            // Schlick's closed form, written out here rather than taken from the code under test:
            // F = F0 + (1 - F0)(1 - cos theta)^5, with F0 below 1 in two channels.
            const double c = std::cos(theta * M_PI / 180.0), s5 = std::pow(1.0 - c, 5.0);
            for (int k = 0; k < 3; ++k)
                EXPECT_NEAR(weight[k], kF0[k] + (1.0 - kF0[k]) * s5, 2e-6)
                    << "theta " << theta << ", channel " << k;
            float evalPdf = 1;
            EXPECT_EQ(bsdfEval(m.sh, m.albedo, m.ng, m.ns, m.wo, wi, evalPdf), vec3(0.0f));
            EXPECT_EQ(evalPdf, 0.0f);
        }
    EXPECT_FALSE(bsdfIsDelta(shaderParams(kModelConductor, kGgxSmoothAlpha)));
    EXPECT_FALSE(bsdfIsDelta(shaderParams(kModelLambert, 0.0f)));
}

// Eval and sample stay finite and non-negative for every alpha at and above the smooth threshold,
// at every angle up to and including the horizon.
TEST(Conductor, FiniteAtTinyAlphaAndGrazingAngles) {
    Uniform u(77);
    size_t checked = 0;
    for (float alpha : {kGgxSmoothAlpha, 2e-4f, 1e-3f, 0.05f, 1.0f})
        for (double to : {0.0, 30.0, 89.0, 89.99, 90.0})
            for (double ti : {0.0, 10.0, 89.99, 90.0}) {
                BsdfUnderTest m = conductor(alpha, to);
                for (double dphi : {M_PI, M_PI + 1e-4, 1.0}) {
                    const vec3 wi = directionAround(m.ng, ti, 0.4 + dphi);
                    float pdf;
                    const vec3 f = bsdfEval(m.sh, m.albedo, m.ng, m.ns, m.wo, wi, pdf);
                    ASSERT_TRUE(std::isfinite(pdf) && pdf >= 0.0f)
                        << alpha << " " << to << " " << ti;
                    ASSERT_TRUE(finiteNonNegative(f)) << alpha << " " << to << " " << ti;
                    ++checked;
                }
                for (int k = 0; k < 200; ++k) {
                    vec3 wi, weight;
                    float pdf;
                    bool specular;
                    if (!bsdfSample(m.sh, m.albedo, m.ng, m.ns, m.wo, u.next3(), wi, weight, pdf,
                                    specular))
                        continue;
                    ASSERT_TRUE(std::isfinite(pdf) && pdf > 0.0f) << alpha << " " << to;
                    ASSERT_TRUE(finiteNonNegative(weight));
                    ASSERT_LE(weight.x, 1.0f + 1e-5f) << "a conductor sample never gains energy";
                }
            }
    EXPECT_GT(checked, 0u);
}

} // namespace
} // namespace spw::test
