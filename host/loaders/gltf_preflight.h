// What is checked of a glTF file before tinygltf parses it, because tinygltf itself would crash,
// hang or misread it: the GLB framing (magic, version, chunk lengths within the file), the JSON's
// nesting (its parser recurses), the asset's version (glTF 1.0 is refused by name), the
// extensions it requires (Draco and the rest, named before tinygltf trips over their buffers),
// and the node graph (a forest: one parent a node at most, so that a DAG of 64 nodes cannot
// unfold into 2^63 paths). And while tinygltf reads: every file a buffer or image names must be
// a regular file (a FIFO would block forever, a folder allocate nonsense), and an image's buffer
// view must lie inside its buffer before its bytes are taken.
//
// Every failure is a SceneError naming the file and a JSON pointer.
#pragma once

#include "host/loaders/gltf_nodes.h"
#include "host/scene/scene.h"

#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include <cstdint>

#include <map>
#include <memory>
#include <set>
#include <string>

namespace spw {

// The deepest the JSON of a glTF file may nest. The format's own objects nest about 8 deep;
// `extras` and `extensions` may hold any JSON, and 64 levels leave room for that.
constexpr int kMaxGltfJsonDepth = 64;

// The deepest nesting of arrays and objects in a JSON text, outside strings, counted up to
// `limit` + 1 (the scan stops there): without parsing, so that no depth can overflow a stack.
int jsonNestingDepth(const std::string& text, int limit);

// A glTF file's JSON as the preflight parsed it, and where a .glb's BIN chunk lies.
struct GltfDocument {
    nlohmann::json doc;          // discarded where the JSON does not parse (tinygltf then says why)
    std::vector<GltfNode> nodes; // its nodes, taken out of `doc` (gltf_nodes.h)
    bool binary = false;
    std::uint64_t binOffset = 0, binLength = 0; // the BIN chunk's bytes (length 0: none)
    std::vector<std::string> warnings;          // what is rendered leniently ("pointer: what")
    // The images written out as data: URIs, read from their text in the file (gltf_text_scan.h),
    // by index; their URIs in `doc` are GltfDataUris::kPlaceholder.
    std::map<int, std::shared_ptr<const EmbeddedImage>> dataUris;
};

// Checks the file at `path` before it is parsed; `honoured` are the extensions a file may require.
// Throws SceneError.
GltfDocument preflightGltf(const std::string& path, const std::set<std::string>& honoured);

// A URI's %XX escapes decoded (glTF's URIs are RFC 3986 references): the file a relative URI
// names, beside the glTF file.
std::string decodeGltfUri(const std::string& uri);

// tinygltf's file callbacks with one change: ReadWholeFile reads only regular files.
tinygltf::FsCallbacks regularFilesOnly();

// Whether image `image`'s buffer view (in `model`, being parsed) lies inside its buffer: "" if so,
// else why not. Called from the image callback, before the bytes are read.
std::string imageViewProblem(const tinygltf::Model& model, const tinygltf::Image& image, int index);
// The same for image `index`'s buffer view `view`: `length` bytes at `offset` of buffer `buffer`,
// which holds `have`.
std::string imageViewProblem(int index, int view, int buffer, std::uint64_t offset,
                             std::uint64_t length, std::uint64_t have);

} // namespace spw
