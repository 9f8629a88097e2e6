#include "host/loaders/gltf_preflight.h"

#include "host/loaders/gltf_text_scan.h"
#include "host/scene/scene.h"

#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <climits>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

namespace spw {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

[[noreturn]] void fail(const std::string& path, const std::string& pointer,
                       const std::string& message) {
    throw SceneError(path, 0, (pointer.empty() ? "" : pointer + ": ") + message);
}

std::uint32_t u32(const std::string& bytes, size_t at) {
    std::uint32_t v;
    std::memcpy(&v, bytes.data() + at, 4);
    return v;
}

std::string readBytes(std::ifstream& in, size_t count) {
    std::string out(count, '\0');
    in.read(out.data(), std::streamsize(count));
    out.resize(size_t(in.gcount()));
    return out;
}

// The JSON of a .glb: its framing checked against the file's size first (tinygltf trusts the
// chunk lengths, and reads past the file's end where they claim more).
std::string glbJson(const std::string& path, std::ifstream& in, std::uint64_t size,
                    GltfDocument& out) {
    const std::string head = readBytes(in, 20);
    if (head.size() < 12 || u32(head, 0) != 0x46546C67u)
        fail(path, "", "not a GLB file: it does not start with the 'glTF' magic");
    if (u32(head, 4) == 1u)
        fail(path, "",
             "glTF 1.0 is not supported (this is a glTF 1.0 binary); Spillway reads "
             "glTF 2.0");
    if (u32(head, 4) != 2u)
        fail(path, "",
             "GLB version " + std::to_string(u32(head, 4)) + "; Spillway reads version 2");
    const std::uint64_t length = u32(head, 8);
    if (length > size)
        fail(path, "",
             "the GLB header claims " + std::to_string(length) + " bytes; the file has " +
                 std::to_string(size));
    if (head.size() < 20 || length < 20) fail(path, "", "the GLB file has no JSON chunk");
    const std::uint64_t jsonLength = u32(head, 12);
    if (u32(head, 16) != 0x4E4F534Au) fail(path, "", "the GLB file's first chunk is not JSON");
    if (20 + jsonLength > length)
        fail(path, "",
             "the JSON chunk claims " + std::to_string(jsonLength) + " bytes, past the file's end");
    std::string text = readBytes(in, size_t(jsonLength));
    if (20 + jsonLength + 8 <= length) {
        const std::string chunk = readBytes(in, 8);
        const std::uint64_t binLength = chunk.size() == 8 ? u32(chunk, 0) : 0;
        if (chunk.size() == 8 && 28 + jsonLength + binLength > length)
            fail(path, "",
                 "the BIN chunk claims " + std::to_string(binLength) +
                     " bytes, past the file's end");
        if (chunk.size() == 8 && u32(chunk, 4) == 0x004E4942u) // "BIN\0"
            out.binOffset = 28 + jsonLength, out.binLength = binLength;
    }
    return text;
}

// What a path names when it is not a regular file ("" when it is one).
std::string notRegular(const fs::path& p) {
    std::error_code ec;
    const fs::file_status st = fs::status(p, ec);
    if (ec || !fs::exists(st)) return "which does not exist";
    if (fs::is_regular_file(st)) return "";
    if (fs::is_directory(st)) return "which is a folder";
    if (fs::is_fifo(st)) return "which is a FIFO";
    return "which is not a regular file";
}

// The files that buffers and images name must be regular files: tinygltf would block on a FIFO
// for ever, and read a folder as a file of nonsense size.
void checkUris(const std::string& path, const json& doc) {
    const fs::path dir = fs::path(path).parent_path();
    for (const char* kind : {"buffers", "images"}) {
        if (!doc.contains(kind) || !doc[kind].is_array()) continue;
        for (size_t i = 0; i < doc[kind].size(); ++i) {
            const json& entry = doc[kind][i];
            if (!entry.is_object() || !entry.contains("uri") || !entry["uri"].is_string()) continue;
            const std::string uri = entry["uri"].get<std::string>();
            if (uri.rfind("data:", 0) == 0) continue;
            const std::string why = notRegular(dir / decodeGltfUri(uri));
            if (!why.empty())
                fail(path, "/" + std::string(kind) + "/" + std::to_string(i) + "/uri",
                     "names '" + uri + "', " + why +
                         "; a glTF file's buffers and images are "
                         "regular files");
        }
    }
}

void checkVersion(const std::string& path, const json& doc) {
    if (doc.contains("scenes") && doc["scenes"].is_object())
        fail(path, "/scenes",
             "glTF 1.0 is not supported (its scenes are a dictionary); Spillway "
             "reads glTF 2.0");
    if (!doc.contains("asset") || !doc["asset"].is_object() || !doc["asset"].contains("version") ||
        !doc["asset"]["version"].is_string())
        return; // tinygltf says what is missing
    const std::string v = doc["asset"]["version"].get<std::string>();
    if (v == "1" || v.rfind("1.", 0) == 0)
        fail(path, "/asset/version",
             "is '" + v +
                 "': glTF 1.0 is not supported; Spillway reads "
                 "glTF 2.0");
    if (v != "2" && v.rfind("2.", 0) != 0)
        fail(path, "/asset/version", "is '" + v + "'; Spillway reads glTF 2.0");
}

void checkRequired(const std::string& path, const json& doc,
                   const std::set<std::string>& honoured) {
    if (!doc.contains("extensionsRequired") || !doc["extensionsRequired"].is_array()) return;
    for (const json& e : doc["extensionsRequired"]) {
        if (!e.is_string() || honoured.count(e.get<std::string>())) continue;
        const std::string name = e.get<std::string>();
        if (name == "KHR_draco_mesh_compression")
            fail(path, "/extensionsRequired",
                 "requires KHR_draco_mesh_compression (Draco-compressed meshes), which Spillway "
                 "does not decode; export the file without Draco compression");
        if (name == "EXT_meshopt_compression")
            fail(path, "/extensionsRequired",
                 "requires EXT_meshopt_compression (meshoptimizer-compressed buffers), which "
                 "Spillway does not decode");
        fail(path, "/extensionsRequired",
             "requires the extension " + name + ", which Spillway does not render");
    }
}

// The nodes some scene holds: its roots and everything below them.
std::vector<bool> nodesInScenes(const json& scenes, const std::vector<GltfNode>& nodes) {
    std::vector<bool> held(nodes.size(), false);
    std::vector<size_t> todo;
    for (const json& scene : scenes) {
        if (!scene.is_object() || !scene.contains("nodes") || !scene["nodes"].is_array()) continue;
        for (const json& n : scene["nodes"])
            if (n.is_number_integer() && n.get<long long>() >= 0 &&
                n.get<long long>() < (long long)nodes.size())
                todo.push_back(size_t(n.get<long long>()));
    }
    while (!todo.empty()) {
        const size_t i = todo.back();
        todo.pop_back();
        if (held[i]) continue;
        held[i] = true;
        for (int c : nodes[i].children)
            if (c >= 0 && c < int(nodes.size())) todo.push_back(size_t(c));
    }
    return held;
}

// The node hierarchy is a set of disjoint trees (glTF 2.0, 3.5.3): a node is the child of one
// node at most, and a scene's nodes are roots, each named once. One leniency, as Blender's
// importer has it: a root whose parent no scene holds (UniGLTF's VRM exports write such files)
// is rendered as a root, and `warnings` says so.
void checkForest(const std::string& path, const json& doc, const std::vector<GltfNode>& nodes,
                 std::vector<std::string>& warnings) {
    std::vector<long long> parent(nodes.size(), -1);
    for (size_t i = 0; i < nodes.size(); ++i) {
        const std::vector<int>& children = nodes[i].children;
        for (size_t k = 0; k < children.size(); ++k) {
            const long long c = children[k];
            if (c >= (long long)nodes.size()) continue; // the reader names it
            if (parent[size_t(c)] >= 0)
                fail(path, "/nodes/" + std::to_string(i) + "/children/" + std::to_string(k),
                     "names node " + std::to_string(c) + ", which node " +
                         std::to_string(parent[size_t(c)]) +
                         " names too: a glTF node has one parent at most");
            parent[size_t(c)] = (long long)i;
        }
    }
    if (!doc.contains("scenes") || !doc["scenes"].is_array()) return;
    std::vector<bool> inScenes;
    for (size_t s = 0; s < doc["scenes"].size(); ++s) {
        const json& scene = doc["scenes"][s];
        if (!scene.is_object() || !scene.contains("nodes") || !scene["nodes"].is_array()) continue;
        std::vector<bool> named(nodes.size(), false);
        for (size_t k = 0; k < scene["nodes"].size(); ++k) {
            const json& n = scene["nodes"][k];
            if (!n.is_number_integer()) continue;
            const long long r = n.get<long long>();
            if (r < 0 || r >= (long long)nodes.size()) continue;
            const std::string at = "/scenes/" + std::to_string(s) + "/nodes/" + std::to_string(k);
            if (const long long p = parent[size_t(r)]; p >= 0) {
                if (inScenes.empty()) inScenes = nodesInScenes(doc["scenes"], nodes);
                const std::string what =
                    "names node " + std::to_string(r) + ", a child of node " + std::to_string(p);
                if (inScenes[size_t(p)]) fail(path, at, what + ": a scene's nodes are roots");
                warnings.push_back(at + ": " + what + ", which no scene holds: rendered as a root");
            }
            if (named[size_t(r)]) fail(path, at, "names node " + std::to_string(r) + " twice");
            named[size_t(r)] = true;
        }
    }
}

// Every extension an object uses is declared in extensionsUsed (glTF 2.0, 3.12): a file that
// uses one it does not declare is not valid, and its author would not know what is read.
void checkDeclared(const std::string& path, const json& j, const std::set<std::string>& used,
                   const std::string& at) {
    if (j.is_object()) {
        for (const auto& [key, value] : j.items()) {
            const std::string here = at + "/" + key;
            if (key == "extensions" && value.is_object())
                for (const auto& [name, body] : value.items())
                    if (!used.count(name))
                        fail(path, here + "/" + name,
                             "uses the extension " + name +
                                 ", which the file's extensionsUsed does not declare");
            checkDeclared(path, value, used, here);
        }
    } else if (j.is_array()) {
        for (size_t i = 0; i < j.size(); ++i)
            checkDeclared(path, j[i], used, at + "/" + std::to_string(i));
    }
}

// The properties whose values are indices or enumerations (integers from 0 to INT_MAX, which
// tinygltf casts to int), and those that are byte offsets, lengths and counts (non-negative
// integers, which it reads as size_t and the readers bound); the arrays and objects whose every
// entry is an index.
const std::set<std::string> kIndexKeys = {
    "index",     "texCoord", "source",  "sampler",       "bufferView",
    "buffer",    "material", "indices", "mesh",          "camera",
    "skin",      "scene",    "node",    "light",         "input",
    "output",    "skeleton", "mode",    "componentType", "magFilter",
    "minFilter", "wrapS",    "wrapT",   "byteStride",    "inverseBindMatrices"};
const std::set<std::string> kSizeKeys = {"byteOffset", "byteLength", "count"};
const std::set<std::string> kIndexLists = {"nodes", "joints", "children", "attributes"};
// The numbers and arrays of numbers tinygltf reads into typed fields, dropping a value of another
// type for the default without a word ("alphaCutoff": "0.9" read as 0.5). The extensions' own
// values are read by Spillway, which refuses a wrong type itself.
const std::set<std::string> kNumberKeys = {"alphaCutoff", "metallicFactor", "roughnessFactor",
                                           "strength",    "yfov",           "aspectRatio",
                                           "znear",       "zfar",           "xmag",
                                           "ymag",        "innerConeAngle", "outerConeAngle",
                                           "intensity",   "range"};
const std::set<std::string> kNumberArrayKeys = {"baseColorFactor", "emissiveFactor", "color"};
// The strings, booleans, objects and arrays tinygltf reads, dropping a value of another type as
// silently (a mesh whose "primitives" is an object has no primitives; "doubleSided": "yes" is
// false).
const std::set<std::string> kStringKeys = {"name",          "uri",        "mimeType",  "alphaMode",
                                           "type",          "path",       "generator", "version",
                                           "interpolation", "minVersion", "copyright"};
const std::set<std::string> kBoolKeys = {"doubleSided", "normalized"};
const std::set<std::string> kObjectKeys = {"pbrMetallicRoughness", "asset",  "perspective",
                                           "orthographic",         "sparse", "spot"};
const std::set<std::string> kArrayKeys = {"primitives", "targets", "channels", "samplers"};

// The JSON type of a value tinygltf reads into a typed field.
void checkType(const std::string& path, const std::string& key, const json& value,
               const std::string& at) {
    if (kNumberKeys.count(key) && !value.is_number()) fail(path, at, "must be a number");
    if (kStringKeys.count(key) && !value.is_string()) fail(path, at, "must be a string");
    if (kBoolKeys.count(key) && !value.is_boolean()) fail(path, at, "must be true or false");
    if (kObjectKeys.count(key) && !value.is_object()) fail(path, at, "must be an object");
    if (kArrayKeys.count(key) && !value.is_array()) fail(path, at, "must be an array");
    // baseColorTexture, transmissionTexture, ...: tinygltf drops an empty object unseen.
    if (key.size() > 7 && key.compare(key.size() - 7, 7, "Texture") == 0) {
        if (!value.is_object()) fail(path, at, "must be a textureInfo object");
        if (!value.contains("index")) fail(path, at, "a textureInfo needs an index");
    }
    if (kNumberArrayKeys.count(key)) {
        bool numbers = value.is_array();
        for (const json& x : numbers ? value : json::array())
            numbers = numbers && x.is_number();
        if (!numbers) fail(path, at, "must be an array of numbers");
    }
}

void checkInteger(const std::string& path, const json& v, const std::string& at,
                  std::uint64_t most) {
    if (!v.is_number_integer() || v.get<double>() < 0.0)
        fail(path, at, "must be an integer of at least 0");
    if (v.get<double>() > double(most))
        fail(path, at,
             "is " + v.dump() + ": must be an integer of at most " + std::to_string(most));
}

// Every index, enumeration, offset, length and count in the document is an integer JSON number
// within the range its type holds, checked before tinygltf casts it (4294967297 would read as
// 1, 1.5 or "1" as 0); every number, string, boolean, object and array tinygltf reads is one;
// every extension Spillway reads is an object. Outside `extras` and the bodies of extensions
// Spillway does not read, which may hold anything.
void checkIntegers(const std::string& path, const json& j, const std::string& at,
                   const std::set<std::string>& honoured) {
    if (j.is_array()) {
        for (size_t i = 0; i < j.size(); ++i)
            checkIntegers(path, j[i], at + "/" + std::to_string(i), honoured);
        return;
    }
    if (!j.is_object()) return;
    for (const auto& [key, value] : j.items()) {
        const std::string here = at + "/" + key;
        if (key == "extras") continue;
        if (key == "extensions" && value.is_object()) {
            for (const auto& [name, body] : value.items()) {
                if (!honoured.count(name)) continue;
                if (!body.is_object()) fail(path, here + "/" + name, "must be an object");
                checkIntegers(path, body, here + "/" + name, honoured);
            }
            continue;
        }
        checkType(path, key, value, here);
        if (kIndexKeys.count(key) && !(key == "indices" && value.is_object())) { // not sparse's
            checkInteger(path, value, here, INT_MAX);
        } else if (kSizeKeys.count(key)) {
            checkInteger(path, value, here, ~std::uint64_t(0)); // each reader bounds its own
        } else if (kIndexLists.count(key) && (value.is_array() || value.is_object())) {
            for (const auto& [k, entry] : value.items())
                checkInteger(path, entry, here + "/" + k, INT_MAX);
        } else {
            checkIntegers(path, value, here, honoured);
        }
    }
}

// ReadWholeFile for regular files only: opened without blocking (a FIFO with no writer would
// block the open), then checked on the open descriptor, so that nothing can swap the file.
bool readRegularFile(std::vector<unsigned char>* out, std::string* err, const std::string& path,
                     void*) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    struct stat st {};
    if (fd < 0 || ::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        if (fd >= 0) ::close(fd);
        if (err) *err += "'" + path + "' is not a readable regular file\n";
        return false;
    }
    out->resize(size_t(st.st_size));
    size_t done = 0;
    while (done < out->size()) {
        const ssize_t n = ::read(fd, out->data() + done, out->size() - done);
        if (n <= 0) break;
        done += size_t(n);
    }
    ::close(fd);
    if (done != out->size()) {
        if (err) *err += "'" + path + "' could not be read whole\n";
        return false;
    }
    return true;
}

} // namespace

int jsonNestingDepth(const std::string& text, int limit) {
    JsonTextScan scan(limit, 0);
    scan.feed(text.data(), text.size());
    return scan.depth();
}

std::string decodeGltfUri(const std::string& uri) {

    std::string out;
    for (size_t i = 0; i < uri.size(); ++i) {
        if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit(uint8_t(uri[i + 1])) &&
            std::isxdigit(uint8_t(uri[i + 2]))) {
            out += char(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
            i += 2;
        } else {
            out += uri[i];
        }
    }
    return out;
}

GltfDocument preflightGltf(const std::string& path, const std::set<std::string>& honoured) {
    std::error_code ec;
    const std::uint64_t size = fs::file_size(path, ec);
    std::ifstream in(path, std::ios::binary);
    if (ec || !in) fail(path, "", "cannot open the glTF file: not a readable file");
    std::string ext = fs::path(path).extension().string();
    for (char& c : ext)
        c = char(std::tolower(static_cast<unsigned char>(c)));
    GltfDocument out;
    out.binary = ext == ".glb";
    // The JSON's text, scanned (gltf_text_scan.h), then read again with the images' data: URIs
    // cut out: from the file a piece at a time (a .gltf), or from memory (a .glb's JSON chunk).
    std::string text;
    JsonTextScan scan(kMaxGltfJsonDepth, out.binary ? 20 : 0);
    JsonTextScan::Reader read;
    if (out.binary) {
        text = glbJson(path, in, size, out);
        scan.feed(text.data(), text.size());
        read = [&text](std::uint64_t at, size_t n, std::string& into) {
            into.append(text, size_t(at - 20), n);
        };
    } else {
        std::string chunk(size_t(1) << 20, '\0');
        while (in.read(chunk.data(), std::streamsize(chunk.size())) || in.gcount() > 0)
            scan.feed(chunk.data(), size_t(in.gcount()));
        read = [&in](std::uint64_t at, size_t n, std::string& into) {
            in.clear();
            in.seekg(std::streamoff(at));
            const size_t had = into.size();
            into.resize(had + n);
            in.read(into.data() + had, std::streamsize(n));
            into.resize(had + size_t(std::max<std::streamsize>(in.gcount(), 0)));
        };
    }
    if (scan.depth() > kMaxGltfJsonDepth)
        fail(path, "",
             "its JSON nests deeper than " + std::to_string(kMaxGltfJsonDepth) +
                 " levels (glTF's own objects nest about 8)");
    std::string cut = scan.cutPayloads(out.binary ? text.size() : size, read);
    GltfNodeCollector nodes(path);
    GltfDataUris uris(path, scan, read);
    out.doc = json::parse(
        cut,
        [&](int depth, json::parse_event_t e, json& parsed) {
            uris(depth, e, parsed);
            return nodes(depth, e, parsed);
        },
        false);
    text = cut = {};
    out.dataUris = uris.take();
    const json& doc = out.doc;
    if (doc.is_discarded() || !doc.is_object()) { // tinygltf says what is wrong
        out.doc = json::value_t::discarded;
        return out;
    }
    checkVersion(path, doc);
    checkRequired(path, doc, honoured);
    if (doc.contains("nodes") && !doc["nodes"].is_array())
        fail(path, "/nodes", "must be an array of nodes");
    out.doc.erase("nodes"); // read into `nodes`: tinygltf is handed none
    out.nodes = nodes.take();
    checkForest(path, doc, out.nodes, out.warnings);
    std::set<std::string> used;
    if (doc.contains("extensionsUsed") && doc["extensionsUsed"].is_array())
        for (const json& e : doc["extensionsUsed"])
            if (e.is_string()) used.insert(e.get<std::string>());
    checkDeclared(path, doc, used, "");
    for (const auto& [name, at] : nodes.extensions())
        if (!used.count(name))
            fail(path, at,
                 "uses the extension " + name +
                     ", which the file's extensionsUsed does not declare");
    checkIntegers(path, doc, "", honoured);
    checkUris(path, doc);
    return out;
}

tinygltf::FsCallbacks regularFilesOnly() {
    return {&tinygltf::FileExists, &tinygltf::ExpandFilePath, &readRegularFile,
            &tinygltf::WriteWholeFile, nullptr};
}

std::string imageViewProblem(int index, int view, int buffer, std::uint64_t offset,
                             std::uint64_t length, std::uint64_t have) {
    const std::string at = "/images/" + std::to_string(index) + "/bufferView: ";
    if (offset > have || length > have - offset)
        return at + "buffer view " + std::to_string(view) + " (bytes " + std::to_string(offset) +
               " + " + std::to_string(length) + ") reaches past the end of buffer " +
               std::to_string(buffer) + " (" + std::to_string(have) + " bytes)";
    if (length > std::uint64_t(INT_MAX))
        return at + "an embedded image of " + std::to_string(length) +
               " bytes; Spillway reads embedded images of up to 2 GiB";
    return "";
}

std::string imageViewProblem(const tinygltf::Model& model, const tinygltf::Image& image,
                             int index) {
    if (image.bufferView < 0 || size_t(image.bufferView) >= model.bufferViews.size()) return "";
    const tinygltf::BufferView& v = model.bufferViews[size_t(image.bufferView)];
    if (v.buffer < 0 || size_t(v.buffer) >= model.buffers.size()) return "";
    return imageViewProblem(index, image.bufferView, v.buffer, v.byteOffset, v.byteLength,
                            model.buffers[size_t(v.buffer)].data.size());
}

} // namespace spw
