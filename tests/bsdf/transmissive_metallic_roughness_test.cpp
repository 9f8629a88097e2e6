// TransmissiveMetallicRoughness (shared/transmissive_metallic_roughness.h), glTF's dielectric
// transmitting part of the light: rough glass mixed with the opaque material sampled against the
// pdf (chi-square), from outside and inside; transmission 0 and 1 are MetallicRoughness and the
// Dielectric bit for bit; over smooth glass, the delta lobes are sampled with probability
// transmission and keep the glass's weights; energy at the narrow-lobe limit; on a metal, the
// glass's weight is transmission (1 - metallic), and metallic 1 is the opaque metal.
#include "bsdf_test_util.h"

#include "shared/metallic_roughness.h"

namespace spw::test {
namespace {

constexpr float kIor = 1.5f;
const vec3 kGlassBase(0.9f, 0.7f, 0.5f);

BsdfUnderTest transmissive(float transmission, float alpha, double thetaDeg, bool inside) {
    BsdfUnderTest m;
    m.sh = shaderParams(kModelTransmissiveMetallicRoughness, alpha, kIor);
    m.sh.transmission = transmission;
    m.albedo = kGlassBase;
    m.ng = m.ns = glm::normalize(vec3(0.1f, -0.2f, 1.0f));
    m.wo = directionAround(inside ? -m.ng : m.ng, thetaDeg, 0.9);
    return m;
}

// The glass's mirror and refracted directions (the opaque part's lobes are wider).
ExpectedLobes glassLobes(const BsdfUnderTest& m) {
    ExpectedLobes l;
    const bool outside = glm::dot(m.wo, m.ng) > 0;
    const vec3 n = outside ? m.ng : -m.ng;
    const float eta = outside ? kIor : 1.0f / kIor;
    const float c = glm::dot(m.wo, n);
    const float sin2t = (1 - c * c) / (eta * eta);
    const vec3 mirror = glm::normalize(2.0f * c * n - m.wo);
    const vec3 refracted =
        sin2t < 1 ? glm::normalize(-m.wo / eta + (c / eta - std::sqrt(1 - sin2t)) * n) : -n;
    (outside ? l.upper : l.lower) = mirror;
    (outside ? l.lower : l.upper) = refracted;
    l.width = std::max(2.0 * m.sh.alpha, 1e-4);
    return l;
}

TEST(TransmissiveMetallicRoughness, SampledDirectionsFollowThePdf) {
    const float transmissions[] = {0.3f, 0.8f};
    const float alphas[] = {0.09f, 0.49f};
    const double thetas[] = {0.0, 60.0};
    const int tests = int(std::size(transmissions) * std::size(alphas) * std::size(thetas) * 2);
    for (bool inside : {false, true})
        for (float t : transmissions)
            for (float alpha : alphas)
                for (double theta : thetas) {
                    const BsdfUnderTest m = transmissive(t, alpha, theta, inside);
                    char name[112];
                    std::snprintf(name, sizeof name, "transmission %g, alpha %g, theta %g, %s", t,
                                  alpha, theta, inside ? "inside" : "outside");
                    expectSamplingMatchesPdf(
                        testSampling(m, glassLobes(m), 200000,
                                     4000 + uint(theta + 10 * t + 100 * alpha) + inside),
                        tests, name);
                }
}

// On a metal the glass's weight is transmission (1 - metallic): at metallic 0.5, sampled against
// the pdf (chi-square) as above.
TEST(TransmissiveMetallicRoughness, OnAMetalSampledDirectionsFollowThePdf) {
    const double thetas[] = {0.0, 60.0};
    for (bool inside : {false, true})
        for (double theta : thetas) {
            BsdfUnderTest m = transmissive(0.8f, 0.09f, theta, inside);
            m.sh.metallic = 0.5f;
            char name[80];
            std::snprintf(name, sizeof name, "metallic 0.5, theta %g, %s", theta,
                          inside ? "inside" : "outside");
            expectSamplingMatchesPdf(
                testSampling(m, glassLobes(m), 200000, 4500 + uint(theta) + inside), 4, name);
        }
}

// Metallic 1 leaves no glass whatever the transmission: MetallicRoughness's metal, bit for bit
// in eval, and never a delta BSDF.
TEST(TransmissiveMetallicRoughness, AWholeMetalIsTheOpaqueMetal) {
    Uniform u(43);
    for (float t : {0.5f, 1.0f})
        for (double theta : {0.0, 50.0}) {
            BsdfUnderTest m = transmissive(t, 0.0f, theta, false);
            m.sh.metallic = 1.0f;
            ShaderParams metal = shaderParams(kModelMetallicRoughness, kGltfMinAlpha, kIor);
            metal.metallic = 1.0f;
            EXPECT_FALSE(bsdfIsDelta(m.sh));
            for (int k = 0; k < 300; ++k) {
                const vec3 wi = glm::normalize(u.next3() - vec3(0.5f));
                float pdfA, pdfB;
                const vec3 a = bsdfEval(m.sh, m.albedo, m.ng, m.ns, m.wo, wi, pdfA);
                ASSERT_EQ(a, bsdfEval(metal, m.albedo, m.ng, m.ns, m.wo, wi, pdfB));
                ASSERT_EQ(pdfA, pdfB);
            }
        }
}

// transmission 0: MetallicRoughness at metallic 0 (its alpha floored as glTF's loader floors
// it); 1: the Dielectric of the same alpha. In eval, bit for bit, over every direction.
TEST(TransmissiveMetallicRoughness, ItsEndsAreTheOpaqueMaterialAndTheGlass) {
    Uniform u(41);
    size_t nonZero = 0;
    for (float alpha : {0.0f, 0.09f, 0.6f})
        for (double theta : {0.0, 50.0, 88.0})
            for (bool inside : {false, true}) {
                BsdfUnderTest m = transmissive(0.0f, alpha, theta, inside);
                ShaderParams opaque =
                    shaderParams(kModelMetallicRoughness, std::max(alpha, kGltfMinAlpha), kIor);
                opaque.metallic = 0.0f;
                ShaderParams glass = shaderParams(kModelDielectric, alpha, kIor);
                for (int k = 0; k < 300; ++k) {
                    const vec3 wi = glm::normalize(u.next3() - vec3(0.5f));
                    float pdfA, pdfB;
                    m.sh.transmission = 0.0f;
                    vec3 a = bsdfEval(m.sh, m.albedo, m.ng, m.ns, m.wo, wi, pdfA);
                    ASSERT_EQ(a, bsdfEval(opaque, m.albedo, m.ng, m.ns, m.wo, wi, pdfB));
                    ASSERT_EQ(pdfA, pdfB);
                    nonZero += a.x > 0.0f;
                    m.sh.transmission = 1.0f;
                    a = bsdfEval(m.sh, m.albedo, m.ng, m.ns, m.wo, wi, pdfA);
                    ASSERT_EQ(a, bsdfEval(glass, m.albedo, m.ng, m.ns, m.wo, wi, pdfB));
                    ASSERT_EQ(pdfA, pdfB);
                    nonZero += a.x > 0.0f;
                }
                m.sh.transmission = 1.0f;
                EXPECT_EQ(bsdfIsDelta(m.sh), bsdfIsDelta(glass));
                m.sh.transmission = 0.5f;
                EXPECT_FALSE(bsdfIsDelta(m.sh));
            }
    EXPECT_GT(nonZero, 2000u);
}

// Over smooth glass the delta lobes are sampled with probability transmission (binomial, 4
// standard deviations), each with the Dielectric's own weight (1 reflected, 1 / eta^2 times the
// base colour refracted); eval sees the opaque part alone.
TEST(TransmissiveMetallicRoughness, OverSmoothGlassTheDeltaLobesKeepTheirWeights) {
    for (float t : {0.25f, 0.75f}) {
        const BsdfUnderTest m = transmissive(t, 0.0f, 30.0, false);
        ShaderParams glass = shaderParams(kModelDielectric, 0.0f, kIor);
        Uniform u(51);
        int deltas = 0;
        const int count = 20000;
        for (int k = 0; k < count; ++k) {
            const vec3 r = u.next3();
            vec3 wi, weight;
            float pdf;
            bool specular;
            if (!bsdfSample(m.sh, m.albedo, m.ng, m.ns, m.wo, r, wi, weight, pdf, specular))
                continue;
            if (!specular) continue;
            ++deltas;
            ASSERT_LT(r.z, t);
            vec3 wiG, weightG;
            float pdfG;
            bool specularG;
            ASSERT_TRUE(bsdfSample(glass, m.albedo, m.ng, m.ns, m.wo, vec3(r.x, r.y, r.z / t), wiG,
                                   weightG, pdfG, specularG));
            ASSERT_EQ(wi, wiG);
            ASSERT_EQ(weight, weightG);
            ASSERT_EQ(pdf, 0.0f);
        }
        const double sd = std::sqrt(t * (1.0 - t) / count);
        EXPECT_NEAR(double(deltas) / count, t, 4 * sd);
    }
}

// A white base colour at a vanishing roughness, seen at normal incidence: the opaque part
// reflects at most 1 and the glass, its refraction's radiance scaling undone, all of it: the
// mixture's albedo is (1 - t) a_opaque + t, and without the scaling it stays at most 1.
TEST(TransmissiveMetallicRoughness, TheMixtureKeepsEachPartsEnergy) {
    for (float t : {0.2f, 0.6f}) {
        BsdfUnderTest m = transmissive(t, 1e-3f, 0.0, false);
        m.albedo = vec3(1.0f);
        BsdfUnderTest opaque = transmissive(0.0f, 1e-3f, 0.0, false);
        opaque.albedo = vec3(1.0f);
        const double aOpaque = testSampling(opaque, glassLobes(opaque), 100000, 61).fcosIntegral;
        Uniform u(62);
        double sum = 0.0;
        const int n = 100000;
        for (int k = 0; k < n; ++k) {
            vec3 wi, weight;
            float pdf;
            bool specular;
            if (!bsdfSample(m.sh, m.albedo, m.ng, m.ns, m.wo, u.next3(), wi, weight, pdf, specular))
                continue;
            const bool refracted = glm::dot(wi, m.ng) < 0;
            sum += weight.x * (refracted ? kIor * kIor : 1.0f);
        }
        EXPECT_NEAR(sum / n, (1.0 - t) * aOpaque + t, 1e-2) << "transmission " << t;
        EXPECT_LE(aOpaque, 1.0 + 1e-3);
    }
}

} // namespace
} // namespace spw::test
