// Hit sorting itself, not only the images it leaves unchanged: the radix sort of hit keys is a
// permutation ordered by key, misses last; shaderRuns() gives one contiguous run per shader that
// was hit, covering every hit; and the largest indices the loader accepts keep their order and
// never read as a miss.
#include "host/pipeline/hit_sort.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

namespace spw {
namespace {

struct Hit {
    bool miss;
    uint shader, object, primitive;
};

// `n` hits over `shaders` shaders, a fifth of them misses, in random order.
std::vector<Hit> randomHits(size_t n, uint shaders, unsigned seed) {
    std::mt19937 rng(seed);
    std::vector<Hit> hits(n);
    for (Hit& h : hits) {
        h.miss = rng() % 5 == 0;
        h.shader = rng() % shaders;
        h.object = rng() % 300;
        h.primitive = rng();
    }
    return hits;
}

std::vector<KeyIndex> keysOf(const std::vector<Hit>& hits) {
    std::vector<KeyIndex> keys(hits.size());
    for (size_t i = 0; i < hits.size(); ++i) {
        const Hit& h = hits[i];
        keys[i] = {h.miss ? kMissKey : hitSortKey(h.shader, h.object, h.primitive),
                   std::uint32_t(i)};
    }
    return keys;
}

// The shaders' ranks in the hit sort: by surface model, then by index within a model, and
// shaderAt the inverse of rank.
TEST(HitSort, ShaderRanksGroupEachSurfaceModel) {
    Scene scene;
    const uint models[] = {kModelLambert,   kModelConductor, kModelLambert,   kModelNull,
                           kModelConductor, kModelLambert,   kModelDielectric};
    for (uint m : models) {
        Shader sh;
        sh.params.model = m;
        scene.shaders.push_back(sh);
    }
    const ShaderRanks order(scene);
    ASSERT_EQ(order.shaderAt.size(), scene.shaders.size());
    for (size_t r = 0; r < order.shaderAt.size(); ++r) {
        EXPECT_EQ(order.rank[order.shaderAt[r]], r);
        if (r == 0) continue;
        const uint a = order.shaderAt[r - 1], b = order.shaderAt[r];
        const uint ma = models[a], mb = models[b];
        EXPECT_TRUE(ma < mb || (ma == mb && a < b)) << "rank " << r;
    }
}

TEST(HitSort, KeysSortIntoOneContiguousRunPerShaderWithMissesLast) {
    for (uint shaders : {1u, 3u, 40u, uint(kMaxShaders)}) {
        std::vector<Hit> hits = randomHits(100000, shaders, shaders);
        std::vector<KeyIndex> keys = keysOf(hits), scratch;
        radixSort(keys, scratch);

        // A permutation of the input, ordered by key, each key the one its hit was given.
        std::vector<bool> seen(hits.size(), false);
        for (size_t i = 0; i < keys.size(); ++i) {
            ASSERT_LT(keys[i].index, hits.size());
            ASSERT_FALSE(seen[keys[i].index]) << "index " << keys[i].index << " twice";
            seen[keys[i].index] = true;
            if (i > 0) {
                ASSERT_LE(keys[i - 1].key, keys[i].key) << "at " << i;
            }
        }
        const std::vector<KeyIndex> original = keysOf(hits);
        for (const KeyIndex& k : keys)
            ASSERT_EQ(k.key, original[k.index].key);

        // Misses last; the runs cover every hit, one per shader that was hit, each holding
        // exactly that shader's hits.
        const size_t hitCount =
            size_t(std::count_if(hits.begin(), hits.end(), [](const Hit& h) { return !h.miss; }));
        for (size_t i = hitCount; i < keys.size(); ++i)
            ASSERT_EQ(keys[i].key, kMissKey);
        std::set<uint> shadersHit;
        std::vector<size_t> perShader(shaders, 0);
        for (const Hit& h : hits)
            if (!h.miss) shadersHit.insert(h.shader), ++perShader[h.shader];
        std::vector<ShaderRun> runs = shaderRuns(keys, hitCount);
        ASSERT_EQ(runs.size(), shadersHit.size()) << shaders << " shaders";
        size_t next = 0;
        for (size_t r = 0; r < runs.size(); ++r) {
            EXPECT_EQ(runs[r].begin, next);
            if (r > 0) {
                EXPECT_LT(runs[r - 1].shader, runs[r].shader);
            }
            EXPECT_EQ(runs[r].count, perShader[runs[r].shader]) << "shader " << runs[r].shader;
            for (size_t i = runs[r].begin; i < runs[r].begin + runs[r].count; ++i)
                ASSERT_EQ(hits[keys[i].index].shader, runs[r].shader);
            next = runs[r].begin + runs[r].count;
        }
        EXPECT_EQ(next, hitCount);
    }
}

// Within a shader, hits order by object, then primitive (coherent vertex and texture reads).
TEST(HitSort, KeyOrdersByShaderThenObjectThenPrimitive) {
    const uint maxShader = uint(kMaxShaders) - 1, maxObject = uint(kMaxObjects) - 1;
    EXPECT_LT(hitSortKey(0, maxObject, 0xFFFFFFFFu), hitSortKey(1, 0, 0));
    EXPECT_LT(hitSortKey(5, 7, 0xFFFFFFFFu), hitSortKey(5, 8, 0));
    EXPECT_LT(hitSortKey(5, 7, 1), hitSortKey(5, 7, 2));
    EXPECT_NE(hitSortKey(maxShader, maxObject, 0xFFFFFFFFu), kMissKey);
    EXPECT_LT(hitSortKey(maxShader, maxObject, 0xFFFFFFFFu), kMissKey);
    EXPECT_EQ(shaderOfKey(hitSortKey(maxShader, maxObject, 0xFFFFFFFFu)), maxShader);
    EXPECT_EQ(shaderOfKey(hitSortKey(maxShader - 1, 0, 0)), maxShader - 1);
}

// Within an object, hits order by the Morton code of their texture coordinates (wrapped), and
// by primitive where the mesh has none.
TEST(HitSort, TextureOrderIsTheMortonCodeOfTheWrappedTextureCoordinates) {
    Mesh mesh;
    mesh.positions = {vec3(0), vec3(1, 0, 0), vec3(0, 1, 0)};
    mesh.triangles = {uvec3(0, 1, 2), uvec3(0, 1, 2)};
    EXPECT_EQ(textureOrder(mesh, 1, 0.3f, 0.3f), 1u) << "no texture coordinates: the primitive";
    // Vertex 0 at uv (0.5, 0.25) + 3 (wrapped), vertex 1 at (1.5, 0.25): u = 0.5 + b1.
    mesh.uvs = {vec2(3.5f, 3.25f), vec2(4.5f, 3.25f), vec2(3.5f, 4.25f)};
    // u = 0.5 is bit 15 of x, spread to bit 30; v = 0.25 is bit 14 of y, spread to bit 29.
    EXPECT_EQ(textureOrder(mesh, 0, 0.0f, 0.0f), (1u << 30) | (1u << 29));
    // u = 0.75 (bits 15 and 14 of x: bits 30 and 28); v = 0.25.
    EXPECT_EQ(textureOrder(mesh, 0, 0.25f, 0.0f), (1u << 30) | (1u << 28) | (1u << 29));
    // The next cell in u is the next key; the next in v, two on.
    const uint a = textureOrder(mesh, 0, 0.0f, 0.0f);
    EXPECT_EQ(textureOrder(mesh, 0, 1.5f / 65536, 0.0f), a + 1);
    EXPECT_EQ(textureOrder(mesh, 0, 0.0f, 1.5f / 65536), a + 2);
}

// The one routing decision, case by case: by shader only where the engine's rule asks for it,
// with object and texture order only where images are read and that pays; unsorted hits as
// traced only where the engine can leave the misses in place and no environment reads them.
TEST(HitOrder, ChooseHitOrderFollowsTheRule) {
    using O = HitOrder;
    for (bool pays : {false, true})
        for (bool inPlace : {false, true})
            for (bool env : {false, true}) {
                const HitOrderRule sorted{true, pays, inPlace};
                EXPECT_EQ(chooseHitOrder(sorted, false, env), O::ByShader);
                EXPECT_EQ(chooseHitOrder(sorted, true, env),
                          pays ? O::ByShaderObjectTexture : O::ByShader);
                const HitOrderRule unsorted{false, pays, inPlace};
                for (bool images : {false, true})
                    EXPECT_EQ(chooseHitOrder(unsorted, images, env),
                              inPlace && !env ? O::AsTraced : O::MissesLast);
            }
    EXPECT_FALSE(sortsByShader(O::AsTraced));
    EXPECT_FALSE(sortsByShader(O::MissesLast));
    EXPECT_TRUE(sortsByShader(O::ByShader));
    EXPECT_TRUE(sortsByShader(O::ByShaderObjectTexture));
    EXPECT_STREQ(hitOrderName(O::ByShaderObjectTexture), "shader, object, texture order");
}

} // namespace
} // namespace spw
