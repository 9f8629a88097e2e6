#include "host/backend/render_config.h"

#include <stdexcept>

namespace spw {
namespace {

// One option's names, in the order the error message lists them.
template <class E, size_t N>
E parseChoice(const char* what, const std::string& name,
              const std::pair<const char*, E> (&choices)[N]) {
    std::string list;
    for (size_t i = 0; i < N; ++i) {
        if (name == choices[i].first) return choices[i].second;
        list += (i == 0 ? "" : i + 1 == N ? " or " : ", ") + std::string(choices[i].first);
    }
    throw std::invalid_argument("unknown " + std::string(what) + " '" + name + "' (" + list + ")");
}
template <class E, size_t N>
const char* nameOf(E value, const std::pair<const char*, E> (&choices)[N]) {
    for (const auto& c : choices)
        if (c.second == value) return c.first;
    return "?";
}

constexpr std::pair<const char*, BackendKind> kBackends[] = {{"auto", BackendKind::Auto},
                                                             {"vulkan", BackendKind::Vulkan},
                                                             {"cpu", BackendKind::Cpu},
                                                             {"reference", BackendKind::Reference}};
constexpr std::pair<const char*, RayFormat> kRayFormats[] = {{"compact", RayFormat::Compact},
                                                             {"full", RayFormat::Full}};
constexpr std::pair<const char*, RaySortMode> kRaySorts[] = {{"auto", RaySortMode::Auto},
                                                             {"morton", RaySortMode::Morton},
                                                             {"median", RaySortMode::Median},
                                                             {"off", RaySortMode::Off}};
constexpr std::pair<const char*, ShadingMode> kShadings[] = {
    {"sorted", ShadingMode::Sorted}, {"megakernel", ShadingMode::Megakernel}};
constexpr std::pair<const char*, HitSortMode> kHitSorts[] = {
    {"auto", HitSortMode::Auto}, {"on", HitSortMode::On}, {"off", HitSortMode::Off}};
constexpr std::pair<const char*, TextureFilter> kTextureFilters[] = {
    {"cone", TextureFilter::Cone}, {"finest", TextureFilter::Finest}};

} // namespace

BackendKind parseBackend(const std::string& name) {
    return parseChoice("backend", name, kBackends);
}
const char* backendName(BackendKind kind) {
    return nameOf(kind, kBackends);
}
RayFormat parseRayFormat(const std::string& name) {
    return parseChoice("ray format", name, kRayFormats);
}
const char* rayFormatName(RayFormat format) {
    return nameOf(format, kRayFormats);
}
RaySortMode parseRaySortMode(const std::string& name) {
    return parseChoice("ray sort", name, kRaySorts);
}
const char* raySortName(RaySortMode mode) {
    return nameOf(mode, kRaySorts);
}
ShadingMode parseShadingMode(const std::string& name) {
    return parseChoice("shading", name, kShadings);
}
const char* shadingModeName(ShadingMode mode) {
    return nameOf(mode, kShadings);
}
HitSortMode parseHitSortMode(const std::string& name) {
    return parseChoice("hit sort", name, kHitSorts);
}
TextureFilter parseTextureFilter(const std::string& name) {
    return parseChoice("texture filter", name, kTextureFilters);
}

} // namespace spw
