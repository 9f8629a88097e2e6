#include "host/image/aov_film.h"

#include <algorithm>
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

AovFilm::AovFilm(int width, int height, int samplesPerIteration, unsigned passes,
                 mat3 cameraToWorld)
    : width_(width), spi_(samplesPerIteration), passes_(passes), cameraToWorld_(cameraToWorld),
      viewAxis_(-glm::normalize(cameraToWorld[2])) {
    for (int k = 0; k < 3; ++k)
        cameraToWorld_[k] = glm::normalize(cameraToWorld_[k]);
    const size_t pixels = size_t(width) * size_t(height);
    slots_.resize(pixels * size_t(spi_) * kValues);
    state_.resize(pixels * size_t(spi_));
    if (passes_ & kAovAlbedo) chain_.resize(pixels * size_t(spi_));
    sums_.resize(pixels * kValues);
    hits_.resize(pixels);
    albedoSamples_.resize(pixels);
}

void AovFilm::beginIteration() {
    std::fill(state_.begin(), state_.end(), std::uint8_t(kMissed));
}

void AovFilm::record(uint pathId, const SurfaceHit& hit) {
    if (size_t(pathId) >= state_.size()) return; // not a camera path of this film
    float* slot = &slots_[size_t(pathId) * kValues];
    slot[0] = slot[1] = slot[2] = 0.0f; // until recordAlbedo
    slot[3] = hit.ns.x, slot[4] = hit.ns.y, slot[5] = hit.ns.z;
    slot[6] = glm::dot(hit.p, viewAxis_);
    state_[pathId] = kHit;
}

void AovFilm::recordAlbedo(uint pathId, vec3 albedo, bool passesOn) {
    if (!albedoPending(pathId)) return;
    std::uint8_t& state = state_[pathId];
    vec3& through = chain_[pathId];
    if (state == kHit) through = vec3(1.0f);
    if (passesOn) {
        through *= albedo; // the specular hit's reflectance (and transmittance)
        state = kThroughSpecular;
        return;
    }
    float* slot = &slots_[size_t(pathId) * kValues];
    const vec3 a = through * albedo;
    slot[0] = a.x, slot[1] = a.y, slot[2] = a.z;
    state = kAlbedoDone;
}

void AovFilm::recordEscape(uint pathId, vec3 radiance) {
    if (!(passes_ & kAovAlbedo) || size_t(pathId) >= state_.size()) return;
    std::uint8_t& state = state_[pathId];
    if (state != kMissed && state != kThroughSpecular) return;
    const vec3 a = state == kMissed ? radiance : chain_[pathId] * radiance;
    float* slot = &slots_[size_t(pathId) * kValues];
    slot[0] = a.x, slot[1] = a.y, slot[2] = a.z;
    state = state == kMissed ? kEscaped : kAlbedoDone;
}

void AovFilm::endIteration() {
    const size_t pixels = hits_.size();
    for (size_t pixel = 0; pixel < pixels; ++pixel)
        for (size_t s = 0; s < size_t(spi_); ++s) {
            const size_t path = pixel * size_t(spi_) + s;
            if (state_[path] == kMissed) continue;
            ++albedoSamples_[pixel];
            const int values = state_[path] == kEscaped ? 3 : kValues; // an escape: albedo alone
            if (values == kValues) ++hits_[pixel];
            for (int k = 0; k < values; ++k)
                sums_[pixel * kValues + size_t(k)] += double(slots_[path * kValues + size_t(k)]);
        }
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
            const std::uint32_t n = hits_[pixel];
            auto mean = [&](int k) {
                return n == 0 ? 0.0f : float(sums_[pixel * kValues + size_t(k)] / n);
            };
            const std::uint32_t seen = albedoSamples_[pixel];
            if (passes_ & kAovAlbedo)
                for (int k = 0; k < 3; ++k)
                    *out++ = seen == 0 ? 0.0f : float(sums_[pixel * kValues + size_t(k)] / seen);
            const vec3 normal(mean(3), mean(4), mean(5));
            if (passes_ & kAovNormal)
                for (int k = 0; k < 3; ++k)
                    *out++ = normal[k];
            if (passes_ & kAovCameraNormal) {
                // The world's normal on the camera's axes: the transpose of cameraToWorld.
                for (int k = 0; k < 3; ++k)
                    *out++ = glm::dot(cameraToWorld_[k], normal);
            }
            if (passes_ & kAovDepth) *out++ = n == 0 ? 1e10f : mean(6);
        }
}

} // namespace spw
