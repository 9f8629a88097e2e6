// CoatedMetallicRoughness (shared/clearcoat.h), glTF's metallic-roughness material under a clear
// coat (KHR_materials_clearcoat): its sampling against its pdf (chi-square) over coat weights and
// roughnesses on dielectric and metal bases, at normal, oblique and grazing incidence; without
// weight it is MetallicRoughness bit for bit; the coat's reflectance at normal incidence in
// closed form; energy in a white furnace.
#include "bsdf_test_util.h"

#include "shared/clearcoat.h"

namespace spw::test {
namespace {

const vec3 kBase(0.9f, 0.55f, 0.2f);

BsdfUnderTest coated(float metallic, float roughness, float coat, float coatRoughness,
                     double thetaDeg, vec3 ng = vec3(0, 0, 1)) {
    BsdfUnderTest m;
    m.sh = shaderParams(kModelCoatedMetallicRoughness, gltfAlpha(roughness));
    m.sh.metallic = metallic;
    m.sh.coat = coat;
    m.sh.coatAlpha = gltfAlpha(coatRoughness);
    m.albedo = kBase;
    m.ng = m.ns = ng;
    m.wo = directionAround(ng, thetaDeg, 0.4);
    return m;
}

ExpectedLobes lobes(const BsdfUnderTest& m) {
    ExpectedLobes l;
    l.upper = glm::normalize(2.0f * glm::dot(m.wo, m.ng) * m.ng - m.wo);
    l.width =
        m.sh.metallic >= 1.0f ? std::max(2.0 * std::min(m.sh.alpha, m.sh.coatAlpha), 1e-4) : 1.0;
    return l;
}

TEST(CoatedMetallicRoughness, SampledDirectionsFollowThePdf) {
    const float metallics[] = {0.0f, 1.0f};
    const float roughnesses[] = {0.2f, 0.8f};
    const float coatRoughnesses[] = {0.0f, 0.3f};
    const double thetas[] = {0.0, 45.0, 85.0};
    const int tests = int(std::size(metallics) * std::size(roughnesses) *
                          std::size(coatRoughnesses) * std::size(thetas)) +
                      1;
    for (float metallic : metallics)
        for (float roughness : roughnesses)
            for (float coatRoughness : coatRoughnesses)
                for (double theta : thetas) {
                    const BsdfUnderTest m = coated(metallic, roughness, 1.0f, coatRoughness, theta);
                    char name[128];
                    std::snprintf(name, sizeof name,
                                  "metallic %g, roughness %g, coat roughness %g, theta %g",
                                  metallic, roughness, coatRoughness, theta);
                    expectSamplingMatchesPdf(
                        testSampling(m, lobes(m), 200000,
                                     700 + uint(theta + 10 * roughness + 100 * coatRoughness)),
                        tests, name);
                }
    // Half a coat, in a tilted frame, wo on the back of ng (the model turns to wo's side).
    const BsdfUnderTest m =
        coated(0.3f, 0.5f, 0.5f, 0.2f, 130.0, glm::normalize(vec3(-0.2f, 0.7f, 0.4f)));
    expectSamplingMatchesPdf(testSampling(m, lobes(m), 200000, 5), tests,
                             "metallic 0.3, coat 0.5, back side, tilted");
}

// Without weight the coat reflects nothing and takes no samples: f and pdf are the base's.
TEST(CoatedMetallicRoughness, WithoutWeightItIsMetallicRoughnessBitForBit) {
    Uniform u(9);
    size_t nonZero = 0;
    for (float metallic : {0.0f, 0.4f, 1.0f})
        for (double theta : {0.0, 50.0, 88.0}) {
            const BsdfUnderTest m = coated(metallic, 0.5f, 0.0f, 0.1f, theta);
            ShaderParams plain = m.sh;
            plain.model = kModelMetallicRoughness;
            for (int k = 0; k < 500; ++k) {
                const vec3 wi = glm::normalize(u.next3() - vec3(0.5f));
                float pdfA, pdfB;
                const vec3 a = bsdfEval(m.sh, m.albedo, m.ng, m.ns, m.wo, wi, pdfA);
                const vec3 b = bsdfEval(plain, m.albedo, m.ng, m.ns, m.wo, wi, pdfB);
                ASSERT_EQ(a, b) << metallic << " " << theta;
                ASSERT_EQ(pdfA, pdfB) << metallic << " " << theta;
                nonZero += a.x > 0.0f;
            }
        }
    EXPECT_GT(nonZero, 1000u);
}

// At normal incidence, narrow lobes: a black dielectric base reflects its own F0 (0.04) of what
// the coat lets through, the coat its weight times 0.04 on top: 0.04 c + (1 - 0.04 c) 0.04. A
// white base in a white furnace gains nothing, coated or not.
TEST(CoatedMetallicRoughness, NarrowLobesReflectTheClosedFormAndAFurnaceGainsNothing) {
    for (float coat : {1.0f, 0.5f}) {
        BsdfUnderTest black = coated(0.0f, 0.0f, coat, 0.0f, 0.0);
        black.albedo = vec3(0.0f);
        const double fc = 0.04 * coat;
        EXPECT_NEAR(testSampling(black, lobes(black), 50000, 31).fcosIntegral,
                    fc + (1.0 - fc) * 0.04, 1e-3)
            << "coat " << coat;
    }
    for (float metallic : {0.0f, 1.0f})
        for (float roughness : {0.0f, 0.5f, 1.0f}) {
            BsdfUnderTest m = coated(metallic, roughness, 1.0f, 0.3f, 0.0);
            m.albedo = vec3(1.0f);
            const SamplingReport r = testSampling(m, lobes(m), 50000, 32);
            EXPECT_LE(r.fcosIntegral, 1.0 + 1e-3)
                << "metallic " << metallic << ", roughness " << roughness;
            EXPECT_GT(r.fcosIntegral, 0.3)
                << "metallic " << metallic << ", roughness " << roughness;
        }
}

} // namespace
} // namespace spw::test
