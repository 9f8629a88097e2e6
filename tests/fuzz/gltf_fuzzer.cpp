// libFuzzer harness: glTF files (.gltf and .glb) through the glTF loader, rendered as a scene.
// scripts/fuzz.sh builds and runs it.
//
// Structure-aware: three mutations in four edit the document rather than its bytes. A .gltf's
// JSON (or a .glb's JSON chunk, its binary chunk kept and the framing rewritten) is parsed and
// one of its values changed the way hostile files change them: a number made an edge of the
// integer ranges a size or index feeds (0, -1, 2^31, 2^32, 2^62 + 1, ...), nudged by one, or
// set to another array's length; an array element duplicated or dropped (a node named twice as
// a child); a value wrapped in many levels of arrays (deep JSON); a key from the format's
// vocabulary (tests/fuzz/gltf.dict) added with a number; a string made a version, a MIME type or
// an extension name. A document that does not parse gets libFuzzer's byte mutations.
#include "fuzz_targets.h"
#include "host/loaders/gltf_preflight.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

extern "C" size_t LLVMFuzzerMutate(std::uint8_t* data, size_t size, size_t maxSize);

namespace {

using nlohmann::json;
using Rng = std::minstd_rand;

const char* const kKeys[] = {
    "bufferView",  "byteOffset",  "byteLength", "byteStride", "count",     "componentType",
    "children",    "mesh",        "camera",     "skin",       "material",  "indices",
    "mode",        "source",      "sampler",    "texCoord",   "index",     "scene",
    "normalized",  "sparse",      "buffer",     "uri",        "mimeType",  "alphaMode",
    "alphaCutoff", "aspectRatio", "yfov",       "znear",      "intensity", "range"};
const char* const kStrings[] = {"2.0",
                                "1.0",
                                "2.1",
                                "3.0",
                                "image/png",
                                "image/jpeg",
                                "image.null",
                                "data:,",
                                "KHR_draco_mesh_compression",
                                "KHR_lights_punctual",
                                "KHR_texture_transform",
                                "KHR_materials_pbrSpecularGlossiness",
                                "BLEND",
                                "MASK",
                                "model.bin",
                                "."};
const double kNumbers[] = {0,
                           1,
                           -1,
                           2,
                           3,
                           255,
                           65535,
                           2147483647,
                           2147483648.0,
                           4294967295.0,
                           4294967296.0,
                           4611686018427387905.0,
                           9.2233720368547758e18,
                           1e308,
                           -1e308,
                           0.5,
                           5120,
                           5121,
                           5123,
                           5125,
                           5126,
                           34962,
                           4,
                           7};

// The deepest the mutator parses a document: as deep as the loader reads.
constexpr int kMaxTreeDepth = spw::kMaxGltfJsonDepth;

// Every value in the document, each once (pointers into it, valid until it changes).
void collect(json& j, std::vector<json*>& out, int depth) {
    out.push_back(&j);
    if (depth > 64 || out.size() > 20000) return;
    if (j.is_object())
        for (auto& [key, value] : j.items())
            collect(value, out, depth + 1);
    else if (j.is_array())
        for (json& value : j)
            collect(value, out, depth + 1);
}

void mutateValue(json& doc, Rng& rng) {
    std::vector<json*> values;
    collect(doc, values, 0);
    json& v = *values[rng() % values.size()];
    auto pick = [&](auto& table) { return table[rng() % (sizeof table / sizeof table[0])]; };
    switch (rng() % 6) {
    case 0: // an edge of the ranges a size or an index feeds
        v = pick(kNumbers);
        break;
    case 1: // nudged by one, or another array's length
        if (v.is_number_integer())
            v = v.get<long long>() + (rng() % 2 ? 1 : -1);
        else if (v.is_number())
            v = v.get<double>() * 2.0;
        else {
            json* other = values[rng() % values.size()];
            v = other->is_array() ? json(other->size()) : json(rng() % 64);
        }
        break;
    case 2: // an element duplicated or dropped
        if (v.is_array() && !v.empty()) {
            const size_t i = rng() % v.size();
            if (rng() % 2)
                v.insert(v.begin() + long(i), v[i]);
            else
                v.erase(v.begin() + long(i));
        } else if (v.is_object() && !v.empty()) {
            auto it = v.begin();
            std::advance(it, long(rng() % v.size()));
            v.erase(it);
        }
        break;
    case 3: // wrapped in many levels of arrays: a marker deepen() writes out after the dump
            // (dumping 60,000 levels would overflow the mutator's own stack)
        v = "@@deep" + std::to_string(rng() % 3 == 0 ? 1000 + rng() % 60000 : 1 + rng() % 80) +
            "@@";
        break;
    case 4: // a key of the format's vocabulary, with a number or a copy of another value
        if (v.is_object())
            v[pick(kKeys)] = rng() % 2 ? json(pick(kNumbers)) : *values[rng() % values.size()];
        break;
    default: // a string of the format's vocabulary
        v = pick(kStrings);
        break;
    }
}

// The markers of mutateValue's case 3 as that many nested arrays around a 0.
std::string deepen(std::string text) {
    for (size_t at; (at = text.find("\"@@deep")) != std::string::npos;) {
        const size_t end = text.find("@@\"", at + 7);
        if (end == std::string::npos) break;
        const size_t levels = std::stoul(text.substr(at + 7, end - at - 7));
        text.replace(at, end + 3 - at, std::string(levels, '[') + "0" + std::string(levels, ']'));
    }
    return text;
}

std::uint32_t u32(const std::uint8_t* p) {
    std::uint32_t v;
    std::memcpy(&v, p, 4);
    return v;
}

// The document of a .gltf or .glb, and what a .glb carries besides it.
struct Split {
    bool binary = false;
    std::string json, bin;
};

bool split(const std::uint8_t* data, size_t size, Split& s) {
    s.binary = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
    if (!s.binary) {
        s.json.assign(reinterpret_cast<const char*>(data), size);
        return true;
    }
    if (size < 20) return false;
    const size_t jsonLength = u32(data + 12);
    if (jsonLength > size - 20) return false;
    s.json.assign(reinterpret_cast<const char*>(data + 20), jsonLength);
    if (size >= 28 + jsonLength) {
        const size_t binLength =
            std::min<size_t>(u32(data + 20 + jsonLength), size - 28 - jsonLength);
        s.bin.assign(reinterpret_cast<const char*>(data + 28 + jsonLength), binLength);
    }
    return true;
}

std::string join(const Split& s, const std::string& text) {
    if (!s.binary) return text;
    std::string out, body = text, bin = s.bin;
    while (body.size() % 4)
        body += ' ';
    while (bin.size() % 4)
        bin += '\0';
    auto put = [&](std::uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
    put(0x46546C67u), put(2u),
        put(std::uint32_t(20 + body.size() + (bin.empty() ? 0 : 8 + bin.size())));
    put(std::uint32_t(body.size())), put(0x4E4F534Au), out += body;
    if (!bin.empty()) put(std::uint32_t(bin.size())), put(0x004E4942u), out += bin;
    return out;
}

} // namespace

extern "C" size_t LLVMFuzzerCustomMutator(std::uint8_t* data, size_t size, size_t maxSize,
                                          unsigned int seed) {
    Rng rng(seed);
    Split s;
    if (rng() % 4 == 0 || !split(data, size, s)) return LLVMFuzzerMutate(data, size, maxSize);
    // A document nested deeper than the loader takes (one an earlier mutation deepened) is left
    // to the byte mutations: copying or dumping it would recurse through the mutator's own stack.
    if (spw::jsonNestingDepth(s.json, kMaxTreeDepth) > kMaxTreeDepth)
        return LLVMFuzzerMutate(data, size, maxSize);
    json doc = json::parse(s.json, nullptr, false);
    if (doc.is_discarded()) return LLVMFuzzerMutate(data, size, maxSize);
    const int edits = 1 + int(rng() % 3);
    for (int i = 0; i < edits; ++i)
        mutateValue(doc, rng);
    const std::string out = join(s, deepen(doc.dump()));
    if (out.size() > maxSize) return LLVMFuzzerMutate(data, size, maxSize);
    std::memcpy(data, out.data(), out.size());
    return out.size();
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    std::string detail;
    if (spw::fuzz::gltf(data, size, &detail) == spw::fuzz::Outcome::Unexpected) {
        std::fprintf(stderr, "unexpected exception: %s\n", detail.c_str());
        std::abort();
    }
    return 0;
}
