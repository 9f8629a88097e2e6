// Instances as lights (kEmitterInstance, shared/instance_light.h): an emissive prototype placed
// more often than SceneLights::kMostCopiedEmitters allows copies of is one emitter per instance,
// its triangles the prototype's, sampled through the instance's transform. Checked against the
// same scene lit by world-space copies: the pdf a light sample reports is the pdf the hit on
// that point reports for MIS (the same triangle, found by a ray), the picks add up to one, the
// records cost what the light tree and one transform cost per instance, and every backend
// renders the copies' image within the standard errors of the paired difference, emission maps
// and mirroring placements included.
#include "embree_backend/batch_traversal.h"
#include "embree_backend/embree_scene.h"
#include "host/loaders/scene_loader.h"
#include "host/scene_view/lights.h"
#include "host/textures/textures.h"
#include "scene/gltf_builder.h"
#include "shared/lights.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <random>

namespace spw::test {
namespace {

// A box [-0.5, 0.5]^3 facing out, 8 vertices (with texture coordinates), 12 triangles.
json lampBox(GltfBuilder& b, int material) {
    std::vector<float> pos, uv;
    for (int c = 0; c < 8; ++c) {
        pos.insert(pos.end(), {c & 1 ? 0.5f : -0.5f, c & 2 ? 0.5f : -0.5f, c & 4 ? 0.5f : -0.5f});
        uv.insert(uv.end(), {c & 1 ? 1.0f : 0.0f, c & 2 ? 1.0f : c & 4 ? 0.5f : 0.0f});
    }
    const std::vector<uint16_t> idx = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                                       2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
    return {{"attributes",
             {{"POSITION", b.accessor(pos, 5126, "VEC3")},
              {"TEXCOORD_0", b.accessor(uv, 5126, "VEC2")}}},
            {"indices", b.accessor(idx, 5123, "SCALAR")},
            {"material", material}};
}

// A cols x rows grid of lamp boxes over a floor, every third one turned, every fourth stretched,
// every fifth mirrored: `shared` one mesh all the nodes name, else a mesh per node (the copies).
// `image`, where not empty, is the lamps' emissiveTexture (a PNG's bytes).
std::string lampGrid(const TempDir& dir, const std::string& name, int cols, int rows, bool shared,
                     const std::string& image = "") {
    GltfBuilder b;
    json lamp = material(vec3(0.2f), 0.0f, 1.0f, vec3(1.0f, 0.75f, 0.5f));
    if (!image.empty()) {
        lamp["emissiveTexture"] = {{"index", 0}};
        b.doc["textures"] = json::array({{{"source", 0}}});
        b.doc["images"] =
            json::array({{{"uri", "data:image/png;base64," + GltfBuilder::base64(image)}}});
    }
    b.doc["materials"] = json::array({lamp, material(vec3(0.7f), 0.0f, 1.0f)});
    b.doc["cameras"] =
        json::array({{{"type", "perspective"},
                      {"perspective", {{"yfov", 0.8}, {"aspectRatio", 1.25}, {"znear", 0.1}}}}});
    const json box = lampBox(b, 0);
    std::vector<int> roots = {b.node(
        {{"mesh", b.mesh(b.quad(1))}, {"scale", {12, 12, 1}}, {"translation", {-6, -6, -0.5}}})};
    const int one = b.mesh(box);
    for (int i = 0; i < cols * rows; ++i) {
        const double x = -4.0 + 8.0 * (i % cols + 0.5) / cols,
                     y = -4.0 + 8.0 * (i / cols + 0.5) / rows;
        json node = {{"mesh", shared ? one : b.mesh(box)},
                     {"translation", {x, y, 1.0 + 0.1 * (i % 3)}}};
        const double s = 2.0 / std::max(cols, rows);
        json scale = {s, s, s};
        if (i % 4 == 1) scale = {0.5 * s, 1.5 * s, s};
        if (i % 5 == 2) scale[0] = -s; // mirrors
        node["scale"] = scale;
        if (i % 3 == 0) node["rotation"] = {0.2588190, 0.0, 0.0, 0.9659258}; // 30 deg about x
        roots.push_back(b.node(node));
    }
    roots.push_back(b.node({{"camera", 0}, {"translation", {0.0, -1.0, 9.0}}}));
    b.scene(roots);
    return b.embedded(dir, name);
}

RenderParams paramsOf(const SceneLights& lights) {
    RenderParams rp{};
    rp.strategy = kStrategyMis;
    rp.emitterCount = lights.sampledEmitters();
    rp.treeEmitters = lights.treeEmitters();
    rp.instanceLights = lights.instanceLights();
    rp.instanceLightCount = lights.instanceLightCount();
    return rp;
}

// The lights of six placements as instances (no copies allowed) and as copies: the pdf of each
// light sample from points over the floor is the pdf that a ray toward the sampled point reports
// from the triangle it hits, and the instances' picks add up to one at every point.
void expectSamplePdfsAreHitPdfs(const Scene& scene, const std::string& what) {
    SCOPED_TRACE(what);
    const SceneLights inst(scene, nullptr, 0), copies(scene);
    for (const Emitter& e : inst.emitters())
        ASSERT_TRUE(std::isfinite(e.pickPdf) && e.pickPdf >= 0.0f && e.pickPdf <= 1.0f)
            << &e - inst.emitters().data() << ": " << e.pickPdf;
    EXPECT_EQ(inst.instanceLightCount(), 6u);
    EXPECT_EQ(copies.instanceLightCount(), 0u);
    EXPECT_EQ(copies.sampledEmitters(), 6u * 12u);
    EXPECT_EQ(inst.sampledEmitters(), 6u);       // one each
    EXPECT_EQ(inst.emitters().size(), 6u + 12u); // and the box's triangles once
    EXPECT_EQ(inst.brightestEmission(), copies.brightestEmission());
    const EmbreeScene bvh(scene);
    const SceneView view = inst.view();
    const RenderParams rp = paramsOf(inst);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    int checked = 0, mirrored = 0;
    for (int i = 0; i < 4000; ++i) {
        SurfaceHit hit{};
        hit.p = vec3(-5.0f + 10.0f * unit(rng), -5.0f + 10.0f * unit(rng), -0.45f);
        hit.ng = hit.ns = vec3(0.0f, 0.0f, 1.0f);
        hit.offset = 1e-4f;
        if (i < 200) { // the picks' probabilities over the instances add up to 1
            double total = 0.0;
            for (uint e = 0; e < inst.sampledEmitters(); ++e)
                total += double(lightPickPdf(view, rp, e, hit.p));
            EXPECT_NEAR(total, 1.0, 1e-5);
        }
        float pickPdf = 0.0f;
        const uint ei = pickLight(view, rp, hit.p, unit(rng), pickPdf);
        ASSERT_NE(ei, kNoEmitter);
        Emitter e = view.emitters[ei];
        ASSERT_EQ(e.type, kEmitterInstance);
        e.pickPdf = pickPdf;
        const LightSample ls = sampleEmitter(view, rp, e, hit, vec2(unit(rng), unit(rng)));
        if (!(ls.pdf > 0.0f)) continue;
        const HitRecord h = intersectOne(bvh, hit.p, ls.wi);
        // Unoccluded: the ray ends on the sampled point (the shadow ray stops just short of
        // it), a lamp's triangle.
        if (h.mesh == kNoHit || h.instance == kNoInstance || std::fabs(h.t - ls.tmax) > 1e-3f * h.t)
            continue;
        uint light = kNoEmitter;
        const Emitter found =
            hitEmitter(view, rp, inst.emitterOf(h.instance, h.mesh, h.prim), light);
        EXPECT_EQ(light, ei);
        const float dist = h.t;
        const float cosLight = emitterCosine(found, -ls.wi);
        Emitter withPick = found;
        withPick.pickPdf *= lightPickPdf(view, rp, light, hit.p);
        EXPECT_NEAR(emitterSolidAnglePdf(withPick, dist, cosLight), ls.pdf, 2e-3f * ls.pdf) << i;
        EXPECT_EQ(found.radiance, ls.radiance);
        mirrored += scene.instances[h.instance].mirrors ? 1 : 0;
        ++checked;
    }
    EXPECT_GT(checked, 1000);
    EXPECT_GT(mirrored, 50); // instance 2 mirrors, and is checked as well
}

TEST(InstancedMeshLight, ALightSamplesPdfIsTheOneItsHitReports) {
    TempDir dir;
    Scene scene = loadScene(lampGrid(dir, "six.gltf", 3, 2, true));
    scene.environment.reset(); // the lamps alone
    ASSERT_EQ(scene.instances.size(), 6u);
    expectSamplePdfsAreHitPdfs(scene, "emission 1");
    // Radiance at the film's limit on a lamp modelled 1e10 times larger and placed 1e-10 times
    // smaller (the same world): its triangles' powers, radiance times their area in the
    // prototype's frame, pass float's range.
    const Prototype& proto = scene.prototypes[0];
    scene.shaders[scene.meshes[proto.meshes[0]].shader].params.emission = vec3(1e20f);
    for (uint m : proto.meshes)
        for (vec3& p : scene.meshes[m].positions)
            p *= 1e10f;
    scene.prototypes[0].lo *= 1e10f;
    scene.prototypes[0].hi *= 1e10f;
    mat4 shrink(1e-10f);
    shrink[3][3] = 1.0f;
    for (Instance& i : scene.instances) {
        i.toWorld = i.toWorld * shrink;
        i.normalToWorld *= 1e10f;
    }
    expectSamplePdfsAreHitPdfs(scene, "emission 1e20, a lamp 1e10 large placed 1e-10 small");
}

// Per instance the light table grows by its record, its CDF entry, its transform and its
// share of the tree, whatever the prototype's triangle count: under 1 KB (at 12 triangles a
// copy costs 12 emitters).
TEST(InstancedMeshLight, AnInstanceCostsARecordNotItsTriangles) {
    TempDir dir;
    const Scene a = loadScene(lampGrid(dir, "a.gltf", 20, 20, true));
    const Scene b = loadScene(lampGrid(dir, "b.gltf", 40, 20, true));
    const SceneLights la(a), lb(b);
    EXPECT_EQ(la.instanceLightCount(), 400u); // 4800 triangles: past kMostCopiedEmitters
    EXPECT_EQ(lb.instanceLightCount(), 800u);
    const double perInstance = double(lb.bytes() - la.bytes()) / 400.0;
    std::printf("light table per instance: %.0f bytes\n", perInstance);
    EXPECT_LT(perInstance, 1024.0);
    EXPECT_LT(perInstance, double(12 * sizeof(Emitter)));
}

// 360 placements of a 12-triangle lamp (instances, as the default limit makes them) against a
// mesh per placement (copies): the same image on every backend, with and without an emission map.
TEST(InstancedMeshLight, AGridOfLampsRendersAsItsCopiesOnEveryBackend) {
    TempDir dir;
    for (const std::string& image : {std::string(), stripesPng(dir)}) {
        const std::string what = image.empty() ? "constant" : "emission map";
        Scene inst = loadScene(lampGrid(dir, "inst.gltf", 20, 18, true, image));
        Scene flat = loadScene(lampGrid(dir, "flat.gltf", 20, 18, false, image));
        {
            const TextureResolver ti(inst, 16.0), tf(flat, 16.0);
            ASSERT_EQ(SceneLights(inst, &ti).instanceLightCount(), 360u) << what;
            ASSERT_EQ(SceneLights(flat, &tf).instanceLightCount(), 0u) << what;
        }
        for (Scene* s : {&inst, &flat})
            s->image = {40, 32, 1, 128};
        for (const std::string& backend : backendsUnderTest()) {
            RenderConfig config;
            config.backend = backendNamed(backend);
            const auto a = iterationImages(inst, config), b = iterationImages(flat, config);
            ASSERT_FALSE(a.empty());
            EXPECT_GT(mean(a.back()), 0.05) << backend;
            expectNoPairedDifference(pairedDifference(a, b), 40, 32,
                                     backend + ", " + what + ": instances - copies",
                                     1e-4 * mean(b.back()));
        }
    }
}

} // namespace
} // namespace spw::test
