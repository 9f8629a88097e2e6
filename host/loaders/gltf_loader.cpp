// A glTF 2.0 file into a Scene (gltf_loader.h). tinygltf parses the JSON and the buffers; every
// index, accessor and value is checked here before it is used, so that a malformed file is a
// SceneError naming the JSON pointer, never a crash. This file reads the document: the file
// parsed, its extensions, the node graph with its transforms, the camera, the lights and the
// bounds; gltf_meshes.cpp reads accessors and meshes, gltf_materials.cpp materials and images.
#include "host/loaders/gltf_loader.h"

#include "host/loaders/gltf_nodes.h"
#include "host/loaders/gltf_preflight.h"
#include "host/loaders/gltf_reader.h"
#include "host/loaders/gltf_sources.h"
#include "host/textures/textures.h"
#include "shared/metallic_roughness.h"

#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>

namespace spw {

namespace fs = std::filesystem;

namespace {

// The extensions this loader honours: a file may require them.
const std::set<std::string> kHonoured = {"KHR_lights_punctual",
                                         "KHR_materials_clearcoat",
                                         "KHR_materials_emissive_strength",
                                         "KHR_materials_ior",
                                         "KHR_materials_pbrSpecularGlossiness",
                                         "KHR_materials_sheen",
                                         "KHR_materials_specular",
                                         "KHR_materials_transmission",
                                         "KHR_materials_volume",
                                         "KHR_texture_transform",
                                         kPrincipledExtension};

// The image of a `spillway render model.glb` without an aspect ratio: 640 pixels wide.
constexpr int kDefaultWidth = 640;
constexpr double kDefaultAspect = 4.0 / 3.0;
constexpr double kMinAspect = 0.01, kMaxAspect = 100.0;

// glTF's photometric units into the radiometric ones Spillway's lights take, as Blender's glTF
// importer converts them (683 lm/W): a point light's candela into W/sr, a directional light's
// lux into W/m^2.
constexpr double kLumensPerWatt = 683.0;

// What the image callback is handed: where to keep an embedded image's bytes, the model being
// parsed (its buffers and views are read before its images), and the first problem found.
struct ImageCallback {
    ImageBytes* bytes;
    const tinygltf::Model* model;
    std::string problem;
};

bool keepImageUndecoded(tinygltf::Image* image, const int index, std::string*, std::string*, int,
                        int, const unsigned char* bytes, int size, void* user) {
    ImageCallback& cb = *static_cast<ImageCallback*>(user);
    // tinygltf hands an image's buffer view without checking that it lies in its buffer.
    if (const std::string why = imageViewProblem(*cb.model, *image, index); !why.empty()) {
        cb.problem = why;
        return false;
    }
    if (image->uri.empty() || image->uri.rfind("data:", 0) == 0) { // in memory: the JSON held it
        auto image = std::make_shared<EmbeddedImage>();
        image->bytes = std::make_shared<const std::string>(reinterpret_cast<const char*>(bytes),
                                                           size_t(std::max(size, 0)));
        image->length = image->bytes->size();
        (*cb.bytes)[index] = image;
    }
    return true;
}

std::string lower(std::string s) {
    for (char& c : s)
        c = char(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

} // namespace

void GltfReader::readScene() {
    read({glm::dmat4(1.0)}, true);
    if (!cameraFound_) frameBounds();
    scene_.objectCount = int(scene_.meshes.size());
    if (scene_.shaders.empty()) scene_.shaders.push_back(defaultShader());
    if (scene_.punctualLights.empty()) lightByDefault();
}

// The share of the default environment's power, at the scene's size, that a file's emissive
// meshes must reach to light it alone.
constexpr double kEmittersLightAlone = 0.05;

void GltfReader::lightByDefault() {
    scene_.environment = Environment{}; // radiance 1 from everywhere
    // The emitters' power as next-event estimation weighs it: emission x area x pi a side, an
    // emission map at its image's mean luminance.
    std::optional<TextureResolver> textures;
    std::map<int, double> mapMeans;
    double power = 0.0;
    for (const Mesh& m : scene_.meshes) {
        const Shader& shader = scene_.shaders[size_t(m.shader)];
        double radiance = double(luminance(shader.params.emission));
        if (!(radiance > 0.0)) continue;
        if (shader.params.flags & kShaderTwoSided) radiance *= 2.0;
        if (const int t = shader.emissionTexture; t >= 0) {
            if (!mapMeans.count(t)) {
                if (!textures) textures.emplace(scene_, 64.0, false, false);
                int width = 0, height = 0;
                double sum = 0.0;
                for (const vec3& texel : textures->finestLevel(t, width, height))
                    sum += double(luminance(texel));
                mapMeans[t] = sum / std::max(1.0, double(width) * double(height));
            }
            radiance *= mapMeans[t];
        }
        // A prototype's mesh lights at each of its instances, with the area each gives it.
        auto area = [&](const glm::dmat3& linear) {
            double sum = 0.0;
            for (const uvec3& tri : m.triangles)
                sum += 0.5 * glm::length(glm::cross(
                                 linear * glm::dvec3(m.positions[tri.y] - m.positions[tri.x]),
                                 linear * glm::dvec3(m.positions[tri.z] - m.positions[tri.x])));
            return sum;
        };
        if (m.prototype < 0) {
            power += kPi * radiance * area(glm::dmat3(1.0));
            continue;
        }
        for (const Instance& inst : scene_.instances)
            if (int(inst.prototype) == m.prototype)
                power += kPi * radiance * area(glm::dmat3(glm::mat3(inst.toWorld)));
    }
    if (power == 0.0) return;
    // The environment's, as the light sampler weighs it: what a disc of the scene's bounding
    // radius r intercepts from every direction, pi r^2 x 4 pi.
    glm::dvec3 lo, hi;
    sceneBounds(scene_, lo, hi);
    const double r = 0.5 * glm::length(hi - lo);
    const double share = power / (4.0 * kPi * kPi * r * r);
    if (share >= kEmittersLightAlone) {
        scene_.environment.reset();
        return;
    }
    char percent[32];
    std::snprintf(percent, sizeof percent, "%.3g %%", 100.0 * share);
    warn("has no light but its emissive materials, whose power is " + std::string(percent) +
         " of a white environment's at the scene's size (under " +
         std::to_string(int(100 * kEmittersLightAlone)) +
         " %): lit by that environment as well, radiance 1 " + kAddedEnvironmentNote);
}

void GltfReader::readObject(const std::vector<glm::dmat4>& transforms, int shader) {
    shaderOverride_ = shader;
    read(transforms, false);
    if (cameraSeen_) warn("its cameras are not used: the scene has its own");
}

void GltfReader::warnOf(const std::string& subject, const std::string& message) {
    auto said = std::find_if(warningsOf_.begin(), warningsOf_.end(),
                             [&](const auto& w) { return w.first == message; });
    if (said == warningsOf_.end()) said = warningsOf_.insert(said, {message, {}});
    if (std::find(said->second.begin(), said->second.end(), subject) == said->second.end())
        said->second.push_back(subject);
}

void GltfReader::sayWarningsOf() {
    constexpr size_t kNamed = 3; // the parts a warning names; the rest it counts
    for (const auto& [message, subjects] : warningsOf_) {
        std::string who;
        for (size_t i = 0; i < std::min(subjects.size(), kNamed); ++i)
            who += (i == 0 ? "" : i + 1 == subjects.size() ? " and " : ", ") + subjects[i];
        if (subjects.size() > kNamed)
            who += " and " + std::to_string(subjects.size() - kNamed) + " more";
        warn(who + ": " + message);
    }
    warningsOf_.clear();
}

void GltfReader::read(const std::vector<glm::dmat4>& transforms, bool takesCamera) {
    parse();
    checkExtensions();
    const int sceneIndex = model_.defaultScene >= 0 ? model_.defaultScene : 0;
    if (model_.scenes.empty()) fail("/scenes", "the file has no scene");
    if (sceneIndex >= int(model_.scenes.size()))
        fail("/scene", "names scene " + std::to_string(sceneIndex) + " of " +
                           std::to_string(model_.scenes.size()));
    const tinygltf::Scene& s = model_.scenes[size_t(sceneIndex)];
    // Two passes over the node graph: the camera first (the world is camera-relative), then
    // the meshes and lights, placed relative to it.
    for (Pass pass : {Pass::Camera, Pass::Geometry}) {
        if (pass == Pass::Camera && !takesCamera) continue;
        for (const glm::dmat4& transform : transforms)
            for (size_t i = 0; i < s.nodes.size(); ++i)
                visit(s.nodes[i], transform,
                      "/scenes/" + std::to_string(sceneIndex) + "/nodes/" + std::to_string(i), pass,
                      0);
    }
    // The graph is read: its nodes go before the meshes are placed.
    std::vector<GltfNode>().swap(nodes_);
    placeMeshes();
    // Every accessor is read: the parser's copies of the buffers go before the BVH is built.
    for (tinygltf::Buffer& b : model_.buffers)
        std::vector<unsigned char>().swap(b.data);
    warnUnrendered();
}

void GltfReader::parse() {
    std::error_code ec;
    if (!fs::is_regular_file(path_, ec))
        throw SceneError(path_, 0, "cannot open the glTF file: not a readable file");
    GltfDocument document = preflightGltf(path_, kHonoured);
    for (const std::string& w : document.warnings)
        warn(w);
    tinygltf::TinyGLTF loader;
    loader.SetFsCallbacks(regularFilesOnly());
    embedded_.clear();
    ImageCallback images{&embedded_, &model_, ""};
    loader.SetImageLoader(keepImageUndecoded, &images);
    std::string err, warnings;
    bool ok = false;
    std::vector<std::string> bufferFiles;
    if (!document.doc.is_discarded()) { // tinygltf reads the buffers through gltf_sources.h
        nodes_ = std::move(document.nodes);
        GltfSources sources(path_, std::move(document));
        loader.SetFsCallbacks(sources.callbacks());
        ok = loader.LoadASCIIFromString(&model_, &err, &warnings, sources.text().data(),
                                        unsigned(sources.text().size()), "");
        for (const auto& [index, uri] : sources.imageFiles())
            if (size_t(index) < model_.images.size()) model_.images[size_t(index)].uri = uri;
        for (const auto& [index, image] : sources.embedded())
            embedded_[index] = image;
        bufferFiles = sources.bufferFiles();
    } else { // a JSON that does not parse: tinygltf says why
        const bool binary = lower(fs::path(path_).extension().string()) == ".glb";
        ok = binary ? loader.LoadBinaryFromFile(&model_, &err, &warnings, path_)
                    : loader.LoadASCIIFromFile(&model_, &err, &warnings, path_);
    }
    if (!images.problem.empty()) throw SceneError(path_, 0, images.problem);
    // tinygltf 2.7 reports a skin without inverseBindMatrices as an error, yet parses it: the
    // specification makes them optional (identity matrices), and skins render in bind pose.
    for (size_t at; (at = err.find("'inverseBindMatrices' property is missing in Skin.\n")) !=
                    std::string::npos;)
        err.erase(at, std::strlen("'inverseBindMatrices' property is missing in Skin.\n"));
    scene_.inputs.push_back(path_);
    scene_.inputs.insert(scene_.inputs.end(), bufferFiles.begin(), bufferFiles.end());
    if (!ok || !err.empty()) {
        while (!err.empty() && (err.back() == '\n' || err.back() == '\r'))
            err.pop_back();
        throw SceneError(path_, 0,
                         "not a glTF 2.0 file Spillway can read: " +
                             (err.empty() ? std::string("tinygltf refused it") : err));
    }
}

void GltfReader::checkExtensions() {
    for (const std::string& e : model_.extensionsRequired)
        if (!kHonoured.count(e))
            fail("/extensionsRequired",
                 "requires the extension " + e + ", which Spillway does not render");
    for (const std::string& e : model_.extensionsUsed)
        if (!kHonoured.count(e)) warn("uses the extension " + e + ", not rendered");
}

glm::dmat4 GltfReader::finite(const glm::dmat4& m, const std::string& at) const {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(m[c][r])) fail(at, "the transform is not finite");
    return m;
}

void GltfReader::visit(int index, const glm::dmat4& parent, const std::string& at, Pass pass,
                       int depth) {
    if (index < 0 || index >= int(nodes_.size()))
        fail(at, "names node " + std::to_string(index) + " of " + std::to_string(nodes_.size()));
    if (onPath_.count(index))
        fail("/nodes/" + std::to_string(index),
             "the node graph is recursive: this node is its own ancestor");
    if (depth > 1024) fail(at, "nodes nest more than 1024 deep");
    const GltfNode& n = nodes_[size_t(index)];
    const std::string self = "/nodes/" + std::to_string(index);
    const glm::dmat4 world = finite(parent * n.local, self);
    if (pass == Pass::Camera) {
        if (n.camera >= 0 && !cameraFound_) readCamera(n.camera, world, self + "/camera");
    } else {
        cameraSeen_ = cameraSeen_ || n.camera >= 0;
        if (n.mesh >= 0) placements_.push_back({n.mesh, index, world});
        readLight(n, world, self);
        if (n.skin >= 0) warn("has skins: rendered in their bind pose");
    }
    onPath_.insert(index);
    for (size_t c = 0; c < n.children.size(); ++c)
        visit(n.children[c], world, self + "/children/" + std::to_string(c), pass, depth + 1);
    onPath_.erase(index);
}

void GltfReader::readCamera(int index, const glm::dmat4& world, const std::string& at) {
    if (index >= int(model_.cameras.size()))
        fail(at, "names camera " + std::to_string(index) + " of " +
                     std::to_string(model_.cameras.size()));
    const tinygltf::Camera& c = model_.cameras[size_t(index)];
    if (c.type != "perspective") {
        warn("has an orthographic camera, not rendered: a camera framing the scene instead");
        return;
    }
    const double yfov = c.perspective.yfov;
    if (!(yfov > 1e-6 && yfov < M_PI * 0.999))
        fail("/cameras/" + std::to_string(index) + "/perspective/yfov", "yfov must lie in (0, pi)");
    const double aspect =
        c.perspective.aspectRatio > 0.0 ? c.perspective.aspectRatio : kDefaultAspect;
    // Past these the image (640 pixels wide) would be squeezed to a row, or millions tall.
    if (!(aspect >= kMinAspect && aspect <= kMaxAspect))
        fail("/cameras/" + std::to_string(index) + "/perspective/aspectRatio",
             "is " + formatNumber(aspect) +
                 "; Spillway renders aspect ratios (width / height) from " +
                 formatNumber(kMinAspect) + " to " + formatNumber(kMaxAspect));
    placeCamera(world, yfov, aspect);
    cameraFound_ = true;
}

void GltfReader::placeCamera(const glm::dmat4& world, double yfov, double aspect) {
    glm::dmat4 m(1.0);
    for (int c = 0; c < 3; ++c) {
        const glm::dvec3 axis(world[c]);
        const double len = glm::length(axis);
        if (!(len > 1e-30)) fail("", "the camera's node has a zero scale");
        m[c] = glm::dvec4(axis / len, 0.0);
    }
    scene_.origin = glm::dvec3(world[3]);
    scene_.camera = Camera{};
    scene_.camera.cameraToWorld = mat4(m);
    const double tanX = std::tan(0.5 * yfov) * aspect;
    scene_.camera.fovDegrees = float(glm::degrees(2.0 * std::atan(tanX)));
    if (!(*scene_.camera.fovDegrees < 179.9f))
        fail("", "the camera's horizontal field of view reaches 180 degrees");
    scene_.image.width = kDefaultWidth;
    scene_.image.height = std::max(1, int(std::lround(kDefaultWidth / aspect)));
}

void GltfReader::frameBounds() {
    const glm::dvec3 lo = bounded_ ? lo_ : glm::dvec3(0.0), hi = bounded_ ? hi_ : lo;
    const glm::dvec3 centre = 0.5 * (lo + hi);
    const double radius = std::max(0.5 * glm::length(hi - lo), 1e-3);
    const double yfov = glm::radians(40.0);
    const double distance = 1.1 * radius / std::sin(0.5 * yfov);
    glm::dmat4 world(1.0);
    world[3] = glm::dvec4(centre + glm::dvec3(0.0, 0.0, distance), 1.0);
    const glm::dvec3 shift = glm::dvec3(world[3]); // the origin moves: shift what was read
    placeCamera(world, yfov, kDefaultAspect);
    for (Mesh& m : scene_.meshes)
        if (m.prototype < 0)
            for (vec3& p : m.positions)
                p = vec3(glm::dvec3(p) - shift);
    for (Instance& inst : scene_.instances)
        inst.toWorld[3] = vec4(vec3(glm::dvec3(vec3(inst.toWorld[3])) - shift), 1.0f);
    for (PunctualLight& l : scene_.punctualLights)
        l.position = vec3(glm::dvec3(l.position) - shift);
    if (const std::string far = beyondReach(hi - glm::dvec3(world[3]), "the scene's bounds");
        !far.empty())
        fail("", far);
    if (const std::string far = beyondReach(lo - glm::dvec3(world[3]), "the scene's bounds");
        !far.empty())
        fail("", far);
}

void GltfReader::include(const glm::dvec3& p) {
    lo_ = bounded_ ? glm::min(lo_, p) : p;
    hi_ = bounded_ ? glm::max(hi_, p) : p;
    bounded_ = true;
}

void GltfReader::readLight(const GltfNode& n, const glm::dmat4& world, const std::string& at) {
    if (n.light == -1) return;
    const std::string where = at + "/extensions/KHR_lights_punctual/light";
    if (n.light < 0 || n.light >= int(model_.lights.size()))
        fail(where, "names no light of the file's KHR_lights_punctual lights");
    const tinygltf::Light& l = model_.lights[size_t(n.light)];
    vec3 colour(1.0f);
    if (!l.color.empty()) {
        if (l.color.size() != 3) fail(where, "a light's color has 3 numbers");
        for (int k = 0; k < 3; ++k)
            colour[k] = float(unit(l.color[size_t(k)], where + "/color"));
    }
    if (!(l.intensity >= 0.0) || !(l.intensity / kLumensPerWatt <= kMaxRadiance))
        fail(where, "a light's intensity must lie in [0, " +
                        formatNumber(kMaxRadiance * kLumensPerWatt) + "] (candela or lux; " +
                        formatNumber(kMaxRadiance) + " W/sr or W/m^2 at 683 lm/W)");
    PunctualLight p;
    p.intensity = colour * float(l.intensity / kLumensPerWatt);
    if (l.type == "point") {
        p.kind = kEmitterPoint;
        const glm::dvec3 rel = glm::dvec3(world[3]) - scene_.origin;
        if (const std::string far = beyondReach(rel, "a point light"); !far.empty()) fail(at, far);
        p.position = vec3(rel);
        include(glm::dvec3(world[3]));
    } else if (l.type == "directional" || l.type == "spot") {
        p.kind = l.type == "spot" ? kEmitterSpot : kEmitterDirectional;
        const glm::dvec3 d = -glm::dvec3(world[2]); // the light shines along its -Z
        const double len = glm::length(d);
        if (!(len > 1e-30)) fail(at, "a " + l.type + " light's node has a zero scale");
        p.direction = vec3(d / len);
        if (l.type == "spot") {
            const double inner = l.spot.innerConeAngle, outer = l.spot.outerConeAngle;
            if (!(inner >= 0.0 && inner < outer && outer <= 0.5 * M_PI))
                fail(where + "/spot", "needs 0 <= innerConeAngle < outerConeAngle <= pi/2");
            p.cosInner = float(std::cos(inner));
            p.cosOuter = float(std::cos(outer));
            const glm::dvec3 rel = glm::dvec3(world[3]) - scene_.origin;
            if (const std::string far = beyondReach(rel, "a spot light"); !far.empty())
                fail(at, far);
            p.position = vec3(rel);
            include(glm::dvec3(world[3]));
        }
    } else {
        warn("has " + l.type + " lights, not rendered yet");
        return;
    }
    if (l.range > 0.0) warn("has lights with a range, rendered without it (as physics has it)");
    scene_.punctualLights.push_back(p);
}

bool isGltfPath(const std::string& path) {
    const std::string ext = lower(fs::path(path).extension().string());
    return ext == ".gltf" || ext == ".glb";
}

Scene loadGltfScene(const std::string& path) {
    Scene scene;
    scene.file = path;
    GltfReader(path, scene).readScene();
    scene.image.samplingStated = false; // glTF has no sampling settings
    // 16 samples a pixel an iteration, where the samples asked for allow it (planSampling): an
    // iteration's work per pixel (the film's sums, the error estimate, adaptive sampling's
    // decision) is then a few per cent of its samples' (docs/performance.md).
    scene.image.sampleBase = kGltfSampleBase;
    scene.settings.minDepth = kGltfMinDepth;
    scene.settings.threshold = kGltfRouletteThreshold;
    return scene;
}

void appendGltfObject(const std::string& path, const std::vector<glm::dmat4>& transforms,
                      int shader, Scene& scene) {
    GltfReader(path, scene).readObject(transforms, shader);
}

} // namespace spw
