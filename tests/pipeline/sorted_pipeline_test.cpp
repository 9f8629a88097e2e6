// The sorted deferred pipeline (--backend cpu): it must render the reference's image, whatever
// its batching, sorting, memory budget and thread count, and it must clean up after itself.
#include "host/loaders/scene_loader.h"
#include "host/pipeline/ray_record.h"
#include "test_util.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sys/inotify.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

namespace spw::test {
namespace {

Scene smallCornell(int size) {
    Scene scene = loadScene(sourceDir() + "/scenes/cornell-box.yaml");
    scene.image.width = scene.image.height = size;
    return scene;
}

std::vector<float> renderImage(const Scene& scene, RenderConfig cfg) {
    return render(scene, cfg)->film->image();
}

bool sameBits(const std::vector<float>& a, const std::vector<float>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

// With full-precision rays the sorted pipeline traces exactly the reference's paths with the
// same random numbers, and the fixed-point film makes the sums order-independent: the images
// are identical, not merely close. The Cornell box (Lambert, Stratified, Box filter) and a
// scene with every surface model, a Layered image texture, a Gaussian filter and a thin lens,
// each also with the Sobol sampler.
TEST(SortedPipeline, FullPrecisionRaysGiveTheReferenceImageBitForBit) {
    // scenes/every-model.yaml at 24 x 24 (8 spp below).
    Scene everyModel = loadScene(sourceDir() + "/scenes/every-model.yaml");
    everyModel.image.width = everyModel.image.height = 24;
    // A 16384 x 4 strip at 4 spp: a sample whose offset in its pixel is within half an ulp of
    // 1 rounds to the next pixel's edge (float(x) + offset == x + 1) about 2^-24 x of the time,
    // some fifty times here; the reference once splatted those into the next pixel.
    Scene strip = smallCornell(4);
    strip.image.width = 16384;
    strip.settings.maxDepth = 2;
    Scene sobolCornell = smallCornell(40), sobolEveryModel = everyModel;
    sobolCornell.sampler = sobolEveryModel.sampler = SamplerType::Sobol;
    for (const Scene& scene :
         {smallCornell(40), everyModel, strip, sobolCornell, sobolEveryModel}) {
        RenderConfig ref;
        ref.backend = BackendKind::Reference;
        ref.spp = 8;
        RenderConfig cpu = ref;
        cpu.backend = BackendKind::Cpu;
        cpu.pipeline.rayFormat = RayFormat::Full;
        Scene binned = scene; // small batches: many of them
        binned.settings.binExponent = 10;
        const std::vector<float> a = renderImage(scene, ref), b = renderImage(binned, cpu);
        EXPECT_GT(mean(a), 0.0);
        EXPECT_TRUE(sameBits(a, b)) << scene.file;
    }
}

// Camera rays are made when their batch is traced, never stored: with compact rays their
// directions are still the camera's own, to the bit. At max depth 1 with light sampling alone,
// everything the image holds comes from camera hits (what they see emitted, and their one
// next-event sample), so it equals the reference's bit for bit; bounce rays still travel as
// compact records and hit the box, but add nothing.
TEST(SortedPipeline, CompactCameraRaysAreTheReferencesToTheBit) {
    Scene scene = smallCornell(40);
    scene.settings.maxDepth = 1;
    RenderConfig ref;
    ref.backend = BackendKind::Reference;
    ref.spp = 8;
    ref.strategy = kStrategyLight;
    RenderConfig cpu = ref;
    cpu.backend = BackendKind::Cpu;
    Scene binned = scene;
    binned.settings.binExponent = 10;
    auto result = render(binned, cpu);
    EXPECT_EQ(result->stats.extra["ray_format"], "compact");
    EXPECT_GT(result->stats.bounceRays.load(), 40u * 40u * 8u / 2u);
    const std::vector<float> a = renderImage(scene, ref);
    EXPECT_GT(mean(a), 0.0);
    EXPECT_TRUE(sameBits(a, result->film->image()));
}

// Compact rays (32 bytes: octahedral direction, stochastically rounded bfloat16 throughput)
// against the reference. Both renders use the same seed, so they trace nearly the same paths:
// the per-iteration difference of their images is tiny except where rounding turns a path, and
// it must have mean zero within its own standard error (a bias far below either render's noise
// fails: the test fails with a 0.5 % scale on the compact throughput).
void expectAgreesWithReference(const Scene& scene, int iterations, const std::string& what) {
    RenderConfig ref;
    ref.backend = BackendKind::Reference;
    ref.spp = iterations * scene.image.samplesPerIteration();
    RenderConfig cpu = ref;
    cpu.backend = BackendKind::Cpu;
    Scene binned = scene;
    binned.settings.binExponent = 10;
    expectNoPairedDifference(
        pairedDifference(iterationImages(binned, cpu), iterationImages(scene, ref)),
        scene.image.width, scene.image.height, what);
}

TEST(SortedPipeline, CompactRaysAgreeWithReferenceOnCornellBox) {
    Scene scene = smallCornell(32);
    scene.image.sampleBase = 1;
    expectAgreesWithReference(scene, 32, "Cornell box");
}

TEST(SortedPipeline, CompactRaysAgreeWithReferenceOnClosedEnclosure) {
    TempDir dir;
    dir.write("cube.obj", insideCubeObj());
    Scene scene = loadScene(dir.write(
        "e.yaml", "image: {width: 16, height: 16, sample base: 1, iterations: 1}\n"
                  "settings: {max depth: 300}\n"
                  "camera: {look at: {eye: [0, 0, 0], target: [0.3, 0.2, -1]}, fov: 100}\n"
                  "object: {filename: cube.obj, shader: 0}\n"
                  "shader: {type: Lambert, reflectance: 0.8, emission: [1, 1, 1]}\n"));
    expectAgreesWithReference(scene, 32, "closed enclosure");
    // And the cpu backend alone against the closed form Le / (1 - a) = 5.
    RenderConfig cpu;
    cpu.spp = 64;
    MeanError m = meanAndError(renderImage(scene, cpu));
    EXPECT_NEAR(m.mean, 5.0, 4.0 * m.stderror);
}

// The film must not depend on how rays were batched, sorted, spilled or scheduled, nor on
// whether the per-hit stages ran fused or one after another, nor on whether the hits were shaded
// SIMD-wide or one at a time (the box is all Lambert, which has a SIMD twin). The Cornell
// box at max depth 16: bounce rays go through the bins, the queue and (with a small budget) the
// spill file and back many times, so a read-back that corrupted one bit would change the image.
TEST(SortedPipeline, ImageIsIndependentOfBatchingSortingBudgetAndThreads) {
    Scene scene = smallCornell(40);
    ASSERT_GE(scene.settings.maxDepth, 8);
    RenderConfig base;
    base.spp = 8;
    base.threads = 1;
    scene.settings.binExponent = 12;
    const std::vector<float> expected = renderImage(scene, base);
    // Returns the batches spilled. `change` edits the configuration, or the scene's settings.
    auto variant = [&](const char* what, auto change) {
        RenderConfig cfg = base;
        Scene changed = scene;
        if constexpr (std::is_invocable_v<decltype(change), RenderConfig&>)
            change(cfg);
        else
            change(changed.settings, cfg);
        auto result = render(changed, cfg);
        EXPECT_TRUE(sameBits(expected, result->film->image())) << what;
        return long(result->stats.spill->batchesSpilled);
    };
    EXPECT_EQ(variant("the same again", [](RenderConfig&) {}), 0);
    EXPECT_NE(render(scene, base)->stats.extra["simd_shading"], "off");
    variant("bin exponent 8", [](Settings& s, RenderConfig&) { s.binExponent = 8; });
    variant("bin exponent 16", [](Settings& s, RenderConfig&) { s.binExponent = 16; });
    variant("2 threads", [](RenderConfig& c) { c.threads = 2; });
    // 64 KiB: less than six 2^12-ray batches (768 KiB), so every batch goes through the disk.
    EXPECT_GT(
        variant("64 KiB budget", [](Settings& s, RenderConfig&) { s.memoryBudgetMiB = 1.0 / 16; }),
        0);
    EXPECT_EQ(
        variant("1 GiB budget", [](Settings& s, RenderConfig&) { s.memoryBudgetMiB = 1024.0; }), 0);
    // 32 KiB: less than six 2^8-ray batches (52 KiB).
    EXPECT_GT(variant("32 KiB budget, 2 threads, exponent 8",
                      [](Settings& s, RenderConfig& c) {
                          s.memoryBudgetMiB = 1.0 / 32;
                          c.threads = 2;
                          s.binExponent = 8;
                      }),
              100);
    variant("morton ray sort", [](RenderConfig& c) { c.pipeline.raySort = RaySortMode::Morton; });
    variant("median ray sort", [](RenderConfig& c) { c.pipeline.raySort = RaySortMode::Median; });
    variant("no ray sort", [](RenderConfig& c) { c.pipeline.raySort = RaySortMode::Off; });
    variant("no hit sort", [](RenderConfig& c) { c.pipeline.hitSort = HitSortMode::Off; });
    variant("hit sort on", [](RenderConfig& c) { c.pipeline.hitSort = HitSortMode::On; });
    // The per-hit stages one whole batch after another instead of fused chunk by chunk.
    variant("separate stages", [](RenderConfig& c) { c.pipeline.fuseStages = false; });
    variant("separate stages, 2 threads, hit sort on", [](RenderConfig& c) {
        c.pipeline.fuseStages = false;
        c.threads = 2;
        c.pipeline.hitSort = HitSortMode::On;
    });
    // shadeSurface() hit by hit instead of the SIMD kernels.
    variant("scalar shading", [](RenderConfig& c) { c.pipeline.simdShading = false; });
    variant("scalar shading, separate stages", [](RenderConfig& c) {
        c.pipeline.simdShading = false;
        c.pipeline.fuseStages = false;
    });
}

// The hit sort's auto rule: the cpu engine sorts hits only where the scene has image textures
// (coherent tile reads), by shader alone unless the images outgrow the tile cache; asked for, it
// always sorts, by the whole key; and the image is the same either way.
TEST(SortedPipeline, HitSortAutoSortsForTexturesOnlyAndByTextureOrderForABusyCache) {
    Scene plain = smallCornell(16);
    Scene textured = loadScene(sourceDir() + "/scenes/every-model.yaml");
    textured.image.width = textured.image.height = 16;
    RenderConfig cfg;
    cfg.spp = 4;
    RenderConfig on = cfg;
    on.pipeline.hitSort = HitSortMode::On;
    auto r = render(plain, cfg), rOn = render(plain, on);
    EXPECT_EQ(r->stats.extra["hit_sort"], false);
    EXPECT_EQ(r->stats.extra["hit_order"], "as traced"); // no environment: misses left in place
    EXPECT_EQ(rOn->stats.extra["hit_sort"], true);
    EXPECT_TRUE(sameBits(r->film->image(), rOn->film->image()));
    const std::string whole = "shader, object, texture order";
    const auto t = render(textured, cfg), tOn = render(textured, on);
    EXPECT_EQ(t->stats.extra["hit_sort"], true);
    EXPECT_EQ(t->stats.extra["hit_sort_key"], "shader");
    EXPECT_EQ(tOn->stats.extra["hit_sort_key"], whole);
    EXPECT_TRUE(sameBits(t->film->image(), tOn->film->image()));
    // Its images a 1024^2 RGB one (4 MB with its levels) over a 1 MiB cache.
    TempDir dir;
    OIIO::ImageBuf big(OIIO::ImageSpec(1024, 1024, 3, OIIO::TypeDesc::UINT8));
    const float grey[3] = {0.5f, 0.5f, 0.5f};
    OIIO::ImageBufAlgo::fill(big, grey);
    ASSERT_TRUE(big.write(dir.file("big.png")));
    Scene cramped = textured;
    for (Texture& tex : cramped.textures)
        if (tex.type == TextureType::Standard) tex.path = dir.file("big.png");
    cramped.settings.textureCacheMiB = 1.0;
    EXPECT_EQ(render(cramped, cfg)->stats.extra["hit_sort_key"], whole);
}

// The thesis's known crash: a tile's buffer (64 x 64 pixels x 64 samples = 262144 rays) far
// larger than a batch (2^8 rays). It must simply become many batches.
TEST(SortedPipeline, ThreadBufferLargerThanABatch) {
    Scene scene = smallCornell(64);
    scene.settings.bucketSize = 64;
    scene.image.sampleBase = 8;
    scene.image.iterations = 1;
    scene.settings.maxDepth = 2;
    scene.settings.binExponent = 8;
    auto result = render(scene, RenderConfig{});
    Scene large = scene;
    large.settings.binExponent = 16;
    EXPECT_TRUE(sameBits(result->film->image(), renderImage(large, RenderConfig{})));
    EXPECT_GE(result->stats.spill->batchesProcessed, 64u * 64u * 64u / 256u);
}

// A scene whose single iteration holds 256 x 256 x 64 = 4M camera rays, 128 MiB as compact
// records, and 2.6 M bounce rays (88 MB). max depth 1 keeps the test fast: one bounce, no shading
// after it. Its batches are 2^12 rays: six of them (816 KiB) exceed a budget of 0.5 MiB, so with
// that budget every batch that is queued spills.
std::string heavyScene(const TempDir& dir) {
    const std::string box = sourceDir() + "/scenes/cornell-box/";
    return dir.write(
        "heavy.yaml",
        "image: {width: 256, height: 256, sample base: 8, iterations: 1}\n"
        "settings: {max depth: 1, bin exponent: 12}\n"
        "camera: {look at: {eye: [278, 273, -800], target: [278, 273, 0]}, fov: 39.3}\n"
        "shader: {type: Lambert}\n"
        "object: {filename: " +
            box +
            "white.obj, shader: 0}\n"
            "object: {filename: " +
            box +
            "blocks.obj, shader: 0}\n"
            "light: {type: Quad, translation: [278, 548.7, 279.5], rotation: [90, 0, 0], scale: "
            "[130, 105], intensity: 10}\n");
}
constexpr long kHeavyBatchBytes = (1L << 12) * long(kCompactRayBytes);

TEST(Spill, SmallBudgetSpillsReadsBackAndBoundsMemory) {
    TempDir dir, spill;
    const std::string scene = heavyScene(dir);
    // --backend cpu in all three: `auto` probes Vulkan, and the suite runs it under the validation
    // layer, whose memory varies from run to run by more than this test's margins.
    auto run = [&](const char* budget, const std::string& stats) {
        return runChild({"render", scene, "-o", dir.file("o.exr"), "--quiet", "--backend", "cpu",
                         "--memory-budget", budget, "--spill-dir", spill.path(), "--stats", stats});
    };
    // The process's own baseline (libraries, Embree and TBB start-up): an 8 x 8 pixel render.
    ChildResult tiny = runChild({"render", dir.write("tiny.yaml", "image: {width: 8, height: 8}\n"),
                                 "-o", dir.file("t.exr"), "--quiet", "--backend", "cpu"});
    ASSERT_EQ(tiny.status, 0) << tiny.output;
    ChildResult big = run("1024", dir.file("big.json"));
    ChildResult small = run("0.5", dir.file("small.json"));
    ASSERT_EQ(big.status, 0) << big.output;
    ASSERT_EQ(small.status, 0) << small.output;
    nlohmann::json s = nlohmann::json::parse(std::ifstream(dir.file("small.json")));
    nlohmann::json b = nlohmann::json::parse(std::ifstream(dir.file("big.json")));
    // Below six batches the queue keeps nothing in RAM: every bounce ray goes through the disk,
    // and every one comes back. Camera rays are made a batch at a time and never spill.
    const long bounce = s["rays"]["bounce"].get<long>();
    EXPECT_GT(bounce, 2000000);
    EXPECT_EQ(s["batches_spilled"], s["batches_queued"]);
    EXPECT_EQ(s["bytes_spilled_written"].get<long>(), bounce * long(kCompactRayBytes));
    EXPECT_EQ(s["bytes_spilled_read"], s["bytes_spilled_written"]);
    EXPECT_EQ(b["batches_spilled"].get<long>(), 0);
    EXPECT_EQ(b["rays"], s["rays"]);
    // Rays in RAM, bins and queue together: within six batches with the small budget (the bins'
    // share); and with 1 GiB, whose queue could hold the whole iteration, under seven batches,
    // because new camera rays are made only when the queue is empty.
    EXPECT_LE(s["peak_ray_bytes_in_ram"].get<long>(), 6 * kHeavyBatchBytes);
    EXPECT_LT(b["peak_ray_bytes_in_ram"].get<long>(), 7 * kHeavyBatchBytes);
    std::printf("peak RSS: baseline %ld MiB, %ld MiB with a 0.5 MiB budget, %ld MiB with 1 GiB\n",
                tiny.maxRssKiB / 1024, small.maxRssKiB / 1024, big.maxRssKiB / 1024);
    // The stated bound, whatever the budget: peak RSS within baseline + budget + 32 MiB (bins,
    // one batch in flight with its hits and shading records, the prefetched batch, the film),
    // where holding the iteration's camera rays alone would take 128 MiB.
    if (!kAddressSanitizer) {
        EXPECT_LE(small.maxRssKiB, tiny.maxRssKiB + 512 + 32 * 1024);
        EXPECT_LE(big.maxRssKiB, tiny.maxRssKiB + 32 * 1024);
    }
    EXPECT_EQ(filesIn(spill.path()), 0u);
}

TEST(Spill, NoFileLeftAfterNormalRunErrorOrAnySignal) {
    TempDir dir, spill;
    const std::string scene = heavyScene(dir);
    std::vector<std::string> args = {"render", scene,         "--quiet",   "--memory-budget",
                                     "0.5",    "--spill-dir", spill.path()};

    std::vector<std::string> ok = args;
    ok.insert(ok.end(), {"-o", dir.file("ok.exr")});
    EXPECT_EQ(runChild(ok).status, 0);
    EXPECT_EQ(filesIn(spill.path()), 0u);

    // An error after spilling: the image goes to a full device, found when it is written.
    std::filesystem::create_symlink("/dev/full", dir.file("full.exr"));
    std::vector<std::string> bad = args;
    bad.insert(bad.end(), {"-o", dir.file("full.exr"), "--stats", dir.file("full.json")});
    ChildResult err = runChild(bad);
    EXPECT_EQ(err.status, 1) << err.output;
    EXPECT_NE(err.output.find("full.exr"), std::string::npos) << err.output;
    EXPECT_FALSE(std::filesystem::exists(dir.file("full.json")))
        << "stats written for a failed render";
    EXPECT_EQ(filesIn(spill.path()), 0u);

    // SIGINT, SIGTERM and SIGKILL while batches are on disk: wait until the process holds an
    // open spill file, then signal it. The spill file is made with O_TMPFILE: it never has a
    // name, so even SIGKILL (no handler runs) leaves nothing. inotify proves the "never": a
    // file created and then unlinked would raise IN_CREATE in the folder, however quickly.
    std::vector<std::string> slow = args;
    slow.insert(slow.end(), {"-o", dir.file("slow.exr"), "--spp", "1024"});
    for (int signal : {SIGINT, SIGTERM, SIGKILL}) {
        const int watch = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
        ASSERT_GE(watch, 0);
        ASSERT_GE(inotify_add_watch(watch, spill.path().c_str(), IN_CREATE | IN_MOVED_TO), 0);
        bool sawSpill = false;
        ChildResult sig = runChild(slow, [&](pid_t pid) {
            for (int i = 0; i < 400 && !sawSpill; ++i) {
                std::error_code ec;
                for (const auto& e : std::filesystem::directory_iterator(
                         "/proc/" + std::to_string(pid) + "/fd", ec)) {
                    std::string target = std::filesystem::read_symlink(e.path(), ec).string();
                    if (target.rfind(spill.path(), 0) == 0) sawSpill = true;
                }
                if (!sawSpill) std::this_thread::sleep_for(std::chrono::milliseconds(25));
            }
            kill(pid, signal);
        });
        char events[4096];
        const ssize_t got = read(watch, events, sizeof events);
        close(watch);
        EXPECT_TRUE(sawSpill) << "the render never opened a spill file (signal " << signal << ")";
        EXPECT_LE(got, 0) << "a file got a name in the spill folder (signal " << signal << ")";
        // SIGINT and SIGTERM stop the render gracefully (exit 128 + signal); SIGKILL kills it.
        EXPECT_EQ(sig.status, signal == SIGKILL ? -signal : 128 + signal) << sig.output;
        EXPECT_EQ(filesIn(spill.path()), 0u) << "signal " << signal;
    }
}

TEST(Spill, UnwritableSpillFolderExitsOneNamingIt) {
    TempDir dir;
    const std::string scene = heavyScene(dir);
    const std::string missing = dir.file("no-such-folder");
    ChildResult r = runChild({"render", scene, "--quiet", "--memory-budget", "0.5", "--spill-dir",
                              missing, "-o", dir.file("x.exr")});
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find(missing), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir.file("x.exr")));
}

// The memory budget is a promise: peak rays in RAM (bins and queue) stay within
// max(budget, six batches), whatever the bin exponent, and a budget below six batches spills
// every batch. Whatever the budget, they stay under seven batches: camera rays are made only
// when the queue is empty. A Cornell box at 64 x 64 x 4 spp holds 512 KiB of camera rays.
TEST(Spill, PeakRaysInRamStayWithinTheBudgetOrSixBatches) {
    TempDir dir, spill;
    const std::string box = sourceDir() + "/scenes/cornell-box";
    const std::string scene = dir.write(
        "b.yaml", "image: {width: 64, height: 64, sample base: 2, iterations: 1}\n"
                  "settings: {max depth: 3}\n"
                  "camera: {look at: {eye: [278, 273, -800], target: [278, 273, 0]}, fov: 39.3}\n"
                  "shader: {type: Lambert}\n"
                  "object: {filename: " +
                      box +
                      "/white.obj}\n"
                      "object: {filename: " +
                      box +
                      "/blocks.obj}\n"
                      "light: {type: Quad, translation: [278, 548.7, 279.5], rotation: [90, 0, 0], "
                      "scale: [130, 105], intensity: 10}\n");
    struct Case {
        const char* budgetMiB;
        int exponent;
    } cases[] = {{"0.1", 8}, {"0.02", 8}, {"0.1", 10}, {"0.25", 6}, {"1", 12}};
    for (const Case& c : cases) {
        const std::string stats = dir.file("s.json");
        ChildResult r =
            runChild({"render", scene, "-o", dir.file("o.exr"), "--quiet", "--backend", "cpu",
                      "--memory-budget", c.budgetMiB, "--bin-exponent", std::to_string(c.exponent),
                      "--spill-dir", spill.path(), "--stats", stats});
        ASSERT_EQ(r.status, 0) << r.output;
        nlohmann::json j = nlohmann::json::parse(std::ifstream(stats));
        const long budget = long(std::stod(c.budgetMiB) * 1024 * 1024);
        const long sixBatches = 6L * (1L << c.exponent) * long(kCompactRayBytes);
        const long peak = j["peak_ray_bytes_in_ram"].get<long>();
        std::printf(
            "budget %s MiB, 2^%d-ray batches: peak %ld bytes, bound %ld, %ld batches spilled\n",
            c.budgetMiB, c.exponent, peak, std::max(budget, sixBatches),
            j["batches_spilled"].get<long>());
        EXPECT_LE(peak, std::max(budget, sixBatches)) << c.budgetMiB << " MiB, 2^" << c.exponent;
        EXPECT_LT(peak, sixBatches / 6 * 7) << c.budgetMiB << " MiB, 2^" << c.exponent;
        if (sixBatches >= budget) {
            EXPECT_GT(j["batches_spilled"].get<long>(), 0) << c.budgetMiB << " MiB";
            EXPECT_EQ(j["batches_spilled"].get<long>(), j["batches_queued"].get<long>())
                << "with no queue budget every batch spills";
        }
    }
}

// A full disk, simulated with a file-size limit (RLIMIT_FSIZE): writes fail with EFBIG. The
// spill file reuses the ranges of batches read back, so it only grows to the most bytes queued
// on disk at once: the limit, 512 KiB, is below one 2^15-ray batch (1.1 MB).
TEST(Spill, FullDiskExitsOneNamingTheFolder) {
    TempDir dir, spill;
    const std::string scene = heavyScene(dir);
    const CommandResult r = runShell("bash -c 'ulimit -f 512; exec " + binary() + " render " +
                                     scene + " --quiet --memory-budget 0.5 --spill-dir " +
                                     spill.path() + " -o " + dir.file("x.exr") + "'");
    const std::string& out = r.output;
    EXPECT_EQ(r.status, 1) << out;
    EXPECT_NE(out.find(spill.path()), std::string::npos) << out;
    EXPECT_EQ(filesIn(spill.path()), 0u);
}

} // namespace
} // namespace spw::test
