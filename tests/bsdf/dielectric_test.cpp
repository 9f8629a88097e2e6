// Dielectric (shared/dielectric.h): exact Fresnel against closed forms; rough reflection and
// refraction sampled against the pdf (chi-square) for alpha from 1e-3 to 1, from outside and
// from inside, at normal and grazing incidence; the smooth interface as two delta lobes with
// total internal reflection; the 1 / eta^2 radiance scaling.
#include "bsdf_test_util.h"

namespace spw::test {
namespace {

constexpr float kIor = 1.5f;

BsdfUnderTest dielectric(float alpha, double thetaDeg, bool inside) {
    BsdfUnderTest m;
    m.sh = shaderParams(kModelDielectric, alpha, kIor);
    m.ng = m.ns = glm::normalize(vec3(0.1f, -0.2f, 1.0f));
    m.wo = directionAround(inside ? -m.ng : m.ng, thetaDeg, 0.9);
    return m;
}

// The mirror direction on wo's side, and the refracted one (or the horizon under TIR).
ExpectedLobes dielectricLobes(const BsdfUnderTest& m) {
    ExpectedLobes l;
    const bool outside = glm::dot(m.wo, m.ng) > 0;
    const vec3 n = outside ? m.ng : -m.ng;
    const float eta = outside ? kIor : 1.0f / kIor;
    const float c = glm::dot(m.wo, n);
    const vec3 mirror = glm::normalize(2.0f * c * n - m.wo);
    const float sin2t = (1 - c * c) / (eta * eta);
    vec3 refracted;
    if (sin2t < 1) {
        refracted = glm::normalize(-m.wo / eta + (c / eta - std::sqrt(1 - sin2t)) * n);
    } else {
        vec3 tangent = m.wo - c * n;
        refracted = glm::length(tangent) > 0 ? glm::normalize(-tangent) : -n;
    }
    (outside ? l.upper : l.lower) = mirror;
    (outside ? l.lower : l.upper) = refracted;
    l.width = std::max(2.0 * m.sh.alpha, 1e-4);
    return l;
}

TEST(Dielectric, FresnelMatchesClosedForms) {
    float cosT;
    // Normal incidence: ((eta - 1) / (eta + 1))^2, from either side.
    EXPECT_NEAR(fresnelDielectric(1.0f, 1.5f, cosT), 0.04f, 1e-6f);
    EXPECT_NEAR(fresnelDielectric(1.0f, 1.0f / 1.5f, cosT), 0.04f, 1e-6f);
    // Brewster's angle: the p-polarised part vanishes, F = rs^2 / 2.
    const double tb = std::atan(1.5);
    const double ct = std::cos(std::asin(std::sin(tb) / 1.5));
    const double rs = (std::cos(tb) - 1.5 * ct) / (std::cos(tb) + 1.5 * ct);
    EXPECT_NEAR(fresnelDielectric(float(std::cos(tb)), 1.5f, cosT), 0.5 * rs * rs, 1e-6);
    // Reciprocity: the same F from both sides of a refraction.
    for (double ci : {0.9, 0.5, 0.2}) {
        float ctOut;
        const float f1 = fresnelDielectric(float(ci), 1.5f, ctOut);
        float back;
        EXPECT_NEAR(fresnelDielectric(ctOut, 1.0f / 1.5f, back), f1, 1e-6f);
        EXPECT_NEAR(back, ci, 1e-6);
    }
    // Total internal reflection beyond the critical angle, 1 at grazing from outside.
    EXPECT_EQ(fresnelDielectric(std::cos(float(0.8)), 1.0f / 1.5f, cosT), 1.0f);
    EXPECT_EQ(cosT, 0.0f);
    EXPECT_NEAR(fresnelDielectric(0.0f, 1.5f, cosT), 1.0f, 1e-6f);
}

TEST(Dielectric, SampledDirectionsFollowThePdf) {
    const float alphas[] = {1e-3f, 1e-2f, 0.1f, 0.5f, 1.0f};
    const double thetas[] = {0.0, 89.0};
    const int tests = int(std::size(alphas) * std::size(thetas) * 2) + 1;
    for (bool inside : {false, true})
        for (float alpha : alphas)
            for (double theta : thetas) {
                BsdfUnderTest m = dielectric(alpha, theta, inside);
                char name[96];
                std::snprintf(name, sizeof name, "dielectric alpha %g, theta %g, %s", alpha, theta,
                              inside ? "inside" : "outside");
                expectSamplingMatchesPdf(
                    testSampling(m, dielectricLobes(m), 200000, 2000 + uint(theta) + inside), tests,
                    name);
            }
    // Inside, just past the critical angle (41.8 degrees): mostly reflection, a rough tail
    // refracts.
    BsdfUnderTest m = dielectric(0.2f, 45.0, true);
    expectSamplingMatchesPdf(testSampling(m, dielectricLobes(m), 200000, 7), tests,
                             "dielectric alpha 0.2, inside, 45");
}

// With a vanishing alpha the rough model keeps (almost) all energy: reflection plus refraction
// weighted by eta^2 (the radiance scaling undone) sums to 1.
TEST(Dielectric, NarrowLobeConservesEnergy) {
    for (bool inside : {false, true})
        for (double theta : {0.0, 30.0}) {
            BsdfUnderTest m = dielectric(1e-3f, theta, inside);
            const float eta = inside ? 1.0f / kIor : kIor;
            Uniform u(31);
            double sum = 0;
            const int n = 200000;
            for (int k = 0; k < n; ++k) {
                vec3 wi, weight;
                float pdf;
                bool specular;
                if (!bsdfSample(m.sh, m.albedo, m.ng, m.ns, m.wo, u.next3(), wi, weight, pdf,
                                specular))
                    continue;
                const bool refracted = glm::dot(wi, m.ng) * glm::dot(m.wo, m.ng) < 0;
                sum += weight.x * (refracted ? eta * eta : 1.0f);
            }
            EXPECT_NEAR(sum / n, 1.0, 3e-3) << "inside " << inside << ", theta " << theta;
        }
}

TEST(Dielectric, SmoothIsTwoDeltaLobes) {
    for (bool inside : {false, true})
        for (double theta : {0.0, 30.0, 60.0, 89.0}) {
            BsdfUnderTest m = dielectric(0.0f, theta, inside);
            ASSERT_TRUE(bsdfIsDelta(m.sh));
            const vec3 n = inside ? -m.ng : m.ng;
            const float eta = inside ? 1.0f / kIor : kIor;
            const float c = glm::dot(m.wo, n);
            float cosT;
            const float F = fresnelDielectric(c, eta, cosT);
            Uniform u(11);
            int reflected = 0;
            const int count = 20000;
            for (int k = 0; k < count; ++k) {
                vec3 wi, weight;
                float pdf;
                bool specular;
                ASSERT_TRUE(bsdfSample(m.sh, m.albedo, m.ng, m.ns, m.wo, u.next3(), wi, weight, pdf,
                                       specular));
                ASSERT_TRUE(specular);
                float evalPdf = 1;
                ASSERT_EQ(bsdfEval(m.sh, m.albedo, m.ng, m.ns, m.wo, wi, evalPdf), vec3(0.0f));
                ASSERT_EQ(evalPdf, 0.0f);
                if (glm::dot(wi, n) > 0) {
                    ++reflected;
                    ASSERT_LT(glm::length(wi - (2.0f * c * n - m.wo)), 1e-5f);
                    ASSERT_NEAR(weight.x, 1.0f, 1e-6f);
                } else {
                    // Snell: sin_t = sin_o / eta, in the plane of wo and n, and radiance / eta^2.
                    const vec3 tangentO = m.wo - c * n, tangentI = wi - glm::dot(wi, n) * n;
                    ASSERT_NEAR(glm::length(tangentI) * eta, glm::length(tangentO), 1e-5f);
                    ASSERT_LE(glm::dot(tangentI, tangentO), 0.0f);
                    ASSERT_NEAR(-glm::dot(wi, n), cosT, 1e-5f);
                    ASSERT_NEAR(weight.x, 1.0f / (eta * eta), 1e-6f);
                }
            }
            // The reflected share is F: binomial, 4 standard deviations.
            const double sd = std::sqrt(F * (1 - F) / count);
            EXPECT_NEAR(double(reflected) / count, F, 4 * sd + 1e-9)
                << "inside " << inside << " theta " << theta;
            if (inside && theta > 42.0) {
                EXPECT_EQ(reflected, count) << "total internal reflection";
            }
        }
}

} // namespace
} // namespace spw::test
