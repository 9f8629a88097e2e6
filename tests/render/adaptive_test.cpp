// Adaptive sampling (host/image/film.h): unbiased on closed forms, fewer samples where the image
// is flat than at edges, and the same decisions for any thread count and on every backend.
#include "host/loaders/scene_loader.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

namespace spw::test {
namespace {

std::string enclosure(TempDir& dir) {
    dir.write("cube.obj", insideCubeObj());
    return dir.write(
        "e.yaml", "image: {width: 32, height: 32, sample base: 1, iterations: 64}\n"
                  "settings: {max depth: 64, adaptive threshold: 0.03, adaptive min samples: 8}\n"
                  "camera: {look at: {eye: [0, 0, 0], target: [0.3, 0.2, -1]}, fov: 100}\n"
                  "object: {filename: cube.obj, shader: 0}\n"
                  "shader: {type: Lambert, reflectance: 0.5, emission: [1, 1, 1]}\n");
}

// The image mean and its standard error from the film's two half buffers: each pixel's
// (A - B)^2 / 4 estimates the variance of its mean, whatever number of samples it took.
MeanError halfBufferMean(const Film& film) {
    const std::vector<float> img = film.image(), a = film.halfImage(0), b = film.halfImage(1);
    double sum = 0, var = 0;
    const size_t n = img.size() / 3;
    for (size_t i = 0; i < n; ++i) {
        double m = 0, d = 0;
        for (int c = 0; c < 3; ++c)
            m += img[i * 3 + size_t(c)] / 3.0,
                d += (a[i * 3 + size_t(c)] - b[i * 3 + size_t(c)]) / 3.0;
        sum += m;
        var += d * d / 4.0;
    }
    return {sum / double(n), std::sqrt(var) / double(n)};
}

// Inside a closed cube of albedo a and emission Le every pixel is Le / (1 - a) = 2: stopping
// tiles early must not move the mean. And the tiles do stop: fewer samples than 64 spp.
TEST(Adaptive, EnclosureMeanIsLeOverOneMinusAlbedo) {
    TempDir dir;
    const Scene scene = loadScene(enclosure(dir));
    for (BackendKind b : {BackendKind::Reference, BackendKind::Cpu}) {
        RenderConfig cfg;
        cfg.backend = b;
        auto result = render(scene, cfg);
        const MeanError m = halfBufferMean(*result->film);
        const std::uint64_t taken = result->film->samplesTaken();
        std::printf("%s: mean %.5f +- %.5f, %llu of %d samples\n", backendName(b), m.mean,
                    m.stderror, (unsigned long long)taken, 32 * 32 * 64);
        EXPECT_NEAR(m.mean, 2.0, 4.0 * m.stderror);
        EXPECT_LT(taken, std::uint64_t(32 * 32 * 64) * 3 / 4) << "adaptive sampling never stopped";
        EXPECT_GE(taken, std::uint64_t(32 * 32 * 8));
        EXPECT_EQ(result->stats.extra["samples_taken"].get<std::uint64_t>(), taken);
    }
}

// A Lambert floor under a quad light, direct light only: the image mean against the closed
// form (each pixel's polygon irradiance at its centre, the Grid sampler), within standard errors.
TEST(Adaptive, QuadLightIrradianceIsUnbiased) {
    TempDir dir;
    const Scene scene =
        floorUnderLight(dir, 256, "max depth: 1, adaptive threshold: 0.02", kQuadOverFloor);
    // The same scene without adaptive sampling, many samples: its mean is the closed form's to
    // well within this test's errors (QuadLight.PixelsMatchPolygonIrradiance).
    Scene full = scene;
    full.settings.adaptiveThreshold = 0.0;
    full.image.iterations = 1024;
    const MeanError truth = halfBufferMean(*render(full, RenderConfig{})->film);
    auto result = render(scene, RenderConfig{});
    const MeanError m = halfBufferMean(*result->film);
    std::printf("adaptive: mean %.5f +- %.5f, %llu samples; full: %.5f +- %.5f\n", m.mean,
                m.stderror, (unsigned long long)result->film->samplesTaken(), truth.mean,
                truth.stderror);
    EXPECT_NEAR(m.mean, truth.mean, 4.0 * std::hypot(m.stderror, truth.stderror));
    EXPECT_LT(result->film->samplesTaken(), std::uint64_t(16 * 16 * 256));
}

// An emissive cube against a constant sky: camera rays see exact values on either, so tiles of
// sky or of the cube's face stop at the minimum, and tiles on the silhouette, whose pixels mix
// sky and cube, keep sampling.
TEST(Adaptive, FlatRegionsTakeFewerSamplesThanEdges) {
    TempDir dir;
    dir.write("cube.obj", "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\n"
                          "v -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
                          "f 4 3 2 1\nf 6 7 8 5\nf 5 8 4 1\nf 3 7 6 2\nf 2 6 5 1\nf 8 7 3 4\n");
    Scene scene = loadScene(
        dir.write("s.yaml", "image: {width: 64, height: 64, sample base: 1, iterations: 128}\n"
                            "settings: {max depth: 4, adaptive threshold: 0.03, "
                            "adaptive min samples: 8}\n"
                            "camera: {look at: {eye: [0, 0, 6], target: [0, 0, 0]}, fov: 40}\n"
                            "sampler: {type: Independent}\n"
                            "object: {filename: cube.obj, shader: 0}\n"
                            "shader: {type: Emissive, emission: [0.2, 0.2, 0.2]}\n"
                            "light: {type: Environment, colour: [1, 1, 1]}\n"));
    auto result = render(scene, RenderConfig{});
    const std::vector<std::uint32_t>& n = result->film->sampleCounts();
    // The cube's front face spans pixels 14.4 .. 49.6 (half-width 1 at distance 5, a 40-degree
    // field of view): a sky pixel, one on the left silhouette, one inside the face.
    const std::uint32_t sky = n[size_t(2 * 64 + 2)], edge = n[size_t(32 * 64 + 14)],
                        face = n[size_t(32 * 64 + 32)];
    std::printf("samples: sky %u, silhouette %u, face %u\n", sky, edge, face);
    EXPECT_EQ(sky, 8u);
    EXPECT_EQ(face, 8u);
    EXPECT_GT(edge, 2 * sky);
    // Every tile converged before 128 spp: the render stopped there.
    EXPECT_EQ(result->stats.extra["stop_reason"], "adaptive");
}

// Decisions read only the film after whole iterations: the image and the sample counts are the
// same bit for bit for 1 or 2 threads and, with full-precision rays, on cpu and reference.
TEST(Adaptive, DecisionsAreTheSameForAnyThreadCountAndBackend) {
    TempDir dir;
    Scene scene = loadScene(enclosure(dir));
    scene.sampler = SamplerType::Sobol;
    std::vector<std::vector<float>> images;
    std::vector<std::vector<std::uint32_t>> counts;
    for (int variant = 0; variant < 3; ++variant) {
        RenderConfig cfg;
        cfg.backend = variant == 2 ? BackendKind::Reference : BackendKind::Cpu;
        cfg.threads = variant == 0 ? 1 : 2;
        cfg.pipeline.rayFormat = RayFormat::Full;
        auto result = render(scene, cfg);
        images.push_back(result->film->image());
        counts.push_back(result->film->sampleCounts());
    }
    for (int v = 1; v < 3; ++v) {
        EXPECT_EQ(counts[size_t(v)], counts[0]) << "variant " << v;
        EXPECT_EQ(std::memcmp(images[size_t(v)].data(), images[0].data(),
                              images[0].size() * sizeof(float)),
                  0)
            << "variant " << v;
    }
}

// Toward a target error (--target-error, Film::setAdaptiveTarget) the tiles share the samples in
// proportion to their noise. Where the noise is even (the enclosure: every pixel the same
// integral) that is uniform sampling: the render takes no more samples than uniform sampling to
// the same target, within 5 %, and its mean stays Le / (1 - a). Where it is uneven (a cube
// against a constant sky: exact values but on the silhouette) the flat tiles rest at the
// minimum and the render reaches the target on fewer than half the samples of uniform sampling.
// Both means agree with uniform sampling's within 4 standard errors. (The target is the
// subject's, the silhouette's pixels: 1e-3 there is about 3e-5 over the whole frame. Much
// further, 3e-4, and the means part by 6 standard errors: a silhouette tile whose 8 minimum
// samples all fell on one side reads flat and rests, a bias adaptive sampling has at any target,
// which the longer render's smaller standard error shows.)
TEST(Adaptive, TowardATargetTheTilesShareTheSamplesByTheirNoise) {
    TempDir dir;
    Scene even = loadScene(enclosure(dir));
    even.settings.adaptiveThreshold = 0.0;
    even.image.iterations = 512;
    dir.write("cube.obj", "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\n"
                          "v -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
                          "f 4 3 2 1\nf 6 7 8 5\nf 5 8 4 1\nf 3 7 6 2\nf 2 6 5 1\nf 8 7 3 4\n");
    Scene uneven = loadScene(
        dir.write("s.yaml", "image: {width: 64, height: 64, sample base: 1, iterations: 512}\n"
                            "settings: {max depth: 4, adaptive min samples: 8}\n"
                            "camera: {look at: {eye: [0, 0, 6], target: [0, 0, 0]}, fov: 40}\n"
                            "object: {filename: cube.obj, shader: 0}\n"
                            "shader: {type: Emissive, emission: [0.2, 0.2, 0.2]}\n"
                            "light: {type: Environment, colour: [1, 1, 1]}\n"));
    for (auto [scene, target] : {std::pair(&even, 2e-4), std::pair(&uneven, 1e-3)}) {
        std::uint64_t taken[2];
        MeanError means[2];
        for (bool adaptive : {false, true}) {
            RenderConfig cfg;
            cfg.targetError = target;
            cfg.adaptiveToTarget = adaptive;
            auto result = render(*scene, cfg);
            taken[adaptive] = result->film->samplesTaken();
            const MeanError m = means[adaptive] = halfBufferMean(*result->film);
            std::printf("%s, %s: %llu samples, stop: %s, estimate %.3g, mean %.5f +- %.5f\n",
                        scene == &even ? "even" : "uneven", adaptive ? "adaptive" : "uniform",
                        (unsigned long long)taken[adaptive],
                        result->stats.extra["stop_reason"].get<std::string>().c_str(),
                        result->film->halfBufferRelMse(), m.mean, m.stderror);
            EXPECT_EQ(result->stats.extra["stop_reason"], "target error");
            if (scene == &even) {
                EXPECT_NEAR(m.mean, 2.0, 4.0 * m.stderror);
            }
        }
        EXPECT_NEAR(means[1].mean, means[0].mean,
                    4.0 * std::hypot(means[0].stderror, means[1].stderror));
        if (scene == &even)
            EXPECT_LE(taken[1], taken[0] * 105 / 100);
        else
            EXPECT_LT(taken[1], taken[0] / 2);
    }
}

// A small subject in a large flat frame reaches the target on itself: scenes/small-subject.yaml
// (a box on a floor, 5 % of a black frame) stopped by --target-error 2e-3, uniform and adaptive.
// Against a 2048-spp render, the true relMSE over the pixels it shows lit is the target's
// within a factor of 2, and over the whole frame far below it: the stop read the subject's
// error, not the frame's mean (which stopped at 26 spp, the subject's error then 0.036).
TEST(Adaptive, ASmallSubjectReachesTheTargetOnItself) {
    Scene scene = loadScene(sourceDir() + "/scenes/small-subject.yaml");
    RenderConfig ref;
    ref.backend = BackendKind::Cpu;
    ref.spp = 2048;
    Scene refScene = scene;
    refScene.settings.seed = 1000;
    const std::vector<float> truth = render(refScene, ref)->film->image();
    const double target = 2e-3;
    for (bool adaptive : {false, true}) {
        RenderConfig cfg;
        cfg.backend = BackendKind::Cpu;
        cfg.spp = 4096;
        cfg.targetError = target;
        cfg.adaptiveToTarget = adaptive;
        const auto result = render(scene, cfg);
        const std::vector<float> image = result->film->image();
        double subject = 0.0, whole = 0.0;
        size_t lit = 0;
        for (size_t p = 0; p < truth.size() / 3; ++p) {
            double term = 0.0;
            for (int c = 0; c < 3; ++c) {
                const double a = image[p * 3 + c], b = truth[p * 3 + c];
                term += (a - b) * (a - b) / (b * b + 0.01);
            }
            whole += term;
            if (truth[p * 3] + truth[p * 3 + 1] + truth[p * 3 + 2] > 0.0f) subject += term, ++lit;
        }
        subject /= double(lit) * 3.0;
        whole /= double(truth.size());
        SCOPED_TRACE(adaptive ? "adaptive" : "uniform");
        EXPECT_EQ(result->stats.extra["stop_reason"], "target error");
        const double fraction = result->stats.extra["target_error"]["subject_fraction"];
        EXPECT_LT(fraction, 0.1);
        EXPECT_NEAR(fraction, double(lit) / double(truth.size() / 3), 0.02);
        EXPECT_GT(subject, target / 2.0);
        EXPECT_LT(subject, target * 2.0);
        EXPECT_LT(whole, target * 0.2);
    }
}

} // namespace
} // namespace spw::test
