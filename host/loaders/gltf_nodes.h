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

#include <map>
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

// The nodes of a glTF file's JSON, read while nlohmann's parser reads it (as its callback): each
// node is read as its object ends and dropped from the tree, so that the nodes' JSON is never
// held whole (a million nodes' would be 785 MB of nlohmann's tree). The document parsed is left
// with an empty "nodes" array.
class GltfNodeCollector {
  public:
    explicit GltfNodeCollector(const std::string& path) : path_(path) {}
    // nlohmann::json::parser_callback_t: false drops `parsed` from the tree.
    bool operator()(int depth, nlohmann::json::parse_event_t event, nlohmann::json& parsed);
    // The nodes read. Throws the first node's SceneError (its JSON pointer), if any.
    std::vector<GltfNode> take();
    // The extensions the nodes use, each with the pointer of its first use.
    const std::map<std::string, std::string>& extensions() const { return extensions_; }

  private:
    void read(const nlohmann::json& node);
    std::string path_;
    std::string key_;      // the top-level key last read
    bool inNodes_ = false; // within the top-level "nodes" array
    std::vector<GltfNode> nodes_;
    std::string error_; // the first node's error, as SceneError's message
    std::map<std::string, std::string> extensions_;
};

} // namespace spw
