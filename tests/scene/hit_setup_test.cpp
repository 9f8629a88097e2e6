// Hit setup SIMD-wide (HitSetup::setUpHits, host/scene_view/wide_hits.cpp) against one hit at a
// time (setUpGeometry and textureQuery, the oracle): bit for bit, in every instruction set this
// machine has, on meshes with and without vertex normals and texture coordinates, an emitter,
// triangles from 1e-4 to 1e5 units and 1e6 units from the origin, degenerate triangles and
// normals, grazing and head-on rays, and cones from none to wide.
#include "host/scene_view/hit_setup.h"
#include "host/simd/lanes.h"
#include "shared/cone.h"
#include "test_util.h"

#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <cstring>
#include <random>

namespace spw::test {
namespace {

// A mesh of `triangles` random triangles near `centre`, `size` units across; some degenerate
// (a repeated vertex, or all three in a line), and with a vertex normal of zero length.
Mesh randomMesh(std::mt19937& rng, int triangles, vec3 centre, float size, bool normals, bool uvs,
                int shader) {
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
    Mesh mesh;
    mesh.shader = shader;
    for (int i = 0; i < triangles; ++i) {
        const uint base = uint(mesh.positions.size());
        vec3 v[3];
        for (vec3& p : v)
            p = centre + size * vec3(unit(rng), unit(rng), unit(rng));
        if (i % 17 == 3) v[2] = v[1];                        // no area
        if (i % 19 == 5) v[2] = v[0] + 2.0f * (v[1] - v[0]); // in a line
        for (int k = 0; k < 3; ++k) {
            mesh.positions.push_back(v[k]);
            if (normals)
                mesh.normals.push_back(i % 13 == 2 ? vec3(0.0f)
                                                   : vec3(unit(rng), unit(rng), unit(rng)));
            if (uvs) mesh.uvs.push_back(4.0f * vec2(unit(rng), unit(rng)));
        }
        if (uvs && i % 23 == 7) mesh.uvs[base + 2] = mesh.uvs[base + 1]; // no texture area
        mesh.triangles.push_back(uvec3(base, base + 1, base + 2));
    }
    return mesh;
}

// The number of hits whose wide setup differs from the scalar one, of `compared`.
size_t wideAgainstScalar(const Scene& scene, std::mt19937& rng, size_t& compared);

TEST(HitSetup, WideSetupIsTheScalarSetupBitForBit) {
    std::mt19937 rng(5);
    // Meshes with and without vertex normals and texture coordinates, and a scene with neither
    // (where the wide setup skips them).
    Scene mixed, bare;
    for (Scene* scene : {&mixed, &bare}) {
        scene->shaders.resize(2);
        scene->shaders[1].params.emission = vec3(1.0f);
        const bool has = scene == &mixed;
        scene->meshes.push_back(randomMesh(rng, 200, vec3(0.0f), 1.0f, has, has, 0));
        scene->meshes.push_back(
            randomMesh(rng, 200, vec3(3.0f, -2.0f, 1.0f), 0.5f, false, false, 0));
        scene->meshes.push_back(
            randomMesh(rng, 200, vec3(1e6f, 0.0f, -1e6f), 1e-4f, has, false, 1));
        scene->meshes.push_back(randomMesh(rng, 200, vec3(-50.0f), 1e5f, false, has, 0));
    }
    for (const Scene* scene : {&mixed, &bare}) {
        size_t compared = 0;
        EXPECT_EQ(wideAgainstScalar(*scene, rng, compared), 0u)
            << (scene == &mixed ? "mixed" : "bare") << " scene, of " << compared;
        EXPECT_GT(compared, 1000u);
    }
}

size_t wideAgainstScalar(const Scene& scene, std::mt19937& rng, size_t& compared) {
    const SceneLights lights(scene);
    const HitSetup setup(scene, lights);

    std::uniform_real_distribution<float> unit(0.0f, 1.0f), signed1(-1.0f, 1.0f);
    std::uniform_int_distribution<uint> mesh(0, uint(scene.meshes.size()) - 1), prim(0, 199);
    const std::vector<std::int64_t> targets = hwy::SupportedAndGeneratedTargets();
    EXPECT_FALSE(targets.empty());
    size_t differing = 0;
    for (int round = 0; round < 60; ++round) {
        // 1 to kBlock hits: runs on one mesh (as sorted hits come) and mixed.
        const size_t n = 1 + size_t(round * 7) % simd::kBlock;
        std::vector<HitRecord> hits(n);
        std::vector<vec3> dir(n);
        std::vector<uint> cone(n);
        const uint runMesh = mesh(rng);
        for (size_t j = 0; j < n; ++j) {
            float u = unit(rng), v = unit(rng) * (1.0f - u);
            if (j % 11 == 0) u = 0.0f, v = 1.0f; // a vertex
            hits[j] = {round % 2 ? runMesh : mesh(rng), prim(rng), u, v, 1e-3f + 1e3f * unit(rng)};
            dir[j] = glm::normalize(vec3(signed1(rng), signed1(rng), signed1(rng)));
            if (j % 7 == 1) dir[j] = vec3(1.0f, 0.0f, 0.0f);
            cone[j] = j % 9 == 4 ? 0u : packCone(unit(rng) * 1e-2f, unit(rng) * 1e-2f);
        }
        std::vector<SurfaceHit> wide(n), scalar(n);
        std::vector<SurfaceHit*> out(n);
        std::vector<const HitRecord*> record(n);
        std::vector<vec2> uv(n), uvScalar(n);
        std::vector<float> footprint(n), footprintScalar(n);
        for (size_t j = 0; j < n; ++j)
            out[j] = &wide[j], record[j] = &hits[j];
        hwy::SetSupportedTargetsForTest(targets[size_t(round) % targets.size()]);
        setup.setUpHits(n, record.data(), dir.data(), cone.data(), out.data(), uv.data(),
                        footprint.data());
        for (size_t j = 0; j < n; ++j) {
            setup.setUpGeometry(hits[j], scalar[j]);
            setup.textureQuery(hits[j], dir[j], cone[j], scalar[j], uvScalar[j],
                               footprintScalar[j]);
            const bool same = std::memcmp(&wide[j], &scalar[j], sizeof(SurfaceHit)) == 0 &&
                              std::memcmp(&uv[j], &uvScalar[j], sizeof(vec2)) == 0 &&
                              std::memcmp(&footprint[j], &footprintScalar[j], sizeof(float)) == 0;
            differing += !same;
            ++compared;
            EXPECT_TRUE(same) << "round " << round << ", hit " << j << " (mesh " << hits[j].mesh
                              << ", triangle " << hits[j].prim << ")";
        }
    }
    hwy::SetSupportedTargetsForTest(0);
    return differing;
}

} // namespace
} // namespace spw::test
