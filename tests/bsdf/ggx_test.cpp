// The GGX distribution itself (shared/ggx.h), by quadrature: projected microfacet area is 1, the
// visible normal density integrates to 1, and both stay finite down to the smooth threshold.
#include "bsdf_test_util.h"

namespace spw::test {
namespace {

TEST(Ggx, ProjectedAreaAndVisibleNormalsIntegrateToOne) {
    for (float alpha : {kGgxSmoothAlpha, 1e-3f, 1e-2f, 0.1f, 0.5f, 1.0f}) {
        // Cells following the lobe around the normal.
        HemisphereGrid grid(vec3(0, 0, 1), vec3(0, 0, 1), std::max(double(alpha), 1e-4), 32, 16);
        double projected = 0;
        for (glm::dvec2 v :
             grid.integrate([&](vec3 h) { return glm::dvec2(double(ggxD(h, alpha)) * h.z, 0.0); }))
            projected += v.x;
        EXPECT_NEAR(projected, 1.0, 1e-4) << "alpha " << alpha;
        for (double theta : {0.0, 45.0, 80.0, 89.9}) {
            const vec3 wo = directionAround(vec3(0, 0, 1), theta, 0.3);
            double visible = 0;
            for (glm::dvec2 v : grid.integrate(
                     [&](vec3 h) { return glm::dvec2(ggxVisibleNormalPdf(wo, h, alpha), 0.0); }))
                visible += v.x;
            EXPECT_NEAR(visible, 1.0, 2e-4) << "alpha " << alpha << ", theta " << theta;
        }
    }
}

TEST(Ggx, SmoothThresholdAndFiniteness) {
    EXPECT_TRUE(ggxIsSmooth(0.0f));
    EXPECT_TRUE(ggxIsSmooth(0.99f * kGgxSmoothAlpha));
    EXPECT_TRUE(ggxIsSmooth(std::nanf("")));
    EXPECT_FALSE(ggxIsSmooth(kGgxSmoothAlpha));
    const float a = kGgxSmoothAlpha;
    EXPECT_TRUE(std::isfinite(ggxD(vec3(0, 0, 1), a)));
    EXPECT_NEAR(ggxD(vec3(0, 0, 1), a), 1.0 / (M_PI * a * a), 1e-3 / (M_PI * a * a));
    EXPECT_EQ(ggxD(vec3(1, 0, 0), a), 0.0f);
    EXPECT_NEAR(ggxD(glm::normalize(vec3(1, 0, 1e-3f)), a), a * a / M_PI, 1e-3 * a * a);
    EXPECT_EQ(ggxG1(vec3(1, 0, 0), a), 0.0f);
    EXPECT_EQ(ggxG1(vec3(0, 0, 1), a), 1.0f);
    EXPECT_EQ(ggxG2Denominator(vec3(1, 0, 0), vec3(0, 1, 0), a), 0.0f);
    // Sampled normals are unit and face wo for every wo, including the horizon.
    Uniform u(3);
    for (double theta : {0.0, 60.0, 89.999, 90.0})
        for (int k = 0; k < 1000; ++k) {
            const vec3 wo = directionAround(vec3(0, 0, 1), theta, 1.0);
            const vec3 h = ggxSampleVisibleNormal(wo, a, vec2(u.next(), u.next()));
            ASSERT_NEAR(glm::length(h), 1.0f, 1e-5f);
            ASSERT_GE(h.z, 0.0f);
            ASSERT_GE(glm::dot(wo, h), -1e-6f);
        }
}

} // namespace
} // namespace spw::test
