#include "host/loaders/gltf_text_scan.h"

#include <algorithm>
#include <cstring>

namespace spw {
namespace {

// Whether c is one of base64's 64 characters or its padding.
bool isBase64(char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '+' ||
           c == '/' || c == '=';
}

// The data: URI headers whose payload is read from the file: images'. (A buffer's bytes are
// tinygltf's to read, "data:application/octet-stream;base64".)
bool readsFromFile(std::string_view header) {
    return header == "data:image/png;base64" || header == "data:image/jpeg;base64";
}

// The longest header looked for, and a few characters more.
constexpr size_t kLongestHeader = 32;

// The payload start a string's reference names, or nothing: "data:...;base64,spillway@N".
std::optional<std::uint64_t> referenceIn(const std::string& s) {
    const size_t comma = s.find(',');
    if (comma == std::string::npos || !readsFromFile(std::string_view(s).substr(0, comma)))
        return std::nullopt;
    const std::string_view rest = std::string_view(s).substr(comma + 1);
    const size_t n = std::strlen(JsonTextScan::kReference);
    if (rest.substr(0, n) != JsonTextScan::kReference || rest.size() == n || rest.size() > n + 20)
        return std::nullopt;
    std::uint64_t start = 0;
    for (const char c : rest.substr(n)) {
        if (c < '0' || c > '9') return std::nullopt;
        start = start * 10 + std::uint64_t(c - '0');
    }
    return start;
}

} // namespace

void JsonTextScan::feed(const char* text, size_t n) {
    for (size_t i = 0; i < n; ++i, ++at_) {
        const char c = text[i];
        if (!inString_) {
            if (c == '"') {
                inString_ = true;
                head_.clear();
                payload_ = false;
            } else if (c == '[' || c == '{') {
                deepest_ = std::max(deepest_, std::min(++depth_, limit_ + 1));
            } else if (c == ']' || c == '}') {
                --depth_;
            }
        } else if (escape_) {
            escape_ = false;
        } else if (c == '\\') {
            escape_ = true;
            valid_ = false;
            head_.assign(kLongestHeader + 1, ' '); // an escape in the header: not looked at
        } else if (c == '"') {
            endString();
            inString_ = false;
        } else if (payload_) {
            if (!valid_) continue;
            size_t j = i; // the run of base64 from here, at once
            while (j < n && isBase64(text[j]) && text[j] != '=' && pads_ == 0)
                ++j;
            if (j == i) { // padding, or not base64
                valid_ = c == '=' && ++pads_ <= 2;
                ++length_;
                continue;
            }
            length_ += j - i;
            at_ += j - i - 1;
            i = j - 1;
        } else if (head_.size() <= kLongestHeader) {
            if (c != ',') {
                head_ += c;
            } else if (readsFromFile(head_)) {
                payload_ = valid_ = true;
                start_ = offset_ + at_ + 1;
                length_ = pads_ = 0;
            } else {
                head_.assign(kLongestHeader + 1, ' ');
            }
        }
    }
}

void JsonTextScan::endString() {
    if (payload_ && valid_ && length_ > 0 && length_ % 4 == 0)
        payloads_[start_] = {start_, length_, length_ / 4 * 3 - pads_};
    payload_ = valid_ = false;
}

std::string JsonTextScan::cutPayloads(std::uint64_t length, const Reader& read) const {
    std::string out;
    std::uint64_t at = offset_;
    const auto copy = [&](std::uint64_t to) {
        for (constexpr std::uint64_t kPiece = std::uint64_t(1) << 20; at < to;) {
            const size_t n = size_t(std::min(kPiece, to - at));
            read(at, n, out);
            at += n;
        }
    };
    for (const auto& [start, p] : payloads_) {
        copy(start);
        out += kReference + std::to_string(start);
        at = start + p.length;
    }
    copy(offset_ + length);
    return out;
}

void GltfDataUris::operator()(int depth, nlohmann::json::parse_event_t event,
                              nlohmann::json& parsed) {
    using E = nlohmann::json::parse_event_t;
    if (depth == 1 && event == E::key) key_ = parsed.get<std::string>();
    if (depth == 1 && event == E::array_start) inImages_ = key_ == "images";
    if (depth == 1 && event == E::array_end) inImages_ = false;
    if (inImages_ && depth == 2 &&
        (event == E::object_start || event == E::array_start || event == E::value)) {
        ++image_;
        imageKey_.clear();
    }
    if (inImages_ && depth == 3 && event == E::key) imageKey_ = parsed.get<std::string>();
    if (event != E::value || !parsed.is_string()) return;
    const auto start = referenceIn(parsed.get_ref<const std::string&>());
    if (!start) return;
    const auto p = scan_.payloads().find(*start);
    if (p == scan_.payloads().end()) return; // not one the scan cut: the file's own text
    if (inImages_ && depth == 3 && imageKey_ == "uri") {
        images_[image_] = std::make_shared<const EmbeddedImage>(
            EmbeddedImage{path_, p->second.start, p->second.bytes, nullptr, true});
        return;
    }
    std::string& s = parsed.get_ref<std::string&>(); // elsewhere: its payload back, as written
    s.erase(s.find(',') + 1);
    read_(p->second.start, size_t(p->second.length), s);
}

} // namespace spw
