// CoatedMetallicRoughness (shared/coated_metallic_roughness.h), glTF's metallic-roughness material
// under a clear coat (KHR_materials_clearcoat): its sampling against its pdf (chi-square) over coat
// weights and roughnesses on dielectric and metal bases, at normal, oblique and grazing incidence;
// without weight it is MetallicRoughness bit for bit; the coat's reflectance at normal incidence in
// closed form; energy in a white furnace; a coat normal of its own (kShaderCoatNormal) moves the
// coat's lobe and not the base's.
#include "bsdf_test_util.h"

#include "shared/coated_metallic_roughness.h"

namespace spw::test {
namespace {

const vec3 kCoatedBase(0.9f, 0.55f, 0.2f);

BsdfUnderTest coated(float metallic, float roughness, float coat, float coatRoughness,
                     double thetaDeg, vec3 ng = vec3(0, 0, 1)) {
    BsdfUnderTest m;
    m.sh = shaderParams(kModelCoatedMetallicRoughness, gltfAlpha(roughness));
    m.sh.metallic = metallic;
    m.sh.coat = coat;
    m.sh.coatAlpha = gltfAlpha(coatRoughness);
    m.albedo = kCoatedBase;
    m.ng = m.ns = ng;
    m.wo = directionAround(ng, thetaDeg, 0.4);
    return m;
}

ExpectedLobes coatedLobes(const BsdfUnderTest& m) {
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
                        testSampling(m, coatedLobes(m), 200000,
                                     700 + uint(theta + 10 * roughness + 100 * coatRoughness)),
                        tests, name);
                }
    // Half a coat, in a tilted frame, wo on the back of ng (the model turns to wo's side).
    const BsdfUnderTest m =
        coated(0.3f, 0.5f, 0.5f, 0.2f, 130.0, glm::normalize(vec3(-0.2f, 0.7f, 0.4f)));
    expectSamplingMatchesPdf(testSampling(m, coatedLobes(m), 200000, 5), tests,
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
        EXPECT_NEAR(testSampling(black, coatedLobes(black), 50000, 31).fcosIntegral,
                    fc + (1.0 - fc) * 0.04, 1e-3)
            << "coat " << coat;
    }
    for (float metallic : {0.0f, 1.0f})
        for (float roughness : {0.0f, 0.5f, 1.0f}) {
            BsdfUnderTest m = coated(metallic, roughness, 1.0f, 0.3f, 0.0);
            m.albedo = vec3(1.0f);
            const SamplingReport r = testSampling(m, coatedLobes(m), 50000, 32);
            EXPECT_LE(r.fcosIntegral, 1.0 + 1e-3)
                << "metallic " << metallic << ", roughness " << roughness;
            EXPECT_GT(r.fcosIntegral, 0.3)
                << "metallic " << metallic << ", roughness " << roughness;
        }
}

// `m` with the coat about normal nc of its own (as a hit carries it: octahedral, in halves); the
// unit vector the model decodes.
vec3 withCoatNormal(BsdfUnderTest& m, vec3 nc) {
    m.sh.flags |= kShaderCoatNormal;
    m.sh.coatNormal = packHalf2x16(octahedralEncode(glm::normalize(nc)));
    return gltfCoatNormal(m.sh, m.ns);
}

TEST(CoatedMetallicRoughness, WithItsOwnNormalSampledDirectionsFollowThePdf) {
    const double thetas[] = {0.0, 40.0, 80.0};
    const vec3 tilts[] = {vec3(0.3f, 0.1f, 1.0f), vec3(-0.6f, 0.4f, 0.7f)};
    const int tests = int(std::size(thetas) * std::size(tilts)) * 2;
    for (float metallic : {0.0f, 1.0f})
        for (vec3 tilt : tilts)
            for (double theta : thetas) {
                BsdfUnderTest m = coated(metallic, 0.6f, 1.0f, 0.2f, theta);
                m.ns = glm::normalize(vec3(-0.2f, 0.0f, 1.0f)); // the base's normal map
                withCoatNormal(m, tilt);
                char name[128];
                std::snprintf(name, sizeof name, "metallic %g, coat normal (%g %g %g), theta %g",
                              metallic, tilt.x, tilt.y, tilt.z, theta);
                ExpectedLobes l = coatedLobes(m);
                l.width = 1.0; // two lobes about two normals
                expectSamplingMatchesPdf(
                    testSampling(m, l, 200000, 900 + uint(theta) + uint(10 * tilt.y)), tests, name);
            }
}

// Over a base that reflects nothing (black, its specular weight 0) only the coat reflects: its
// f cos follows the coat's normal bit for bit, whatever the base's; with the coat's normal equal
// to the base's, the flag changes nothing.
TEST(CoatedMetallicRoughness, TheCoatsOwnNormalTurnsTheCoatAlone) {
    Uniform u(11);
    size_t differ = 0, lit = 0;
    for (double theta : {0.0, 35.0, 70.0}) {
        BsdfUnderTest m = coated(0.0f, 0.5f, 1.0f, 0.3f, theta);
        m.albedo = vec3(0.0f);
        m.sh.flags |= kShaderSpecular;
        m.sh.specular = 0.0f;
        m.sh.specularColour = vec3(1.0f);
        m.ns = glm::normalize(vec3(0.3f, -0.2f, 1.0f));
        const vec3 nc = withCoatNormal(m, vec3(-0.25f, 0.15f, 1.0f));
        BsdfUnderTest same = m; // the base about the coat's normal too
        same.ns = nc;
        BsdfUnderTest unflagged = same;
        unflagged.sh.flags &= ~kShaderCoatNormal;
        BsdfUnderTest shared = m; // the coat about the base's normal
        shared.sh.flags &= ~kShaderCoatNormal;
        for (int k = 0; k < 500; ++k) {
            const vec3 wi = glm::normalize(u.next3() - vec3(0.5f));
            float pdf, pdfSame, pdfUnflagged, pdfShared;
            const vec3 f = bsdfEval(m.sh, m.albedo, m.ng, m.ns, m.wo, wi, pdf);
            const vec3 fSame = bsdfEval(same.sh, m.albedo, m.ng, same.ns, m.wo, wi, pdfSame);
            const vec3 fUnflagged =
                bsdfEval(unflagged.sh, m.albedo, m.ng, same.ns, m.wo, wi, pdfUnflagged);
            const vec3 fShared = bsdfEval(shared.sh, m.albedo, m.ng, m.ns, m.wo, wi, pdfShared);
            ASSERT_EQ(f, fSame) << theta;
            ASSERT_EQ(fSame, fUnflagged) << theta;
            ASSERT_EQ(pdfSame, pdfUnflagged) << theta;
            lit += f.x > 0.0f;
            differ += f != fShared;
        }
    }
    EXPECT_GT(lit, 600u);
    EXPECT_GT(differ, 600u);
}

} // namespace
} // namespace spw::test
