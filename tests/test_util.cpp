#include "test_util.h"

#include "host/image/image_io.h"
#include "host/loaders/scene_loader.h"
#include "host/scene/camera.h"
#include "host/vk/context.h"

#include <OpenImageIO/imagebuf.h>
#include <gtest/gtest.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <sys/file.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

namespace spw::test {

namespace {

// Every Vulkan render in the suite runs under the Khronos validation layer, the spillway
// processes the CLI tests start included (they inherit the environment), and any message the
// layer reports during a test fails it: the listener names the test and the process exits 1
// (ctest runs one test per process), as a listener may not add failures itself. The one test
// that provokes a message on purpose (to show the layer is live) is exempt. In the sanitized
// build only the Vulkan* tests ask for the layer (and run without leak detection): LeakSanitizer
// reports the layer's allocations after the loader has unloaded it (docs/testing.md).
class ValidationListener : public ::testing::EmptyTestEventListener {
    std::uint64_t before_ = 0;
    bool failed_ = false;
    void OnTestStart(const ::testing::TestInfo&) override {
        before_ = vk::validationMessageCount();
    }
    void OnTestEnd(const ::testing::TestInfo& info) override {
        const std::uint64_t messages = vk::validationMessageCount() - before_;
        if (messages == 0 || std::string(info.name()) == "ValidationLayerIsLiveAndCounted") return;
        std::fprintf(stderr,
                     "FAILED: the Vulkan validation layer reported %llu message(s) during %s.%s "
                     "(see above)\n",
                     (unsigned long long)messages, info.test_suite_name(), info.name());
        failed_ = true;
    }
    void OnTestProgramEnd(const ::testing::UnitTest&) override {
        if (failed_) std::_Exit(1);
    }
};

const bool kValidationEverywhere = [] {
    if (!kAddressSanitizer) ::setenv("SPILLWAY_VK_VALIDATION", "1", 1);
    ::testing::UnitTest::GetInstance()->listeners().Append(new ValidationListener);
    return true;
}();

} // namespace

TempDir::TempDir() {
    std::random_device rd;
    for (int tries = 0; tries < 100; ++tries) {
        auto p = std::filesystem::temp_directory_path() / ("spillway-test-" + std::to_string(rd()));
        if (std::filesystem::create_directory(p)) {
            path_ = p.string();
            return;
        }
    }
    throw std::runtime_error("cannot create a temporary folder");
}

TempDir::~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
}

std::string TempDir::write(const std::string& name, const std::string& text) const {
    std::string p = file(name);
    std::filesystem::create_directories(std::filesystem::path(p).parent_path());
    std::ofstream(p) << text;
    return p;
}

std::string sourceDir() {
    return SPILLWAY_SOURCE_DIR;
}

std::string runCached(const std::string& key, const std::function<std::string()>& make) {
    const char* dir = std::getenv("SPILLWAY_TEST_CACHE");
    if (!dir || !*dir) return make();
    char name[32];
    std::snprintf(name, sizeof name, "%016zx", std::hash<std::string>{}(key));
    const std::string path = std::string(dir) + "/" + name;
    // The lock is held while the value is made: a second process asking waits, then reads it.
    const int lock = ::open((path + ".lock").c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0644);
    if (lock < 0 || ::flock(lock, LOCK_EX) != 0) {
        if (lock >= 0) ::close(lock);
        ADD_FAILURE() << "cannot lock " << path << ".lock: " << std::strerror(errno);
        return make();
    }
    // The file holds the key, a NUL, then the value: another key of the same hash is remade.
    std::string kept = readFile(path), value;
    if (kept.size() > key.size() && kept.compare(0, key.size(), key) == 0 &&
        kept[key.size()] == '\0') {
        value = kept.substr(key.size() + 1);
    } else {
        value = make();
        const std::string partial = path + ".partial";
        {
            std::ofstream out(partial, std::ios::binary);
            out << key << '\0' << value;
        }
        std::filesystem::rename(partial, path);
    }
    ::close(lock);
    return value;
}

std::string readFile(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

std::string replaceAll(std::string s, const std::string& key, const std::string& value) {
    for (size_t at = 0; (at = s.find(key, at)) != std::string::npos; at += value.size())
        s.replace(at, key.size(), value);
    return s;
}

std::string loadError(const std::string& path) {
    try {
        loadScene(path);
    } catch (const SceneError& e) {
        return e.what();
    }
    return "";
}

std::vector<std::string> backendsUnderTest() {
    return {"reference", "cpu", "vulkan"};
}
std::string binary() {
    return SPILLWAY_BINARY;
}

CommandResult runSpillway(const std::string& args) {
    return runShell(binary() + " " + args);
}

CommandResult runShell(const std::string& command) {
    const std::string cmd = command + " 2>&1";
    FILE* p = popen(cmd.c_str(), "r");
    if (!p) return {-1, "popen failed"};
    std::string out;
    char buf[4096];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, p)) > 0)
        out.append(buf, n);
    int st = pclose(p);
    return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

double mean(const std::vector<float>& rgb) {
    double s = 0;
    for (float v : rgb)
        s += v;
    return rgb.empty() ? 0.0 : s / double(rgb.size());
}

MeanError meanAndError(const std::vector<float>& rgb) {
    const size_t n = rgb.size() / 3;
    double s = 0, s2 = 0;
    for (size_t i = 0; i < n; ++i) {
        double v = (double(rgb[3 * i]) + rgb[3 * i + 1] + rgb[3 * i + 2]) / 3.0;
        s += v;
        s2 += v * v;
    }
    double m = s / double(n);
    double var = (s2 - double(n) * m * m) / double(n - 1);
    return {m, std::sqrt(std::max(0.0, var) / double(n))};
}

void PixelStats::add(const std::vector<float>& img) {
    if (sum.empty()) sum.assign(img.size() / 3, 0.0), sum2.assign(img.size() / 3, 0.0);
    for (size_t i = 0; i < sum.size(); ++i) {
        const double v = (double(img[3 * i]) + img[3 * i + 1] + img[3 * i + 2]) / 3.0;
        sum[i] += v;
        sum2[i] += v * v;
    }
    ++n;
}

double PixelStats::variance(size_t i) const {
    return std::max(0.0, (sum2[i] - n * mean(i) * mean(i)) / (n - 1));
}

double PixelStats::stderror(size_t i) const {
    return std::sqrt(meanVariance(i));
}

double PixelStats::averageVariance() const {
    double v = 0;
    for (size_t i = 0; i < pixels(); ++i)
        v += variance(i);
    return v / double(pixels());
}

MeanError PixelStats::imageMean() const {
    double m = 0, var = 0;
    for (size_t i = 0; i < pixels(); ++i)
        m += mean(i), var += meanVariance(i);
    const double p = double(pixels());
    return {m / p, std::sqrt(var) / p};
}

std::vector<std::vector<float>> iterationImages(const Scene& scene, const RenderConfig& config) {
    std::vector<std::vector<float>> images;
    render(scene, config,
           [&](int, int, const Film& film) { images.push_back(film.lastIterationImage()); });
    return images;
}

PixelStats pairedDifference(const std::vector<std::vector<float>>& a,
                            const std::vector<std::vector<float>>& b) {
    PixelStats d;
    EXPECT_EQ(a.size(), b.size()) << "iterations";
    for (size_t k = 0; k < std::min(a.size(), b.size()); ++k) {
        EXPECT_EQ(a[k].size(), b[k].size());
        std::vector<float> diff(a[k].size());
        for (size_t i = 0; i < diff.size(); ++i)
            diff[i] = a[k][i] - b[k][i];
        d.add(diff);
    }
    return d;
}

double worstBlockZ(int width, int height, const std::function<double(size_t)>& difference,
                   const std::function<double(size_t)>& variance, double allowed) {
    double worst = 0;
    for (int by = 0; by < height; by += 8)
        for (int bx = 0; bx < width; bx += 8) {
            double sum = 0, var = 0, allowance = 0;
            for (int y = by; y < std::min(height, by + 8); ++y)
                for (int x = bx; x < std::min(width, bx + 8); ++x) {
                    const size_t i = size_t(y) * size_t(width) + size_t(x);
                    sum += difference(i);
                    var += variance(i);
                    allowance += allowed;
                }
            const double excess = std::max(0.0, std::fabs(sum) - allowance);
            if (excess > 0.0) worst = std::max(worst, excess / std::sqrt(var));
        }
    return worst;
}

void expectNoPairedDifference(const PixelStats& d, int width, int height, const std::string& what,
                              double tolerance) {
    ASSERT_EQ(d.pixels(), size_t(width) * size_t(height)) << what;
    ASSERT_GE(d.n, 2) << what;
    const MeanError m = d.imageMean();
    size_t outliers = 0;
    for (size_t i = 0; i < d.pixels(); ++i)
        if (std::fabs(d.mean(i)) > 4.5 * d.stderror(i) + tolerance + 1e-12) ++outliers;
    const double worstZ = worstBlockZ(
        width, height, [&](size_t i) { return d.mean(i); },
        [&](size_t i) { return d.meanVariance(i); }, tolerance);
    std::printf("  %-40s paired difference %+.3g +- %.3g (z %+.2f), worst 8x8 block |z| %.2f, "
                "outlier pixels %zu/%zu\n",
                what.c_str(), m.mean, m.stderror, m.stderror > 0 ? m.mean / m.stderror : 0.0,
                worstZ, outliers, d.pixels());
    EXPECT_LE(std::fabs(m.mean), 4.0 * m.stderror + tolerance) << what;
    EXPECT_LT(worstZ, 4.5) << what;
    EXPECT_LE(double(outliers), 0.001 * double(d.pixels())) << what;
}

std::string insideCubeObj() {
    // 8 corners; faces wound so that cross(v1 - v0, v2 - v0) points into the cube.
    return "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\n"
           "v -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
           "f 1 2 3 4\n"  // z = -1, normal +z
           "f 5 8 7 6\n"  // z = +1, normal -z
           "f 1 4 8 5\n"  // x = -1, normal +x
           "f 2 6 7 3\n"  // x = +1, normal -x
           "f 1 5 6 2\n"  // y = -1, normal +y
           "f 4 3 7 8\n"; // y = +1, normal -y
}

std::string stripesPng(const TempDir& dir) {
    OIIO::ImageBuf img(OIIO::ImageSpec(8, 8, 3, OIIO::TypeDesc::UINT8));
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
            const float c[3] = {x < 4 ? 1.0f : 0.2f, 0.3f + 0.1f * float(y), x % 2 ? 0.9f : 0.1f};
            img.setpixel(x, y, c);
        }
    EXPECT_TRUE(img.write(dir.file("stripes.png")));
    return readFile(dir.file("stripes.png"));
}

BackendKind backendNamed(const std::string& name) {
    return name == "reference" ? BackendKind::Reference
           : name == "cpu"     ? BackendKind::Cpu
                               : BackendKind::Vulkan;
}

std::string floorObj(float h) {
    char buf[256];
    std::snprintf(buf, sizeof buf, "v %g 0 %g\nv %g 0 %g\nv %g 0 %g\nv %g 0 %g\nf 1 2 3 4\n", -h,
                  -h, -h, h, h, h, h, -h);
    return buf;
}

Scene floorUnderLight(TempDir& dir, int iterations, const std::string& settings,
                      const std::string& light) {
    dir.write("floor.obj", floorObj(4.0f));
    return loadScene(dir.write(
        "floor.yaml", "image: {width: 16, height: 16, sample base: 1, iterations: " +
                          std::to_string(iterations) + "}\nsettings: {" + settings +
                          "}\n"
                          "camera: {look at: {eye: [0.2, 0.6, 0.1], target: [0.2, 0, 0.1], "
                          "up: [0, 0, -1]}, fov: 90}\n"
                          "sampler: {type: Grid}\n"
                          "object: {filename: floor.obj, shader: 0}\n"
                          "shader: {type: Lambert, reflectance: 0.5}\n"
                          "light: " +
                          light + "\n"));
}

vec3 floorPointAtPixelCentre(const Scene& scene, int x, int y) {
    const CameraRay r = CameraModel(scene, 1).generate(uint(x), uint(y), 0, 0, 0);
    const vec3 o = vec3(scene.origin) + r.origin; // the world is camera-relative
    return o + r.dir * (-o.y / r.dir.y);
}

std::string childLogPath() {
    return (std::filesystem::temp_directory_path() /
            ("spillway-child-" + std::to_string(getpid()) + ".log"))
        .string();
}

bool waitForChildOutput(pid_t pid, const std::string& text) {
    for (int i = 0; i < 2400; ++i) {
        if (readFile(childLogPath()).find(text) != std::string::npos) return true;
        // Exited (a zombie not yet waited for): the text will not come.
        const std::string stat = readFile("/proc/" + std::to_string(pid) + "/stat");
        const size_t close = stat.rfind(')');
        if (stat.empty() ||
            (close != std::string::npos && close + 2 < stat.size() && stat[close + 2] == 'Z'))
            return false;
        std::this_thread::sleep_for(std::chrono::milliseconds(25));
    }
    return false;
}

std::string smallCornellBox(const TempDir& dir, int width, int height, const std::string& name,
                            const std::string& light) {
    std::string text = readFile(sourceDir() + "/scenes/cornell-box.yaml");
    text = replaceAll(text, "{width: 256, height: 256, sample base: 2, iterations: 16}",
                      "{width: " + std::to_string(width) + ", height: " + std::to_string(height) +
                          ", sample base: 1, iterations: 16}");
    text = replaceAll(text, "filename: cornell-box/",
                      "filename: " + sourceDir() + "/scenes/cornell-box/");
    text = replaceAll(text, "colour: [17, 12, 4]", "colour: " + light);
    return dir.write(name, text);
}

bool samePixels(const std::string& a, const std::string& b) {
    const ImageRGB x = readImage(a), y = readImage(b);
    return x.width == y.width && x.height == y.height && x.rgb.size() == y.rgb.size() &&
           std::memcmp(x.rgb.data(), y.rgb.data(), x.rgb.size() * sizeof(float)) == 0;
}

ChildResult runChild(const std::vector<std::string>& args,
                     const std::function<void(pid_t)>& whileRunning) {
    const std::string log = childLogPath();
    pid_t pid = fork();
    if (pid == 0) {
        FILE* f = std::freopen(log.c_str(), "w", stderr);
        (void)f;
        dup2(2, 1);
        std::vector<char*> argv;
        std::string bin = binary();
        argv.push_back(bin.data());
        std::vector<std::string> copy = args;
        for (std::string& a : copy)
            argv.push_back(a.data());
        argv.push_back(nullptr);
        execv(bin.c_str(), argv.data());
        _exit(127);
    }
    if (whileRunning) whileRunning(pid);
    int st = 0;
    struct rusage ru {};
    wait4(pid, &st, 0, &ru);
    std::ifstream in(log);
    std::string out((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::filesystem::remove(log);
    return {WIFEXITED(st) ? WEXITSTATUS(st) : -WTERMSIG(st), ru.ru_maxrss, out};
}

size_t filesIn(const std::string& dir) {
    size_t n = 0;
    for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir))
        ++n;
    return n;
}

} // namespace spw::test
