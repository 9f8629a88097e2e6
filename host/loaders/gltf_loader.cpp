// A glTF 2.0 file into a Scene (gltf_loader.h). tinygltf parses the JSON and the buffers; every
// index, accessor and value is checked here before it is used, so that a malformed file is a
// SceneError naming the JSON pointer, never a crash.
#include "host/loaders/gltf_loader.h"

#include "shared/gltf.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/quaternion.hpp>
#include <tiny_gltf.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <set>

namespace spw {

namespace fs = std::filesystem;

namespace {

// The extensions this loader honours: a file may require them.
const std::set<std::string> kHonoured = {"KHR_lights_punctual", "KHR_materials_emissive_strength",
                                         "KHR_texture_transform"};

// The image of a `spillway render model.glb` without an aspect ratio: 640 pixels wide.
constexpr int kDefaultWidth = 640;
constexpr double kDefaultAspect = 4.0 / 3.0;

// glTF's photometric units into the radiometric ones Spillway's lights take, as Blender's glTF
// importer converts them (683 lm/W): a point light's candela into W/sr, a directional light's
// lux into W/m^2.
constexpr double kLumensPerWatt = 683.0;

// tinygltf reads every image's bytes; the pixels are left to OpenImageIO's texture cache, which
// reads an image file itself, and an embedded image (a buffer view, a data: URI) from these
// bytes, kept here per image.
using ImageBytes = std::map<int, std::shared_ptr<const std::string>>;
bool keepImageUndecoded(tinygltf::Image* image, const int index, std::string*, std::string*, int,
                        int, const unsigned char* bytes, int size, void* user) {
    if (image->uri.empty() || image->uri.rfind("data:", 0) == 0)
        (*static_cast<ImageBytes*>(user))[index] = std::make_shared<const std::string>(
            reinterpret_cast<const char*>(bytes), size_t(std::max(size, 0)));
    return true;
}

std::string lower(std::string s) {
    for (char& c : s)
        c = char(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

class GltfReader {
  public:
    GltfReader(const std::string& path, Scene& scene)
        : path_(path), dir_(fs::path(path).parent_path()), scene_(scene) {}

    // The whole file as the scene: its camera (or one framing it), its lights (or a uniform
    // environment).
    void readScene() {
        read(glm::dmat4(1.0), true);
        if (!cameraFound_) frameBounds();
        scene_.objectCount = int(scene_.meshes.size());
        bool emissive = !scene_.punctualLights.empty();
        for (const Mesh& m : scene_.meshes)
            emissive = emissive || scene_.shaders[size_t(m.shader)].params.emission != vec3(0.0f);
        if (!emissive) scene_.environment = Environment{}; // radiance 1 from everywhere
        if (scene_.shaders.empty()) scene_.shaders.push_back(defaultShader());
    }

    // The file's meshes and lights placed by `transform` into a scene whose camera is set;
    // every mesh takes `shader` where it is >= 0, else the file's materials, appended.
    void readObject(const glm::dmat4& transform, int shader) {
        shaderOverride_ = shader;
        read(transform, false);
        if (cameraSeen_) warn("its cameras are not used: the scene has its own");
    }

  private:
    void read(const glm::dmat4& transform, bool takesCamera) {
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
            for (size_t i = 0; i < s.nodes.size(); ++i)
                visit(s.nodes[i], transform,
                      "/scenes/" + std::to_string(sceneIndex) + "/nodes/" + std::to_string(i), pass,
                      0);
        }
        warnUnrendered();
    }

    enum class Pass { Camera, Geometry };

    [[noreturn]] void fail(const std::string& pointer, const std::string& message) const {
        throw SceneError(path_, 0, (pointer.empty() ? "" : pointer + ": ") + message);
    }
    void warn(const std::string& message) {
        if (warned_.insert(message).second) scene_.warnings.push_back(path_ + ": " + message);
    }

    void parse() {
        std::error_code ec;
        if (!fs::is_regular_file(path_, ec))
            throw SceneError(path_, 0, "cannot open the glTF file: not a readable file");
        tinygltf::TinyGLTF loader;
        loader.SetImageLoader(keepImageUndecoded, &embedded_);
        std::string err, warnings;
        const bool binary = lower(fs::path(path_).extension().string()) == ".glb";
        const bool ok = binary ? loader.LoadBinaryFromFile(&model_, &err, &warnings, path_)
                               : loader.LoadASCIIFromFile(&model_, &err, &warnings, path_);
        if (!ok || !err.empty()) {
            while (!err.empty() && (err.back() == '\n' || err.back() == '\r'))
                err.pop_back();
            throw SceneError(path_, 0,
                             "not a glTF 2.0 file Spillway can read: " +
                                 (err.empty() ? std::string("tinygltf refused it") : err));
        }
    }

    void checkExtensions() {
        for (const std::string& e : model_.extensionsRequired)
            if (!kHonoured.count(e))
                fail("/extensionsRequired",
                     "requires the extension " + e + ", which Spillway does not render");
        for (const std::string& e : model_.extensionsUsed)
            if (!kHonoured.count(e)) warn("uses the extension " + e + ", not rendered");
    }

    // The node's local transform: its matrix, or translation x rotation x scale.
    glm::dmat4 localTransform(const tinygltf::Node& n, const std::string& at) const {
        if (!n.matrix.empty()) {
            if (n.matrix.size() != 16) fail(at + "/matrix", "a matrix has 16 numbers");
            glm::dmat4 m;
            for (int c = 0; c < 4; ++c)
                for (int r = 0; r < 4; ++r)
                    m[c][r] = n.matrix[size_t(4 * c + r)];
            return finite(m, at + "/matrix");
        }
        glm::dmat4 m(1.0);
        if (!n.translation.empty()) {
            if (n.translation.size() != 3) fail(at + "/translation", "a translation has 3 numbers");
            m = glm::translate(m, glm::dvec3(n.translation[0], n.translation[1], n.translation[2]));
        }
        if (!n.rotation.empty()) {
            if (n.rotation.size() != 4) fail(at + "/rotation", "a rotation has 4 numbers");
            // glTF's quaternions are (x, y, z, w); glm's constructor takes w first.
            const glm::dquat q(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2]);
            const double len = glm::length(q);
            if (!(len > 0.0) || !std::isfinite(len))
                fail(at + "/rotation", "a rotation must be a non-zero quaternion");
            m = m * glm::mat4_cast(q / len);
        }
        if (!n.scale.empty()) {
            if (n.scale.size() != 3) fail(at + "/scale", "a scale has 3 numbers");
            m = glm::scale(m, glm::dvec3(n.scale[0], n.scale[1], n.scale[2]));
        }
        return finite(m, at);
    }
    glm::dmat4 finite(const glm::dmat4& m, const std::string& at) const {
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r)
                if (!std::isfinite(m[c][r])) fail(at, "the transform is not finite");
        return m;
    }

    void visit(int index, const glm::dmat4& parent, const std::string& at, Pass pass, int depth) {
        if (index < 0 || index >= int(model_.nodes.size()))
            fail(at, "names node " + std::to_string(index) + " of " +
                         std::to_string(model_.nodes.size()));
        if (onPath_.count(index))
            fail("/nodes/" + std::to_string(index),
                 "the node graph is recursive: this node is its own ancestor");
        if (depth > 1024) fail(at, "nodes nest more than 1024 deep");
        const tinygltf::Node& n = model_.nodes[size_t(index)];
        const std::string self = "/nodes/" + std::to_string(index);
        const glm::dmat4 world = finite(parent * localTransform(n, self), self);
        if (pass == Pass::Camera) {
            if (n.camera >= 0 && !cameraFound_) readCamera(n.camera, world, self + "/camera");
        } else {
            cameraSeen_ = cameraSeen_ || n.camera >= 0;
            if (n.mesh >= 0) readMesh(n.mesh, world, self + "/mesh");
            readLight(n, world, self);
            if (n.skin >= 0) warn("has skins: rendered in their bind pose");
        }
        onPath_.insert(index);
        for (size_t c = 0; c < n.children.size(); ++c)
            visit(n.children[c], world, self + "/children/" + std::to_string(c), pass, depth + 1);
        onPath_.erase(index);
    }

    void readCamera(int index, const glm::dmat4& world, const std::string& at) {
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
            fail("/cameras/" + std::to_string(index) + "/perspective/yfov",
                 "yfov must lie in (0, pi)");
        const double aspect =
            c.perspective.aspectRatio > 0.0 ? c.perspective.aspectRatio : kDefaultAspect;
        placeCamera(world, yfov, aspect);
        cameraFound_ = true;
    }

    // The camera at `world`'s origin, looking along its -Z with +Y up (scale taken out).
    void placeCamera(const glm::dmat4& world, double yfov, double aspect) {
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

    // Without a camera: one on the scene's +Z side looking at the centre of its bounds, far
    // enough back that a 40-degree vertical field of view holds the bounding sphere.
    void frameBounds() {
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
            for (vec3& p : m.positions)
                p = vec3(glm::dvec3(p) - shift);
        for (PunctualLight& l : scene_.punctualLights)
            l.position = vec3(glm::dvec3(l.position) - shift);
        if (const std::string far = beyondReach(hi - glm::dvec3(world[3]), "the scene's bounds");
            !far.empty())
            fail("", far);
        if (const std::string far = beyondReach(lo - glm::dvec3(world[3]), "the scene's bounds");
            !far.empty())
            fail("", far);
    }
    void include(const glm::dvec3& p) {
        lo_ = bounded_ ? glm::min(lo_, p) : p;
        hi_ = bounded_ ? glm::max(hi_, p) : p;
        bounded_ = true;
    }

    // --- accessors -------------------------------------------------------------------------

    // Accessor `index` as `count` elements of `components` doubles each (normalized integers
    // mapped to [0, 1] or [-1, 1]), its sparse substitutions applied; every byte it reads checked
    // to lie inside its buffer.
    std::vector<double> readAccessor(int index, int components, const std::string& at,
                                     bool integersOnly = false) const {
        if (index < 0 || index >= int(model_.accessors.size()))
            fail(at, "names accessor " + std::to_string(index) + " of " +
                         std::to_string(model_.accessors.size()));
        const std::string self = "/accessors/" + std::to_string(index);
        const tinygltf::Accessor& a = model_.accessors[size_t(index)];
        const int have = tinygltf::GetNumComponentsInType(uint32_t(a.type));
        if (have != components)
            fail(self + "/type", "has " + std::to_string(have) + " components where " +
                                     std::to_string(components) + " are needed");
        const int size = tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType));
        if (size <= 0) fail(self + "/componentType", "unknown component type");
        const bool isFloat = a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT;
        if (integersOnly && isFloat) fail(self + "/componentType", "indices must be integers");
        const size_t element = size_t(size) * size_t(components);
        std::vector<double> out(a.count * size_t(components), 0.0);
        if (a.bufferView >= 0) { // without one, all zeros (the specification's rule)
            size_t stride = 0;
            const unsigned char* base =
                viewBytes(a.bufferView, a.byteOffset, a.count, element, self, stride);
            for (size_t i = 0; i < a.count; ++i)
                for (int k = 0; k < components; ++k)
                    out[i * size_t(components) + size_t(k)] =
                        component(base + i * stride + size_t(k) * size_t(size), a.componentType,
                                  a.normalized);
        }
        if (a.sparse.isSparse) applySparse(a, components, self, out);
        return out;
    }

    // A sparse accessor's substitutions: element indices[j] of `out` becomes values[j].
    void applySparse(const tinygltf::Accessor& a, int components, const std::string& self,
                     std::vector<double>& out) const {
        const std::string at = self + "/sparse";
        const auto& s = a.sparse;
        if (s.count < 0 || size_t(s.count) > a.count)
            fail(at + "/count", "must lie between 0 and the accessor's count");
        const int indexType = s.indices.componentType;
        if (indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
            indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
            indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
            fail(at + "/indices/componentType", "must be an unsigned integer type");
        const size_t indexSize = size_t(tinygltf::GetComponentSizeInBytes(uint32_t(indexType)));
        const size_t size = size_t(tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType)));
        size_t indexStride = 0, valueStride = 0;
        const unsigned char* indices =
            viewBytes(s.indices.bufferView, size_t(s.indices.byteOffset), size_t(s.count),
                      indexSize, at + "/indices", indexStride);
        const unsigned char* values =
            viewBytes(s.values.bufferView, size_t(s.values.byteOffset), size_t(s.count),
                      size * size_t(components), at + "/values", valueStride);
        for (size_t j = 0; j < size_t(s.count); ++j) {
            const double i = component(indices + j * indexStride, indexType, false);
            if (!(i < double(a.count)))
                fail(at + "/indices", "index " + std::to_string(uint64_t(i)) +
                                          " is past the accessor's count " +
                                          std::to_string(a.count));
            for (int k = 0; k < components; ++k)
                out[size_t(i) * size_t(components) + size_t(k)] = component(
                    values + j * valueStride + size_t(k) * size, a.componentType, a.normalized);
        }
    }

    // The first of `count` elements of `element` bytes at `byteOffset` in buffer view `view`,
    // and their stride; `at` (what reads them) names the error when any would lie outside.
    const unsigned char* viewBytes(int view, size_t byteOffset, size_t count, size_t element,
                                   const std::string& at, size_t& stride) const {
        const std::string viewAt = "/bufferViews/" + std::to_string(view);
        if (view < 0 || view >= int(model_.bufferViews.size()))
            fail(at + "/bufferView", "names buffer view " + std::to_string(view) + " of " +
                                         std::to_string(model_.bufferViews.size()));
        const tinygltf::BufferView& v = model_.bufferViews[size_t(view)];
        if (v.buffer < 0 || v.buffer >= int(model_.buffers.size()))
            fail(viewAt + "/buffer", "names no buffer");
        const std::vector<unsigned char>& data = model_.buffers[size_t(v.buffer)].data;
        stride = v.byteStride ? v.byteStride : element;
        if (stride < element) fail(viewAt + "/byteStride", "is smaller than an element");
        if (v.byteOffset > data.size() || v.byteLength > data.size() - v.byteOffset)
            fail(viewAt, "reaches past the end of its buffer");
        const size_t room = byteOffset <= v.byteLength ? v.byteLength - byteOffset : 0;
        if (byteOffset > v.byteLength ||
            (count > 0 && (room < element || (count - 1) > (room - element) / stride)))
            fail(at, "reaches past the end of its buffer view");
        return data.data() + v.byteOffset + byteOffset;
    }

    static double component(const unsigned char* p, int componentType, bool norm) {
        auto get = [&](auto type) {
            decltype(type) x;
            std::memcpy(&x, p, sizeof x);
            return x;
        };
        switch (componentType) {
        case TINYGLTF_COMPONENT_TYPE_FLOAT:
            return get(float{});
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
            return norm ? get(uint8_t{}) / 255.0 : get(uint8_t{});
        case TINYGLTF_COMPONENT_TYPE_BYTE:
            return norm ? std::max(get(int8_t{}) / 127.0, -1.0) : get(int8_t{});
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
            return norm ? get(uint16_t{}) / 65535.0 : get(uint16_t{});
        case TINYGLTF_COMPONENT_TYPE_SHORT:
            return norm ? std::max(get(int16_t{}) / 32767.0, -1.0) : get(int16_t{});
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
            return get(uint32_t{});
        case TINYGLTF_COMPONENT_TYPE_INT:
            return get(int32_t{});
        default:
            return 0.0;
        }
    }

    // --- meshes ----------------------------------------------------------------------------

    void readMesh(int index, const glm::dmat4& world, const std::string& at) {
        if (index >= int(model_.meshes.size()))
            fail(at, "names mesh " + std::to_string(index) + " of " +
                         std::to_string(model_.meshes.size()));
        const tinygltf::Mesh& mesh = model_.meshes[size_t(index)];
        for (size_t p = 0; p < mesh.primitives.size(); ++p)
            readPrimitive(mesh.primitives[p], world,
                          "/meshes/" + std::to_string(index) + "/primitives/" + std::to_string(p),
                          mesh.name.empty() ? "mesh " + std::to_string(index) : mesh.name);
    }

    void readPrimitive(const tinygltf::Primitive& prim, const glm::dmat4& world,
                       const std::string& at, const std::string& name) {
        const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
        if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
            mode != TINYGLTF_MODE_TRIANGLE_FAN) {
            warn("has points or lines (primitive mode " + std::to_string(mode) + "), not rendered");
            return;
        }
        if (!prim.targets.empty()) warn("has morph targets: rendered without them");
        const auto position = prim.attributes.find("POSITION");
        if (position == prim.attributes.end()) fail(at + "/attributes", "has no POSITION");
        const std::vector<double> pos =
            readAccessor(position->second, 3, at + "/attributes/POSITION");
        const size_t vertices = pos.size() / 3;
        Mesh m;
        m.name = path_ + ": " + name;
        m.shader = shaderFor(prim.material, at + "/material");
        m.positions.resize(vertices);
        for (size_t i = 0; i < vertices; ++i) {
            const glm::dvec3 local(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]);
            const glm::dvec3 w = glm::dvec3(world * glm::dvec4(local, 1.0));
            if (!std::isfinite(w.x) || !std::isfinite(w.y) || !std::isfinite(w.z))
                fail("/accessors/" + std::to_string(position->second),
                     "position " + std::to_string(i) + " is not finite");
            include(w);
            const glm::dvec3 rel = w - scene_.origin;
            if (const std::string far = beyondReach(rel, "position " + std::to_string(i));
                !far.empty())
                fail("/accessors/" + std::to_string(position->second), far);
            m.positions[i] = vec3(rel);
        }
        readNormals(prim, world, vertices, at, m);
        if (prim.attributes.count("TANGENT"))
            warn("TANGENT attributes are not read: normal maps take tangents made from the "
                 "texture coordinates, triangle by triangle");
        readTextureCoordinates(prim, vertices, at, m);
        readColours(prim, vertices, at, m);
        readTriangles(prim, mode, world, vertices, at, m);
        if (m.triangles.empty()) return;
        if (scene_.meshes.size() >= size_t(kMaxObjects))
            fail(at, "more than " + std::to_string(kMaxObjects) + " primitives");
        scene_.meshes.push_back(std::move(m));
    }

    // NORMAL, turned into world space (the inverse transpose); where one is zero or not finite,
    // none (the faces' own normals).
    void readNormals(const tinygltf::Primitive& prim, const glm::dmat4& world, size_t vertices,
                     const std::string& at, Mesh& m) {
        const auto n = prim.attributes.find("NORMAL");
        if (n == prim.attributes.end()) return;
        const glm::dmat3 normalMatrix = glm::inverseTranspose(glm::dmat3(world));
        const std::vector<double> nor = readAccessor(n->second, 3, at + "/attributes/NORMAL");
        if (nor.size() != 3 * vertices)
            fail(at + "/attributes/NORMAL", "has another count than POSITION");
        m.normals.resize(vertices);
        for (size_t i = 0; i < vertices && !m.normals.empty(); ++i) {
            const glm::dvec3 w =
                normalMatrix * glm::dvec3(nor[3 * i], nor[3 * i + 1], nor[3 * i + 2]);
            const double len = glm::length(w);
            if (!(len > 1e-30) || !std::isfinite(len)) {
                warn("has zero or non-finite normals: its faces' own normals used there");
                m.normals.clear();
            } else {
                m.normals[i] = vec3(w / len);
            }
        }
    }

    // TEXCOORD_0, its v turned to run up: glTF's v runs down the image, Spillway's (OBJ's) up.
    void readTextureCoordinates(const tinygltf::Primitive& prim, size_t vertices,
                                const std::string& at, Mesh& m) const {
        const auto t = prim.attributes.find("TEXCOORD_0");
        if (t == prim.attributes.end()) return;
        const std::vector<double> uv = readAccessor(t->second, 2, at + "/attributes/TEXCOORD_0");
        if (uv.size() != 2 * vertices)
            fail(at + "/attributes/TEXCOORD_0", "has another count than POSITION");
        m.uvs.resize(vertices);
        for (size_t i = 0; i < vertices; ++i) {
            m.uvs[i] = vec2(float(uv[2 * i]), float(1.0 - uv[2 * i + 1]));
            if (!std::isfinite(m.uvs[i].x) || !std::isfinite(m.uvs[i].y))
                fail("/accessors/" + std::to_string(t->second),
                     "a texture coordinate is not finite");
        }
    }

    // COLOR_0 (RGB, or RGBA whose alpha is not read): per-vertex factors of the base colour,
    // clamped to [0, 1]. Not read where a YAML shader overrides the file's materials.
    void readColours(const tinygltf::Primitive& prim, size_t vertices, const std::string& at,
                     Mesh& m) const {
        const auto c = prim.attributes.find("COLOR_0");
        if (c == prim.attributes.end() || shaderOverride_ >= 0) return;
        const std::string where = at + "/attributes/COLOR_0";
        const int index = c->second;
        const std::string self = "/accessors/" + std::to_string(index);
        const int components =
            index >= 0 && index < int(model_.accessors.size())
                ? tinygltf::GetNumComponentsInType(uint32_t(model_.accessors[size_t(index)].type))
                : 3; // readAccessor names the bad index
        if (components != 3 && components != 4)
            fail(self + "/type", "COLOR_0 must be VEC3 or VEC4");
        const std::vector<double> rgba = readAccessor(index, components, where);
        if (rgba.size() != size_t(components) * vertices)
            fail(where, "has another count than POSITION");
        m.colours.resize(vertices);
        for (size_t i = 0; i < vertices; ++i)
            for (int k = 0; k < 3; ++k) {
                const double x = rgba[i * size_t(components) + size_t(k)];
                if (!std::isfinite(x)) fail(self, "a colour is not finite");
                m.colours[i][k] = float(std::clamp(x, 0.0, 1.0));
            }
    }

    // The primitive's triangles (a list, strip or fan; without indices, its vertices in order),
    // each index checked against the vertex count; zero-area triangles counted, not kept.
    void readTriangles(const tinygltf::Primitive& prim, int mode, const glm::dmat4& world,
                       size_t vertices, const std::string& at, Mesh& m) const {
        std::vector<uint> indices;
        if (prim.indices >= 0) {
            for (double x : readAccessor(prim.indices, 1, at + "/indices", true)) {
                if (!(x >= 0.0) || x >= double(vertices))
                    fail("/accessors/" + std::to_string(prim.indices),
                         "index " + std::to_string(uint64_t(std::max(x, 0.0))) +
                             " is past the vertex count " + std::to_string(vertices));
                indices.push_back(uint(x));
            }
        } else {
            for (size_t i = 0; i < vertices; ++i)
                indices.push_back(uint(i));
        }
        // A mirroring transform turns the winding: keep the front faces the file's.
        const bool mirrored = glm::determinant(glm::dmat3(world)) < 0.0;
        auto add = [&](uint a, uint b, uint c) {
            if (mirrored) std::swap(b, c);
            const vec3 e1 = m.positions[b] - m.positions[a], e2 = m.positions[c] - m.positions[a];
            if (glm::length(glm::cross(e1, e2)) > 0.0f)
                m.triangles.push_back(uvec3(a, b, c));
            else
                ++m.droppedTriangles;
        };
        if (mode == TINYGLTF_MODE_TRIANGLES) {
            if (indices.size() % 3 != 0) fail(at + "/indices", "a triangle list needs 3n indices");
            for (size_t i = 0; i + 2 < indices.size(); i += 3)
                add(indices[i], indices[i + 1], indices[i + 2]);
        } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
            for (size_t i = 0; i + 2 < indices.size(); ++i)
                i % 2 ? add(indices[i + 1], indices[i], indices[i + 2])
                      : add(indices[i], indices[i + 1], indices[i + 2]);
        } else {
            for (size_t i = 1; i + 1 < indices.size(); ++i)
                add(indices[0], indices[i], indices[i + 1]);
        }
    }

    // --- materials -------------------------------------------------------------------------

    // glTF's default material: white, metallic 1, roughness 1.
    static Shader defaultShader() {
        Shader s;
        s.typeName = "MetallicRoughness";
        s.params.model = kModelMetallicRoughness;
        s.params.colour = vec3(1.0f);
        s.params.reflectance = 1.0f;
        s.params.metallic = 1.0f;
        s.params.alpha = gltfAlpha(1.0f);
        s.params.ior = 1.5f;
        return s;
    }

    int shaderFor(int material, const std::string& at) {
        if (shaderOverride_ >= 0) return shaderOverride_;
        if (material >= int(model_.materials.size()))
            fail(at, "names material " + std::to_string(material) + " of " +
                         std::to_string(model_.materials.size()));
        // Materials 0 .. n-1 are shaders 0 .. n-1, made on first use; the default one is n.
        const size_t count = model_.materials.size();
        if (shaderOf_.empty()) shaderOf_.assign(count + 1, -1);
        const size_t key = material < 0 ? count : size_t(material);
        if (shaderOf_[key] < 0) {
            if (scene_.shaders.size() >= size_t(kMaxShaders))
                fail(at, "more than " + std::to_string(kMaxShaders) + " materials");
            shaderOf_[key] = int(scene_.shaders.size());
            scene_.shaders.push_back(material < 0 ? defaultShader() : readMaterial(material));
        }
        return shaderOf_[key];
    }

    Shader readMaterial(int index) {
        const tinygltf::Material& mat = model_.materials[size_t(index)];
        const std::string at = "/materials/" + std::to_string(index);
        const std::string name =
            "material " + std::to_string(index) + (mat.name.empty() ? "" : " (" + mat.name + ")");
        Shader s = defaultShader();
        const tinygltf::PbrMetallicRoughness& pbr = mat.pbrMetallicRoughness;
        if (pbr.baseColorFactor.size() != 4)
            fail(at + "/pbrMetallicRoughness/baseColorFactor", "needs 4 numbers");
        for (int k = 0; k < 3; ++k)
            s.params.colour[k] =
                unit(pbr.baseColorFactor[size_t(k)], at + "/pbrMetallicRoughness/baseColorFactor");
        s.params.metallic =
            float(unit(pbr.metallicFactor, at + "/pbrMetallicRoughness/metallicFactor"));
        s.roughness =
            float(unit(pbr.roughnessFactor, at + "/pbrMetallicRoughness/roughnessFactor"));
        s.params.alpha = gltfAlpha(s.roughness);
        readImages(mat, s, at, name);
        if (mat.alphaMode == "BLEND")
            warn(name + ": alphaMode BLEND is not rendered (it is drawn opaque)");
        else if (mat.alphaMode != "OPAQUE" && mat.alphaMode != "MASK")
            fail(at + "/alphaMode", "must be OPAQUE, MASK or BLEND");
        readEmission(mat, s, at, name);
        if (mat.doubleSided) s.params.flags |= kShaderTwoSided;
        return s;
    }

    // The material's images: base colour (and its alpha, for MASK), metallic-roughness and
    // normal map, and what is not rendered of the rest.
    void readImages(const tinygltf::Material& mat, Shader& s, const std::string& at,
                    const std::string& name) {
        const tinygltf::PbrMetallicRoughness& pbr = mat.pbrMetallicRoughness;
        if (pbr.baseColorTexture.index >= 0) baseColourTexture(pbr.baseColorTexture, s, at, name);
        if (mat.alphaMode == "MASK") readCutout(mat, s, at, name);
        if (pbr.metallicRoughnessTexture.index >= 0) {
            Texture mr = imageTexture(pbr.metallicRoughnessTexture,
                                      at + "/pbrMetallicRoughness/metallicRoughnessTexture",
                                      name + ": its metallicRoughnessTexture");
            mr.linear = true;
            s.metallicRoughnessTexture = int(scene_.textures.size());
            scene_.textures.push_back(mr);
            s.params.flags |= kShaderHitParams;
        }
        if (mat.normalTexture.index >= 0) {
            Texture normals = imageTexture(mat.normalTexture, at + "/normalTexture",
                                           name + ": its normalTexture");
            normals.linear = true;
            s.normalTexture = int(scene_.textures.size());
            scene_.textures.push_back(normals);
            s.normalScale = float(mat.normalTexture.scale);
            if (!std::isfinite(s.normalScale) || std::fabs(s.normalScale) > 1e3f)
                fail(at + "/normalTexture/scale", "must be a finite number of at most 1000");
        }
        if (mat.occlusionTexture.index >= 0)
            warn(name + ": its occlusionTexture is ignored (a path tracer finds occlusion itself)");
    }

    // emissiveFactor times KHR_materials_emissive_strength's strength, times emissiveTexture's
    // image (sRGB) where the material has one and the factor is not black.
    void readEmission(const tinygltf::Material& mat, Shader& s, const std::string& at,
                      const std::string& name) {
        double strength = 1.0;
        if (const auto e = mat.extensions.find("KHR_materials_emissive_strength");
            e != mat.extensions.end() && e->second.Has("emissiveStrength")) {
            const tinygltf::Value& v = e->second.Get("emissiveStrength");
            strength = v.IsNumber() ? v.GetNumberAsDouble() : -1.0;
            if (!(strength >= 0.0) || !std::isfinite(strength))
                fail(at + "/extensions/KHR_materials_emissive_strength/emissiveStrength",
                     "must be a non-negative number");
        }
        if (mat.emissiveFactor.size() != 3) fail(at + "/emissiveFactor", "needs 3 numbers");
        for (int k = 0; k < 3; ++k) {
            const double e = unit(mat.emissiveFactor[size_t(k)], at + "/emissiveFactor") * strength;
            if (!(e <= kMaxRadiance))
                fail(at + "/extensions/KHR_materials_emissive_strength",
                     "emission beyond " + std::to_string(kMaxRadiance));
            s.params.emission[k] = float(e);
        }
        if (mat.emissiveTexture.index >= 0 && maxComponent(s.params.emission) > 0.0f) {
            s.emissionTexture = int(scene_.textures.size());
            scene_.textures.push_back(imageTexture(mat.emissiveTexture, at + "/emissiveTexture",
                                                   name + ": its emissiveTexture"));
        }
    }

    double unit(double x, const std::string& at) const {
        if (!(x >= 0.0 && x <= 1.0)) fail(at, "must lie in [0, 1]");
        return x;
    }

    // The base colour's image, times the factor: Layered(upper: image, lower: 0, mask: factor).
    void baseColourTexture(const tinygltf::TextureInfo& info, Shader& s, const std::string& at,
                           const std::string& name) {
        Texture picture = imageTexture(info, at + "/pbrMetallicRoughness/baseColorTexture",
                                       name + ": its baseColorTexture");
        Texture zero{};
        zero.colour = vec3(0.0f);
        Texture factor{};
        factor.colour = s.params.colour;
        const int base = int(scene_.textures.size());
        scene_.textures.push_back(picture);
        scene_.textures.push_back(zero);
        scene_.textures.push_back(factor);
        Texture layered{};
        layered.type = TextureType::Layered;
        layered.upper = base, layered.lower = base + 1, layered.mask = base + 2;
        scene_.textures.push_back(layered);
        s.texture = base + 3;
        s.params.flags |= kShaderTextured;
    }

    // alphaMode MASK: a cut-out where baseColorFactor's alpha times the base colour image's
    // alpha channel (1 where it has none) is below alphaCutoff. A factor that decides alone is
    // no cut-out at all (at least the cutoff) or hides the whole surface.
    void readCutout(const tinygltf::Material& mat, Shader& s, const std::string& at,
                    const std::string& name) {
        const tinygltf::PbrMetallicRoughness& pbr = mat.pbrMetallicRoughness;
        Cutout& c = s.cutout;
        c.alpha = float(unit(pbr.baseColorFactor[3], at + "/pbrMetallicRoughness/baseColorFactor"));
        c.cutoff = float(mat.alphaCutoff);
        if (!(c.cutoff >= 0.0f) || !std::isfinite(mat.alphaCutoff))
            fail(at + "/alphaCutoff", "must be a non-negative number");
        if (pbr.baseColorTexture.index >= 0) {
            Texture alpha =
                imageTexture(pbr.baseColorTexture, at + "/pbrMetallicRoughness/baseColorTexture",
                             name + ": its baseColorTexture");
            alpha.channel = 3;
            alpha.linear = true;
            c.texture = int(scene_.textures.size());
            scene_.textures.push_back(alpha);
        }
        c.enabled = c.texture >= 0 || c.alpha < c.cutoff;
    }

    // A texture reference's image, as a Standard texture with its KHR_texture_transform: read
    // from memory where the file embeds it (checked readable now), else from beside the file.
    template <class Info> // tinygltf::TextureInfo, NormalTextureInfo
    Texture imageTexture(const Info& info, const std::string& where, const std::string& what) {
        const int index = info.index;
        if (info.texCoord != 0)
            warn(what + "'s texCoord " + std::to_string(info.texCoord) + " is read as TEXCOORD_0");
        if (index >= int(model_.textures.size()))
            fail(where, "names texture " + std::to_string(index) + " of " +
                            std::to_string(model_.textures.size()));
        const int source = model_.textures[size_t(index)].source;
        if (source < 0 || source >= int(model_.images.size()))
            fail("/textures/" + std::to_string(index) + "/source", "names no image");
        const tinygltf::Image& image = model_.images[size_t(source)];
        Texture picture{};
        picture.type = TextureType::Standard;
        const std::string imageAt = "/images/" + std::to_string(source);
        if (const auto e = embedded_.find(source); e != embedded_.end()) {
            // A name no file has, its extension telling OpenImageIO the format.
            const std::string ext = image.mimeType == "image/jpeg" ? ".jpg" : ".png";
            picture.path = fs::absolute(path_).lexically_normal().string() + "#image" +
                           std::to_string(source) + ext;
            picture.bytes = e->second;
            OIIO::Filesystem::IOMemReader proxy(const_cast<char*>(picture.bytes->data()),
                                                picture.bytes->size());
            auto in = OIIO::ImageInput::open(picture.path, nullptr, &proxy);
            if (!in || in->spec().width < 1 || in->spec().height < 1)
                fail(imageAt, "the embedded image is not one OpenImageIO can read" + imageError());
            in->close();
        } else {
            if (image.uri.empty()) fail(imageAt, "an image needs a uri or a bufferView");
            picture.path = fs::absolute(dir_ / decodeUri(image.uri)).lexically_normal().string();
            auto in = OIIO::ImageInput::open(picture.path);
            if (!in)
                fail(imageAt + "/uri",
                     "'" + picture.path + "' is not an image OpenImageIO can read" + imageError());
            in->close();
        }
        readTextureTransform(info, where, picture);
        if (const int sampler = model_.textures[size_t(index)].sampler; sampler >= 0) {
            if (sampler >= int(model_.samplers.size()))
                fail("/textures/" + std::to_string(index) + "/sampler",
                     "names sampler " + std::to_string(sampler) + " of " +
                         std::to_string(model_.samplers.size()));
            readSampler(model_.samplers[size_t(sampler)], "/samplers/" + std::to_string(sampler),
                        what, picture);
        }
        return picture;
    }

    // OpenImageIO's error after a failed open, as ": why" (or nothing). Asking also clears it:
    // OpenImageIO keeps it per thread until asked, and reports it at exit otherwise.
    static std::string imageError() {
        std::string why = OIIO::geterror();
        while (!why.empty() && (why.back() == '\n' || why.back() == '\r'))
            why.pop_back();
        return why.empty() ? "" : ": " + why;
    }

    // A sampler's wrap modes; its filters are always bilinear and trilinear across MIP levels,
    // and a NEAREST one is warned about.
    void readSampler(const tinygltf::Sampler& s, const std::string& at, const std::string& what,
                     Texture& picture) {
        auto wrap = [&](int mode, const char* field) {
            switch (mode) {
            case TINYGLTF_TEXTURE_WRAP_REPEAT:
                return Texture::Wrap::Repeat;
            case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE:
                return Texture::Wrap::Clamp;
            case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT:
                return Texture::Wrap::Mirror;
            default:
                fail(at + "/" + field, "must be 33071, 33648 or 10497");
            }
        };
        picture.wrapU = wrap(s.wrapS, "wrapS");
        picture.wrapV = wrap(s.wrapT, "wrapT");
        if (s.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST ||
            s.minFilter == TINYGLTF_TEXTURE_FILTER_NEAREST ||
            s.minFilter == TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_NEAREST ||
            s.minFilter == TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_LINEAR)
            warn(what + "'s sampler asks for NEAREST filtering: rendered bilinear");
    }

    // KHR_texture_transform on a texture reference: T(offset) R(rotation) S(scale) of glTF's
    // texture coordinates, written for Spillway's (v = 1 - glTF's v) as F M F, F that flip.
    template <class Info>
    void readTextureTransform(const Info& info, const std::string& where, Texture& picture) {
        const auto e = info.extensions.find("KHR_texture_transform");
        if (e == info.extensions.end()) return;
        const std::string at = where + "/extensions/KHR_texture_transform";
        auto numbers = [&](const char* key, std::vector<double> fallback) {
            if (!e->second.Has(key)) return fallback;
            const tinygltf::Value& v = e->second.Get(key);
            std::vector<double> out;
            if (v.IsNumber()) out.push_back(v.GetNumberAsDouble());
            for (int i = 0; v.IsArray() && i < int(v.ArrayLen()); ++i)
                out.push_back(v.Get(i).IsNumber() ? v.Get(i).GetNumberAsDouble() : NAN);
            for (double x : out)
                if (!std::isfinite(x) || std::fabs(x) > 1e6)
                    fail(at + "/" + key, "must be finite numbers of at most 1e6");
            if (out.size() != fallback.size())
                fail(at + "/" + key, "needs " + std::to_string(fallback.size()) + " numbers");
            return out;
        };
        const std::vector<double> offset = numbers("offset", {0.0, 0.0});
        const double rotation = numbers("rotation", {0.0})[0];
        const std::vector<double> scale = numbers("scale", {1.0, 1.0});
        if (e->second.Has("texCoord"))
            warn("KHR_texture_transform's texCoord is read as TEXCOORD_0");
        const double c = std::cos(rotation), sn = std::sin(rotation);
        // Column by column, as the extension's GLSL writes them.
        const glm::dmat3 t(1, 0, 0, 0, 1, 0, offset[0], offset[1], 1);
        const glm::dmat3 r(c, sn, 0, -sn, c, 0, 0, 0, 1);
        const glm::dmat3 sc(scale[0], 0, 0, 0, scale[1], 0, 0, 0, 1);
        const glm::dmat3 flip(1, 0, 0, 0, -1, 0, 0, 1, 1); // (u, v) -> (u, 1 - v)
        picture.uvTransformed = true;
        picture.uvTransform = mat3(flip * t * r * sc * flip);
        picture.footprintScale = float(std::max({std::fabs(scale[0]), std::fabs(scale[1]), 1e-6}));
    }

    static std::string decodeUri(const std::string& uri) {
        std::string out;
        for (size_t i = 0; i < uri.size(); ++i) {
            if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit(uri[i + 1]) &&
                std::isxdigit(uri[i + 2])) {
                out += char(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
                i += 2;
            } else {
                out += uri[i];
            }
        }
        return out;
    }

    // --- lights ----------------------------------------------------------------------------

    void readLight(const tinygltf::Node& n, const glm::dmat4& world, const std::string& at) {
        const auto ext = n.extensions.find("KHR_lights_punctual");
        if (ext == n.extensions.end()) return;
        const tinygltf::Value& v = ext->second.Get("light");
        const std::string where = at + "/extensions/KHR_lights_punctual/light";
        if (!v.IsInt() || v.GetNumberAsInt() < 0 || v.GetNumberAsInt() >= int(model_.lights.size()))
            fail(where, "names no light of the file's KHR_lights_punctual lights");
        const tinygltf::Light& l = model_.lights[size_t(v.GetNumberAsInt())];
        vec3 colour(1.0f);
        if (!l.color.empty()) {
            if (l.color.size() != 3) fail(where, "a light's color has 3 numbers");
            for (int k = 0; k < 3; ++k)
                colour[k] = float(unit(l.color[size_t(k)], where + "/color"));
        }
        if (!(l.intensity >= 0.0) || !(l.intensity / kLumensPerWatt <= kMaxRadiance))
            fail(where,
                 "a light's intensity must lie in [0, " + std::to_string(kMaxRadiance) + "]");
        PunctualLight p;
        p.intensity = colour * float(l.intensity / kLumensPerWatt);
        if (l.type == "point") {
            p.kind = kEmitterPoint;
            const glm::dvec3 rel = glm::dvec3(world[3]) - scene_.origin;
            if (const std::string far = beyondReach(rel, "a point light"); !far.empty())
                fail(at, far);
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

    void warnUnrendered() {
        if (!model_.animations.empty()) warn("has animations: rendered at rest");
        if (model_.scenes.size() > 1) warn("has more than one scene: the default one rendered");
    }

    std::string path_;
    fs::path dir_;
    Scene& scene_;
    tinygltf::Model model_;
    ImageBytes embedded_;
    std::set<std::string> warned_;
    std::set<int> onPath_;
    std::vector<int> shaderOf_;
    glm::dvec3 lo_{0.0}, hi_{0.0}; // the bounds of every position and point light read
    bool bounded_ = false;
    bool cameraFound_ = false, cameraSeen_ = false;
    int shaderOverride_ = -1;
};

} // namespace

bool isGltfPath(const std::string& path) {
    const std::string ext = lower(fs::path(path).extension().string());
    return ext == ".gltf" || ext == ".glb";
}

Scene loadGltfScene(const std::string& path) {
    Scene scene;
    scene.file = path;
    GltfReader(path, scene).readScene();
    return scene;
}

void appendGltfObject(const std::string& path, const glm::dmat4& transform, int shader,
                      Scene& scene) {
    GltfReader(path, scene).readObject(transform, shader);
}

} // namespace spw
