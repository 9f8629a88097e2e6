#include "host/pipeline/hit_sort.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace spw {
namespace {

// The 16 low bits of x spread to the even bits.
uint spreadBits(uint x) {
    x &= 0xFFFFu;
    x = (x | (x << 8)) & 0x00FF00FFu;
    x = (x | (x << 4)) & 0x0F0F0F0Fu;
    x = (x | (x << 2)) & 0x33333333u;
    x = (x | (x << 1)) & 0x55555555u;
    return x;
}

// A texture coordinate wrapped into [0, 1) as 16 bits (periodic textures wrap the same way).
uint wrapped16(float t) {
    const float f = t - std::floor(t);
    return f >= 0.0f && f < 1.0f ? std::min(uint(f * 65536.0f), 0xFFFFu) : 0u;
}

} // namespace

uint textureOrder(const Mesh& mesh, uint primitive, float u, float v) {
    if (mesh.uvs.empty()) return primitive;
    const uvec3 t = mesh.triangles[primitive];
    const vec2 uv = (1.0f - u - v) * mesh.uvs[t.x] + u * mesh.uvs[t.y] + v * mesh.uvs[t.z];
    return spreadBits(wrapped16(uv.x)) | spreadBits(wrapped16(uv.y)) << 1;
}

const char* hitOrderName(HitOrder order) {
    switch (order) {
    case HitOrder::AsTraced:
        return "as traced";
    case HitOrder::MissesLast:
        return "misses last";
    case HitOrder::ByShader:
        return "shader";
    case HitOrder::ByShaderObjectTexture:
        return "shader, object, texture order";
    }
    return "?";
}

HitOrder chooseHitOrder(const HitOrderRule& rule, bool readsImages, bool hasEnvironment) {
    if (rule.byShader)
        return readsImages && rule.textureOrderPays ? HitOrder::ByShaderObjectTexture
                                                    : HitOrder::ByShader;
    return rule.takesMissesInPlace && !hasEnvironment ? HitOrder::AsTraced : HitOrder::MissesLast;
}

ShaderRanks::ShaderRanks(const Scene& scene) : shaderAt(scene.shaders.size()) {
    std::iota(shaderAt.begin(), shaderAt.end(), 0u);
    std::stable_sort(shaderAt.begin(), shaderAt.end(), [&](uint a, uint b) {
        return scene.shaders[a].params.model < scene.shaders[b].params.model;
    });
    rank.resize(shaderAt.size());
    for (uint r = 0; r < uint(shaderAt.size()); ++r)
        rank[shaderAt[r]] = r;
}

std::vector<ShaderRun> shaderRuns(const std::vector<SortedHit>& keys, size_t hitCount) {
    std::vector<ShaderRun> runs;
    size_t begin = 0;
    while (begin < hitCount) {
        const uint shader = shaderOfKey(keys[begin].key);
        size_t end = begin + 1;
        while (end < hitCount && shaderOfKey(keys[end].key) == shader)
            ++end;
        runs.push_back({shader, begin, end - begin});
        begin = end;
    }
    return runs;
}

} // namespace spw
