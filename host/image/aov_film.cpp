#include "host/image/aov_film.h"

#include <sstream>
#include <stdexcept>

namespace spw {

unsigned parseAovList(const std::string& list) {
    unsigned passes = 0;
    std::stringstream in(list);
    std::string name;
    while (std::getline(in, name, ',')) {
        if (name == "albedo")
            passes |= kAovAlbedo;
        else if (name == "normal")
            passes |= kAovNormal;
        else if (name == "depth")
            passes |= kAovDepth;
        else
            throw std::invalid_argument("'" + name + "' is not a pass (albedo, normal, depth)");
    }
    if (passes == 0) throw std::invalid_argument("names no pass (albedo, normal, depth)");
    return passes;
}

AovFilm::AovFilm(int width, int height, int samplesPerIteration, unsigned passes, vec3 viewAxis)
    : width_(width), height_(height), spi_(samplesPerIteration), passes_(passes),
      viewAxis_(viewAxis) {
    const size_t pixels = size_t(width) * size_t(height);
    slots_.resize(pixels * size_t(spi_) * kValues);
    hit_.resize(pixels * size_t(spi_));
    sums_.resize(pixels * kValues);
    hits_.resize(pixels);
}

void AovFilm::beginIteration() {
    std::fill(hit_.begin(), hit_.end(), std::uint8_t(0));
}

void AovFilm::record(uint pathId, const SurfaceHit& hit) {
    if (size_t(pathId) >= hit_.size()) return; // not a camera path of this film
    float* slot = &slots_[size_t(pathId) * kValues];
    slot[0] = hit.albedo.x, slot[1] = hit.albedo.y, slot[2] = hit.albedo.z;
    slot[3] = hit.ns.x, slot[4] = hit.ns.y, slot[5] = hit.ns.z;
    slot[6] = glm::dot(hit.p, viewAxis_);
    hit_[pathId] = 1;
}

void AovFilm::endIteration() {
    const size_t pixels = hits_.size();
    for (size_t pixel = 0; pixel < pixels; ++pixel)
        for (size_t s = 0; s < size_t(spi_); ++s) {
            const size_t path = pixel * size_t(spi_) + s;
            if (!hit_[path]) continue;
            ++hits_[pixel];
            for (int k = 0; k < kValues; ++k)
                sums_[pixel * kValues + size_t(k)] += double(slots_[path * kValues + size_t(k)]);
        }
}

std::vector<std::string> AovFilm::channelNames() const {
    std::vector<std::string> names;
    if (passes_ & kAovAlbedo)
        for (const char* c : {"R", "G", "B"})
            names.push_back(std::string("Denoising Albedo.") + c);
    if (passes_ & kAovNormal)
        for (const char* c : {"X", "Y", "Z"})
            names.push_back(std::string("Normal.") + c);
    if (passes_ & kAovDepth) names.push_back("Depth.Z");
    return names;
}

void AovFilm::rows(int y0, int y1, float* out) const {
    for (int y = y0; y < y1; ++y)
        for (int x = 0; x < width_; ++x) {
            const size_t pixel = size_t(y) * size_t(width_) + size_t(x);
            const std::uint32_t n = hits_[pixel];
            auto mean = [&](int k) {
                return n == 0 ? 0.0f : float(sums_[pixel * kValues + size_t(k)] / n);
            };
            if (passes_ & kAovAlbedo)
                for (int k = 0; k < 3; ++k)
                    *out++ = mean(k);
            if (passes_ & kAovNormal)
                for (int k = 3; k < 6; ++k)
                    *out++ = mean(k);
            if (passes_ & kAovDepth) *out++ = n == 0 ? 1e10f : mean(6);
        }
}

} // namespace spw
