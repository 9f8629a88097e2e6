// The kernels' unpacking functions (shaders/shade_kernel.glsl: kernelShader, kernelEmitter,
// loadInput, storeResult) are GLSL twins of the C++ structs of shaders/shared/types.h and
// shade_io.h: the host uploads a struct's bytes and the kernel reads them back word by word, or
// the kernel packs words the host reads as the struct. This test reads each function's
// assignments and checks, field by field, that the word the kernel reads or writes is the field's
// offset in the C++ struct, with its size, and that together they cover every byte of the struct,
// so a field added, moved or resized on one side fails here, naming the field, instead of as a
// wrong picture. No Vulkan device needed.
#include "test_util.h"

#include "shared/shade_io.h"
#include "shared/types.h"

#include <gtest/gtest.h>

#include <cstddef>
#include <map>
#include <regex>
#include <string>
#include <vector>

namespace spw::test {
namespace {

struct Field {
    size_t offset, size; // bytes
};
using Fields = std::map<std::string, Field>;

#define SPW_FIELD(S, f)                                                                            \
    {                                                                                              \
#f, {                                                                                      \
            offsetof(S, f), sizeof(S::f)                                                           \
        }                                                                                          \
    }
const Fields kShaderParams = {
    SPW_FIELD(ShaderParams, emission),    SPW_FIELD(ShaderParams, model),
    SPW_FIELD(ShaderParams, colour),      SPW_FIELD(ShaderParams, reflectance),
    SPW_FIELD(ShaderParams, flags),       SPW_FIELD(ShaderParams, ior),
    SPW_FIELD(ShaderParams, alpha),       SPW_FIELD(ShaderParams, metallic),
    SPW_FIELD(ShaderParams, absorption),  SPW_FIELD(ShaderParams, coat),
    SPW_FIELD(ShaderParams, coatAlpha),   SPW_FIELD(ShaderParams, specularColour),
    SPW_FIELD(ShaderParams, specular),    SPW_FIELD(ShaderParams, transmission),
    SPW_FIELD(ShaderParams, sheenColour), SPW_FIELD(ShaderParams, sheenRoughness),
    SPW_FIELD(ShaderParams, coatNormal),  SPW_FIELD(ShaderParams, specularTint),
    SPW_FIELD(ShaderParams, sheen),       SPW_FIELD(ShaderParams, sheenTint),
    SPW_FIELD(ShaderParams, pad1),        SPW_FIELD(ShaderParams, pad2)};
const Fields kEmitter = {SPW_FIELD(Emitter, p0),       SPW_FIELD(Emitter, area),
                         SPW_FIELD(Emitter, e1),       SPW_FIELD(Emitter, pickPdf),
                         SPW_FIELD(Emitter, e2),       SPW_FIELD(Emitter, twoSided),
                         SPW_FIELD(Emitter, normal),   SPW_FIELD(Emitter, type),
                         SPW_FIELD(Emitter, radiance), SPW_FIELD(Emitter, map)};
// Nested structs: "hit.p" is ShadeInput::hit's p.
Fields nested(const std::string& prefix, size_t base, const Fields& inner) {
    Fields out;
    for (const auto& [name, f] : inner)
        out[prefix + "." + name] = {base + f.offset, f.size};
    return out;
}
const Fields kSurfaceHit = {
    SPW_FIELD(SurfaceHit, p),      SPW_FIELD(SurfaceHit, t),        SPW_FIELD(SurfaceHit, ng),
    SPW_FIELD(SurfaceHit, shader), SPW_FIELD(SurfaceHit, ns),       SPW_FIELD(SurfaceHit, emitter),
    SPW_FIELD(SurfaceHit, albedo), SPW_FIELD(SurfaceHit, offset),   SPW_FIELD(SurfaceHit, material),
    SPW_FIELD(SurfaceHit, lift),   SPW_FIELD(SurfaceHit, extension)};
const Fields kPathState = {SPW_FIELD(PathState, beta),   SPW_FIELD(PathState, prevPdf),
                           SPW_FIELD(PathState, pathId), SPW_FIELD(PathState, bounce),
                           SPW_FIELD(PathState, flags),  SPW_FIELD(PathState, cone)};
Fields shadeInputFields() {
    Fields out = nested("hit", offsetof(ShadeInput, hit), kSurfaceHit);
    for (const auto& f : nested("path", offsetof(ShadeInput, path), kPathState))
        out.insert(f);
    out.insert(SPW_FIELD(ShadeInput, rayDir));
    out.insert(SPW_FIELD(ShadeInput, pad0));
    return out;
}
Fields shadeResultFields() {
    Fields out = {SPW_FIELD(ShadeResult, flags),        SPW_FIELD(ShadeResult, emitted),
                  SPW_FIELD(ShadeResult, shadowOrigin), SPW_FIELD(ShadeResult, shadowTmax),
                  SPW_FIELD(ShadeResult, shadowDir),    SPW_FIELD(ShadeResult, shadowContribution),
                  SPW_FIELD(ShadeResult, nextOrigin),   SPW_FIELD(ShadeResult, nextDir)};
    for (const auto& f : nested("next", offsetof(ShadeResult, next), kPathState))
        out.insert(f);
    return out;
}
#undef SPW_FIELD

// The body of GLSL function `name` in `source`: from its signature to the closing brace at the
// start of a line.
std::string functionBody(const std::string& source, const std::string& signature) {
    const size_t begin = source.find(signature);
    if (begin == std::string::npos) return "";
    const size_t end = source.find("\n}", begin);
    return source.substr(begin, end - begin);
}

// One word range the kernel maps to a field: [word, word + words) of the record.
struct Mapping {
    std::string field;
    size_t firstByte, bytes;
};

size_t lane(char c) {
    return std::string("xyzw").find(c);
}

// A field plus an optional swizzle of it ("shadowContribution.yz", "next.beta"): the byte range
// it names within the struct.
bool fieldRange(const Fields& fields, const std::string& path, Mapping& m) {
    if (fields.count(path)) {
        m.field = path;
        m.firstByte = fields.at(path).offset;
        m.bytes = fields.at(path).size;
        return true;
    }
    const size_t dot = path.rfind('.');
    if (dot == std::string::npos || !fields.count(path.substr(0, dot))) return false;
    const std::string swizzle = path.substr(dot + 1);
    if (swizzle.find_first_not_of("xyzw") != std::string::npos) return false;
    m.field = path;
    m.firstByte = fields.at(path.substr(0, dot)).offset + 4 * lane(swizzle[0]);
    m.bytes = 4 * swizzle.size();
    return true;
}

// The unpacking functions: `v.field = [uintBitsToFloat(]wK.swz[)]` or `w[K].swz`, with K the
// record's K-th uvec4.
std::vector<Mapping> readsOf(const std::string& body, const std::string& var,
                             const Fields& fields) {
    std::vector<Mapping> out;
    const std::regex assign(
        "\\b" + var +
        "\\.([\\w.]+) = (?:uintBitsToFloat\\()?w(?:(\\d)|\\[(\\d)\\])\\.([xyzw]+)"
        "\\)?;");
    for (std::sregex_iterator it(body.begin(), body.end(), assign), end; it != end; ++it) {
        const std::smatch& m = *it;
        Mapping map;
        EXPECT_TRUE(fieldRange(fields, m[1], map))
            << "the kernel reads a field C++ lacks: " << m[1];
        const size_t word = std::stoul(m[2].matched ? m[2].str() : m[3].str());
        const std::string swizzle = m[4];
        const size_t kernelByte = 16 * word + 4 * lane(swizzle[0]);
        EXPECT_EQ(kernelByte, map.firstByte) << var << "." << m[1] << ": the kernel reads byte "
                                             << kernelByte << ", C++ has it at " << map.firstByte;
        EXPECT_EQ(4 * swizzle.size(), map.bytes) << var << "." << m[1] << ": size";
        out.push_back(map);
    }
    return out;
}

// storeResult: `results[o (+ Ku)] = uvec4(a, b, ...)`, each argument `[floatBitsToUint(]r.f[)]`,
// packed one after another from word K.
std::vector<Mapping> writesOf(const std::string& body, const Fields& fields) {
    std::vector<Mapping> out;
    const std::regex store("results\\[o(?: \\+ (\\d)u)?\\] = uvec4\\(([^;]*)\\);");
    const std::regex arg("(?:floatBitsToUint\\()?r\\.([\\w.]+)\\)?");
    for (std::sregex_iterator it(body.begin(), body.end(), store), end; it != end; ++it) {
        const size_t word = (*it)[1].matched ? std::stoul((*it)[1].str()) : 0;
        size_t byte = 16 * word;
        const std::string args = (*it)[2];
        for (std::sregex_iterator a(args.begin(), args.end(), arg); a != end; ++a) {
            Mapping map;
            EXPECT_TRUE(fieldRange(fields, (*a)[1], map))
                << "the kernel writes a field C++ lacks: " << (*a)[1];
            EXPECT_EQ(byte, map.firstByte) << "r." << (*a)[1] << ": the kernel writes byte " << byte
                                           << ", C++ has it at " << map.firstByte;
            byte += map.bytes;
            out.push_back(map);
        }
        EXPECT_EQ(byte, 16 * word + 16) << "results[o + " << word << "] is not one whole uvec4";
    }
    return out;
}

// Every byte of a struct of `size` bytes is mapped exactly once.
void expectCoversEveryByteOnce(const std::vector<Mapping>& maps, size_t size,
                               const std::string& what) {
    std::vector<int> covered(size, 0);
    for (const Mapping& m : maps)
        for (size_t b = m.firstByte; b < m.firstByte + m.bytes && b < size; ++b)
            ++covered[b];
    for (size_t b = 0; b < size; b += 4)
        EXPECT_EQ(covered[b], 1) << what << ": byte " << b << " is mapped " << covered[b]
                                 << " times";
}

const std::string& kernelSource() {
    static const std::string s = readFile(sourceDir() + "/shaders/shade_kernel.glsl");
    return s;
}

TEST(KernelLayout, KernelShaderReadsShaderParamsFieldByField) {
    const std::string body = functionBody(kernelSource(), "ShaderParams kernelShader(uint i)");
    ASSERT_FALSE(body.empty());
    expectCoversEveryByteOnce(readsOf(body, "s", kShaderParams), sizeof(ShaderParams),
                              "ShaderParams");
}

TEST(KernelLayout, KernelEmitterReadsEmitterFieldByField) {
    const std::string body = functionBody(kernelSource(), "Emitter kernelEmitter(uint i)");
    ASSERT_FALSE(body.empty());
    expectCoversEveryByteOnce(readsOf(body, "e", kEmitter), sizeof(Emitter), "Emitter");
}

TEST(KernelLayout, LoadInputReadsShadeInputFieldByField) {
    const std::string body = functionBody(kernelSource(), "ShadeInput loadInput(uint i)");
    ASSERT_FALSE(body.empty());
    expectCoversEveryByteOnce(readsOf(body, "r", shadeInputFields()), sizeof(ShadeInput),
                              "ShadeInput");
}

TEST(KernelLayout, StoreResultWritesShadeResultFieldByField) {
    const std::string body =
        functionBody(kernelSource(), "void storeResult(uint i, ShadeResult r)");
    ASSERT_FALSE(body.empty());
    expectCoversEveryByteOnce(writesOf(body, shadeResultFields()), sizeof(ShadeResult),
                              "ShadeResult");
}

} // namespace
} // namespace spw::test
