// The spillway command line: usage and version, exit status 2 for every kind of bad usage, the
// Cornell box rendered to both output formats, the --stats JSON, and --seed reproducibility.
#include "host/cpu/simd_shading.h"
#include "host/image/image_io.h"
#include "host/pipeline/stage_chunks.h"
#include "host/scene/surface_models.h"
#include "test_util.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace spw::test {
namespace {

namespace fs = std::filesystem;

std::string cornellBox() {
    return sourceDir() + "/scenes/cornell-box.yaml";
}

bool contains(const std::string& s, const std::string& part) {
    return s.find(part) != std::string::npos;
}

TEST(Cli, HelpPrintsUsage) {
    CommandResult r = runSpillway("--help");
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "usage")) << r.output;
    EXPECT_TRUE(contains(r.output, "render")) << r.output;
}

// The help texts that describe constants and lists are made from them: the fused stages' chunk
// (kChunk), the surface models with a SIMD twin (kWideTwins). Wrapped lines are joined first.
TEST(Cli, HelpTextsSayWhatTheCodeDoes) {
    CommandResult r = runSpillway("render --help");
    EXPECT_EQ(r.status, 0) << r.output;
    std::string text;
    for (char c : r.output)
        if (c != '\n' && !(c == ' ' && !text.empty() && text.back() == ' '))
            text += c;
        else if (c == '\n' && !text.empty() && text.back() != ' ')
            text += ' ';
    EXPECT_TRUE(contains(text, "chunk by chunk of " + std::to_string(kChunk) + " hits")) << text;
    std::vector<std::string> wide;
    for (uint model = 0; model < kModelCount; ++model)
        if (kWideTwins[model].shade) wide.push_back(surfaceModel(model)->name);
    ASSERT_GE(wide.size(), 2u);
    std::string list = wide[0];
    for (size_t k = 1; k < wide.size(); ++k)
        list += (k + 1 == wide.size() ? " and " : ", ") + wide[k];
    EXPECT_TRUE(contains(text, "shade the hits of " + list + " 4, 8 or 16 at a time")) << text;
}

TEST(Cli, VersionExitsZero) {
    CommandResult r = runSpillway("--version");
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "spillway")) << r.output;
}

TEST(Cli, NoArgumentsIsAUsageError) {
    CommandResult r = runSpillway("");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "usage")) << r.output;
}

TEST(Cli, UnknownCommandIsAUsageError) {
    CommandResult r = runSpillway("paint " + cornellBox());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "paint")) << r.output;
}

// A bad render command line: its arguments after "render" ({scene}, {out} and {dir} are
// replaced) and a word the message must contain.
struct BadUsage {
    const char* name;
    const char* args;
    const char* mention;
};

void PrintTo(const BadUsage& c, std::ostream* os) {
    *os << c.name;
}

class CliBadUsage : public ::testing::TestWithParam<BadUsage> {};

// Each exits 2 before rendering and writes no file.
TEST_P(CliBadUsage, ExitsTwoAndWritesNothing) {
    const BadUsage& c = GetParam();
    TempDir dir;
    std::string args = replaceAll(replaceAll(replaceAll(replaceAll(c.args, "{scene}", cornellBox()),
                                                        "{out}", dir.file("out.exr")),
                                             "{dir}", dir.path()),
                                  "{dirname}", fs::path(dir.path()).filename().string());
    CommandResult r = runSpillway("render " + args);
    EXPECT_EQ(r.status, 2) << args << "\n" << r.output;
    EXPECT_TRUE(contains(r.output, c.mention)) << args << "\n" << r.output;
    EXPECT_TRUE(fs::is_empty(dir.path())) << "a failed command wrote a file";
}

const BadUsage kBadUsages[] = {
    {"UnknownOption", "{scene} -o {out} --quiet --frobnicate", "--frobnicate"},
    {"TextureCacheBelowOneMiB", "{scene} -o {out} --quiet --texture-cache 0.5", "--texture-cache"},
    {"MissingValueAtEnd", "{scene} --quiet -o {out} --spp", "--spp"},
    {"MissingOutputValue", "{scene} --quiet --spp 1 -o", "-o"},
    {"EmptyResumeFile", "{scene} -o {out} --quiet --spp 1 --resume ''",
     "--resume needs a file name"},
    {"EmptyOutputFile", "{scene} --quiet --spp 1 -o ''", "-o needs a file name"},
    {"SppNotAnInteger", "{scene} -o {out} --quiet --spp abc", "abc"},
    {"SppZero", "{scene} -o {out} --quiet --spp 0", "--spp"},
    {"SppNegative", "{scene} -o {out} --quiet --spp -3", "--spp"},
    {"SppTrailingGarbage", "{scene} -o {out} --quiet --spp 4x", "4x"},
    {"ThreadsZero", "{scene} -o {out} --quiet --threads 0", "--threads"},
    {"SeedNegative", "{scene} -o {out} --quiet --seed -1", "--seed"},
    {"UnknownBackend", "{scene} -o {out} --quiet --backend nonsense", "nonsense"},
    {"SimdShadingNeitherOnNorOff", "{scene} -o {out} --quiet --simd-shading maybe", "maybe"},
    {"NoScene", "-o {out} --quiet", "scene"},
    {"TwoScenes", "{scene} {scene} -o {out} --quiet", "more than one"},
    {"JpgOutput", "{scene} -o {dir}/out.jpg --quiet --spp 1", "out.jpg"},
    {"OutputWithoutExtension", "{scene} -o {dir}/out --quiet --spp 1", ".exr"},
    // Outputs that would destroy one another, or an input, however they are spelt.
    {"OutputIsTheCheckpoint", "{scene} -o {dir}/x.exr --checkpoint {dir}/./x.exr --quiet",
     "-o and --checkpoint name the same file"},
    {"OutputIsThePartial", "{scene} --spp 2 --samples 0:1 --partial {dir}/x.exr -o {dir}/x.exr",
     "-o and --partial name the same file"},
    {"StatsIsTheOutput", "{scene} -o {dir}/x.exr --stats {dir}/../{dirname}/x.exr --quiet",
     "-o and --stats name the same file"},
    {"ErrorCsvIsTheStats", "{scene} -o {out} --stats {dir}/s.csv --error-csv {dir}/s.csv",
     "--stats and --error-csv name the same file"},
    {"StatsIsTheScene", "{scene} -o {out} --stats {scene} --quiet",
     "--stats and the scene name the same file"},
    {"ErrorMapAsPng", "{scene} -o {out} --error-map {dir}/e.png --quiet", "ending in .exr"},
    {"ErrorMapWithoutAName", "{scene} -o {out} --error-map {dir}/.exr --quiet",
     "must be a file name ending in .exr (a name, then .exr)"},
    {"UniformWithoutATarget", "{scene} -o {out} --spp 1 --uniform --quiet",
     "--uniform goes with --target-error"},
    {"EnvironmentStrengthAlone", "{scene} -o {out} --spp 1 --environment-strength 2 --quiet",
     "--environment-strength scales --environment"},
    {"EnvironmentAbsent", "{scene} -o {out} --spp 1 --environment {dir}/sky.hdr --quiet",
     "--environment: environment image"},
    {"EnvironmentNeitherImageNorColour", "{scene} -o {out} --spp 1 --environment 1,x,1 --quiet",
     "an image or R,G,B"},
    {"ErrorMapIsTheOutput", "{scene} -o {dir}/x.exr --error-map {dir}/x.exr --quiet",
     "-o and --error-map name the same file"},
};

INSTANTIATE_TEST_SUITE_P(Cli, CliBadUsage, ::testing::ValuesIn(kBadUsages),
                         [](const ::testing::TestParamInfo<BadUsage>& info) {
                             return std::string(info.param.name);
                         });

// merge A B -o A would overwrite a part with the image: refused before anything is read.
TEST(Cli, MergeRefusesAnOutputThatIsOneOfItsParts) {
    TempDir dir;
    const std::string a = dir.file("a.exr"), b = dir.file("b.exr");
    CommandResult r = runSpillway("merge " + a + " " + b + " -o " + dir.path() + "/./a.exr");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "name the same file")) << r.output;
    EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(Cli, MissingSceneFileExitsTwo) {
    TempDir dir;
    const std::string scene = dir.file("absent.yaml");
    CommandResult r = runSpillway("render " + scene + " -o " + dir.file("out.exr") + " --quiet");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_EQ(r.output.rfind(scene + ":", 0), 0u) << r.output;
    EXPECT_FALSE(fs::exists(dir.file("out.exr")));
}

void expectCornellImage(const std::string& path) {
    ASSERT_TRUE(fs::exists(path)) << path;
    ImageRGB img = readImage(path);
    EXPECT_EQ(img.width, 256);
    EXPECT_EQ(img.height, 256);
    ASSERT_EQ(img.rgb.size(), 256u * 256u * 3u);
    for (float v : img.rgb)
        ASSERT_TRUE(std::isfinite(v)) << path;
    EXPECT_GT(mean(img.rgb), 0.0) << path << " is black";
}

TEST(Cli, RendersCornellBoxToExr) {
    TempDir dir;
    const std::string out = dir.file("cornell.exr");
    CommandResult r = runSpillway("render " + cornellBox() + " --spp 1 --quiet -o " + out);
    ASSERT_EQ(r.status, 0) << r.output;
    expectCornellImage(out);
}

TEST(Cli, RendersCornellBoxToPng) {
    TempDir dir;
    const std::string out = dir.file("cornell.png");
    CommandResult r = runSpillway("render " + cornellBox() + " --spp 1 --quiet --output " + out);
    ASSERT_EQ(r.status, 0) << r.output;
    expectCornellImage(out);
}

TEST(Cli, StatsFileIsJsonWithTheDocumentedKeys) {
    TempDir dir;
    const std::string stats = dir.file("stats.json");
    CommandResult r = runSpillway("render " + cornellBox() + " --spp 1 --quiet -o " +
                                  dir.file("c.exr") + " --stats " + stats);
    ASSERT_EQ(r.status, 0) << r.output;
    std::ifstream in(stats);
    ASSERT_TRUE(in) << "no stats file";
    nlohmann::json j = nlohmann::json::parse(in); // throws (fails the test) on malformed JSON
    for (const char* key :
         {"backend", "device", "width", "height", "spp", "wall_seconds", "rays", "stage_seconds"})
        EXPECT_TRUE(j.contains(key)) << "missing key " << key << " in " << j.dump(2);
    ASSERT_TRUE(j["backend"].is_string());
    EXPECT_FALSE(j["backend"].get<std::string>().empty());
    ASSERT_TRUE(j["device"].is_string());
    EXPECT_FALSE(j["device"].get<std::string>().empty());
    EXPECT_EQ(j["width"], 256);
    EXPECT_EQ(j["height"], 256);
    EXPECT_EQ(j["spp"], 1);
    EXPECT_TRUE(j["wall_seconds"].is_number());
    EXPECT_GT(j["wall_seconds"].get<double>(), 0.0);
    ASSERT_TRUE(j["rays"].is_object());
    for (const char* key : {"camera", "bounce", "shadow"}) {
        ASSERT_TRUE(j["rays"].contains(key)) << "missing rays." << key;
        EXPECT_TRUE(j["rays"][key].is_number_unsigned()) << key;
    }
    EXPECT_EQ(j["rays"]["camera"], 256 * 256);
    EXPECT_GT(j["rays"]["bounce"].get<double>(), 0.0);
    EXPECT_GT(j["rays"]["shadow"].get<double>(), 0.0);
    ASSERT_TRUE(j["stage_seconds"].is_object());
    EXPECT_FALSE(j["stage_seconds"].empty());
    for (const auto& [stage, seconds] : j["stage_seconds"].items()) {
        EXPECT_TRUE(seconds.is_number()) << stage;
        EXPECT_GE(seconds.get<double>(), 0.0) << stage;
    }
}

std::vector<float> renderWithSeed(const TempDir& dir, const std::string& name,
                                  const std::string& seed) {
    const std::string out = dir.file(name);
    CommandResult r =
        runSpillway("render " + cornellBox() + " --spp 1 --quiet --seed " + seed + " -o " + out);
    EXPECT_EQ(r.status, 0) << r.output;
    return readImage(out).rgb;
}

// --simd-shading: the cpu backend names the instruction set its kernel ran in, or "off"; the
// image is the same either way.
TEST(Cli, SimdShadingIsReportedAndChangesNoPixel) {
    TempDir dir;
    const std::string common = "render " + cornellBox() + " --backend cpu --spp 2 --quiet ";
    for (const char* mode : {"on", "off"}) {
        CommandResult r = runSpillway(common + "--simd-shading " + mode + " -o " +
                                      dir.file(std::string(mode) + ".exr") + " --stats " +
                                      dir.file(std::string(mode) + ".json"));
        ASSERT_EQ(r.status, 0) << r.output;
    }
    auto simd = [&](const char* mode) {
        std::ifstream in(dir.file(std::string(mode) + ".json"));
        return nlohmann::json::parse(in)["simd_shading"].get<std::string>();
    };
    EXPECT_EQ(simd("off"), "off");
    EXPECT_NE(simd("on"), "off");
    EXPECT_FALSE(simd("on").empty());
    EXPECT_TRUE(samePixels(dir.file("on.exr"), dir.file("off.exr")));
}

TEST(Cli, SameSeedReproducesTheImageBitForBit) {
    TempDir dir;
    std::vector<float> a = renderWithSeed(dir, "a.exr", "7");
    std::vector<float> b = renderWithSeed(dir, "b.exr", "7");
    std::vector<float> c = renderWithSeed(dir, "c.exr", "8");
    ASSERT_EQ(a.size(), 256u * 256u * 3u);
    ASSERT_EQ(b.size(), a.size());
    ASSERT_EQ(c.size(), a.size());
    EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(float)), 0)
        << "seed 7 twice gave different images";
    EXPECT_NE(std::memcmp(a.data(), c.data(), a.size() * sizeof(float)), 0)
        << "seeds 7 and 8 gave the same image";
}

} // namespace
} // namespace spw::test
