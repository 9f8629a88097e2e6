#include "host/loaders/gltf_nodes.h"

#include "host/scene/scene.h"

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include <climits>
#include <cmath>

namespace spw {
namespace {

using nlohmann::json;

// A node's problem: its JSON pointer and what is wrong.
struct NodeError {
    std::string message;
};

class NodeReader {
  public:
    GltfNode read(const json& o, const std::string& at) const {
        if (!o.is_object()) fail(at, "a node is a JSON object");
        GltfNode n;
        n.mesh = index(o, "mesh", at);
        n.camera = index(o, "camera", at);
        n.skin = index(o, "skin", at);
        if (o.contains("children")) {
            const json& c = o["children"];
            if (!c.is_array()) fail(at + "/children", "must be an array of node indices");
            n.children.reserve(c.size());
            for (size_t k = 0; k < c.size(); ++k)
                n.children.push_back(index(c[k], at + "/children/" + std::to_string(k)));
        }
        n.light = light(o);
        n.local = transform(o, at);
        return n;
    }

  private:
    [[noreturn]] static void fail(const std::string& at, const std::string& message) {
        throw NodeError{at + ": " + message};
    }

    // An index: an integer JSON number from 0 to INT_MAX (not 2^32, which a cast reads as 0).
    int index(const json& v, const std::string& at) const {
        if (!v.is_number_integer() || v.get<double>() < 0.0)
            fail(at, "must be an integer of at least 0");
        if (v.get<double>() > double(INT_MAX))
            fail(at,
                 "is " + v.dump() + ": must be an integer of at most " + std::to_string(INT_MAX));
        return int(v.get<double>());
    }
    int index(const json& o, const char* key, const std::string& at) const {
        return o.contains(key) ? index(o[key], at + "/" + key) : -1;
    }

    int light(const json& o) const {
        if (!o.contains("extensions") || !o["extensions"].is_object() ||
            !o["extensions"].contains("KHR_lights_punctual"))
            return -1;
        const json& e = o["extensions"]["KHR_lights_punctual"];
        if (!e.is_object() || !e.contains("light") || !e["light"].is_number_integer() ||
            e["light"].get<double>() < 0.0 || e["light"].get<double>() > double(INT_MAX))
            return GltfNode::kNoSuchLight;
        return e["light"].get<int>();
    }

    // The `count` numbers of o[key] (absent: false), or an error naming them.
    bool numbers(const json& o, const char* key, size_t count, const std::string& at,
                 const char* what, double* out) const {
        if (!o.contains(key)) return false;
        const json& a = o[key];
        if (!a.is_array() || a.size() != count) fail(at + "/" + key, what);
        for (size_t i = 0; i < count; ++i) {
            if (!a[i].is_number()) fail(at + "/" + key, what);
            out[i] = a[i].get<double>();
        }
        return true;
    }

    glm::dmat4 finite(const glm::dmat4& m, const std::string& at) const {
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r)
                if (!std::isfinite(m[c][r])) fail(at, "the transform is not finite");
        return m;
    }

    // Its matrix, or translation x rotation x scale (glTF 2.0, 5.25), each checked.
    glm::dmat4 transform(const json& o, const std::string& at) const {
        double v[16];
        if (numbers(o, "matrix", 16, at, "a matrix has 16 numbers", v)) {
            glm::dmat4 m;
            for (int c = 0; c < 4; ++c)
                for (int r = 0; r < 4; ++r)
                    m[c][r] = v[4 * c + r];
            return finite(m, at + "/matrix");
        }
        glm::dmat4 m(1.0);
        if (numbers(o, "translation", 3, at, "a translation has 3 numbers", v))
            m = glm::translate(m, glm::dvec3(v[0], v[1], v[2]));
        if (numbers(o, "rotation", 4, at, "a rotation has 4 numbers", v)) {
            // glTF's quaternions are (x, y, z, w); glm's constructor takes w first.
            const glm::dquat q(v[3], v[0], v[1], v[2]);
            const double len = glm::length(q);
            if (!(len > 0.0) || !std::isfinite(len))
                fail(at + "/rotation", "a rotation must be a non-zero quaternion");
            m = m * glm::mat4_cast(q / len);
        }
        if (numbers(o, "scale", 3, at, "a scale has 3 numbers", v))
            m = glm::scale(m, glm::dvec3(v[0], v[1], v[2]));
        return finite(m, at);
    }
};

} // namespace

bool GltfNodeCollector::operator()(int depth, json::parse_event_t event, json& parsed) {
    using E = json::parse_event_t;
    if (depth == 1 && event == E::key) key_ = parsed.get<std::string>();
    if (depth == 1 && event == E::array_start) inNodes_ = key_ == "nodes";
    if (depth == 1 && event == E::array_end) inNodes_ = false;
    if (!inNodes_ || depth != 2 ||
        (event != E::object_end && event != E::array_end && event != E::value))
        return true;
    read(parsed);
    return false; // read: not kept in the tree
}

void GltfNodeCollector::read(const json& node) {
    const std::string at = "/nodes/" + std::to_string(nodes_.size());
    try {
        nodes_.push_back(NodeReader().read(node, at));
    } catch (const NodeError& e) {
        if (error_.empty()) error_ = e.message;
        nodes_.emplace_back();
    }
    if (node.is_object() && node.contains("extensions") && node["extensions"].is_object())
        for (const auto& [name, body] : node["extensions"].items())
            extensions_.emplace(name, at + "/extensions/" + name);
}

std::vector<GltfNode> GltfNodeCollector::take() {
    if (!error_.empty()) throw SceneError(path_, 0, error_);
    return std::move(nodes_);
}

} // namespace spw
