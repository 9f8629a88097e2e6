// SheenMetallicRoughness (shared/sheen_metallic_roughness.h), glTF's metallic-roughness material
// under a sheen (KHR_materials_sheen): its sampling against its pdf (chi-square) over dielectric
// and metal bases, smooth and rough sheens, normal to grazing incidence; a sheen of colour 0 is the
// base bit for bit; the albedo table (sheen_albedo.h) is the sheen lobe's own albedo by quadrature;
// over a base that reflects nothing, the material's albedo is the sheen's.
#include "bsdf_test_util.h"

#include "shared/sheen_metallic_roughness.h"

namespace spw::test {
namespace {

const vec3 kSheenBase(0.2f, 0.35f, 0.7f);
const vec3 kSheen(1.0f, 0.6f, 0.3f);

BsdfUnderTest sheened(float metallic, float sheenRoughness, double thetaDeg, vec3 sheen = kSheen) {
    BsdfUnderTest m;
    m.sh = shaderParams(kModelSheenMetallicRoughness, gltfAlpha(0.5f));
    m.sh.metallic = metallic;
    m.sh.sheenColour = sheen;
    m.sh.sheenRoughness = sheenRoughness;
    m.albedo = kSheenBase;
    m.wo = directionAround(m.ng, thetaDeg, 0.4);
    return m;
}

ExpectedLobes sheenLobes(const BsdfUnderTest& m) {
    ExpectedLobes l;
    l.upper = glm::normalize(2.0f * glm::dot(m.wo, m.ng) * m.ng - m.wo);
    l.width = 1.0;
    return l;
}

// The sheen lobe's albedo at cosine mu, by the midpoint rule over the half vector (as
// scripts/make_sheen_table.py integrates it), from sheen_metallic_roughness.h's own D and V.
double sheenLobeAlbedo(double mu, float roughness) {
    const float alpha = sheenAlpha(roughness);
    const vec3 wo(float(std::sqrt(1.0 - mu * mu)), 0.0f, float(mu));
    const int nTheta = 512, nPhi = 128;
    const double dt = M_PI / 2 / nTheta, dp = M_PI / nPhi;
    double sum = 0.0;
    for (int i = 0; i < nTheta; ++i) {
        const double th = (i + 0.5) * dt;
        const float d = sheenD(float(std::cos(th)), alpha);
        for (int k = 0; k < nPhi; ++k) {
            const double ph = (k + 0.5) * dp;
            const vec3 h(float(std::sin(th) * std::cos(ph)), float(std::sin(th) * std::sin(ph)),
                         float(std::cos(th)));
            const float oh = glm::dot(wo, h);
            const float muI = 2.0f * oh * h.z - wo.z;
            if (oh <= 0.0f || muI <= 0.0f) continue;
            sum += double(d) * sheenV(wo.z, muI, alpha) * muI * 4.0 * oh * std::sin(th);
        }
    }
    return 2.0 * sum * dt * dp;
}

TEST(SheenMetallicRoughness, SampledDirectionsFollowThePdf) {
    const float metallics[] = {0.0f, 1.0f};
    const float roughnesses[] = {0.3f, 0.8f};
    const double thetas[] = {0.0, 60.0, 85.0};
    const int tests = int(std::size(metallics) * std::size(roughnesses) * std::size(thetas));
    for (float metallic : metallics)
        for (float r : roughnesses)
            for (double theta : thetas) {
                const BsdfUnderTest m = sheened(metallic, r, theta);
                char name[96];
                std::snprintf(name, sizeof name, "metallic %g, sheen roughness %g, theta %g",
                              metallic, r, theta);
                expectSamplingMatchesPdf(
                    testSampling(m, sheenLobes(m), 200000, 7000 + uint(theta + 10 * r + metallic)),
                    tests, name);
            }
}

// Sheen colour 0: MetallicRoughness, to the bit, in eval and sample.
TEST(SheenMetallicRoughness, ASheenOfColourZeroIsTheBaseBitForBit) {
    Uniform u(71);
    for (float metallic : {0.0f, 0.5f})
        for (double theta : {0.0, 50.0, 88.0}) {
            const BsdfUnderTest m = sheened(metallic, 0.5f, theta, vec3(0.0f));
            ShaderParams base = m.sh;
            base.model = kModelMetallicRoughness;
            for (int k = 0; k < 300; ++k) {
                const vec3 wi = glm::normalize(u.next3() - vec3(0.5f));
                float pdfA, pdfB;
                ASSERT_EQ(bsdfEval(m.sh, m.albedo, m.ng, m.ns, m.wo, wi, pdfA),
                          bsdfEval(base, m.albedo, m.ng, m.ns, m.wo, wi, pdfB));
                ASSERT_EQ(pdfA, pdfB);
                const vec3 r = u.next3();
                vec3 wiA, wiB, wA, wB;
                bool sA, sB;
                const bool okA = bsdfSample(m.sh, m.albedo, m.ng, m.ns, m.wo, r, wiA, wA, pdfA, sA);
                const bool okB = bsdfSample(base, m.albedo, m.ng, m.ns, m.wo, r, wiB, wB, pdfB, sB);
                ASSERT_EQ(okA, okB);
                if (okA) {
                    ASSERT_TRUE(wiA == wiB && wA == wB && pdfA == pdfB);
                }
            }
        }
}

// The table holds the lobe's albedo: at its nodes (cos = (i / (rows - 1))^2, roughness =
// 0.1^(1 - j / (columns - 1))) to 2e-3 (float against the generator's double), between them within
// 7 % or 5e-3 (bilinear interpolation of a smooth function: 5.8 % at worst, at the least
// roughness between two rows).
TEST(SheenMetallicRoughness, TheAlbedoTableIsTheSheenLobesAlbedo) {
    const double rows = kSheenAlbedoCos - 1u, columns = kSheenAlbedoRough - 1u;
    for (double i : {1.0, 1.5, 3.0, 6.5, 10.0, 12.5, 15.0})
        for (double j : {0.0, 0.5, 1.5, 4.0, 7.5, 15.0}) {
            const double mu = (i / rows) * (i / rows);
            const float r = float(std::pow(0.1, 1.0 - j / columns));
            const bool onNode = i == std::floor(i) && j == std::floor(j);
            const double expected = sheenLobeAlbedo(mu, r);
            EXPECT_NEAR(sheenAlbedo(float(mu), r), expected,
                        onNode ? 2e-3 : std::max(0.07 * expected, 5e-3))
                << "cos " << mu << ", roughness " << r;
        }
}

// Over a black dielectric whose reflection is off (KHR_materials_specular's weight 0) the base
// reflects nothing, and the material's albedo seen from wo is the sheen's: mean(sheen) E(cos wo).
TEST(SheenMetallicRoughness, OverANonReflectingBaseItsAlbedoIsTheSheens) {
    for (float r : {0.3f, 1.0f})
        for (double theta : {0.0, 70.0}) {
            BsdfUnderTest m = sheened(0.0f, r, theta);
            m.albedo = vec3(0.0f);
            m.sh.flags |= kShaderSpecular;
            m.sh.specular = 0.0f;
            m.sh.specularColour = vec3(1.0f);
            const double expected = (kSheen.x + kSheen.y + kSheen.z) / 3.0 *
                                    sheenLobeAlbedo(std::cos(theta * M_PI / 180.0), r);
            EXPECT_NEAR(testSampling(m, sheenLobes(m), 100000, 80).fcosIntegral, expected,
                        2e-3 + 0.01 * expected)
                << "roughness " << r << ", theta " << theta;
        }
}

} // namespace
} // namespace spw::test
