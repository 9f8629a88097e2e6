#include "host/loaders/light_loader.h"

#include "host/image/image_io.h"
#include "host/scene/surface_models.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace spw::scene_file {

namespace fs = std::filesystem;

// A light's `intensity` (1) x `colour` ([1, 1, 1]): the radiance of a quad light or an
// environment, the intensity of a point light. Each channel must fit the range of any emission.
namespace {

glm::dvec3 lightIntensity(const Reader& rd, const YAML::Node& n, bool colourKey) {
    const double intensity =
        n["intensity"] ? rd.number(n["intensity"], "light intensity", 0.0, kMaxRadiance) : 1.0;
    const glm::dvec3 colour = colourKey && n["colour"]
                                  ? rd.dvec<3>(n["colour"], "light colour", 0.0, kMaxRadiance)
                                  : glm::dvec3(1.0);
    for (int i = 0; i < 3; ++i)
        if (intensity * colour[i] > kMaxRadiance)
            rd.fail(n["colour"] ? n["colour"] : n["intensity"],
                    "light intensity x colour = " + Reader::fmt(intensity * colour[i]) +
                        " exceeds " + Reader::fmt(kMaxRadiance) +
                        ", the brightest radiance Spillway renders");
    return intensity * colour;
}

} // namespace

// A quad light becomes two triangles (appended to lightMeshes) and an emissive Null shader of
// its own (returned); both go after the scene's objects and shaders once the file is read.
Shader readQuadLight(const Reader& rd, const YAML::Node& n, const glm::dvec3& origin,
                     std::vector<Mesh>& lightMeshes) {
    rd.checkKeys(n, "Quad light",
                 {"type", "translation", "rotation", "scale", "intensity", "colour"});
    glm::dvec2 size(1.0);
    if (n["scale"]) {
        size = rd.dvec<2>(n["scale"], "light scale", 1e-30, kMaxDistance);
    }
    const glm::dvec3 emitted = lightIntensity(rd, n, true);
    const glm::dmat4 xf = readTransform(rd, n, "light", false);

    Mesh m;
    m.name = "quad light " + std::to_string(lightMeshes.size());
    for (glm::dvec2 c : {glm::dvec2(-0.5, -0.5), glm::dvec2(0.5, -0.5), glm::dvec2(0.5, 0.5),
                         glm::dvec2(-0.5, 0.5)}) {
        const glm::dvec3 p =
            glm::dvec3(xf * glm::dvec4(c.x * size.x, c.y * size.y, 0.0, 1.0)) - origin;
        checkDistance(rd, n, p, "quad light corner");
        m.positions.push_back(vec3(p));
    }
    m.triangles = {uvec3(0, 1, 2), uvec3(0, 2, 3)};
    // A light too small (or too far out) for float to span: refuse it rather than divide by its
    // area.
    for (const uvec3& tri : m.triangles) {
        vec3 c = glm::cross(m.positions[tri.y] - m.positions[tri.x],
                            m.positions[tri.z] - m.positions[tri.x]);
        float a2 = glm::dot(c, c);
        if (!(a2 >= std::numeric_limits<float>::min()) || !std::isfinite(a2))
            rd.fail(n, "quad light has no area in float after its scale and transform");
    }
    Shader s;
    s.typeName = "Quad light";
    s.line = n.Mark().line + 1;
    s.params.model = kModelNull;
    s.params.emission = vec3(emitted);
    lightMeshes.push_back(std::move(m));
    return s;
}

// A punctual light: the keys its kind's flags name, and intensity x colour.
PunctualLight readPunctualLight(const Reader& rd, const YAML::Node& n, const glm::dvec3& origin,
                                const EmitterKindInfo& kind) {
    const std::string what = std::string(kind.scene) + " light";
    std::vector<std::string> keys = {"type", "intensity", "colour"};
    const bool positioned = (kind.flags & kLightTakesPosition) != 0u;
    const bool directed = (kind.flags & kLightTakesDirection) != 0u;
    if (positioned) keys.push_back("position");
    if (directed) keys.push_back("direction");
    if (kind.kind == kEmitterSpot) keys.insert(keys.end(), {"inner angle", "outer angle"});
    rd.checkKeys(n, what, keys);
    PunctualLight light;
    light.kind = kind.kind;
    if (positioned) {
        if (!n["position"]) rd.fail(n, what + " needs a position");
        const glm::dvec3 p = rd.dvec<3>(n["position"], "light position") - origin;
        checkDistance(rd, n["position"], p, "point light");
        light.position = vec3(p);
    }
    if (directed) {
        if (!n["direction"]) rd.fail(n, what + " needs a direction");
        const glm::dvec3 d = rd.dvec<3>(n["direction"], "light direction");
        const double length = glm::length(d);
        if (!(length > 1e-30) || !std::isfinite(length))
            rd.fail(n["direction"], what + " direction must be a non-zero vector");
        light.direction = vec3(d / length);
    }
    if (kind.kind == kEmitterSpot) { // degrees, glTF's defaults
        const double outer =
            n["outer angle"] ? rd.number(n["outer angle"], "outer angle", 0.01, 90.0) : 45.0;
        const double inner =
            n["inner angle"] ? rd.number(n["inner angle"], "inner angle", 0.0, 90.0) : 0.0;
        if (!(inner < outer))
            rd.fail(n["inner angle"], "a spot light's inner angle must be less than its outer one");
        light.cosInner = float(std::cos(inner * M_PI / 180.0));
        light.cosOuter = float(std::cos(outer * M_PI / 180.0));
    }
    light.intensity = vec3(lightIntensity(rd, n, true));
    light.line = n.Mark().line + 1;
    return light;
}

// `colour` (a constant) or `string` / `filename` (a lat-long image, read here, so that a bad
// file is a scene error), times `intensity`.
Environment readEnvironment(const Reader& rd, const YAML::Node& n, const fs::path& dir) {
    rd.checkKeys(n, "Environment light", {"type", "colour", "string", "filename", "intensity"});
    const YAML::Node file = n["string"] ? n["string"] : n["filename"];
    if (file && n["colour"])
        rd.fail(n["colour"], "Environment light takes a colour or an image ('string'), not both");
    const vec3 radiance = vec3(lightIntensity(rd, n, !file));
    Environment env;
    if (file) {
        try {
            env = environmentMap(dir / rd.string(file, "environment image"), radiance);
        } catch (const std::exception& e) {
            rd.fail(file, e.what());
        }
    } else {
        env.radiance = radiance;
    }
    env.line = n.Mark().line + 1;
    return env;
}

Environment environmentMap(const fs::path& p, vec3 radiance) {
    if (!fs::is_regular_file(p))
        throw std::runtime_error("environment image '" + p.string() + "' does not exist");
    Environment env;
    env.radiance = radiance;
    env.path = fs::absolute(p).lexically_normal().string();
    ImageRGB img = spw::readImage(env.path); // throws std::runtime_error
    if (img.width < 1 || img.height < 1 || size_t(img.width) * size_t(img.height) > (1u << 26))
        throw std::runtime_error("environment image '" + env.path + "' is " +
                                 std::to_string(img.width) + " x " + std::to_string(img.height) +
                                 "; Spillway takes maps of 1 to 2^26 texels");
    // The map holds floats: a texel written as 1e20 reads as the float nearest it, a little
    // above, and is as much within the range as the scene text's 1e20.
    const double brightest = double(float(kMaxRadiance));
    for (size_t i = 0; i < img.rgb.size(); ++i) {
        const double v = double(img.rgb[i]) * double(env.radiance[int(i % 3)]);
        if (!(v >= 0.0 && v <= brightest)) {
            const size_t texel = i / 3;
            throw std::runtime_error(
                "environment image '" + env.path + "' has radiance " + Reader::fmt(v) +
                " at texel (" + std::to_string(texel % size_t(img.width)) + ", " +
                std::to_string(texel / size_t(img.width)) + "): every value must lie in 0 .. " +
                Reader::fmt(kMaxRadiance));
        }
    }
    env.width = img.width;
    env.height = img.height;
    env.rgb = std::move(img.rgb);
    return env;
}

} // namespace spw::scene_file
