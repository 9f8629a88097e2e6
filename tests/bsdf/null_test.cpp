// Null (shared/null.h): the model of emitter-only geometry scatters nothing, whatever the
// directions, the albedo and the parameters a shader of another model would carry.
#include "bsdf_test_util.h"

#include <random>

namespace spw::test {
namespace {

TEST(Null, ScattersAndSamplesNothing) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    auto direction = [&] {
        vec3 d;
        do
            d = vec3(2 * u(rng) - 1, 2 * u(rng) - 1, 2 * u(rng) - 1);
        while (glm::dot(d, d) > 1.0f || glm::dot(d, d) < 1e-4f);
        return glm::normalize(d);
    };
    for (float alpha : {0.0f, 0.3f}) {
        const ShaderParams sh = shaderParams(kModelNull, alpha, 1.5f);
        EXPECT_FALSE(bsdfIsDelta(sh)) << "alpha " << alpha;
        for (int i = 0; i < 10000; ++i) {
            const vec3 ng = direction(), wo = direction(), wi = direction();
            const vec3 albedo(u(rng), u(rng), u(rng));
            float pdf = -1.0f;
            EXPECT_EQ(bsdfEval(sh, albedo, ng, ng, wo, wi, pdf), vec3(0.0f));
            EXPECT_EQ(pdf, 0.0f);
            vec3 sampled, weight;
            bool specular = true;
            EXPECT_FALSE(bsdfSample(sh, albedo, ng, ng, wo, vec3(u(rng), u(rng), u(rng)), sampled,
                                    weight, pdf, specular));
            EXPECT_EQ(weight, vec3(0.0f));
            EXPECT_EQ(pdf, 0.0f);
            EXPECT_FALSE(specular);
        }
    }
}

} // namespace
} // namespace spw::test
