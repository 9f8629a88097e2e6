#include "host/image/aov_film.h"

#include "host/image/pixel_ranges.h"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <sstream>
#include <stdexcept>

namespace spw {

unsigned parseAovList(const std::string& list) {
    const char* const kKnown = "albedo, normal, camera-normal, depth";
    unsigned passes = 0;
    std::stringstream in(list);
    std::string name;
    while (std::getline(in, name, ',')) {
        if (name == "albedo")
            passes |= kAovAlbedo;
        else if (name == "normal")
            passes |= kAovNormal;
        else if (name == "camera-normal")
            passes |= kAovCameraNormal;
        else if (name == "depth")
            passes |= kAovDepth;
        else
            throw std::invalid_argument("'" + name + "' is not a pass (" + kKnown + ")");
    }
    if (passes == 0) throw std::invalid_argument(std::string("names no pass (") + kKnown + ")");
    return passes;
}

namespace {

// The largest magnitude, as a power of two, that each value may take: a normal's components
// are at most 1, a depth at most kMaxDistance (1e15, under 2^50) and an albedo at most
// kMaxRadiance (1e20, the environment's brightest) times a specular chain's throughput (2^72).
constexpr int kNormalBound = 1, kDepthBound = 50, kAlbedoBound = 72;

} // namespace

AovFilm::AovFilm(int width, int height, int samplesPerIteration, unsigned passes,
                 mat3 cameraToWorld)
    : width_(width), spi_(samplesPerIteration), pixels_(size_t(width) * size_t(height)),
      samples_(pixels_ * size_t(samplesPerIteration)), passes_(passes),
      cameraToWorld_(cameraToWorld), viewAxis_(-glm::normalize(cameraToWorld[2])) {
    for (int k = 0; k < 3; ++k)
        cameraToWorld_[k] = glm::normalize(cameraToWorld_[k]);
    auto place = [&](int& at, int count, int bound) {
        at = values_;
        for (int k = 0; k < count; ++k)
            bound_[values_++] = bound;
    };
    if (passes_ & kAovAlbedo) place(albedoAt_, 3, kAlbedoBound);
    if (passes_ & (kAovNormal | kAovCameraNormal)) place(normalAt_, 3, kNormalBound);
    if (passes_ & kAovDepth) place(depthAt_, 1, kDepthBound);
    // A pixel's iteration sum is at most samplesPerIteration values of 2^bound: 2^126 at most.
    const int logSamples = int(std::ceil(std::log2(double(std::max(1, samplesPerIteration)))));
    for (int k = 0; k < values_; ++k)
        exponent_[k] = 126 - logSamples - bound_[k];
    const size_t words = pixels_ * size_t(values_) * 2;
    iter_.reset(new std::atomic<std::uint64_t>[words]);
    iterCounts_.reset(new std::atomic<std::uint32_t>[pixels_ * 2]);
    if (passes_ & kAovAlbedo) {
        pendingWords_ = (samples_ + 63) / 64;
        pending_.reset(new std::atomic<std::uint64_t>[pendingWords_]);
    }
    sums_.resize(pixels_ * size_t(values_));
    hits_.resize(pixels_);
    albedoSamples_.resize(pixels_);
    iterDirty_ = true; // the sums are not yet zeroed
    beginIteration();
}

size_t AovFilm::bytes() const {
    return pixels_ * (size_t(values_) * (2 * sizeof(std::uint64_t) + sizeof(double)) +
                      2 * sizeof(std::uint32_t) * 2) +
           pendingWords_ * sizeof(std::uint64_t);
}

void AovFilm::beginIteration() {
    if (iterDirty_) // new, or a stopped iteration's: endIteration() zeroes them as it reads them
        forPixels(pixels_, [&](size_t begin, size_t end) {
            for (size_t w = begin * size_t(values_) * 2; w < end * size_t(values_) * 2; ++w)
                iter_[w].store(0, std::memory_order_relaxed);
            for (size_t c = begin * 2; c < end * 2; ++c)
                iterCounts_[c].store(0, std::memory_order_relaxed);
        });
    for (size_t w = 0; w < pendingWords_; ++w)
        pending_[w].store(0, std::memory_order_relaxed);
    iterDirty_ = true;
}

void AovFilm::add(size_t pixel, int k, float v) {
    if (!std::isfinite(v)) return; // a sample's NaN or infinity adds nothing
    const double limit = std::ldexp(1.0, bound_[k]);
    // Exact: a float times a power of two is a double, and its integral part an __int128; the
    // fraction below the value's fixed point (2^-exponent_, far below a float's precision of any
    // value near the bound) is rounded to nearest, the same for every order of adds.
    const double scaled = std::ldexp(std::clamp(double(v), -limit, limit), exponent_[k]);
    const __int128 q = static_cast<__int128>(std::nearbyint(scaled));
    const std::uint64_t lo = std::uint64_t(q);
    std::uint64_t hi = std::uint64_t(q >> 64);
    std::atomic<std::uint64_t>* w = &iter_[(pixel * size_t(values_) + size_t(k)) * 2];
    const std::uint64_t before = w[0].fetch_add(lo, std::memory_order_relaxed);
    if (before + lo < before) ++hi; // the low word's carry
    if (hi != 0) w[1].fetch_add(hi, std::memory_order_relaxed);
}

void AovFilm::addAlbedo(size_t pixel, vec3 albedo) {
    for (int c = 0; c < 3; ++c)
        add(pixel, albedoAt_ + c, albedo[c]);
}

void AovFilm::record(const PathState& path, const SurfaceHit& hit) {
    if (size_t(path.pathId) >= samples_) return; // not a camera path of this film
    const size_t pixel = pixelOf(path.pathId);
    if (normalAt_ >= 0)
        for (int c = 0; c < 3; ++c)
            add(pixel, normalAt_ + c, hit.ns[c]);
    if (depthAt_ >= 0) add(pixel, depthAt_, glm::dot(hit.p, viewAxis_));
    count(pixel, kHitCount);
    if (albedoAt_ >= 0) count(pixel, kAlbedoCount); // its albedo 0 unless one comes
}

void AovFilm::recordAlbedo(const PathState& path, vec3 albedo, bool passesOn) {
    if (!albedoPending(path)) return;
    std::atomic<std::uint64_t>& word = pending_[path.pathId / 64u];
    if (passesOn) { // the specular hit's reflectance (and transmittance) is in the throughput
        if (path.bounce == 0u) word.fetch_or(bit(path.pathId), std::memory_order_relaxed);
        return;
    }
    addAlbedo(pixelOf(path.pathId), path.bounce == 0u ? albedo : path.beta * albedo);
    if (path.bounce != 0u) word.fetch_and(~bit(path.pathId), std::memory_order_relaxed);
}

void AovFilm::recordEscape(const PathState& path, vec3 radiance) {
    if (!(passes_ & kAovAlbedo) || size_t(path.pathId) >= samples_) return;
    const size_t pixel = pixelOf(path.pathId);
    if (path.bounce == 0u) { // the camera ray missed
        addAlbedo(pixel, radiance);
        count(pixel, kAlbedoCount);
        return;
    }
    if (!albedoPending(path)) return;
    addAlbedo(pixel, path.beta * radiance);
    pending_[path.pathId / 64u].fetch_and(~bit(path.pathId), std::memory_order_relaxed);
}

void AovFilm::endIteration() {
    forPixels(pixels_, [&](size_t begin, size_t end) {
        for (size_t pixel = begin; pixel < end; ++pixel) {
            for (int k = 0; k < values_; ++k) {
                std::atomic<std::uint64_t>* w = &iter_[(pixel * size_t(values_) + size_t(k)) * 2];
                const std::uint64_t lo = w[0].exchange(0, std::memory_order_relaxed);
                const std::uint64_t hi = w[1].exchange(0, std::memory_order_relaxed);
                if ((lo | hi) == 0) continue;
                const __int128 q =
                    static_cast<__int128>((static_cast<unsigned __int128>(hi) << 64) | lo);
                sums_[pixel * size_t(values_) + size_t(k)] +=
                    std::ldexp(static_cast<double>(q), -exponent_[k]);
            }
            hits_[pixel] += iterCounts_[pixel * 2 + kHitCount].exchange(0);
            albedoSamples_[pixel] += iterCounts_[pixel * 2 + kAlbedoCount].exchange(0);
        }
    });
    iterDirty_ = false;
}

std::vector<std::string> AovFilm::channelNames() const {
    std::vector<std::string> names;
    auto layer = [&](const char* name, std::initializer_list<const char*> channels) {
        for (const char* c : channels)
            names.push_back(std::string(name) + "." + c);
    };
    if (passes_ & kAovAlbedo) layer("Denoising Albedo", {"R", "G", "B"});
    if (passes_ & kAovNormal) layer("Normal", {"X", "Y", "Z"});
    if (passes_ & kAovCameraNormal) layer("Camera Normal", {"X", "Y", "Z"});
    if (passes_ & kAovDepth) layer("Depth", {"Z"});
    return names;
}

std::vector<std::pair<std::string, std::string>> AovFilm::layerNotes() const {
    std::vector<std::pair<std::string, std::string>> notes;
    if (passes_ & kAovAlbedo)
        notes.emplace_back("spillway/Denoising Albedo",
                           "the directional albedo of what the pixel shows (diffuse and "
                           "Fresnel-weighted specular), through perfect mirrors and smooth glass "
                           "to the next hit");
    if (passes_ & kAovNormal)
        notes.emplace_back("spillway/Normal",
                           "world space: the scene's axes, +Y up (glTF's); unit per sample, "
                           "averaged per pixel");
    if (passes_ & kAovCameraNormal)
        notes.emplace_back("spillway/Camera Normal",
                           "camera space: +X right, +Y up, +Z toward the camera; unit per "
                           "sample, averaged per pixel");
    if (passes_ & kAovDepth)
        notes.emplace_back("spillway/Depth",
                           "distance along the camera's viewing axis; 1e10 where no sample hit");
    return notes;
}

void AovFilm::rows(int y0, int y1, float* out) const {
    for (int y = y0; y < y1; ++y)
        for (int x = 0; x < width_; ++x) {
            const size_t pixel = size_t(y) * size_t(width_) + size_t(x);
            const double* sum = &sums_[pixel * size_t(values_)];
            auto mean = [&](int k, std::uint32_t n) { return n == 0 ? 0.0f : float(sum[k] / n); };
            const std::uint32_t n = hits_[pixel];
            if (passes_ & kAovAlbedo)
                for (int k = 0; k < 3; ++k)
                    *out++ = mean(albedoAt_ + k, albedoSamples_[pixel]);
            const vec3 normal = normalAt_ < 0 ? vec3(0.0f)
                                              : vec3(mean(normalAt_, n), mean(normalAt_ + 1, n),
                                                     mean(normalAt_ + 2, n));
            if (passes_ & kAovNormal)
                for (int k = 0; k < 3; ++k)
                    *out++ = normal[k];
            if (passes_ & kAovCameraNormal) {
                // The world's normal on the camera's axes: the transpose of cameraToWorld.
                for (int k = 0; k < 3; ++k)
                    *out++ = glm::dot(cameraToWorld_[k], normal);
            }
            if (passes_ & kAovDepth) *out++ = n == 0 ? 1e10f : mean(depthAt_, n);
        }
}

} // namespace spw
