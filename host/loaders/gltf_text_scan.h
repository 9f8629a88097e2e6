// One pass over a glTF file's JSON text before it is parsed, fed a piece at a time (a .gltf is
// read a MiB at a time): how deep it nests (nlohmann's parser recurses, so the depth is checked
// first), and where the base64 text of each image written out as a data: URI (image/png,
// image/jpeg) lies in the file. The parser is then handed the text with each such payload cut
// out and a reference to its place in its stead (cutPayloads): neither the JSON tree nor
// tinygltf holds the images, nor does the parser read them a character at a time, and the image
// is read from its text in the file (EmbeddedImage::base64), a piece at a time.
//
// A payload with a JSON escape in it ("\/", legal JSON) or that is not base64 is left as it is:
// tinygltf decodes it into memory, or says what is wrong with it, as before.
#pragma once

#include "host/scene/scene.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <string_view>

namespace spw {

class JsonTextScan {
  public:
    // `limit`: nesting counted up to limit + 1 (the deepest a file may nest is kMaxGltfJsonDepth).
    // `offset`: where the text starts in its file (a .glb's JSON chunk starts at byte 20).
    JsonTextScan(int limit, std::uint64_t offset) : limit_(limit), offset_(offset) {}
    // The text, in order, a piece at a time.
    void feed(const char* text, size_t n);
    // The deepest nesting of arrays and objects outside strings, up to limit + 1.
    int depth() const { return deepest_; }

    // A payload found: where its text starts in the file, its characters, its decoded bytes.
    struct Payload {
        std::uint64_t start = 0, length = 0, bytes = 0;
    };
    const std::map<std::uint64_t, Payload>& payloads() const { return payloads_; }
    // The text fed, as `read(offset, n, out)` reads it back (from the file or from memory), with
    // each payload replaced by a reference: kReference and its start offset.
    using Reader = std::function<void(std::uint64_t offset, size_t n, std::string& out)>;
    std::string cutPayloads(std::uint64_t length, const Reader& read) const;
    static constexpr const char* kReference = "spillway@";

  private:
    void endString();
    int limit_;
    std::uint64_t offset_, at_ = 0; // the file offset of the text, and of the next byte fed
    int depth_ = 0, deepest_ = 0;
    bool inString_ = false, escape_ = false;
    // Within a string: its first characters (up to the comma of a data: URI's header), then,
    // once the header names an image in base64, the payload's start, length, padding, validity.
    std::string head_;
    bool payload_ = false, valid_ = false;
    std::uint64_t start_ = 0, length_ = 0, pads_ = 0;
    std::map<std::uint64_t, Payload> payloads_; // by start
};

// The parser callback's part for the references (alongside GltfNodeCollector's): at the value of
// /images/N/uri, a reference becomes image N's EmbeddedImage (the value stays the reference); a
// reference anywhere else is given its payload back from the file, as the file wrote it.
class GltfDataUris {
  public:
    GltfDataUris(const std::string& path, const JsonTextScan& scan, JsonTextScan::Reader read)
        : path_(path), scan_(scan), read_(std::move(read)) {}
    void operator()(int depth, nlohmann::json::parse_event_t event, nlohmann::json& parsed);
    // The images found, by index, each read from its base64 text in the file.
    std::map<int, std::shared_ptr<const EmbeddedImage>> take() { return std::move(images_); }

  private:
    std::string path_;
    const JsonTextScan& scan_;
    JsonTextScan::Reader read_;
    std::string key_, imageKey_; // the top-level key, the image's key, last read
    bool inImages_ = false;
    int image_ = -1;
    std::map<int, std::shared_ptr<const EmbeddedImage>> images_;
};

} // namespace spw
