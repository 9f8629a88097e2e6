// The scene file's render-wide entries (settings_loader.h).
#include "host/loaders/settings_loader.h"
#include "host/image/image_io.h"
#include "host/scene/settings_table.h"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

namespace spw::scene_file {
namespace {
// Largest image the loader accepts (image_io.h).
constexpr long long kMaxPixels = kMaxImagePixels;
constexpr int kMaxDimension = 1 << 15;
constexpr int kMaxSampleBase = 256;
} // namespace

void readImage(const Reader& rd, const YAML::Node& n, ImageSettings& img) {
    rd.checkKeys(n, "image", {"width", "height", "sample base", "iterations"});
    if (n["width"]) img.width = int(rd.integer(n["width"], "image width", 1, kMaxDimension));
    if (n["height"]) img.height = int(rd.integer(n["height"], "image height", 1, kMaxDimension));
    if (n["sample base"])
        img.sampleBase = int(rd.integer(n["sample base"], "sample base", 1, kMaxSampleBase));
    if (n["iterations"])
        img.iterations = int(rd.integer(n["iterations"], "iterations", 1, 1 << 24));
    if ((long long)img.width * img.height > kMaxPixels)
        rd.fail(n, "image of " + std::to_string(img.width) + "x" + std::to_string(img.height) +
                       " pixels is larger than the " + std::to_string(kMaxPixels) +
                       " pixels Spillway renders");
    // Render-wide sample indices are 32-bit (they key the random numbers): refuse more samples
    // per pixel than that holds instead of silently repeating random numbers.
    if ((long long)img.samplesPerIteration() * img.iterations > 0xFFFFFFFFLL)
        rd.fail(n, "sample base^2 x iterations = " +
                       std::to_string((long long)img.samplesPerIteration() * img.iterations) +
                       " samples per pixel exceeds 2^32 - 1");
}

void readSettings(const Reader& rd, const YAML::Node& n, Settings& s) {
    std::vector<std::string> keys;
    for (const SettingSpec& spec : settingsTable())
        keys.push_back(spec.key);
    rd.checkKeys(n, "settings", keys);
    for (const SettingSpec& spec : settingsTable())
        if (const YAML::Node v = n[spec.key])
            spec.set(s, spec.integer ? double(rd.integer(v, spec.key, (long long)spec.lo,
                                                         (long long)spec.hi))
                                     : rd.number(v, spec.key, spec.lo, spec.hi));
}

glm::dvec3 readCamera(const Reader& rd, const YAML::Node& n, Camera& c) {
    rd.checkKeys(n, "camera",
                 {"type", "translation", "rotation", "look at", "focal length", "fov",
                  "aperture radius", "focal distance", "film width"});
    glm::dvec3 origin(0.0);
    if (n["type"]) {
        std::string t = rd.string(n["type"], "camera type");
        if (t == "PinHole")
            c.type = CameraType::PinHole;
        else if (t == "ThinLens")
            c.type = CameraType::ThinLens;
        else
            rd.fail(n["type"], "unknown camera type '" + t + "' (PinHole or ThinLens)");
    }
    if (n["look at"]) {
        const YAML::Node& la = n["look at"];
        if (n["translation"] || n["rotation"])
            rd.fail(la, "camera takes either 'look at' or translation/rotation, not both");
        rd.checkKeys(la, "look at", {"eye", "target", "up"});
        if (!la["eye"] || !la["target"]) rd.fail(la, "look at needs eye and target");
        const glm::dvec3 eye = rd.dvec<3>(la["eye"], "look at eye");
        const glm::dvec3 target = rd.dvec<3>(la["target"], "look at target");
        const glm::dvec3 up = la["up"] ? rd.dvec<3>(la["up"], "look at up") : glm::dvec3(0, 1, 0);
        // Relative to the eye, in double, and scaled to unit length before any product: an eye
        // or target at 1e300 neither overflows nor reads as "parallel".
        const glm::dvec3 d = target - eye;
        const double span = std::max({std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)});
        if (span == 0) rd.fail(la, "look at eye and target are the same point");
        if (!std::isfinite(span))
            rd.fail(la, "look at eye and target are too far apart for double precision");
        checkDistance(rd, la["target"], d, "look at target");
        const double upSpan = std::max({std::fabs(up.x), std::fabs(up.y), std::fabs(up.z)});
        if (upSpan == 0) rd.fail(la["up"], "look at up must not be zero");
        const glm::dvec3 fwd = glm::normalize(d / span), upDir = glm::normalize(up / upSpan);
        if (glm::length(glm::cross(fwd, upDir)) < 1e-6)
            rd.fail(la, "look at up is parallel to the viewing direction");
        glm::dmat4 m = glm::inverse(glm::lookAt(glm::dvec3(0.0), fwd, upDir));
        m[3] = glm::dvec4(0, 0, 0, 1);
        c.cameraToWorld = mat4(m);
        origin = eye;
    } else {
        glm::dmat4 m = readTransform(rd, n, "camera", false);
        origin = glm::dvec3(m[3]);
        m[3] = glm::dvec4(0, 0, 0, 1);
        c.cameraToWorld = mat4(m);
    }
    if (n["focal length"])
        c.focalLength = float(rd.number(n["focal length"], "focal length", 1e-6, 1e9));
    if (n["film width"]) c.filmWidth = float(rd.number(n["film width"], "film width", 1e-6, 1e9));
    if (n["fov"]) {
        c.fovDegrees = float(rd.number(n["fov"], "fov", 1e-4, 179.9));
    }
    // The lens and the focal plane lie within kMaxDistance of the camera like everything else.
    if (n["aperture radius"])
        c.apertureRadius =
            float(rd.number(n["aperture radius"], "aperture radius", 0.0, kMaxDistance));
    if (n["focal distance"])
        c.focalDistance =
            float(rd.number(n["focal distance"], "focal distance", 1e-30, kMaxDistance));
    if (c.type == CameraType::PinHole && (n["aperture radius"] || n["focal distance"]))
        rd.fail(n, "aperture radius and focal distance need camera type ThinLens");
    // fov is bounded by its range; focal length and film width must give no wider a view, or
    // the camera's ray directions overflow float before they are normalised.
    if (!c.fovDegrees && c.tanHalfFovX() > std::tan(glm::radians(179.9) / 2))
        rd.fail(n["focal length"] ? n["focal length"] : n["film width"],
                "film width / focal length gives a field of view wider than 179.9 degrees");
    return origin;
}

void readFilter(const Reader& rd, const YAML::Node& n, Filter& f) {
    rd.checkKeys(n, "filter", {"type", "width"});
    std::string t = n["type"] ? rd.string(n["type"], "filter type") : "Box";
    if (t == "Box")
        f = {FilterType::Box, 0.5f};
    else if (t == "Tent")
        f = {FilterType::Tent, 1.0f};
    else if (t == "Gaussian")
        f = {FilterType::Gaussian, 1.5f};
    else
        rd.fail(n["type"], "unknown filter type '" + t + "' (Box, Tent or Gaussian)");
    if (n["width"]) {
        float w = float(rd.number(n["width"], "filter width", 1e-3, kMaxFilterRadius));
        if (f.type != FilterType::Box) f.radius = w;
    }
}

SamplerType readSampler(const Reader& rd, const YAML::Node& n) {
    rd.checkKeys(n, "sampler", {"type"});
    std::string t = n["type"] ? rd.string(n["type"], "sampler type") : "Sobol";
    if (std::optional<SamplerType> s = parseSampler(t)) return *s;
    rd.fail(n["type"], "unknown sampler type '" + t + "' (Independent, Grid, Stratified or Sobol)");
}

} // namespace spw::scene_file
