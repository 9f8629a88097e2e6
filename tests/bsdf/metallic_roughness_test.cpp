// MetallicRoughness (shared/metallic_roughness.h), glTF 2.0's metallic-roughness material: its
// sampling against its pdf (chi-square) from dielectric to metal, smooth to rough, at normal,
// oblique and grazing incidence; the pdf and f |cos| integrated by quadrature; a pure metal is the
// Conductor bit for bit; energy in a white furnace; closed forms at the narrow-lobe limit; and
// KHR_materials_specular's weight and F0 colour (kShaderSpecular): sampled as the pdf says, their
// defaults glTF's own material to the bit, their F0 at the narrow-lobe limit.
#include "bsdf_test_util.h"

#include "shared/metallic_roughness.h"

namespace spw::test {
namespace {

const vec3 kBase(0.9f, 0.55f, 0.2f);

BsdfUnderTest metallicRoughness(float metallic, float roughness, double thetaDeg,
                                vec3 ng = vec3(0, 0, 1)) {
    BsdfUnderTest m;
    m.sh = shaderParams(kModelMetallicRoughness, gltfAlpha(roughness));
    m.sh.metallic = metallic;
    m.albedo = kBase;
    m.ng = m.ns = ng;
    m.wo = directionAround(ng, thetaDeg, 0.4);
    return m;
}

ExpectedLobes lobes(const BsdfUnderTest& m) {
    ExpectedLobes l;
    l.upper = glm::normalize(2.0f * glm::dot(m.wo, m.ng) * m.ng - m.wo);
    l.width = m.sh.metallic >= 1.0f ? std::max(2.0 * m.sh.alpha, 1e-4) : 1.0;
    return l;
}

TEST(MetallicRoughness, SampledDirectionsFollowThePdf) {
    const float metallics[] = {0.0f, 0.5f, 1.0f};
    const float roughnesses[] = {0.0f, 0.2f, 0.6f, 1.0f};
    const double thetas[] = {0.0, 45.0, 85.0};
    const int tests = int(std::size(metallics) * std::size(roughnesses) * std::size(thetas)) + 1;
    for (float metallic : metallics)
        for (float roughness : roughnesses)
            for (double theta : thetas) {
                const BsdfUnderTest m = metallicRoughness(metallic, roughness, theta);
                char name[96];
                std::snprintf(name, sizeof name, "metallic %g, roughness %g, theta %g", metallic,
                              roughness, theta);
                expectSamplingMatchesPdf(
                    testSampling(m, lobes(m), 200000, 500 + uint(theta + 10 * roughness)), tests,
                    name);
            }
    // In a tilted frame, wo on the back of ng (the model turns to wo's side).
    const BsdfUnderTest m =
        metallicRoughness(0.3f, 0.5f, 130.0, glm::normalize(vec3(-0.2f, 0.7f, 0.4f)));
    expectSamplingMatchesPdf(testSampling(m, lobes(m), 200000, 3), tests,
                             "metallic 0.3, roughness 0.5, back side, tilted");
}

// The lobe is picked by the lobes' weights seen from wo, Fs / (Fs + Fd), at normal incidence
// F = f0: floored at 0.25 (1 - alpha)^2 while the specular lobe is narrow, not at all at alpha 1,
// where it is as wide as the diffuse one; at most 0.9; 1 for a pure metal.
TEST(MetallicRoughness, TheSpecularLobeIsPickedByItsWeightFlooredWhileItIsNarrow) {
    const vec3 f0(kGltfDielectricF0), white(0.9f);
    const float ratio = 0.04f / (0.04f + 0.9f * 0.96f); // about 0.044
    EXPECT_NEAR(gltfSpecularProbability(f0, 1.0f, white, 1.0f, 1.0f), ratio, 1e-6f);
    EXPECT_NEAR(gltfSpecularProbability(f0, 1.0f, white, 1.0f, 0.5f), 0.0625f, 1e-6f);
    EXPECT_NEAR(gltfSpecularProbability(f0, 1.0f, white, 1.0f, kGltfMinAlpha),
                0.25f * (1.0f - kGltfMinAlpha) * (1.0f - kGltfMinAlpha), 1e-6f);
    EXPECT_NEAR(gltfSpecularProbability(f0, 1.0f, vec3(0.01f), 1.0f, 1.0f),
                0.04f / (0.04f + 0.01f * 0.96f), 1e-6f); // a dark base: the weights alone
    EXPECT_EQ(gltfSpecularProbability(vec3(0.9f), 1.0f, vec3(1e-3f), 1.0f, 1.0f), 0.9f);
    EXPECT_EQ(gltfSpecularProbability(vec3(0.9f), 1.0f, vec3(0.0f), 1.0f, 0.01f), 1.0f);
}

// metallic 1: c_diff = 0 and f0 = the base colour, which is the Conductor's model exactly.
TEST(MetallicRoughness, APureMetalIsTheConductorBitForBit) {
    Uniform u(8);
    size_t nonZero = 0;
    for (float roughness : {0.0f, 0.3f, 1.0f})
        for (double theta : {0.0, 50.0, 88.0}) {
            BsdfUnderTest m = metallicRoughness(1.0f, roughness, theta);
            ShaderParams conductor = shaderParams(kModelConductor, m.sh.alpha);
            for (int k = 0; k < 500; ++k) {
                const vec3 wi = glm::normalize(u.next3() - vec3(0.5f));
                float pdfA, pdfB;
                const vec3 a = bsdfEval(m.sh, m.albedo, m.ng, m.ns, m.wo, wi, pdfA);
                const vec3 b = bsdfEval(conductor, m.albedo, m.ng, m.ns, m.wo, wi, pdfB);
                ASSERT_EQ(a, b) << roughness << " " << theta;
                nonZero += a.x > 0.0f;
            }
        }
    EXPECT_GT(nonZero, 1000u);
}

// A white furnace at normal incidence: with a white base colour nothing is gained, at any
// metalness or roughness. (At grazing angles the specification's BRDF does gain: its diffuse
// term is weighted by 1 - F of each direction's half vector, not by what the specular lobe
// reflects in all, so a smooth white dielectric seen at 85 degrees reflects 1.59, at 60
// degrees 1.03; docs/scene-format.md says so.) A white metal's narrow lobe keeps all the
// energy, and a black dielectric's reflects Schlick's 0.04 at normal incidence.
TEST(MetallicRoughness, WhiteFurnaceAndTheNarrowLobeLimits) {
    for (float metallic : {0.0f, 0.5f, 1.0f})
        for (float roughness : {0.0f, 0.5f, 1.0f}) {
            BsdfUnderTest m = metallicRoughness(metallic, roughness, 0.0);
            m.albedo = vec3(1.0f);
            const SamplingReport r = testSampling(m, lobes(m), 50000, 21);
            EXPECT_LE(r.fcosIntegral, 1.0 + 1e-3)
                << "metallic " << metallic << ", roughness " << roughness;
            EXPECT_GT(r.fcosIntegral, 0.3)
                << "metallic " << metallic << ", roughness " << roughness;
        }
    BsdfUnderTest metal = metallicRoughness(1.0f, 0.0f, 0.0);
    metal.albedo = vec3(1.0f);
    EXPECT_NEAR(testSampling(metal, lobes(metal), 50000, 22).fcosIntegral, 1.0, 5e-3);
    BsdfUnderTest black = metallicRoughness(0.0f, 0.0f, 0.0);
    black.albedo = vec3(0.0f);
    EXPECT_NEAR(testSampling(black, lobes(black), 50000, 23).fcosIntegral, 0.04, 1e-3);
}

// metallicRoughness with KHR_materials_specular's weight and F0 colour.
BsdfUnderTest withSpecular(BsdfUnderTest m, float weight, vec3 colour) {
    m.sh.flags |= kShaderSpecular;
    m.sh.specular = weight;
    m.sh.specularColour = colour;
    return m;
}

TEST(MetallicRoughness, WithSpecularSampledDirectionsFollowThePdf) {
    const float weights[] = {0.0f, 0.4f};
    const float metallics[] = {0.0f, 0.5f};
    const float roughnesses[] = {0.2f, 0.7f};
    const double thetas[] = {0.0, 60.0};
    const int tests =
        int(std::size(weights) * std::size(metallics) * std::size(roughnesses) * std::size(thetas));
    for (float w : weights)
        for (float metallic : metallics)
            for (float roughness : roughnesses)
                for (double theta : thetas) {
                    const BsdfUnderTest m = withSpecular(
                        metallicRoughness(metallic, roughness, theta), w, vec3(2.5f, 1.0f, 0.2f));
                    char name[128];
                    std::snprintf(name, sizeof name,
                                  "specular %g, metallic %g, roughness %g, theta %g", w, metallic,
                                  roughness, theta);
                    expectSamplingMatchesPdf(
                        testSampling(m, lobes(m), 200000, 900 + uint(theta + 10 * roughness + w)),
                        tests, name);
                }
}

// specular 1 and colour (1, 1, 1) are glTF's material without the extension, to the bit, in eval
// and in sample; and a black dielectric reflects min(0.04 c, 1) w at normal incidence (the
// channels' mean, as testSampling integrates it), nothing at w = 0.
TEST(MetallicRoughness, SpecularDefaultsChangeNothingAndItsF0IsTheReflectance) {
    Uniform u(31);
    for (float metallic : {0.0f, 0.4f, 1.0f})
        for (double theta : {0.0, 50.0, 88.0}) {
            const BsdfUnderTest plain = metallicRoughness(metallic, 0.4f, theta);
            const BsdfUnderTest flagged = withSpecular(plain, 1.0f, vec3(1.0f));
            for (int k = 0; k < 300; ++k) {
                const vec3 wi = glm::normalize(u.next3() - vec3(0.5f));
                float pdfA, pdfB;
                ASSERT_EQ(bsdfEval(plain.sh, plain.albedo, plain.ng, plain.ns, plain.wo, wi, pdfA),
                          bsdfEval(flagged.sh, flagged.albedo, flagged.ng, flagged.ns, flagged.wo,
                                   wi, pdfB));
                ASSERT_EQ(pdfA, pdfB);
                const vec3 r = u.next3();
                vec3 wiA, wiB, wA, wB;
                bool sA, sB;
                const bool okA = bsdfSample(plain.sh, plain.albedo, plain.ng, plain.ns, plain.wo, r,
                                            wiA, wA, pdfA, sA);
                const bool okB = bsdfSample(flagged.sh, flagged.albedo, flagged.ng, flagged.ns,
                                            flagged.wo, r, wiB, wB, pdfB, sB);
                ASSERT_EQ(okA, okB);
                if (okA) {
                    ASSERT_TRUE(wiA == wiB && wA == wB && pdfA == pdfB);
                }
            }
        }
    BsdfUnderTest black =
        withSpecular(metallicRoughness(0.0f, 0.0f, 0.0), 0.5f, vec3(2.0f, 1.0f, 0.25f));
    black.albedo = vec3(0.0f);
    EXPECT_NEAR(testSampling(black, lobes(black), 50000, 32).fcosIntegral,
                0.5 * (0.08 + 0.04 + 0.01) / 3.0, 1e-3);
    black.sh.specular = 0.0f;
    EXPECT_EQ(testSampling(black, lobes(black), 50000, 33).fcosIntegral, 0.0);
}

} // namespace
} // namespace spw::test
