// glTF documents built by the tests in memory (tests/scene/gltf_test.cpp, gltf_hostile_test.cpp):
// accessors appended to one buffer, written as a .gltf with an embedded or external buffer, or
// as a .glb.
#pragma once

#include "test_util.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace spw::test {

using nlohmann::json;

// A glTF document built in memory: one buffer of bytes, accessors appended to it.
struct GltfBuilder {
    json doc = {{"asset", {{"version", "2.0"}}}};
    std::string bytes;

    // An accessor over `data` (each value written as `componentType`) of glTF type `type`.
    template <class T>
    int accessor(const std::vector<T>& data, int componentType, const std::string& type,
                 bool normalized = false, size_t stride = 0) {
        while (bytes.size() % 4 != 0)
            bytes.push_back('\0');
        const size_t offset = bytes.size();
        const int components = type == "SCALAR" ? 1 : type == "VEC2" ? 2 : type == "VEC3" ? 3 : 4;
        const size_t element = sizeof(T) * size_t(components);
        const size_t step = stride ? stride : element;
        const size_t count = data.size() / size_t(components);
        bytes.resize(offset + step * count, '\x7f'); // the padding between strided elements
        for (size_t i = 0; i < count; ++i)
            std::memcpy(&bytes[offset + i * step], &data[i * size_t(components)], element);
        json view = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", step * count}};
        if (stride) view["byteStride"] = stride;
        doc["bufferViews"].push_back(view);
        json a = {{"bufferView", doc["bufferViews"].size() - 1},
                  {"componentType", componentType},
                  {"count", count},
                  {"type", type}};
        if (normalized) a["normalized"] = true;
        if (type == "VEC3" && componentType == 5126) { // POSITION needs its bounds
            json lo = json::array(), hi = json::array();
            for (int k = 0; k < 3; ++k) {
                float l = 1e30f, h = -1e30f;
                for (size_t i = 0; i < count; ++i)
                    l = std::min(l, float(data[3 * i + size_t(k)])),
                    h = std::max(h, float(data[3 * i + size_t(k)]));
                lo.push_back(l), hi.push_back(h);
            }
            a["min"] = lo, a["max"] = hi;
        }
        doc["accessors"].push_back(a);
        return int(doc["accessors"].size()) - 1;
    }

    // A tightly packed buffer view of `data` (for a sparse accessor's indices and values).
    template <class T> int view(const std::vector<T>& data) {
        while (bytes.size() % 4 != 0)
            bytes.push_back('\0');
        const size_t offset = bytes.size();
        bytes.append(reinterpret_cast<const char*>(data.data()), data.size() * sizeof(T));
        doc["bufferViews"].push_back(
            {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", data.size() * sizeof(T)}});
        return int(doc["bufferViews"].size()) - 1;
    }

    // A unit quad in z = 0 facing +Z (two triangles), with normals and texture coordinates.
    json quad(int material = -1, int indexType = 5123) {
        const int pos = accessor<float>({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, 5126, "VEC3");
        const int nor = accessor<float>({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, 5126, "VEC3");
        const int uv = accessor<float>({0, 1, 1, 1, 1, 0, 0, 0}, 5126, "VEC2");
        int idx;
        if (indexType == 5121)
            idx = accessor<uint8_t>({0, 1, 2, 0, 2, 3}, 5121, "SCALAR");
        else if (indexType == 5125)
            idx = accessor<uint32_t>({0, 1, 2, 0, 2, 3}, 5125, "SCALAR");
        else
            idx = accessor<uint16_t>({0, 1, 2, 0, 2, 3}, 5123, "SCALAR");
        json prim = {{"attributes", {{"POSITION", pos}, {"NORMAL", nor}, {"TEXCOORD_0", uv}}},
                     {"indices", idx}};
        if (material >= 0) prim["material"] = material;
        return prim;
    }
    int mesh(const json& primitive) {
        doc["meshes"].push_back({{"primitives", json::array({primitive})}});
        return int(doc["meshes"].size()) - 1;
    }
    int node(json n) {
        doc["nodes"].push_back(std::move(n));
        return int(doc["nodes"].size()) - 1;
    }
    void scene(const std::vector<int>& roots) {
        doc["scenes"] = json::array({{{"nodes", roots}}});
        doc["scene"] = 0;
    }

    static std::string base64(const std::string& in) {
        static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        std::string out;
        for (size_t i = 0; i < in.size(); i += 3) {
            const uint32_t b = uint32_t(uint8_t(in[i])) << 16 |
                               (i + 1 < in.size() ? uint32_t(uint8_t(in[i + 1])) << 8 : 0u) |
                               (i + 2 < in.size() ? uint32_t(uint8_t(in[i + 2])) : 0u);
            out += k[b >> 18 & 63];
            out += k[b >> 12 & 63];
            out += i + 1 < in.size() ? k[b >> 6 & 63] : '=';
            out += i + 2 < in.size() ? k[b & 63] : '=';
        }
        return out;
    }

    // The document as a .gltf with its buffer embedded (a data: URI).
    std::string embedded(const TempDir& dir, const std::string& name) {
        json d = doc;
        d["buffers"] =
            json::array({{{"byteLength", bytes.size()},
                          {"uri", "data:application/octet-stream;base64," + base64(bytes)}}});
        return dir.write(name, d.dump());
    }
    // As a .gltf beside its buffer file.
    std::string external(const TempDir& dir, const std::string& name) {
        json d = doc;
        d["buffers"] = json::array({{{"byteLength", bytes.size()}, {"uri", name + ".bin"}}});
        dir.write(name + ".bin", bytes);
        return dir.write(name, d.dump());
    }
    // As a .glb: the JSON chunk and the binary chunk, each padded to 4 bytes.
    std::string binary(const TempDir& dir, const std::string& name) {
        json d = doc;
        d["buffers"] = json::array({{{"byteLength", bytes.size()}}});
        std::string text = d.dump(), bin = bytes;
        while (text.size() % 4)
            text += ' ';
        while (bin.size() % 4)
            bin += '\0';
        std::string out;
        auto u32 = [&](uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
        u32(0x46546C67u), u32(2u), u32(uint32_t(12 + 8 + text.size() + 8 + bin.size()));
        u32(uint32_t(text.size())), u32(0x4E4F534Au), out += text;
        u32(uint32_t(bin.size())), u32(0x004E4942u), out += bin;
        return dir.write(name, out);
    }
};

// A material: base colour, metallic, roughness, emission.
inline json material(vec3 colour, float metallic, float roughness, vec3 emission = vec3(0.0f)) {
    return {{"pbrMetallicRoughness",
             {{"baseColorFactor", {colour.x, colour.y, colour.z, 1.0}},
              {"metallicFactor", metallic},
              {"roughnessFactor", roughness}}},
            {"emissiveFactor", {emission.x, emission.y, emission.z}}};
}

} // namespace spw::test
