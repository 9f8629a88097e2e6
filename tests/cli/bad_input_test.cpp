// Bad input, as a hostile user would give it: one generated case per class of defect that ever
// crashed, hung or rendered silently wrong. Each runs the real binary under a time limit and
// asserts: no signal, no hang, exit 2 with FILE:LINE for a scene error and exit 1 for a runtime
// failure, and no file left in the output folder (nor a changed one) on failure.
#include "host/image/image_io.h"
#include "host/loaders/scene_loader.h"
#include "host/scene/scene.h"
#include "test_util.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <random>
#include <sys/wait.h>

namespace spw::test {
namespace {

namespace fs = std::filesystem;

struct Outcome {
    bool signalled = false; // killed by a signal: a crash, or the time limit (hang)
    int signal = 0;
    int status = -1;
    std::string output;
};

// The binary with a time limit (coreutils `timeout`, SIGKILL), reporting a signal as such.
Outcome runLimited(const std::string& args, int seconds = 120, const std::string& prefix = "") {
    const std::string cmd = prefix + "timeout -s KILL " + std::to_string(seconds) + " " + binary() +
                            " " + args + " 2>&1; echo \"@status $?\"";
    FILE* p = popen(cmd.c_str(), "r");
    Outcome r;
    if (!p) return r;
    char buf[4096];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, p)) > 0)
        r.output.append(buf, n);
    pclose(p);
    const size_t at = r.output.rfind("@status ");
    if (at == std::string::npos) return r;
    const int code = std::stoi(r.output.substr(at + 8));
    r.output.erase(at);
    // The shell reports a child killed by signal N as 128 + N; spillway itself exits 0, 1 or 2.
    if (code > 128)
        r.signalled = true, r.signal = code - 128;
    else
        r.status = code;
    return r;
}

const char* const kTriangleObj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

// 64 KiB of bytes from a fixed seed: what `head -c 65536 /dev/urandom` gives, reproducibly.
std::string garbage(size_t size, unsigned seed) {
    std::mt19937 rng(seed);
    std::string s(size, '\0');
    for (char& c : s)
        c = char(rng() & 0xFF);
    return s;
}

// Layered textures 30 levels deep, each anchor used three times by the next: 3^30 leaves if
// aliases were copied, 31 textures when they are shared.
std::string aliasBomb(int levels) {
    std::string s =
        "shaders:\n  - {type: Lambert, texture: &a0 {type: Constant, colour: [0.5, 0.5, 0.5]}}\n";
    for (int i = 1; i <= levels; ++i) {
        const std::string prev = "*a" + std::to_string(i - 1);
        s += "  - {type: Lambert, texture: &a" + std::to_string(i) +
             " {type: Layered, upper: " + prev + ", lower: " + prev + ", mask: " + prev + "}}\n";
    }
    return s + "object: {filename: tri.obj, shader: " + std::to_string(levels) +
           "}\n"
           "image: {width: 8, height: 8}\n";
}

std::string nested(int levels) {
    std::string s = "camera: ";
    for (int i = 0; i < levels; ++i)
        s += "[";
    for (int i = 0; i < levels; ++i)
        s += "]";
    return s + "\n";
}

std::string deepTexture(int levels) {
    std::string t = "{type: Constant}";
    for (int i = 0; i < levels; ++i)
        t = "{type: Layered, upper: " + t + ", lower: {type: Constant}, mask: {type: Constant}}";
    return "shader: {type: Lambert, texture: " + t + "}\n";
}

// A scene whose camera looks at the triangle from `eye` (set far away to break it).
std::string lookingFrom(const std::string& eye) {
    return "camera:\n  look at: {eye: " + eye +
           ", target: [0.3, 0.3, 0]}\nshader: {type: Lambert}\n"
           "object: {filename: tri.obj}\nimage: {width: 8, height: 8}\n";
}

enum class Expect { SceneError, RuntimeError, Success };

struct BadInput {
    const char* name;
    std::vector<std::pair<std::string, std::string>> files; // written beside scene.yaml
    std::string scene;                                      // scene.yaml's text
    std::string
        args; // after "render"; {scene}, {out} (out/image.exr), {dir} and {cornell} are replaced
    Expect expect;
    std::string where;   // SceneError: the file (relative to the folder) and line, "scene.yaml:3"
    std::string mention; // a part of the message
    std::string prefix = ""; // shell words before the command (ulimit, environment)
};

void PrintTo(const BadInput& c, std::ostream* os) {
    *os << c.name;
}

class BadInputs : public ::testing::TestWithParam<BadInput> {};

TEST_P(BadInputs, NeverCrashHangOrLeaveAFile) {
    const BadInput& c = GetParam();
    TempDir dir;
    dir.write("tri.obj", kTriangleObj);
    for (const auto& [name, text] : c.files)
        dir.write(name, text);
    const std::string scene = dir.write("scene.yaml", c.scene);
    fs::create_directories(dir.file("out"));
    // An image from before: a failed render must leave it as it was.
    const std::string before = "not an image, and must stay so\n";
    dir.write("out/keep.exr", before);
    std::string args = c.args.empty() ? "{scene} -o {out} --quiet" : c.args;
    args = replaceAll(replaceAll(replaceAll(replaceAll(args, "{scene}", scene), "{out}",
                                            dir.file("out/image.exr")),
                                 "{dir}", dir.path()),
                      "{cornell}", sourceDir() + "/scenes/cornell-box.yaml");
    const Outcome r = runLimited("render " + args, 120, replaceAll(c.prefix, "{dir}", dir.path()));

    ASSERT_FALSE(r.signalled) << (r.signal == SIGKILL
                                      ? "hung (killed after 120 s)"
                                      : "killed by signal " + std::to_string(r.signal))
                              << "\n"
                              << r.output;
    EXPECT_EQ(readFile(dir.file("out/keep.exr")), before) << "an existing file was changed";
    switch (c.expect) {
    case Expect::SceneError: {
        EXPECT_EQ(r.status, 2) << r.output;
        const std::string where = (c.where.empty() ? dir.path() : dir.file(c.where)) + ":";
        EXPECT_EQ(r.output.rfind(where, 0), 0u)
            << "expected the message to start with '" << where << "': " << r.output;
        break;
    }
    case Expect::RuntimeError:
        EXPECT_EQ(r.status, 1) << r.output;
        EXPECT_EQ(r.output.rfind("spillway: error: ", 0), 0u) << r.output;
        break;
    case Expect::Success:
        EXPECT_EQ(r.status, 0) << r.output;
        // --quiet: a clean render prints nothing, not even a warning (non-finite samples).
        EXPECT_EQ(r.output, "");
        break;
    }
    EXPECT_NE(r.output.find(c.mention), std::string::npos)
        << "expected '" << c.mention << "' in: " << r.output;
    if (c.expect != Expect::Success) {
        std::vector<std::string> left;
        for (const auto& e : fs::directory_iterator(dir.path()))
            if (e.path().filename().string()[0] == '.')
                left.push_back(e.path().filename().string());
        for (const auto& e : fs::directory_iterator(dir.file("out")))
            if (e.path().filename() != "keep.exr")
                left.push_back("out/" + e.path().filename().string());
        EXPECT_TRUE(left.empty()) << "left behind: " << (left.empty() ? "" : left[0]);
    }
}

const std::string kTri =
    "shader: {type: Lambert}\nobject: {filename: tri.obj}\nimage: {width: 8, height: 8}\n";
std::string objScene(const std::string& obj) {
    return "shader: {type: Lambert}\nobject: {filename: " + obj +
           "}\nimage: {width: 8, height: 8}\n";
}

// A Radiance HDR header that claims 100000 x 100000 texels, and no texel.
const std::string kBombHdr = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 100000 +X 100000\n";

const BadInput kBadInputs[] = {
    // 1. OBJ indices that name no element.
    {"ObjFaceIndexPastInt",
     {{"m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2147483648\n"}},
     objScene("m.obj"),
     "",
     Expect::SceneError,
     "m.obj:4",
     "2147483648"},
    {"ObjFaceIndexPastLastVertex",
     {{"m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n"}},
     objScene("m.obj"),
     "",
     Expect::SceneError,
     "m.obj:5",
     "index 4"},
    {"ObjNegativeIndexBeforeFirstVertex",
     {{"m.obj", "v 0 0 0\nv 1 0 0\nf -1 -2 -3\nv 0 1 0\n"}},
     objScene("m.obj"),
     "",
     Expect::SceneError,
     "m.obj:3",
     "-3"},
    {"ObjIndexZero",
     {{"m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"}},
     objScene("m.obj"),
     "",
     Expect::SceneError,
     "m.obj:4",
     "index 0"},
    {"ObjTexcoordIndexOutOfRange",
     {{"m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/1\n"}},
     objScene("m.obj"),
     "",
     Expect::SceneError,
     "m.obj:5",
     "texture coordinate"},
    {"ObjNormalIndexOutOfRange",
     {{"m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//-2\n"}},
     objScene("m.obj"),
     "",
     Expect::SceneError,
     "m.obj:5",
     "normal"},
    {"ObjIndexNotANumber",
     {{"m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 three\n"}},
     objScene("m.obj"),
     "",
     Expect::SceneError,
     "m.obj:4",
     "three"},
    // 2. Not an OBJ at all.
    {"ObjBinaryGarbage",
     {{"m.obj", garbage(65536, 1)}},
     objScene("m.obj"),
     "",
     Expect::SceneError,
     "m.obj:1",
     "not an OBJ"},
    {"ObjGarbageAfterValidLines",
     {{"m.obj", std::string(kTriangleObj) + "\x01\x02\x7f\n"}},
     objScene("m.obj"),
     "",
     Expect::SceneError,
     "m.obj:5",
     "not text"},
    {"ObjUnknownStatement",
     {{"m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nface 1 2 3\n"}},
     objScene("m.obj"),
     "",
     Expect::SceneError,
     "m.obj:4",
     "not an OBJ statement"},
    {"ObjTextWithNoFace",
     {{"m.obj", "# only vertices\nv 0 0 0\nv 1 0 0\n"}},
     objScene("m.obj"),
     "",
     Expect::SceneError,
     "scene.yaml:2",
     "no face"},
    {"ObjEmpty",
     {{"m.obj", ""}},
     objScene("m.obj"),
     "",
     Expect::SceneError,
     "scene.yaml:2",
     "no face"},
    {"ObjTwoVertexFace",
     {{"m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2\n"}},
     objScene("m.obj"),
     "",
     Expect::SceneError,
     "m.obj:5",
     "at least 3 vertices"},
    {"ObjHexFloatVertex",
     {{"m.obj", "v 0 0 0\nv 0x1p0 0 0\nv 0 1 0\nf 1 2 3\n"}},
     objScene("m.obj"),
     "",
     Expect::SceneError,
     "m.obj:2",
     "0x1p0"},
    // 3, 4. Texture trees: a cycle, an alias bomb (shared: renders), too deep.
    {"LayeredTextureContainsItself",
     {},
     "shader:\n  type: Lambert\n  texture: &t {type: Layered, upper: *t, lower: {type: Constant}, "
     "mask: {type: Constant}}\n",
     "",
     Expect::SceneError,
     "scene.yaml:3",
     "contains itself"},
    {"LayeredAliasBombIsShared", {}, aliasBomb(30), "", Expect::Success, "", ""},
    {"LayeredTextureTooDeep",
     {},
     deepTexture(80),
     "",
     Expect::SceneError,
     "scene.yaml:1",
     "deeper than 64"},
    {"YamlNestedTenThousandLevels",
     {},
     nested(10000),
     "",
     Expect::SceneError,
     "scene.yaml:1",
     "nests deeper"},
    // 5. What would hand Embree an invalid ray.
    {"CameraFarFromTheScene",
     {},
     lookingFrom("[1e20, 0, 5]"),
     "",
     Expect::SceneError,
     "scene.yaml:2",
     "from the camera"},
    {"EyeAt1e38",
     {},
     lookingFrom("[1e38, 0, 5]"),
     "",
     Expect::SceneError,
     "scene.yaml:2",
     "from the camera"},
    {"CameraTranslatedFar",
     {},
     "camera: {translation: [0, 0, 1e20]}\n" + kTri,
     "",
     Expect::SceneError,
     "tri.obj:1",
     "from the camera"},
    {"ObjectTranslatedFar",
     {},
     "shader: {type: Lambert}\nobject: {filename: tri.obj, translation: [0, -1e16, 0]}\n",
     "",
     Expect::SceneError,
     "tri.obj:1",
     "from the camera"},
    {"ThinLensApertureHuge",
     {},
     "camera: {type: ThinLens, aperture radius: 1e20}\n" + kTri,
     "",
     Expect::SceneError,
     "scene.yaml:1",
     "aperture radius"},
    {"ThinLensFocalDistanceHuge",
     {},
     "camera:\n  type: ThinLens\n  focal distance: 1e30\n" + kTri,
     "",
     Expect::SceneError,
     "scene.yaml:3",
     "focal distance"},
    {"ThinLensFocalPlaneFar",
     {},
     "camera:\n  type: ThinLens\n  fov: 179\n  focal distance: 1e13\n" + kTri,
     "",
     Expect::SceneError,
     "scene.yaml:4",
     "focal plane"},
    {"FilmWidthOverFocalLengthWiderThan180Degrees",
     {},
     "camera:\n  focal length: 1e-6\n  film width: 1e9\n" + kTri,
     "",
     Expect::SceneError,
     "scene.yaml:2",
     "wider than 179.9"},
    {"QuadLightWithPowerBeyondFloat",
     {},
     kTri + "light: {type: Quad, translation: [0, 0, 1e9], rotation: [180, 0, 0], scale: [3e9, "
            "3e9], intensity: 1e20}\n",
     "",
     Expect::Success,
     "",
     ""},
    {"QuadLightFar",
     {},
     kTri + "light: {type: Quad, translation: [0, 0, -1e18]}\n",
     "",
     Expect::SceneError,
     "scene.yaml:4",
     "quad light corner"},
    // 6, 7. Radiance beyond float's headroom, or beyond the film.
    {"LightPowerOverflowsFloat",
     {},
     kTri + "light:\n  type: Quad\n  intensity: 1e20\n  colour: [1e19, 1, 1]\n",
     "",
     Expect::SceneError,
     "scene.yaml:7",
     "exceeds 1e20"},
    {"EmissionAboveTheRange",
     {},
     "shader: {type: Lambert, emission: [1e30, 0, 0]}\nobject: {filename: tri.obj}\n",
     "",
     Expect::SceneError,
     "scene.yaml:1",
     "emission"},
    {"LightIntensityAboveTheRange",
     {},
     kTri + "light: {type: Quad, intensity: 1e30}\n",
     "",
     Expect::SceneError,
     "scene.yaml:4",
     "intensity"},
    // 8. One depth limit for every backend.
    {"MaxDepthBeyondTheRayRecord",
     {},
     "settings: {max depth: 40000}\n" + kTri,
     "",
     Expect::SceneError,
     "scene.yaml:1",
     "32767"},
    // 9. Scene errors that used to be runtime failures.
    {"TextureNotAnImage",
     {{"t.png", "this is text, not a PNG\n"}},
     "shader:\n  type: Lambert\n  texture: {type: Standard, filename: t.png}\nobject: {filename: "
     "tri.obj}\n",
     "",
     Expect::SceneError,
     "scene.yaml:3",
     "not an image"},
    {"SceneIsAFolder", {}, kTri, "{dir} -o {out} --quiet", Expect::SceneError, "", "is a folder"},
    {"SceneMissing",
     {},
     kTri,
     "{dir}/nosuch.yaml -o {out} --quiet",
     Expect::SceneError,
     "nosuch.yaml",
     "cannot open the scene file"},
    // 10, 12. Outputs that cannot be written: found before rendering, nothing left behind.
    {"OutputFolderMissing",
     {},
     kTri,
     "{scene} -o {dir}/out/missing/image.exr --quiet --spp 16000000",
     Expect::RuntimeError,
     "",
     "missing"},
    {"StatsFolderMissing",
     {},
     kTri,
     "{scene} -o {out} --stats {dir}/out/none/s.json --quiet --spp 16000000",
     Expect::RuntimeError,
     "",
     "none"},
    {"ErrorCsvFolderMissing",
     {},
     kTri,
     "{scene} -o {out} --error-csv {dir}/out/none/e.csv --quiet --spp 16000000",
     Expect::RuntimeError,
     "",
     "none"},
    {"OutputIsAFolder",
     {},
     kTri,
     "{scene} -o {dir}/d.exr --quiet --spp 16000000",
     Expect::RuntimeError,
     "",
     "folder",
     "mkdir {dir}/d.exr && "},
    {"PngToAFullDevice",
     {},
     kTri,
     "{cornell} -o {dir}/full.png --quiet --spp 1",
     Expect::RuntimeError,
     "",
     "No space left",
     "ln -s /dev/full {dir}/full.png && "},
    {"ImageOverAFileSizeLimit",
     {},
     kTri,
     "{cornell} -o {dir}/out/big.exr --quiet --spp 1",
     Expect::RuntimeError,
     "",
     "too large",
     "ulimit -f 1; "},
    {"PngOverAFileSizeLimit",
     {},
     kTri,
     "{cornell} -o {dir}/out/big.png --quiet --spp 1",
     Expect::RuntimeError,
     "",
     "too large",
     "ulimit -f 1; "},
    // The image is small enough; the stats are not: neither appears, as all outputs commit
    // together.
    {"StatsOverAFileSizeLimit",
     {},
     kTri,
     "{scene} -o {dir}/out/image.png --stats {dir}/out/s.json --quiet --spp 1",
     Expect::RuntimeError,
     "",
     "s.json",
     "ulimit -f 1; "},
    {"CsvOverAFileSizeLimit",
     {},
     kTri,
     "{scene} -o {dir}/out/image.png --error-csv {dir}/out/e.csv --quiet --spp 10000 --backend cpu",
     Expect::RuntimeError,
     "",
     "e.csv",
     "ulimit -f 1; "},
    // 12. A spill folder that is missing matters only when a batch spills.
    {"MissingTmpdirWithoutSpill",
     {},
     kTri,
     "{scene} -o {dir}/out/fine.exr --quiet --spp 4 --backend cpu",
     Expect::Success,
     "",
     "",
     "TMPDIR={dir}/missing "},
    {"MissingTmpdirWithSpill",
     {},
     objScene("tri.obj"),
     "{scene} -o {out} --quiet --spp 16 --backend cpu --memory-budget 0.001 --bin-exponent 6",
     Expect::RuntimeError,
     "",
     "spill file",
     "TMPDIR={dir}/missing "},
    // 5. Header bombs: a 56-byte HDR that claims 100000 x 100000 texels is refused from its
    //    header, before 120 GB are asked for (before: std::bad_alloc, or 4.8 GB and 33 s at
    //    20000^2).
    {"EnvironmentMapHeaderBomb",
     {{"bomb.hdr", kBombHdr}},
     kTri + "light: {type: Environment, string: bomb.hdr}\n",
     "",
     Expect::SceneError,
     "scene.yaml:4",
     "Spillway reads images of 1 to 2^26 pixels"},
    // 10. Samples per pixel past the documented 2^32 - 1 (indices are 32-bit): 256^2 x 65536 is
    //     exactly 2^32, refused with the limit the docs give.
    {"ExactlyTwoToThe32SamplesPerPixel",
     {},
     "shader: {type: Lambert}\nobject: {filename: tri.obj}\n"
     "image: {width: 1, height: 1, sample base: 256, iterations: 65536}\n",
     "",
     Expect::SceneError,
     "scene.yaml:3",
     "4294967296 samples per pixel exceeds 2^32 - 1"},
};

INSTANTIATE_TEST_SUITE_P(Cli, BadInputs, ::testing::ValuesIn(kBadInputs),
                         [](const ::testing::TestParamInfo<BadInput>& info) {
                             return std::string(info.param.name);
                         });

TEST(BadInputs, RenderHelpPrintsUsageAndExitsZero) {
    const Outcome r = runLimited("render --help", 30);
    ASSERT_FALSE(r.signalled);
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("usage"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("exit status"), std::string::npos) << r.output;
}

// A valid 8 x 8 EXR whose header attribute `name` of `type` has `bytes` written at `offset`
// from the attribute's type name (0: its size field, 4: its value); "" if it has no such one.
std::string patchedExr(const TempDir& dir, const std::string& file, const std::string& name,
                       const std::string& type, size_t offset, const std::string& bytes) {
    const std::string path = dir.file(file);
    writeImage(path, ImageRGB{8, 8, std::vector<float>(8 * 8 * 3, 0.5f)});
    std::string exr = readFile(path);
    const std::string key = name + '\0' + type + '\0';
    const size_t at = exr.find(key);
    if (at == std::string::npos) return "";
    exr.replace(at + key.size() + offset, bytes.size(), bytes);
    return dir.write(file, exr);
}

// Its data window rewritten to claim 100000 x 100000 pixels: OpenEXR would size its offset table
// from that before any check of ours.
std::string exrBomb(const TempDir& dir) {
    const std::int32_t box[4] = {0, 0, 99999, 99999};
    return patchedExr(dir, "bomb.exr", "dataWindow", "box2i", 4,
                      std::string(reinterpret_cast<const char*>(box), 16));
}

// Its Software attribute claiming 2^31 - 1 bytes: OpenEXR allocates an attribute's claimed size
// before reading it (fuzzing found it: 12 s per file under ASan).
std::string exrAttributeBomb(const TempDir& dir) {
    const std::int32_t size = 0x7FFFFFFF;
    return patchedExr(dir, "attribute-bomb.exr", "Software", "string", 0,
                      std::string(reinterpret_cast<const char*>(&size), 4));
}

// Each command is refused as bad input (exit 2, no signal), its message saying `says`.
void expectRefused(const std::vector<std::string>& commands, const std::string& says) {
    for (const std::string& args : commands) {
        const Outcome r = runLimited(args, 60);
        ASSERT_FALSE(r.signalled) << args << "\n" << r.output;
        EXPECT_EQ(r.status, 2) << args << "\n" << r.output;
        EXPECT_NE(r.output.find(says), std::string::npos) << args << "\n" << r.output;
    }
}

// The same header bombs everywhere else an image is read, refused from the header with exit 2:
// compare (either side) and render's --reference; and an EXR's, whose header OpenEXR itself
// would trust, as a checkpoint too.
TEST(BadInputs, ImageHeaderBombsAreRefusedBeforeAllocating) {
    TempDir dir;
    const std::string bomb = dir.write("bomb.hdr", kBombHdr);
    const std::string exr = exrBomb(dir);
    ASSERT_FALSE(exr.empty()) << "no dataWindow in OpenImageIO's EXR header";
    const std::string ok = dir.file("ok.exr");
    writeImage(ok, ImageRGB{8, 8, std::vector<float>(8 * 8 * 3, 0.5f)});
    expectRefused({"compare " + exr + " " + ok, "merge " + exr + " -o " + dir.file("x.exr"),
                   "render " + sourceDir() + "/scenes/cornell-box.yaml --spp 1 --quiet -o " +
                       dir.file("x.exr") + " --resume " + exr},
                  "is 100000 x 100000 pixels; Spillway reads images of 1 to 2^26");
    const std::string attribute = exrAttributeBomb(dir);
    ASSERT_FALSE(attribute.empty()) << "no Software attribute in OpenImageIO's EXR header";
    expectRefused(
        {"compare " + attribute + " " + ok, "merge " + attribute + " -o " + dir.file("x.exr")},
        "attribute 'Software' claims 2147483647 bytes, past the end");
    expectRefused({"compare " + bomb + " " + ok, "compare " + ok + " " + bomb,
                   "render " + sourceDir() + "/scenes/cornell-box.yaml --spp 1 --quiet -o " +
                       dir.file("x.exr") + " --error-csv " + dir.file("e.csv") + " --reference " +
                       bomb},
                  "is 100000 x 100000 pixels; Spillway reads images of 1 to 2^26");
    EXPECT_FALSE(fs::exists(dir.file("x.exr")));
}

// 10. What the docs promise is what the loader takes: 2^32 - 65536 samples per pixel load, and
// the docs name the limit the loader applies.
TEST(BadInputs, TheSampleLimitIsTheDocumentedOne) {
    TempDir dir;
    dir.write("tri.obj", kTriangleObj);
    const Scene s = loadScene(dir.write(
        "scene.yaml", "shader: {type: Lambert}\nobject: {filename: tri.obj}\n"
                      "image: {width: 1, height: 1, sample base: 256, iterations: 65535}\n"));
    EXPECT_EQ(std::uint64_t(s.image.samplesPerIteration()) * std::uint64_t(s.image.iterations),
              (1ull << 32) - 65536);
    EXPECT_NE(readFile(sourceDir() + "/docs/scene-format.md")
                  .find("The total samples per pixel are n² × iterations, at most 2^32 − 1"),
              std::string::npos);
}

// 10. A map texel of exactly the brightest radiance the format takes (1e20, which a float file
// holds as the float nearest it, a little above) renders; twice that is refused, naming it.
TEST(BadInputs, AnEnvironmentTexelOfTheBrightestRadianceIsInRange) {
    TempDir dir;
    dir.write("tri.obj", kTriangleObj);
    for (const float texel : {1e20f, 2e20f}) {
        writeImage(dir.file("sky.exr"), ImageRGB{2, 1, {texel, 1, 1, 0, 0, 0}});
        const std::string scene =
            dir.write("scene.yaml", kTri + "light: {type: Environment, string: sky.exr}\n");
        const Outcome r = runLimited("render " + scene + " --spp 1 --quiet -o " +
                                         dir.file("out.exr") + " --backend reference",
                                     60);
        ASSERT_FALSE(r.signalled) << r.output;
        if (texel == 1e20f) {
            EXPECT_EQ(r.status, 0) << r.output;
        } else {
            EXPECT_EQ(r.status, 2) << r.output;
            EXPECT_NE(r.output.find("has radiance 2e20 at texel (0, 0)"), std::string::npos)
                << r.output;
        }
    }
}

// 10. A heatmap that cannot be written is a disk failure, exit 1 as the README's table says,
// found before the images are read; unreadable inputs stay bad input, exit 2.
TEST(BadInputs, CompareHeatmapIntoAMissingFolderIsADiskFailure) {
    TempDir dir;
    const std::string ok = dir.file("ok.exr");
    writeImage(ok, ImageRGB{2, 2, std::vector<float>(2 * 2 * 3, 0.5f)});
    const Outcome r =
        runLimited("compare " + ok + " " + ok + " --heatmap " + dir.file("missing/h.png"), 30);
    ASSERT_FALSE(r.signalled) << r.output;
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_EQ(r.output.rfind("spillway: error: cannot write '" + dir.file("missing/h.png"), 0), 0u)
        << r.output;
    const Outcome unreadable = runLimited(
        "compare " + dir.file("nosuch.exr") + " " + ok + " --heatmap " + dir.file("h.png"), 30);
    EXPECT_EQ(unreadable.status, 2) << unreadable.output;
    EXPECT_FALSE(fs::exists(dir.file("h.png")));
}

// 8. A heatmap that names an input, however spelt (./, a link), is refused before anything is
// read or written: exit 2, the input unchanged.
TEST(BadInputs, CompareHeatmapNamingAnInputIsRefused) {
    TempDir dir;
    const std::string a = dir.file("a.png"), b = dir.file("b.png");
    writeImage(a, ImageRGB{2, 2, std::vector<float>(2 * 2 * 3, 0.5f)});
    writeImage(b, ImageRGB{2, 2, std::vector<float>(2 * 2 * 3, 0.25f)});
    fs::create_symlink(a, dir.file("link.png"));
    const std::string before = readFile(a);
    for (const std::string& heatmap :
         {a, dir.path() + "/./a.png", dir.file("link.png"),
          dir.path() + "/../" + fs::path(dir.path()).filename().string() + "/b.png"}) {
        const Outcome r = runLimited("compare " + a + " " + b + " --heatmap " + heatmap, 30);
        ASSERT_FALSE(r.signalled) << r.output;
        EXPECT_EQ(r.status, 2) << heatmap << ": " << r.output;
        EXPECT_NE(r.output.find("names the input"), std::string::npos) << r.output;
    }
    EXPECT_EQ(readFile(a), before);
    EXPECT_EQ(runLimited("compare " + a + " " + b + " --heatmap " + dir.file("h.png"), 30).status,
              0);
}

// 10. --spp that the scene's n x n pattern does not divide takes one sample per iteration, so a
// checkpoint of the scene's own pattern cannot continue: the message says that, and how to ask,
// instead of blaming a sample base the user never set.
TEST(BadInputs, ResumeWithAnSppTheSampleBaseDoesNotDivideSaysWhy) {
    TempDir dir;
    dir.write("tri.obj", kTriangleObj);
    const std::string scene =
        dir.write("scene.yaml", "shader: {type: Lambert}\nobject: {filename: tri.obj}\n"
                                "image: {width: 8, height: 8, sample base: 2, iterations: 2}\n");
    const std::string common = " --quiet --backend cpu -o " + dir.file("out.exr");
    ASSERT_EQ(
        runLimited("render " + scene + common + " --checkpoint " + dir.file("ck.exr"), 60).status,
        0);
    const Outcome r =
        runLimited("render " + scene + common + " --spp 10 --resume " + dir.file("ck.exr"), 60);
    ASSERT_FALSE(r.signalled) << r.output;
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("--spp 10 is not a multiple of 4"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("such as 12"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("where this render has"), std::string::npos) << r.output;
    EXPECT_EQ(
        runLimited("render " + scene + common + " --spp 12 --resume " + dir.file("ck.exr"), 60)
            .status,
        0);
}

TEST(BadInputs, SceneMissingIsReportedWithoutALineNumber) {
    TempDir dir;
    const Outcome r = runLimited(
        "render " + dir.file("nosuch.yaml") + " -o " + dir.file("x.exr") + " --quiet", 30);
    ASSERT_FALSE(r.signalled);
    EXPECT_EQ(r.status, 2);
    EXPECT_EQ(r.output.rfind(dir.file("nosuch.yaml") + ": cannot open the scene file", 0), 0u)
        << r.output;
}

} // namespace
} // namespace spw::test
