// A glTF file's nodes, read from its JSON by Spillway instead of tinygltf. A production scene's
// nodes are most of its JSON (a forest of a million placements is a million nodes), and
// tinygltf's Node is 456 bytes before its vectors, kept beside its own JSON tree while it parses:
// a million nodes took 600 MB of it. A GltfNode is what the reader visits, its local transform
// already composed and checked: about 170 bytes. Reading them here also checks what tinygltf
// would have cast or dropped: every index an integer from 0 to 2^31 - 1 (4294967296 is not 0),
// every transform an array of the numbers it needs.
#pragma once

#include <glm/mat4x4.hpp>
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace spw {

struct GltfNode {
    // What the node names, -1 where it names nothing. light: its KHR_lights_punctual light, or
    // kNoSuchLight where the extension names none that can be (the reader says so when it
    // places the node).
    int mesh = -1, camera = -1, skin = -1, light = -1;
    static constexpr int kNoSuchLight = -2;
    std::vector<int> children;
    glm::dmat4 local{1.0}; // its matrix, or translation x rotation x scale
};

// The nodes of `doc` (the file at `path`), taken out of it: the document tinygltf is then handed
// has none. Throws SceneError naming the node's JSON pointer.
std::vector<GltfNode> takeGltfNodes(const std::string& path, nlohmann::json& doc);

} // namespace spw
