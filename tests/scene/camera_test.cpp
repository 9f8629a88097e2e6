// Camera rays (host/scene/camera.h): the sorted backends make them a block at a time, SIMD-wide
// (generateMany); the reference one at a time (generate). Both must be the same rays to the bit,
// or the backends' images part.
#include "host/scene/camera.h"
#include "host/simd/simd_target.h"

#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <glm/gtc/matrix_transform.hpp>

#include <cstring>
#include <random>
#include <vector>

namespace spw {
namespace {

Scene cameraScene(CameraType type, SamplerType sampler, int width, int height) {
    Scene scene;
    scene.image.width = width;
    scene.image.height = height;
    scene.sampler = sampler;
    scene.camera.type = type;
    scene.camera.fovDegrees = 50.0f;
    scene.camera.apertureRadius = type == CameraType::ThinLens ? 0.37f : 0.0f;
    scene.camera.focalDistance = 6.5f;
    // An oblique camera, so that every term of the rotation is non-zero.
    scene.camera.cameraToWorld = glm::rotate(glm::rotate(mat4(1.0f), 0.7f, vec3(0.2f, 1.0f, 0.1f)),
                                             -0.4f, vec3(1.0f, 0.0f, 0.3f));
    return scene;
}

bool sameBits(vec3 a, vec3 b) {
    return std::memcmp(&a, &b, sizeof(vec3)) == 0;
}
bool sameBits(vec2 a, vec2 b) {
    return std::memcmp(&a, &b, sizeof(vec2)) == 0;
}

} // namespace

// Every sampler, both cameras, every instruction set, ragged block ends: the same origin,
// direction and film position as generate(). The image is 4096 pixels wide so that, over the
// right half's pixels, offsets within 2^-24 x of 1 occur and filmPosition's clamp into the pixel
// runs (counted: the test fails if no sample reached it).
TEST(CameraModel, GenerateManyIsGenerateToTheBit) {
    constexpr int kWidth = 4096, kHeight = 3, kBase = 4;
    std::mt19937 rng(5);
    const size_t n = 20011; // not a multiple of a block
    std::vector<uint> x(n), y(n), sample(n), sampleIndex(n);
    for (size_t i = 0; i < n; ++i) {
        x[i] = kWidth / 2 + uint(rng() % (kWidth / 2));
        y[i] = uint(rng() % kHeight);
        sample[i] = uint(rng() % (kBase * kBase));
        sampleIndex[i] = i % 5 == 0 ? sample[i] : uint(rng() % 100000);
    }
    size_t clamped = 0;
    for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
        hwy::SetSupportedTargetsForTest(target);
        SCOPED_TRACE(simdTarget());
        for (CameraType type : {CameraType::PinHole, CameraType::ThinLens})
            for (SamplerType sampler : {SamplerType::Independent, SamplerType::Grid,
                                        SamplerType::Stratified, SamplerType::Sobol}) {
                SCOPED_TRACE(samplerName(sampler));
                const Scene scene = cameraScene(type, sampler, kWidth, kHeight);
                const CameraModel camera(scene, kBase);
                std::vector<CameraRay> many(n);
                camera.generateMany(x.data(), y.data(), sample.data(), sampleIndex.data(), 77u, n,
                                    many.data());
                for (size_t i = 0; i < n; ++i) {
                    const CameraRay one =
                        camera.generate(x[i], y[i], sample[i], sampleIndex[i], 77u);
                    ASSERT_TRUE(sameBits(one.origin, many[i].origin)) << "ray " << i;
                    ASSERT_TRUE(sameBits(one.dir, many[i].dir)) << "ray " << i;
                    ASSERT_TRUE(sameBits(one.filmPos, many[i].filmPos)) << "ray " << i;
                    clamped += one.filmPos.x == std::nextafter(float(x[i] + 1u), 0.0f);
                }
            }
    }
    hwy::SetSupportedTargetsForTest(0);
    EXPECT_GT(clamped, 0u) << "no sample reached filmPosition's clamp into its pixel";
}

// Nothing to make: no rays, no call into the kernel.
TEST(CameraModel, GenerateManyOfNothingWritesNothing) {
    const Scene scene = cameraScene(CameraType::PinHole, SamplerType::Sobol, 8, 8);
    const CameraModel camera(scene, 1);
    CameraRay untouched{vec3(7.0f), vec3(7.0f), vec2(7.0f)};
    camera.generateMany(nullptr, nullptr, nullptr, nullptr, 1u, 0, &untouched);
    EXPECT_EQ(untouched.origin, vec3(7.0f));
}

} // namespace spw
