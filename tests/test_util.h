// Helpers shared by the test suites: scratch folders, scene files written on the fly, running
// the spillway binary, and statistics over images.
#pragma once

#include "host/render/render.h"
#include "host/scene/scene.h"

#include <functional>
#include <string>
#include <vector>

#include <sys/types.h>

namespace spw::test {

// True in the sanitized build (scripts/test.sh's build-asan/): a process's RSS there includes
// AddressSanitizer's shadow memory and quarantine, so bounds on RSS are not checked in it.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kAddressSanitizer = true;
#else
constexpr bool kAddressSanitizer = false;
#endif
#else
constexpr bool kAddressSanitizer = false;
#endif
// The long statistical tests take this many times fewer samples under the sanitizers, which
// slow them 5-10x (their tolerances are computed from, or scaled with, the samples taken).
constexpr int kSanitizedFewer = kAddressSanitizer ? 4 : 1;

// A fresh folder under the system temp dir, removed with everything in it on destruction.
class TempDir {
  public:
    TempDir();
    ~TempDir();
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    const std::string& path() const { return path_; }
    std::string file(const std::string& name) const { return path_ + "/" + name; }
    // Writes `text` to `name` inside the folder and returns its path.
    std::string write(const std::string& name, const std::string& text) const;

  private:
    std::string path_;
};

// Every backend the suites must hold for. Vulkan runs on lavapipe in CI (always installed).
std::vector<std::string> backendsUnderTest();

std::string sourceDir();
std::string binary();

// The whole file as bytes ("" when it cannot be read).
std::string readFile(const std::string& path);
// `s` with every `key` replaced by `value` (placeholders in command lines).
std::string replaceAll(std::string s, const std::string& key, const std::string& value);

struct CommandResult {
    int status;         // exit status, or -1 when killed by a signal
    std::string output; // stdout and stderr together
};
CommandResult runSpillway(const std::string& args);
// Runs a shell command line, stdout and stderr captured together; status -1 unless it exited.
CommandResult runShell(const std::string& command);

// Runs the binary (fork and exec), stdout and stderr captured together; `whileRunning` is
// called with the child's pid before waiting for it. Status: the exit status, or -signal.
struct ChildResult {
    int status;
    long maxRssKiB; // the child's peak resident set
    std::string output;
};
ChildResult runChild(const std::vector<std::string>& args,
                     const std::function<void(pid_t)>& whileRunning = {});
// Entries in a folder.
size_t filesIn(const std::string& dir);
// Where runChild collects the running child's output (readable while it runs).
std::string childLogPath();
// Waits (up to 60 s) until the running child's output contains `text`; false if it does not,
// or if the child `pid` exits first.
bool waitForChildOutput(pid_t pid, const std::string& text);
// The scenes/cornell-box.yaml Cornell box at width x height with one sample per pixel and
// iteration (many short iterations), its light colour `light`, written as dir/name.
std::string smallCornellBox(const TempDir& dir, int width, int height,
                            const std::string& name = "box.yaml",
                            const std::string& light = "[17, 12, 4]");
// The SceneError message that loading scene `path` throws ("" where it loads).
std::string loadError(const std::string& path);
// Whether two image files hold the same pixels, bit for bit.
bool samePixels(const std::string& a, const std::string& b);

// What `make` returns, made once for a whole scripts/test.sh run: kept as a file named by a hash
// of `key` in the folder SPILLWAY_TEST_CACHE names (test.sh makes one for its run and removes it
// at the end, so both its suites share it and no run reads another's), under a lock, so that
// tests running in parallel wait for one another rather than each making it. Without the
// variable, make() each time. `key` must name everything the value depends on but the code
// (one run builds one tree).
std::string runCached(const std::string& key, const std::function<std::string()>& make);

// Mean of the channel average over all pixels.
double mean(const std::vector<float>& rgb);
// Mean and standard error of the mean of a per-pixel quantity (channel average), treating
// pixels as independent samples.
struct MeanError {
    double mean;
    double stderror;
};
MeanError meanAndError(const std::vector<float>& rgb);

// Per-pixel statistics of the channel average over iterations, each iteration an independent
// estimate (feed it Film::lastIterationImage() from a render callback).
struct PixelStats {
    std::vector<double> sum, sum2;
    int n = 0;
    void add(const std::vector<float>& img);
    size_t pixels() const { return sum.size(); }
    double mean(size_t i) const { return sum[i] / n; }
    // Sample variance of pixel i's per-iteration values.
    double variance(size_t i) const;
    // Variance and standard error of pixel i's mean.
    double meanVariance(size_t i) const { return variance(i) / n; }
    double stderror(size_t i) const;
    // The per-iteration variance averaged over pixels: how noisy a strategy is.
    double averageVariance() const;
    // The image mean and its standard error (pixels independent).
    MeanError imageMean() const;
};

// The images of a render's iterations, one by one (Film::lastIterationImage() after each).
std::vector<std::vector<float>> iterationImages(const Scene& scene, const RenderConfig& config);

// The per-iteration difference a - b of two renders, as PixelStats. For renders that share
// their random numbers (same seed, same sample counts) most of the noise cancels iteration by
// iteration: what is left is the difference between the two renderers, and its standard errors
// come from its own spread, far smaller than either render's (pixels and iterations independent).
PixelStats pairedDifference(const std::vector<std::vector<float>>& a,
                            const std::vector<std::vector<float>>& b);

// The largest |z| over the image's 8x8 blocks of a per-pixel difference: |sum of the
// differences| less `allowed` per pixel, over the square root of the sum of their variances
// (a block whose difference is within the allowance counts 0).
double worstBlockZ(int width, int height, const std::function<double(size_t)>& difference,
                   const std::function<double(size_t)>& variance, double allowed = 0.0);

// Asserts that a paired difference has mean zero: over the image within 4 standard errors, no
// 8x8 block beyond 4.5, and at most 0.1 % of pixels beyond 4.5 (a difference that is exactly 0
// everywhere passes). `tolerance`: a difference per pixel that is allowed on top (for scenes
// that are the same only up to float rounding of their input). Prints the figures, labelled `what`.
void expectNoPairedDifference(const PixelStats& d, int width, int height, const std::string& what,
                              double tolerance = 0.0);

// An axis-aligned box [-1,1]^3 whose faces point inward, as OBJ text.
std::string insideCubeObj();
// A square [-h,h]^2 at y = 0 facing +Y, as OBJ text.
std::string floorObj(float halfSize);
// An 8 x 8 PNG of coloured stripes, none of them black (for an emission map), as its bytes;
// written to dir/stripes.png on the way.
std::string stripesPng(const TempDir& dir);
// The backend a name of backendsUnderTest() names.
BackendKind backendNamed(const std::string& name);

// The scene of the per-pixel closed-form tests: a Lambert floor of albedo 0.5 (floorObj(4)) seen
// from 0.6 above by a 90-degree camera looking down, 16 x 16 pixels, the Grid sampler (every
// sample at the pixel centre), `iterations` of one sample, under `light` (a light entry), with
// `settings` (the settings map's entries, max depth 1 among them). Returns the loaded scene.
Scene floorUnderLight(TempDir& dir, int iterations, const std::string& settings,
                      const std::string& light);
// floorUnderLight's quad light: 1 x 0.5, intensity 3, facing down from 1 above the floor (its
// corners (+-0.5, 1, +-0.25)).
constexpr const char* kQuadOverFloor =
    "{type: Quad, translation: [0, 1, 0], rotation: [90, 0, 0], scale: [1, 0.5], intensity: 3}";
// The point of the floor y = 0, in the scene file's coordinates, that pixel (x, y)'s centre sees.
vec3 floorPointAtPixelCentre(const Scene& scene, int x, int y);

} // namespace spw::test
