// Principled (shared/principled.h), Blender 3.4's Principled BSDF v1: its sampling against its pdf
// (chi-square) over dielectric and metal bases, with and without sheen and clear coat, normal to
// grazing incidence; each lobe against a closed form or a quadrature of the formula it implements
// (Burley's diffuse albedo, the metal's GGX lobe as the Conductor's, the sheen's albedo, GTR1's
// normalisation); the tints.
#include "bsdf_test_util.h"

#include "shared/principled.h"

namespace spw::test {
namespace {

const vec3 kPrincipledBase(0.8f, 0.45f, 0.2f);

struct PrincipledKnobs {
    float metallic = 0.0f, roughness = 0.5f, specular = 0.5f, sheen = 0.0f, coat = 0.0f;
};

BsdfUnderTest principledUnderTest(const PrincipledKnobs& k, double thetaDeg,
                                  vec3 base = kPrincipledBase) {
    BsdfUnderTest m;
    m.sh = shaderParams(kModelPrincipled, gltfAlpha(k.roughness));
    m.sh.metallic = k.metallic;
    m.sh.specular = k.specular;
    m.sh.specularTint = 0.3f;
    m.sh.sheen = k.sheen;
    m.sh.sheenTint = 0.5f;
    m.sh.coat = k.coat;
    m.sh.coatAlpha = gltfAlpha(0.1f);
    m.albedo = base;
    m.wo = directionAround(m.ng, thetaDeg, 0.4);
    return m;
}

ExpectedLobes principledLobes(const BsdfUnderTest& m) {
    ExpectedLobes l;
    l.upper = glm::normalize(2.0f * glm::dot(m.wo, m.ng) * m.ng - m.wo);
    l.width = std::max(0.05, std::sqrt(double(m.sh.alpha)));
    return l;
}

TEST(Principled, SampledDirectionsFollowThePdf) {
    const PrincipledKnobs knobs[] = {
        {0.0f, 0.5f, 0.5f, 0.0f, 0.0f}, // Blender's default material
        {0.0f, 0.2f, 1.0f, 1.0f, 0.0f}, // glossy plastic with a sheen
        {0.0f, 0.8f, 0.5f, 0.5f, 1.0f}, // rough, sheen and clear coat
        {1.0f, 0.3f, 0.5f, 0.0f, 0.0f}, // metal
        {1.0f, 0.6f, 0.5f, 0.0f, 1.0f}, // coated metal
    };
    const double thetas[] = {0.0, 60.0, 85.0};
    const int tests = int(std::size(knobs) * std::size(thetas));
    int seed = 0;
    for (const PrincipledKnobs& k : knobs)
        for (double theta : thetas) {
            const BsdfUnderTest m = principledUnderTest(k, theta);
            char name[128];
            std::snprintf(name, sizeof name, "m %g r %g s %g sheen %g coat %g, theta %g",
                          k.metallic, k.roughness, k.specular, k.sheen, k.coat, theta);
            expectSamplingMatchesPdf(testSampling(m, principledLobes(m), 200000, 9100 + ++seed),
                                     tests, name);
        }
}

// Burley's diffuse alone (specular 0) seen from the normal: its albedo is
// c (1 - 1/42 + 5 r / 84), the integral of (1 - W(mu) / 2 + r (1 + mu) W(mu)) 2 mu over mu.
TEST(Principled, TheDiffuseAlbedoAtNormalIncidenceIsBurleysClosedForm) {
    for (float r : {0.2f, 0.9f}) {
        const BsdfUnderTest m = principledUnderTest({0.0f, r, 0.0f, 0.0f, 0.0f}, 0.0);
        const double mean = (kPrincipledBase.x + kPrincipledBase.y + kPrincipledBase.z) / 3.0;
        const double expected = mean * (1.0 - 1.0 / 42.0 + 5.0 * r / 84.0);
        const SamplingReport report = testSampling(m, principledLobes(m), 200000, 9200);
        EXPECT_NEAR(report.fcosIntegral, expected, 2e-3 * expected) << "roughness " << r;
        EXPECT_NEAR(report.meanWeight, expected, 4.0 * report.meanWeightError + 1e-4)
            << "roughness " << r;
    }
}

// A white metal's Fresnel is 1 (cspec0 = 1), and nothing else reflects (no diffuse, no sheen at
// metallic 1): the lobe is the Conductor's GGX of F0 = 1, direction by direction.
TEST(Principled, AWhiteMetalIsTheConductorsGgxLobe) {
    Uniform u(93);
    for (float r : {0.1f, 0.5f, 1.0f})
        for (double theta : {0.0, 45.0, 80.0}) {
            BsdfUnderTest m = principledUnderTest({1.0f, r, 0.5f, 1.0f, 0.0f}, theta, vec3(1.0f));
            ShaderParams conductor = shaderParams(kModelConductor, m.sh.alpha);
            for (int k = 0; k < 400; ++k) {
                const vec3 wi = glm::normalize(u.next3() - vec3(0.5f));
                float pdfA, pdfB;
                const vec3 a = bsdfEval(m.sh, m.albedo, m.ng, m.ns, m.wo, wi, pdfA);
                const vec3 b = bsdfEval(conductor, vec3(1.0f), m.ng, m.ns, m.wo, wi, pdfB);
                for (int c = 0; c < 3; ++c)
                    ASSERT_NEAR(a[c], b[c], 1e-5f * b[c] + 1e-12f)
                        << "roughness " << r << ", theta " << theta;
            }
        }
}

// The sheen alone (a black base, specular 0) seen from the normal: wi.h = sqrt((1 + mu) / 2), so
// the albedo is sheen colour x 2 pi int W(sqrt((1 + mu) / 2)) mu dmu, here by the midpoint rule.
// The sheen colour is (1 - tint) + tint x hue, the hue 1 where the base is black.
TEST(Principled, TheSheensAlbedoAtNormalIncidenceIsItsIntegral) {
    double integral = 0.0;
    const int n = 200000;
    for (int i = 0; i < n; ++i) {
        const double mu = (i + 0.5) / n;
        integral += std::pow(1.0 - std::sqrt((1.0 + mu) / 2.0), 5.0) * mu;
    }
    integral *= 2.0 * M_PI / n;
    const BsdfUnderTest m = principledUnderTest({0.0f, 0.5f, 0.0f, 0.8f, 0.0f}, 0.0, vec3(0.0f));
    const SamplingReport report = testSampling(m, principledLobes(m), 200000, 9300);
    EXPECT_NEAR(report.fcosIntegral, 0.8 * integral, 2e-3 * 0.8 * integral);
    EXPECT_NEAR(report.meanWeight, 0.8 * integral, 4.0 * report.meanWeightError + 1e-5);
}

// GTR1 is a distribution of normals: int D1(h) cos(theta_h) dh = 1 over the hemisphere, for
// narrow and wide coats; its sampler draws from D1 cos (the sampling test above checks the
// coat's pdf through the whole material).
TEST(Principled, GtrOneIsNormalised) {
    for (float alpha : {gltfAlpha(0.03f), 0.01f, 0.1f, 0.5f, 0.9f}) {
        // Substituting x = cos^2: int D1 cos 2 pi sin dtheta = pi int_0^1 D1(sqrt(x)) dx.
        double sum = 0.0;
        const int n = 2000000;
        for (int i = 0; i < n; ++i) {
            const double x = (i + 0.5) / n;
            const vec3 h(float(std::sqrt(1.0 - x)), 0.0f, float(std::sqrt(x)));
            sum += principledGtr1D(h, alpha);
        }
        EXPECT_NEAR(sum * M_PI / n, 1.0, 2e-3) << "alpha " << alpha;
    }
}

// The tints: the specular's F0 at tint 1 is 0.08 s times the base colour's hue by (0.3, 0.6, 0.1);
// the sheen's colour at tint 1 is the hue by Rec. 709's luminance; a metal's F0 is its colour.
TEST(Principled, TheTintsAreTheBaseColoursHue) {
    ShaderParams sh = shaderParams(kModelPrincipled, 0.25f);
    sh.specular = 0.5f;
    sh.specularTint = 1.0f;
    sh.sheen = 1.0f;
    sh.sheenTint = 1.0f;
    const vec3 c = kPrincipledBase;
    const vec3 hue = c / (0.3f * c.x + 0.6f * c.y + 0.1f * c.z);
    const vec3 f0 = principledSpecularF0(sh, c);
    const vec3 sheen = principledSheenColour(sh, c);
    const vec3 hue709 = c / (0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z);
    for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(f0[k], 0.04f * hue[k], 1e-6f);
        EXPECT_NEAR(sheen[k], hue709[k], 1e-6f);
    }
    sh.metallic = 1.0f;
    EXPECT_EQ(principledSpecularF0(sh, c), c);
    // Seen head on, the principled Fresnel is F0: the dielectric's FH is 0 there.
    EXPECT_NEAR(principledFresnel(vec3(0.04f), 0.5f, 1.0f).x, 0.04f, 1e-6f);
    EXPECT_NEAR(principledFresnel(vec3(0.04f), 0.5f, 0.0f).x, 1.0f, 1e-6f);
}

} // namespace
} // namespace spw::test
