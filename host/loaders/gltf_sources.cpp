#include "host/loaders/gltf_sources.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstring>
#include <filesystem>
#include <optional>

namespace spw {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kBufferMarker = "spillway:buffer:";
constexpr const char* kImageMarker = "spillway:image:";

// A non-negative integer member of a JSON object, or nothing (tinygltf names what is wrong).
std::optional<std::uint64_t> count(const json& o, const char* key) {
    if (!o.is_object() || !o.contains(key) || !o[key].is_number_integer()) return std::nullopt;
    if (o[key].is_number_unsigned()) return o[key].get<std::uint64_t>();
    if (o[key].get<long long>() < 0) return std::nullopt;
    return std::uint64_t(o[key].get<long long>());
}

const json& array(const json& doc, const char* key) {
    static const json empty = json::array();
    return doc.contains(key) && doc[key].is_array() ? doc[key] : empty;
}

// The index a marker names after its prefix, or -1.
int markerIndex(const std::string& marker, const char* prefix) {
    const size_t at = marker.rfind(prefix);
    if (at == std::string::npos) return -1;
    try {
        return std::stoi(marker.substr(at + std::strlen(prefix)));
    } catch (const std::exception&) {
        return -1;
    }
}

// The buffer views accessors read (their own and a sparse accessor's indices and values).
std::set<int> accessorViews(const json& doc) {
    std::set<int> views;
    auto note = [&](const json& o) {
        if (const auto v = count(o, "bufferView"))
            views.insert(int(std::min<std::uint64_t>(*v, INT_MAX)));
    };
    for (const json& a : array(doc, "accessors")) {
        note(a);
        if (a.is_object() && a.contains("sparse") && a["sparse"].is_object())
            for (const char* part : {"indices", "values"})
                if (a["sparse"].contains(part)) note(a["sparse"][part]);
    }
    return views;
}

} // namespace

using nlohmann::json;

GltfSources::GltfSources(const std::string& path, GltfDocument document) : path_(path) {
    json& doc = document.doc;
    embedded_ = std::move(document.dataUris); // in the file's text (gltf_text_scan.h)
    locateBuffers(doc, document);
    readImages(doc);
    for (auto& [index, buffer] : buffers_) {
        compact(doc, index, buffer);
        doc["buffers"][size_t(index)]["uri"] = kBufferMarker + std::to_string(index);
        doc["buffers"][size_t(index)]["byteLength"] = buffer.size;
    }
    json_ = doc.dump();
}

void GltfSources::locateBuffers(const json& doc, const GltfDocument& document) {
    const fs::path dir = fs::path(path_).parent_path();
    const json& buffers = array(doc, "buffers");
    for (size_t b = 0; b < buffers.size(); ++b) {
        const json& entry = buffers[b];
        const auto byteLength = count(entry, "byteLength");
        if (!byteLength) continue;
        Buffer buffer;
        buffer.length = *byteLength;
        const std::string at = "/buffers/" + std::to_string(b);
        if (entry.contains("uri") && entry["uri"].is_string()) {
            const std::string uri = entry["uri"].get<std::string>();
            if (uri.rfind("data:", 0) == 0) continue; // the JSON holds its bytes
            buffer.file = (dir / decodeGltfUri(uri)).string();
            std::error_code ec;
            const std::uint64_t size = fs::file_size(buffer.file, ec);
            if (ec) throw SceneError(path_, 0, at + "/uri: cannot read '" + buffer.file + "'");
            if (size != buffer.length)
                throw SceneError(path_, 0,
                                 at + "/byteLength: is " + std::to_string(buffer.length) +
                                     "; the file '" + buffer.file + "' is " + std::to_string(size) +
                                     " bytes");
        } else if (document.binary && b == 0 && document.binLength > 0) {
            buffer.file = path_;
            buffer.base = document.binOffset;
            if (buffer.length > document.binLength)
                throw SceneError(path_, 0,
                                 at + "/byteLength: is " + std::to_string(buffer.length) +
                                     "; the GLB's BIN chunk holds " +
                                     std::to_string(document.binLength) + " bytes");
        } else {
            continue; // tinygltf says what is missing
        }
        buffers_[int(b)] = buffer;
    }
}

void GltfSources::readImages(json& doc) {
    if (!doc.contains("images") || !doc["images"].is_array()) return;
    const json& views = array(doc, "bufferViews");
    json& images = doc["images"];
    for (size_t i = 0; i < images.size(); ++i) {
        json& entry = images[i];
        if (!entry.is_object()) continue;
        const std::string marker = kImageMarker + std::to_string(i);
        if (entry.contains("uri") && entry["uri"].is_string()) {
            const std::string uri = entry["uri"].get<std::string>();
            if (entry.contains("bufferView")) continue;
            if (uri.rfind("data:", 0) == 0) { // read from its text in the file, where it was found
                if (embedded_.count(int(i))) entry["uri"] = marker;
                continue;
            }
            imageFiles_[int(i)] = uri;
            entry["uri"] = marker;
            continue;
        }
        const auto view = count(entry, "bufferView");
        if (!view || *view >= views.size()) continue;
        imageViews_.insert(int(*view));
        const json& v = views[size_t(*view)];
        const auto buffer = count(v, "buffer");
        const auto length = count(v, "byteLength");
        if (!buffer || !length || !buffers_.count(int(*buffer))) continue;
        const Buffer& b = buffers_.at(int(*buffer));
        const std::uint64_t offset = count(v, "byteOffset").value_or(0);
        if (const std::string why =
                imageViewProblem(int(i), int(*view), int(*buffer), offset, *length, b.length);
            !why.empty())
            throw SceneError(path_, 0, why);
        embedded_[int(i)] = std::make_shared<const EmbeddedImage>(
            EmbeddedImage{b.file, b.base + offset, *length, nullptr});
        entry.erase("bufferView");
        entry["uri"] = marker;
    }
}

void GltfSources::compact(json& doc, int index, Buffer& buffer) {
    buffer.size = buffer.length;
    buffer.pieces = {{buffer.base, buffer.length, 0}};
    // The views of this buffer that something besides an image reads, and whether any is an
    // image's alone (only then is there anything to leave out).
    if (!doc.contains("bufferViews") || !doc["bufferViews"].is_array()) return;
    const std::set<int> read = accessorViews(doc);
    json& views = doc["bufferViews"];
    std::vector<size_t> kept;
    bool imageOnly = false;
    for (size_t v = 0; v < views.size(); ++v) {
        if (count(views[v], "buffer") != std::uint64_t(index)) continue;
        if (imageViews_.count(int(v)) && !read.count(int(v))) {
            imageOnly = true;
            continue;
        }
        const auto length = count(views[v], "byteLength");
        const std::uint64_t offset = count(views[v], "byteOffset").value_or(0);
        // A view tinygltf or the mesh reader refuses is left for them to name, in the whole
        // buffer.
        if (!length || offset > buffer.length || *length > buffer.length - offset) return;
        kept.push_back(v);
    }
    if (!imageOnly) return;
    // The kept views' bytes as disjoint ranges, in order.
    std::vector<std::pair<std::uint64_t, std::uint64_t>> ranges;
    for (size_t v : kept) {
        const std::uint64_t from = count(views[v], "byteOffset").value_or(0);
        ranges.push_back({from, from + *count(views[v], "byteLength")});
    }
    std::sort(ranges.begin(), ranges.end());
    buffer.pieces.clear();
    std::uint64_t end = 0, cursor = 0;
    for (const auto& [from, to] : ranges) {
        if (!buffer.pieces.empty() && from <= end) { // overlaps or touches the piece before
            if (to > end) buffer.pieces.back().length += to - end, cursor += to - end, end = to;
            continue;
        }
        cursor += (from % 16 + 16 - cursor % 16) % 16; // the same offset modulo 16
        buffer.pieces.push_back({buffer.base + from, to - from, cursor});
        cursor += to - from;
        end = to;
    }
    buffer.size = cursor;
    for (size_t v : kept) {
        const std::uint64_t from = count(views[v], "byteOffset").value_or(0);
        auto piece =
            std::upper_bound(buffer.pieces.begin(), buffer.pieces.end(), buffer.base + from,
                             [](std::uint64_t at, const Piece& p) { return at < p.from; });
        --piece; // the last piece starting at or before the view
        views[v]["byteOffset"] = piece->to + (buffer.base + from - piece->from);
    }
}

tinygltf::FsCallbacks GltfSources::callbacks() {
    tinygltf::FsCallbacks c{};
    c.FileExists = &GltfSources::exists;
    c.ExpandFilePath = [](const std::string& p, void*) { return p; };
    c.ReadWholeFile = &GltfSources::read;
    c.WriteWholeFile = nullptr;
    c.user_data = this;
    return c;
}

bool GltfSources::isMarker(const std::string& uri) {
    return uri.rfind(kImageMarker, 0) == 0 || uri.rfind(kBufferMarker, 0) == 0;
}

bool GltfSources::exists(const std::string& marker, void* self) {
    const auto& s = *static_cast<const GltfSources*>(self);
    return s.buffers_.count(markerIndex(marker, kBufferMarker)) ||
           s.imageFiles_.count(markerIndex(marker, kImageMarker)) ||
           s.embedded_.count(markerIndex(marker, kImageMarker));
}

bool GltfSources::read(std::vector<unsigned char>* out, std::string* err, const std::string& marker,
                       void* self) {
    const auto& s = *static_cast<const GltfSources*>(self);
    const auto found = s.buffers_.find(markerIndex(marker, kBufferMarker));
    if (found == s.buffers_.end()) { // an image: its bytes are read where it is looked up
        out->assign(1, 0);
        return true;
    }
    const Buffer& b = found->second;
    out->assign(size_t(b.size), 0);
    const int fd = ::open(b.file.c_str(), O_RDONLY | O_CLOEXEC);
    bool ok = fd >= 0;
    for (const Piece& p : b.pieces) {
        for (std::uint64_t done = 0; ok && done < p.length;) {
            const ssize_t n = ::pread(fd, out->data() + p.to + done, size_t(p.length - done),
                                      off_t(p.from + done));
            if (n < 0 && errno == EINTR) continue;
            ok = n > 0;
            done += std::uint64_t(std::max<ssize_t>(n, 0));
        }
    }
    if (fd >= 0) ::close(fd);
    if (!ok && err) *err += "'" + b.file + "' could not be read whole\n";
    return ok;
}

std::vector<std::string> GltfSources::bufferFiles() const {
    std::vector<std::string> files;
    for (const auto& [index, b] : buffers_)
        if (b.file != path_) files.push_back(b.file);
    return files;
}

} // namespace spw
