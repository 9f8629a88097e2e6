// GltfReader's accessors and meshes (gltf_reader.h): every accessor read through bounds-checked
// buffer views, sparse substitutions applied; each primitive's positions, normals, texture
// coordinates, vertex colours and triangles into a Mesh in the camera-relative world.
#include "host/loaders/gltf_reader.h"

#include "shared/metallic_roughness.h"

#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/quaternion.hpp>

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

template <class T>
std::vector<T> GltfReader::readAccessor(int index, int components, const std::string& at,
                                        bool integersOnly) const {
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
    if (integersOnly && (a.componentType == TINYGLTF_COMPONENT_TYPE_BYTE ||
                         a.componentType == TINYGLTF_COMPONENT_TYPE_SHORT ||
                         a.componentType == TINYGLTF_COMPONENT_TYPE_INT))
        fail(self + "/componentType", "indices must be unsigned integers");
    // Normalized indices would read as fractions of the largest index, most of them 0.
    if (integersOnly && a.normalized) fail(self + "/normalized", "indices are never normalized");
    const size_t element = size_t(size) * size_t(components);
    // Before anything is allocated: the values a count asks for, within the loader's limit (a
    // count whose product with the components wraps would otherwise allocate a few bytes).
    if (a.count > kMaxGltfAccessorValues / size_t(components))
        fail(self + "/count", "is " + std::to_string(a.count) + ": an accessor holds at most " +
                                  std::to_string(kMaxGltfAccessorValues) +
                                  " values (2^28) in Spillway");
    std::vector<T> out(a.count * size_t(components), T(0));
    if (a.bufferView >= 0) { // without one, all zeros (the specification's rule)
        size_t stride = 0;
        const unsigned char* base =
            viewBytes(a.bufferView, a.byteOffset, a.count, element, self, stride);
        for (size_t i = 0; i < a.count; ++i)
            for (int k = 0; k < components; ++k)
                out[i * size_t(components) + size_t(k)] = T(component(
                    base + i * stride + size_t(k) * size_t(size), a.componentType, a.normalized));
    }
    if (a.sparse.isSparse) applySparse(a, components, self, out);
    return out;
}
template std::vector<double> GltfReader::readAccessor<double>(int, int, const std::string&,
                                                              bool) const;
template std::vector<uint32_t> GltfReader::readAccessor<uint32_t>(int, int, const std::string&,
                                                                  bool) const;

template <class T>
void GltfReader::applySparse(const tinygltf::Accessor& a, int components, const std::string& self,
                             std::vector<T>& out) const {
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
        viewBytes(s.indices.bufferView, size_t(s.indices.byteOffset), size_t(s.count), indexSize,
                  at + "/indices", indexStride);
    const unsigned char* values =
        viewBytes(s.values.bufferView, size_t(s.values.byteOffset), size_t(s.count),
                  size * size_t(components), at + "/values", valueStride);
    for (size_t j = 0; j < size_t(s.count); ++j) {
        const double i = component(indices + j * indexStride, indexType, false);
        if (!(i < double(a.count)))
            fail(at + "/indices", "index " + std::to_string(uint64_t(i)) +
                                      " is past the accessor's count " + std::to_string(a.count));
        for (int k = 0; k < components; ++k)
            out[size_t(i) * size_t(components) + size_t(k)] = T(component(
                values + j * valueStride + size_t(k) * size, a.componentType, a.normalized));
    }
}

const unsigned char* GltfReader::viewBytes(int view, size_t byteOffset, size_t count,
                                           size_t element, const std::string& at,
                                           size_t& stride) const {
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

double GltfReader::component(const unsigned char* p, int componentType, bool norm) {
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

void GltfReader::readMesh(int index, const glm::dmat4& world, const std::string& at) {
    if (index >= int(model_.meshes.size()))
        fail(at,
             "names mesh " + std::to_string(index) + " of " + std::to_string(model_.meshes.size()));
    const tinygltf::Mesh& mesh = model_.meshes[size_t(index)];
    for (size_t p = 0; p < mesh.primitives.size(); ++p)
        readPrimitive(mesh.primitives[p], world,
                      "/meshes/" + std::to_string(index) + "/primitives/" + std::to_string(p),
                      mesh.name.empty() ? "mesh " + std::to_string(index) : mesh.name);
}

void GltfReader::readPrimitive(const tinygltf::Primitive& prim, const glm::dmat4& world,
                               const std::string& at, const std::string& name) {
    const int mode = prim.mode; // tinygltf's default where the file has none: triangles
    if (mode < 0 || mode > TINYGLTF_MODE_TRIANGLE_FAN) // points, lines (3), triangles (3)
        fail(at + "/mode", "is " + std::to_string(mode) + ", not a glTF primitive mode (0 to 6)");
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
        mode != TINYGLTF_MODE_TRIANGLE_FAN) {
        warn("has points or lines (primitive mode " + std::to_string(mode) + "), not rendered");
        return;
    }
    if (!prim.targets.empty()) warn("has morph targets: rendered without them");
    const auto position = prim.attributes.find("POSITION");
    if (position == prim.attributes.end()) fail(at + "/attributes", "has no POSITION");
    std::vector<double> pos = readAccessor(position->second, 3, at + "/attributes/POSITION");
    const size_t vertices = pos.size() / 3;
    Mesh m;
    m.name = path_ + ": " + name;
    m.shader = shaderFor(prim.material, at + "/material");
    m.positions.reserve(vertices + 1); // padForSharing's room, without a reallocation
    m.positions.resize(vertices);
    for (size_t i = 0; i < vertices; ++i) {
        const glm::dvec3 local(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]);
        const glm::dvec3 w = glm::dvec3(world * glm::dvec4(local, 1.0));
        if (!std::isfinite(w.x) || !std::isfinite(w.y) || !std::isfinite(w.z))
            fail("/accessors/" + std::to_string(position->second),
                 "position " + std::to_string(i) + " is not finite");
        // A prototype's vertices stay in its frame; its instances are placed (and bounded) later.
        if (prototype_ < 0) include(w);
        const glm::dvec3 rel = prototype_ < 0 ? w - scene_.origin : w;
        if (const std::string far = beyondReach(rel, "position " + std::to_string(i)); !far.empty())
            fail("/accessors/" + std::to_string(position->second), far);
        m.positions[i] = vec3(rel);
    }
    std::vector<double>().swap(pos); // released before the other attributes are read
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
    m.prototype = prototype_;
    scene_.meshes.push_back(std::move(m));
}

int GltfReader::readPrototype(int index, const std::string& at) {
    Prototype proto;
    const size_t first = scene_.meshes.size();
    prototype_ = int(scene_.prototypes.size());
    readMesh(index, glm::dmat4(1.0), at);
    prototype_ = -1;
    if (scene_.meshes.size() == first) return -1; // no triangles: nothing to place
    const tinygltf::Mesh& mesh = model_.meshes[size_t(index)];
    proto.name = path_ + ": " + (mesh.name.empty() ? "mesh " + std::to_string(index) : mesh.name);
    proto.lo = vec3(std::numeric_limits<float>::max());
    proto.hi = vec3(-std::numeric_limits<float>::max());
    for (size_t m = first; m < scene_.meshes.size(); ++m) {
        proto.meshes.push_back(uint(m));
        for (const vec3& p : scene_.meshes[m].positions) {
            proto.lo = glm::min(proto.lo, p);
            proto.hi = glm::max(proto.hi, p);
        }
    }
    scene_.prototypes.push_back(std::move(proto));
    return int(scene_.prototypes.size()) - 1;
}

void GltfReader::placeMeshes() {
    std::map<int, size_t> uses;
    for (const Placement& p : placements_)
        ++uses[p.mesh];
    std::map<int, int> prototypeOf; // glTF mesh -> prototype, or -1 for none (no triangles)
    for (const Placement& p : placements_) {
        if (uses[p.mesh] < 2) {
            readMesh(p.mesh, p.world, p.at());
            continue;
        }
        const auto known = prototypeOf.find(p.mesh);
        const int proto = known != prototypeOf.end()
                              ? known->second
                              : prototypeOf[p.mesh] = readPrototype(p.mesh, p.at());
        if (proto < 0) continue;
        glm::dmat4 world = p.world;
        world[3] -= glm::dvec4(scene_.origin, 0.0);
        std::string error;
        const Prototype& prototype = scene_.prototypes[size_t(proto)];
        if (world[0][3] != 0.0 || world[1][3] != 0.0 || world[2][3] != 0.0 || world[3][3] != 1.0)
            fail(p.at(), "the node's transform is not affine (its last row is not 0 0 0 1)");
        Instance inst = makeInstance(prototype, uint(proto), world, error);
        if (!error.empty()) {
            if (error.find("singular") == std::string::npos) fail(p.at(), error);
            warn("places a mesh with a singular transform (a zero scale): not rendered there");
            continue;
        }
        if (scene_.instances.size() >= size_t(kMaxInstances))
            fail(p.at(), "more than " + std::to_string(kMaxInstances) + " instances");
        instancedEmitters_ += emissiveTriangles(scene_, prototype);
        if (instancedEmitters_ > kMaxInstancedEmitters)
            fail(p.at(), "the emissive triangles instances place, counted at each placement, "
                         "are more than " +
                             std::to_string(kMaxInstancedEmitters));
        for (int k = 0; k < 8; ++k) { // the bounds a camera framing the scene sees
            const glm::dvec3 corner(k & 1 ? prototype.hi.x : prototype.lo.x,
                                    k & 2 ? prototype.hi.y : prototype.lo.y,
                                    k & 4 ? prototype.hi.z : prototype.lo.z);
            include(glm::dvec3(p.world * glm::dvec4(corner, 1.0)));
        }
        scene_.instances.push_back(inst);
    }
    placements_.clear();
}

void GltfReader::readNormals(const tinygltf::Primitive& prim, const glm::dmat4& world,
                             size_t vertices, const std::string& at, Mesh& m) {
    const auto n = prim.attributes.find("NORMAL");
    if (n == prim.attributes.end()) return;
    const glm::dmat3 normalMatrix = glm::inverseTranspose(glm::dmat3(world));
    const std::vector<double> nor = readAccessor(n->second, 3, at + "/attributes/NORMAL");
    if (nor.size() != 3 * vertices)
        fail(at + "/attributes/NORMAL", "has another count than POSITION");
    m.normals.resize(vertices);
    for (size_t i = 0; i < vertices && !m.normals.empty(); ++i) {
        const glm::dvec3 w = normalMatrix * glm::dvec3(nor[3 * i], nor[3 * i + 1], nor[3 * i + 2]);
        const double len = glm::length(w);
        if (!(len > 1e-30) || !std::isfinite(len)) {
            warn("has zero or non-finite normals: its faces' own normals used there");
            m.normals.clear();
        } else {
            m.normals[i] = vec3(w / len);
        }
    }
}

void GltfReader::readTextureCoordinates(const tinygltf::Primitive& prim, size_t vertices,
                                        const std::string& at, Mesh& m) {
    const auto set = uvSetOf_.find(m.shader);
    const std::string attribute =
        "TEXCOORD_" + std::to_string(set == uvSetOf_.end() ? 0 : set->second);
    const auto t = prim.attributes.find(attribute);
    if (t == prim.attributes.end()) {
        const Shader& shader = scene_.shaders[size_t(m.shader)];
        if (shader.looksUpTextures() || shader.cutout.texture >= 0 || shader.emissionTexture >= 0)
            warn("a primitive whose material has images has no " + attribute +
                 ": they are read at (0, 0) there");
        return;
    }
    const std::string where = at + "/attributes/" + attribute;
    const std::vector<double> uv = readAccessor(t->second, 2, where);
    if (uv.size() != 2 * vertices) fail(where, "has another count than POSITION");
    m.uvs.resize(vertices);
    for (size_t i = 0; i < vertices; ++i) {
        m.uvs[i] = vec2(float(uv[2 * i]), float(1.0 - uv[2 * i + 1]));
        if (!std::isfinite(m.uvs[i].x) || !std::isfinite(m.uvs[i].y))
            fail("/accessors/" + std::to_string(t->second), "a texture coordinate is not finite");
    }
}

void GltfReader::readColours(const tinygltf::Primitive& prim, size_t vertices,
                             const std::string& at, Mesh& m) const {
    const auto c = prim.attributes.find("COLOR_0");
    if (c == prim.attributes.end() || shaderOverride_ >= 0) return;
    const std::string where = at + "/attributes/COLOR_0";
    const int index = c->second;
    const std::string self = "/accessors/" + std::to_string(index);
    const int components =
        index >= 0 && index < int(model_.accessors.size())
            ? tinygltf::GetNumComponentsInType(uint32_t(model_.accessors[size_t(index)].type))
            : 3; // readAccessor names the bad index
    if (components != 3 && components != 4) fail(self + "/type", "COLOR_0 must be VEC3 or VEC4");
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

void GltfReader::readTriangles(const tinygltf::Primitive& prim, int mode, const glm::dmat4& world,
                               size_t vertices, const std::string& at, Mesh& m) const {
    std::vector<uint32_t> indices;
    if (prim.indices >= 0) {
        indices = readAccessor<uint32_t>(prim.indices, 1, at + "/indices", true);
        for (uint32_t x : indices)
            if (x >= vertices)
                fail("/accessors/" + std::to_string(prim.indices),
                     "index " + std::to_string(x) + " is past the vertex count " +
                         std::to_string(vertices));
    } else {
        indices.resize(vertices);
        for (size_t i = 0; i < vertices; ++i)
            indices[i] = uint32_t(i);
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

} // namespace spw
