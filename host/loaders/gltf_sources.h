// What tinygltf is handed in place of a glTF file, so that no image and no byte a mesh does not
// read is ever copied into memory. tinygltf reads every buffer whole (a .glb's BIN chunk after the
// whole file) and every image file whole, only to hand the bytes to a callback; a .glb of 256
// embedded 2048^2 images held its 3 GB twice that way before a ray was traced. Instead:
// - every image that is a file, or a buffer view of a buffer in a file, is renamed in the JSON to
//   a marker that tinygltf reads as one byte; the loader takes the file, or where its encoded
//   bytes lie in the file (an EmbeddedImage read a piece at a time), from here;
// - every buffer in a file (a .glb's BIN chunk, a .bin beside the file) is renamed to a marker
//   that tinygltf reads through these callbacks: only the byte ranges of the buffer views that
//   are not an image's alone, read from the file in pieces and laid end to end (each at its
//   original offset modulo 16, so accessors stay aligned), the views' offsets moved to match.
// - every image written out as a data: URI that the preflight found in the file's text
//   (gltf_text_scan.h) is renamed to a marker too, and read from that text.
// Other data: URIs (buffers, images whose text has a JSON escape) are left as they are: the JSON
// already held their bytes. The markers never name a file: the JSON is the loader's own.
#pragma once

#include "host/loaders/gltf_preflight.h"
#include "host/scene/scene.h"

#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

namespace spw {

class GltfSources {
  public:
    // The sources of the glTF file at `path`, whose preflight gave `document` (a parsed JSON).
    // Throws SceneError (a JSON pointer) where an image's buffer view lies outside its buffer or
    // a buffer's file is not the size the buffer says.
    GltfSources(const std::string& path, GltfDocument document);

    // The JSON tinygltf parses, and the callbacks that answer its markers. Parse with base
    // folder "" (the markers are not paths).
    const std::string& text() const { return json_; }
    void releaseJson() { json_ = {}; }
    tinygltf::FsCallbacks callbacks();
    // Whether `uri`, as tinygltf has image->uri after parsing, is one of the markers.
    static bool isMarker(const std::string& uri);

    // The images tinygltf was handed markers for: each one's uri, as the file names it (an image
    // file), or where its encoded bytes lie in a file (an image in a buffer).
    const std::map<int, std::string>& imageFiles() const { return imageFiles_; }
    const std::map<int, std::shared_ptr<const EmbeddedImage>>& embedded() const {
        return embedded_;
    }
    // The files the buffers are read from (the glTF file itself for a .glb's BIN chunk).
    std::vector<std::string> bufferFiles() const;

  private:
    struct Piece {
        std::uint64_t from = 0, length = 0, to = 0; // file offset, bytes, offset in the buffer
    };
    struct Buffer {
        std::string file;
        std::uint64_t base = 0;   // where the buffer starts in the file
        std::uint64_t length = 0; // its byteLength in the file
        std::uint64_t size = 0;   // the bytes tinygltf is handed
        std::vector<Piece> pieces;
    };
    // The buffers that lie in files, each checked against its file.
    void locateBuffers(const nlohmann::json& doc, const GltfDocument& document);
    // The images that are files or lie in those buffers, each renamed to a marker.
    void readImages(nlohmann::json& doc);
    // Buffer `index` cut down to the views that are not images' alone; their offsets moved.
    void compact(nlohmann::json& doc, int index, Buffer& buffer);
    static bool read(std::vector<unsigned char>* out, std::string* err, const std::string& marker,
                     void* self);
    static bool exists(const std::string& marker, void* self);

    std::string path_;
    std::string json_;
    std::map<int, Buffer> buffers_; // by buffer index: those read from files
    std::set<int> imageViews_;      // the buffer views images name
    std::map<int, std::string> imageFiles_;
    std::map<int, std::shared_ptr<const EmbeddedImage>> embedded_;
};

} // namespace spw
