// Shading normals made valid before shading (facingShadingNormal, shared/sampling.h): a shading
// normal whose mirror reflection of wo would fall below the geometric surface is bent toward the
// geometric normal, in the plane of the two, just far enough; one that needs no bending is kept
// bit for bit; and no surface model then returns black for wo and wi above the surface where the
// unbent normal made it black. (Its SIMD twin is checked lane by lane in tests/simd.)
#include "bsdf_test_util.h"

#include "shared/bsdf.h"

#include <random>

namespace spw::test {
namespace {

vec3 randomDirection(std::mt19937& rng) {
    std::normal_distribution<float> g;
    return glm::normalize(vec3(g(rng), g(rng), g(rng)));
}

// dot(reflect(-wo about n), g): how far wo's mirror image about n points above the surface.
float reflectionHeight(vec3 n, vec3 g, vec3 wo) {
    return 2.0f * glm::dot(wo, n) * glm::dot(n, g) - glm::dot(wo, g);
}

TEST(ShadingNormal, BentJustEnoughInThePlaneOfTheNormalsAndKeptWhereValid) {
    std::mt19937 rng(7);
    int farSide = 0, kept = 0, bent = 0, geometric = 0;
    for (int i = 0; i < 200000; ++i) {
        const vec3 ns = randomDirection(rng), ng = randomDirection(rng), wo = randomDirection(rng);
        const vec3 n = facingShadingNormal(ns, ng, wo);
        const float side = glm::dot(ng, wo) >= 0.0f ? 1.0f : -1.0f;
        const vec3 g = ng * side, facing = ns * side;
        const float clearance = std::min(0.9f * glm::dot(wo, g), 0.01f);
        SCOPED_TRACE(i);
        ASSERT_NEAR(glm::length(n), 1.0f, 1e-5f);
        ASSERT_GT(glm::dot(n, g), 0.0f);
        ASSERT_GE(glm::dot(wo, n), 0.0f) << "wo below the shading hemisphere";
        if (!(glm::dot(facing, g) > 0.0f)) {
            ASSERT_EQ(n, g) << "a normal behind the surface is the geometric normal";
            ++farSide;
            continue;
        }
        if (reflectionHeight(facing, g, wo) >= clearance) {
            ASSERT_EQ(n, facing) << "a valid normal is returned unchanged";
            ++kept;
            continue;
        }
        if (n == g) {
            ++geometric;
            continue;
        }
        ++bent;
        // In the plane of the shading and geometric normals, turned toward the geometric one...
        ASSERT_NEAR(glm::dot(n, glm::normalize(glm::cross(facing, g))), 0.0f, 1e-4f);
        ASSERT_GT(glm::dot(n, g), glm::dot(facing, g));
        // ... just far enough: its reflection clears the surface by the clearance (at least 90 %
        // of it: a root of the squared equation may be taken within that), no more.
        ASSERT_GE(reflectionHeight(n, g, wo), 0.9f * clearance - 1e-6f);
        ASSERT_LE(reflectionHeight(n, g, wo), clearance + 1e-3f);
    }
    // Random directions: half the normals are behind the surface; of the others about a third
    // are kept, and nearly all the rest bent rather than dropped to the geometric normal.
    EXPECT_NEAR(farSide, 100000, 2000);
    EXPECT_GT(kept, 30000);
    EXPECT_GT(bent, 55000);
    EXPECT_LT(geometric, bent / 100) << kept << " kept, " << bent << " bent";
}

// wo grazing from -x over a shading normal tilted 53 degrees toward +x: wo is below the unbent
// normal's hemisphere, where every model but Lambert returned black. Bent, each reflects light
// arriving from above toward wo, on every rough surface model.
// A normal carried as two halves (a clear coat's, SurfaceHit::extension) through the octahedral
// map: in floats it comes back within rounding, in halves within 2e-3; the axes exactly.
TEST(ShadingNormal, TheOctahedralMapBringsANormalBack) {
    std::mt19937 rng(8);
    float worstFloat = 0.0f, worstHalf = 0.0f;
    for (int i = 0; i < 100000; ++i) {
        const vec3 n = randomDirection(rng);
        const vec2 p = octahedralEncode(n);
        ASSERT_LE(std::max(std::fabs(p.x), std::fabs(p.y)), 1.0f);
        worstFloat = std::max(worstFloat, glm::length(octahedralDecode(p) - n));
        const vec3 half = octahedralDecode(unpackHalf2x16(packHalf2x16(p)));
        worstHalf = std::max(worstHalf, glm::length(half - n));
    }
    EXPECT_LT(worstFloat, 1e-6f);
    EXPECT_LT(worstHalf, 2e-3f);
    for (int axis = 0; axis < 3; ++axis)
        for (float sign : {1.0f, -1.0f}) {
            vec3 n(0.0f);
            n[axis] = sign;
            EXPECT_EQ(octahedralDecode(unpackHalf2x16(packHalf2x16(octahedralEncode(n)))), n);
        }
}

TEST(ShadingNormal, NoSurfaceModelIsBlackWhereTheUnbentNormalTurnsAwayFromTheViewer) {
    const vec3 ng(0, 0, 1), ns = glm::normalize(vec3(0.8f, 0, 0.6f));
    const vec3 wo = glm::normalize(vec3(-0.9f, 0.1f, 0.3f));
    ASSERT_LT(glm::dot(wo, ns), 0.0f);
    const vec3 mirror = glm::normalize(2.0f * glm::dot(wo, ng) * ng - wo);
    for (uint model : {kModelLambert, kModelConductor, kModelDielectric, kModelMetallicRoughness}) {
        SCOPED_TRACE(model);
        ShaderParams sh = shaderParams(model, 0.3f);
        sh.metallic = 0.5f;
        double total = 0.0;
        // Light from around the mirror direction and straight above.
        for (const vec3 wi : {mirror, vec3(0, 0, 1), glm::normalize(mirror + vec3(0, 0, 1))}) {
            float pdf = 0.0f;
            const vec3 f = bsdfEval(sh, vec3(0.8f), ng, ns, wo, wi, pdf);
            ASSERT_TRUE(finiteNonNegative(f));
            total += f.x + f.y + f.z;
        }
        EXPECT_GT(total, 0.0);
    }
}

} // namespace
} // namespace spw::test
