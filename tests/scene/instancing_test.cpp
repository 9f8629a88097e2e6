// Instancing (Scene::prototypes, Scene::instances): a glTF mesh that several nodes name, a glTF
// file that several YAML objects place and an OBJ placed by `instances:` are one prototype,
// traced through a two-level BVH. Each is checked against the same scene flattened (every
// placement a copy): the same counts, the same world-space hits up to float rounding (mirrored
// instances included), and on every backend the same image within the standard errors of the
// paired difference. Malformed placements are refused with the file and where in it.
#include "embree_backend/batch_traversal.h"
#include "embree_backend/embree_scene.h"
#include "host/loaders/scene_loader.h"
#include "host/scene_view/hit_setup.h"
#include "host/scene_view/lights.h"
#include "host/textures/textures.h"
#include "scene/gltf_builder.h"
#include "test_util.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace spw::test {
namespace {

using nlohmann::json;

// A box [-0.5, 0.5]^3 with smooth normals (each corner's along its diagonal) and texture
// coordinates: 8 vertices, 12 triangles facing out.
json boxPrimitive(GltfBuilder& b, int material) {
    std::vector<float> pos, nor, uv;
    for (int c = 0; c < 8; ++c) {
        const vec3 p(c & 1 ? 0.5f : -0.5f, c & 2 ? 0.5f : -0.5f, c & 4 ? 0.5f : -0.5f);
        const vec3 n = glm::normalize(p);
        pos.insert(pos.end(), {p.x, p.y, p.z});
        nor.insert(nor.end(), {n.x, n.y, n.z});
        uv.insert(uv.end(), {p.x + 0.5f, p.y + 0.5f});
    }
    const std::vector<uint16_t> idx = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                                       2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
    json prim = {{"attributes",
                  {{"POSITION", b.accessor(pos, 5126, "VEC3")},
                   {"NORMAL", b.accessor(nor, 5126, "VEC3")},
                   {"TEXCOORD_0", b.accessor(uv, 5126, "VEC2")}}},
                 {"indices", b.accessor(idx, 5123, "SCALAR")},
                 {"material", material}};
    return prim;
}

// The box placed by four nodes (turned, stretched, one mirrored) over a floor, under the file's
// default lighting, seen by a camera: `shared` one mesh the four name, else four meshes of the
// same accessors (the flattened scene). `emission` makes the boxes' material emissive;
// `emissionImage` (a PNG's bytes), where not empty, is its emissiveTexture.
std::string boxes(const TempDir& dir, const std::string& name, bool shared,
                  vec3 emission = vec3(0.0f), const std::string& emissionImage = "") {
    GltfBuilder b;
    json lamp = material(vec3(0.8f, 0.5f, 0.25f), 0.0f, 0.5f, emission);
    if (!emissionImage.empty()) {
        lamp["emissiveTexture"] = {{"index", 0}};
        b.doc["textures"] = json::array({{{"source", 0}}});
        b.doc["images"] =
            json::array({{{"uri", "data:image/png;base64," + GltfBuilder::base64(emissionImage)}}});
    }
    b.doc["materials"] = json::array({lamp, material(vec3(0.6f), 0.0f, 1.0f)});
    b.doc["cameras"] =
        json::array({{{"type", "perspective"},
                      {"perspective", {{"yfov", 0.9}, {"aspectRatio", 1.25}, {"znear", 0.1}}}}});
    const json box = boxPrimitive(b, 0);
    const int floor = b.mesh(b.quad(1));
    std::vector<int> roots = {
        b.node({{"mesh", floor}, {"scale", {8, 8, 1}}, {"translation", {-4, -4, -0.5}}})};
    const std::vector<json> placements = {
        {{"translation", {-1.2, 0.0, 0.0}}},
        {{"translation", {0.0, 0.3, 0.2}}, {"rotation", {0.0, 0.3826834, 0.0, 0.9238795}}},
        {{"translation", {1.2, -0.2, 0.1}}, {"scale", {0.6, 1.4, 0.8}}},
        {{"translation", {0.3, 1.3, 0.0}}, {"scale", {-1.0, 0.7, 1.0}}}, // mirrors
    };
    const int one = b.mesh(box);
    for (json node : placements) {
        node["mesh"] = shared ? one : b.mesh(box);
        roots.push_back(b.node(node));
    }
    roots.push_back(b.node({{"camera", 0}, {"translation", {0.0, 0.4, 5.0}}}));
    b.scene(roots);
    return b.embedded(dir, name);
}

// The direction from the camera at the origin of ray (x, y) of a 50 x 40 grid over the boxes,
// offset so that no ray grazes a box's edge in one scene only.
vec3 gridRay(int x, int y) {
    return glm::normalize(
        vec3((x - 25 + 0.3183f) / 29.7f, (y - 20 + 0.2718f) / 29.7f - 0.1f, -1.0f));
}

TEST(Instancing, AMeshNamedByManyNodesIsOnePrototype) {
    TempDir dir;
    const Scene inst = loadScene(boxes(dir, "shared.gltf", true));
    const Scene flat = loadScene(boxes(dir, "flat.gltf", false));
    ASSERT_EQ(inst.prototypes.size(), 1u);
    ASSERT_EQ(inst.instances.size(), 4u);
    EXPECT_EQ(inst.meshes.size(), 2u); // the floor and the box, once
    EXPECT_TRUE(flat.prototypes.empty());
    EXPECT_TRUE(flat.instances.empty());
    EXPECT_EQ(flat.meshes.size(), 5u);
    EXPECT_EQ(inst.renderedTriangles(), flat.renderedTriangles());
    EXPECT_EQ(inst.renderedTriangles(), 2.0 + 4 * 12.0);
    EXPECT_EQ(inst.instances[3].mirrors, true);
    EXPECT_EQ(inst.instances[0].mirrors, false);
    // The bounds every light is measured at are the flattened scene's.
    glm::dvec3 lo, hi, flo, fhi;
    sceneBounds(inst, lo, hi);
    sceneBounds(flat, flo, fhi);
    for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(lo[k], flo[k], 1e-5);
        EXPECT_NEAR(hi[k], fhi[k], 1e-5);
    }
}

// Rays from the camera through a grid: each hits the same surface in both scenes, and hit setup
// gives the same world-space point, normals, offset, lift and texture coordinates (a mirrored
// instance's winding turned as its copy's is).
TEST(Instancing, HitsSetUpInWorldSpaceAsTheirCopies) {
    TempDir dir;
    const Scene inst = loadScene(boxes(dir, "shared.gltf", true));
    const Scene flat = loadScene(boxes(dir, "flat.gltf", false));
    const SceneLights li(inst, nullptr), lf(flat, nullptr);
    const EmbreeScene ei(inst), ef(flat);
    const HitSetup si(inst, li), sf(flat, lf);
    int instanced = 0, mirrored = 0, rays = 0, apart = 0;
    for (int y = 0; y < 40; ++y)
        for (int x = 0; x < 50; ++x) { // off the boxes' edges: no ray grazes one in one scene only
            const vec3 dir = gridRay(x, y);
            const HitRecord a = intersectOne(ei, vec3(0.0f), dir),
                            b = intersectOne(ef, vec3(0.0f), dir);
            ++rays;
            if (a.mesh == kNoHit && b.mesh == kNoHit) continue;
            if (a.mesh == kNoHit || b.mesh == kNoHit || a.prim != b.prim ||
                std::fabs(a.t - b.t) > 1e-5f * b.t) {
                ++apart; // an edge that rounding puts on the other side
                continue;
            }
            SurfaceHit ha{}, hb{};
            si.setUpGeometry(a, ha);
            sf.setUpGeometry(b, hb);
            vec2 uva, uvb;
            float fa, fb;
            si.textureQuery(a, dir, 0u, ha, uva, fa);
            sf.textureQuery(b, dir, 0u, hb, uvb, fb);
            if (a.instance != kNoInstance) {
                ++instanced;
                mirrored += inst.instances[a.instance].mirrors;
            }
            for (int k = 0; k < 3; ++k) {
                EXPECT_NEAR(ha.p[k], hb.p[k], 1e-5f);
                EXPECT_NEAR(ha.ng[k], hb.ng[k], 1e-5f);
                EXPECT_NEAR(ha.ns[k], hb.ns[k], 1e-5f);
            }
            EXPECT_NEAR(ha.offset, hb.offset, 1e-6f + 1e-3f * hb.offset);
            EXPECT_NEAR(ha.lift, hb.lift, 1e-5f);
            EXPECT_NEAR(uva.x, uvb.x, 1e-5f);
            EXPECT_NEAR(uva.y, uvb.y, 1e-5f);
            EXPECT_NEAR(fa, fb, 1e-4f * fb);
            EXPECT_EQ(ha.shader, hb.shader);
        }
    EXPECT_LE(apart, rays / 500) << "hits on other surfaces";
    EXPECT_GT(instanced, 150);
    EXPECT_GT(mirrored, 20);
}

// The compact layout (kCompactBvhTriangles) finds the same closest hits as the fast one,
// instances and all: the same triangle of the same instance, at the same distance and
// barycentrics up to rounding (to the bit on some CPUs; on an AMD EPYC with AVX2, Embree's two
// layouts round u, v and t a few ulps apart).
TEST(Instancing, ACompactBvhFindsTheSameHits) {
    TempDir dir;
    const Scene s = loadScene(boxes(dir, "shared.gltf", true));
    const EmbreeScene fast(s), compact(s, nullptr, 0);
    EXPECT_FALSE(fast.compact());
    EXPECT_TRUE(compact.compact());
    int hits = 0;
    for (int y = 0; y < 40; ++y)
        for (int x = 0; x < 50; ++x) {
            const vec3 dir = gridRay(x, y);
            const HitRecord a = intersectOne(fast, vec3(0.0f), dir),
                            b = intersectOne(compact, vec3(0.0f), dir);
            ASSERT_EQ(a.mesh, b.mesh);
            if (a.mesh == kNoHit) continue;
            ++hits;
            EXPECT_EQ(a.instance, b.instance);
            EXPECT_EQ(a.prim, b.prim);
            EXPECT_NEAR(a.t, b.t, 1e-5f * a.t);
            EXPECT_NEAR(a.u, b.u, 1e-5f);
            EXPECT_NEAR(a.v, b.v, 1e-5f);
        }
    EXPECT_GT(hits, 1000);
}

// Every backend renders the instanced scene as the flattened one: iteration by iteration (the
// same random numbers), their difference has mean zero within its standard errors, with a
// per-pixel allowance for the float rounding of the two scenes' vertices.
TEST(Instancing, EveryBackendRendersTheFlattenedImage) {
    TempDir dir;
    Scene inst = loadScene(boxes(dir, "shared.gltf", true));
    Scene flat = loadScene(boxes(dir, "flat.gltf", false));
    for (Scene* s : {&inst, &flat})
        s->image.width = 40, s->image.height = 32;
    for (const std::string& backend : backendsUnderTest()) {
        RenderConfig config;
        config.backend = backendNamed(backend);
        config.spp = 64;
        const auto a = iterationImages(inst, config), b = iterationImages(flat, config);
        ASSERT_FALSE(a.empty());
        EXPECT_GT(mean(a.back()), 0.05) << backend;
        expectNoPairedDifference(pairedDifference(a, b), 40, 32, backend + ": instanced - flat",
                                 1e-4 * mean(b.back()));
    }
}

// An emissive mesh that four nodes name stays one prototype, its triangles lights at each
// placement: the light table is the flattened scene's (the same count, and per emitter the same
// area, front face, radiance and pick probability; a mirrored copy's corners come in another
// order), each hit on an instance names the emitter its copy's hit names, and every backend
// renders the flattened image. So it is under an emission map, whose records are made once per
// prototype triangle and read by every instance's emitters.
TEST(Instancing, AnEmissiveMeshLightsAtEachPlacement) {
    TempDir dir;
    for (const std::string& image : {std::string(), stripesPng(dir)}) {
        const std::string what = image.empty() ? "constant" : "emission map";
        Scene inst = loadScene(boxes(dir, "lamps.gltf", true, vec3(1.0f), image));
        Scene flat = loadScene(boxes(dir, "flat.gltf", false, vec3(1.0f), image));
        ASSERT_EQ(inst.prototypes.size(), 1u);
        ASSERT_EQ(inst.instances.size(), 4u);
        EXPECT_EQ(emissiveTriangles(inst, inst.prototypes[0]), 12u);
        EXPECT_EQ(bool(inst.environment), bool(flat.environment)) << what;
        const TextureResolver ti(inst, 16.0), tf(flat, 16.0);
        const SceneLights li(inst, &ti), lf(flat, &tf);
        ASSERT_EQ(li.emitters().size(), lf.emitters().size());
        EXPECT_GE(li.emitters().size(), 4 * 12u);
        EXPECT_EQ(li.emissionImages(), image.empty() ? 0u : 1u);
        for (size_t k = 0; k < li.emitters().size(); ++k) {
            const Emitter &a = li.emitters()[k], &b = lf.emitters()[k];
            ASSERT_EQ(a.type, b.type);
            EXPECT_NEAR(a.area, b.area, 1e-5f * b.area) << what << " " << k;
            EXPECT_NEAR(a.pickPdf, b.pickPdf, 1e-5f * b.pickPdf) << what << " " << k;
            EXPECT_EQ(a.map != kNoEmissionMap, b.map != kNoEmissionMap);
            if (a.type != kEmitterTriangle) continue;
            for (int c = 0; c < 3; ++c) {
                EXPECT_NEAR(a.p0[c], b.p0[c], 1e-5f) << what << " " << k;
                EXPECT_NEAR(a.normal[c], b.normal[c], 1e-5f) << what << " " << k;
                EXPECT_EQ(a.radiance[c], b.radiance[c]);
            }
        }
        const EmbreeScene ei(inst), ef(flat);
        int lit = 0;
        for (int y = 0; y < 40; ++y)
            for (int x = 0; x < 50; ++x) {
                const vec3 d = gridRay(x, y);
                const HitRecord a = intersectOne(ei, vec3(0.0f), d),
                                b = intersectOne(ef, vec3(0.0f), d);
                if (a.instance == kNoInstance || b.mesh == kNoHit || a.prim != b.prim) continue;
                ++lit;
                EXPECT_EQ(li.emitterOf(a.instance, a.mesh, a.prim),
                          lf.emitterOf(kNoInstance, b.mesh, b.prim));
            }
        EXPECT_GT(lit, 150);
        // The two light trees differ where rounding moves a split (an emitter's corners are
        // made in float from the instance's transform, a copy's in double), so their picks do:
        // 32 iterations of one sample each, for per-pixel errors of the difference to rely on.
        for (Scene* s : {&inst, &flat})
            s->image = {40, 32, 1, 32};
        for (const std::string& backend : backendsUnderTest()) {
            RenderConfig config;
            config.backend = backendNamed(backend);
            const auto a = iterationImages(inst, config), b = iterationImages(flat, config);
            ASSERT_FALSE(a.empty());
            EXPECT_GT(mean(a.back()), 0.05) << backend;
            expectNoPairedDifference(pairedDifference(a, b), 40, 32,
                                     backend + ", " + what + ": instanced - flat",
                                     1e-4 * mean(b.back()));
        }
    }
}

// A YAML object's `instances:` and a glTF file placed by several objects: prototypes, rendered
// as the same placements written out as objects of their own; an emissive cube's instances light
// the scene as its copies do.
TEST(Instancing, YamlInstancesRenderAsSeparateObjects) {
    TempDir dir;
    dir.write("floor.obj", floorObj(4.0f));
    dir.write("cube.obj", insideCubeObj());
    const std::string head =
        "image: {width: 32, height: 24}\n"
        "camera: {translation: [0, 1.5, 6], rotation: [-10, 0, 0]}\n"
        "settings: {max depth: 4}\n"
        "shaders:\n  - {type: Lambert, colour: [0.7, 0.6, 0.5]}\n"
        "  - {type: Lambert, colour: [0.5, 0.5, 0.5], emission: [3, 2, 1], two sided: true}\n"
        "lights:\n  - {type: Point, position: [1, 4, 2], intensity: 20}\n"
        "  - {type: Environment, intensity: 0.3}\n"
        "objects:\n  - {filename: floor.obj}\n";
    const std::vector<std::string> places = {
        "{translation: [-1.5, 0.5, 0], scale: 0.4}",
        "{translation: [0, 0.6, 0], rotation: [0, 30, 0], "
        "scale: [0.5, 0.6, 0.4]}",
        "{translation: [1.5, 0.5, 0], scale: [-0.4, 0.4, 0.4]}"};
    for (const std::string shader : {"0", "1"}) {
        std::string instanced =
            head + "  - filename: cube.obj\n    shader: " + shader + "\n    instances:\n";
        std::string flattened = head;
        for (const std::string& p : places) {
            instanced += "      - " + p + "\n";
            std::string object = p;
            object.insert(1, "filename: cube.obj, shader: " + shader + ", ");
            flattened += "  - " + object + "\n";
        }
        const Scene a = loadScene(dir.write("instanced.yaml", instanced));
        const Scene b = loadScene(dir.write("flattened.yaml", flattened));
        ASSERT_EQ(a.instances.size(), 3u);
        EXPECT_TRUE(a.instances[2].mirrors);
        EXPECT_TRUE(b.instances.empty());
        EXPECT_EQ(SceneLights(a).emitters().size(), SceneLights(b).emitters().size());
        for (BackendKind backend : {BackendKind::Reference, BackendKind::Cpu}) {
            RenderConfig config;
            config.backend = backend;
            config.spp = 64;
            const auto ia = iterationImages(a, config), ib = iterationImages(b, config);
            EXPECT_GT(mean(ia.back()), 0.01);
            expectNoPairedDifference(pairedDifference(ia, ib), 32, 24,
                                     "shader " + shader + ", instances: - objects",
                                     1e-4 * mean(ib.back()));
        }
    }

    // One glTF file placed by three objects: one reader, its mesh a prototype of three.
    boxes(dir, "box.gltf", false);
    const Scene g = loadScene(dir.write(
        "gltf.yaml", head + "  - {type: Gltf, filename: box.gltf, translation: [0, 0, -3]}\n"
                            "  - {type: Gltf, filename: box.gltf, translation: [0, 0, -6]}\n"
                            "  - type: Gltf\n    filename: box.gltf\n"
                            "    instances: [{translation: [0, 0, -9]}]\n"));
    // The file's five meshes (the floor and four boxes), each placed three times.
    EXPECT_EQ(g.prototypes.size(), 5u);
    EXPECT_EQ(g.instances.size(), 15u);
}

// --stats says where the memory went: the scene's arrays to the byte (the box once, 8 vertices
// of position, normal and uv and 12 triangles, beside the floor quad), the instances' records,
// the lights' (with emissive boxes, an emitter per triangle per instance), and the peaks in the
// order they are reached.
TEST(Instancing, StatsReportTheMemoryOfTheSceneAndItsPeaks) {
    TempDir dir;
    for (float emission : {0.0f, 1.0f}) {
        const std::string file = boxes(dir, "boxes.gltf", true, vec3(emission));
        const Scene scene = loadScene(file);
        ASSERT_EQ(scene.instances.size(), 4u);
        const std::string stats = dir.file("stats.json");
        const CommandResult r =
            runSpillway("render " + file + " --backend cpu --spp 1 --width 16 " +
                        "--height 12 --quiet -o " + dir.file("b.exr") + " --stats " + stats);
        ASSERT_EQ(r.status, 0) << r.output;
        const json all = json::parse(readFile(stats)), m = all["memory"];
        double expected = 0.0;
        for (const Mesh& mesh : scene.meshes)
            expected +=
                double(mesh.positions.size() * 12 + mesh.normals.size() * 12 + mesh.uvs.size() * 8 +
                       mesh.colours.size() * 12 + mesh.triangles.size() * 12);
        EXPECT_EQ(m["scene_geometry_bytes"].get<double>(), expected) << m.dump();
        EXPECT_EQ(m["instances_bytes"].get<double>(), double(4 * sizeof(Instance)));
        const TextureResolver textures(scene, 16.0);
        const SceneLights lights(scene, &textures);
        EXPECT_EQ(m["lights_bytes"].get<double>(), double(lights.bytes()));
        EXPECT_EQ(all["lights"]["emitters"].get<double>(), double(lights.emitters().size()));
        if (emission > 0.0f) {
            EXPECT_EQ(lights.emitters().size(), 4 * 12u); // the file's lights alone
        }
        EXPECT_GE(double(lights.bytes()), double(lights.emitters().size() * sizeof(Emitter)));
        EXPECT_LE(m["after_load_mib"].get<double>(), m["after_bvh_mib"].get<double>());
        EXPECT_LE(m["after_bvh_mib"].get<double>(), m["peak_rss_mib"].get<double>());
        EXPECT_DOUBLE_EQ(m["peak_bytes_per_instance"].get<double>(),
                         m["peak_rss_mib"].get<double>() * 1048576.0 / 4.0);
        EXPECT_GT(m["ray_batches_peak_bytes"].get<double>(), 0.0);
    }
}

TEST(Instancing, MalformedPlacementsAreRefusedWithWhere) {
    TempDir dir;
    dir.write("cube.obj", insideCubeObj());
    const std::string head = "shaders: [{type: Lambert}]\nobjects:\n  - filename: cube.obj\n";
    const std::string empty = dir.write("empty.yaml", head + "    instances: []\n");
    EXPECT_EQ(loadError(empty), empty + ":4: instances must be a list of transforms "
                                        "({translation, rotation, scale})");
    const std::string notMap = dir.write("scalar.yaml", head + "    instances: [3]\n");
    EXPECT_EQ(loadError(notMap),
              notMap + ":4: an instance is a map of translation, rotation and scale");
    const std::string key = dir.write("key.yaml", head + "    instances: [{shader: 0}]\n");
    EXPECT_NE(loadError(key).find(key + ":4: "), std::string::npos) << loadError(key);
    const std::string zero = dir.write("zero.yaml", head + "    instances: [{scale: 0}]\n");
    EXPECT_NE(loadError(zero).find("scale must not be zero"), std::string::npos);
    const std::string far =
        dir.write("far.yaml", head + "    instances: [{translation: [1e16, 0, 0]}]\n");
    EXPECT_NE(loadError(far).find(far + ":4: an instance of"), std::string::npos) << loadError(far);
    EXPECT_NE(loadError(far).find("units from the camera"), std::string::npos);

    // glTF: a projective matrix on a node naming a shared mesh, with its JSON pointer.
    GltfBuilder b;
    const int quad = b.mesh(b.quad());
    const int a = b.node({{"mesh", quad}});
    const int p =
        b.node({{"mesh", quad}, {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0.5, 0, 0, 0, 1}}});
    b.scene({a, p});
    const std::string projective = b.embedded(dir, "projective.gltf");
    EXPECT_EQ(loadError(projective),
              projective + ": /nodes/1/mesh: the node's transform is not affine (its last row is "
                           "not 0 0 0 1)");
    // A zero scale hides the placement (a warning), as it drops a copy's triangles.
    GltfBuilder h;
    const int q = h.mesh(h.quad());
    h.scene({h.node({{"mesh", q}}), h.node({{"mesh", q}, {"scale", {0, 1, 1}}})});
    const Scene hidden = loadScene(h.embedded(dir, "hidden.gltf"));
    EXPECT_EQ(hidden.instances.size(), 1u);
    ASSERT_FALSE(hidden.warnings.empty());
    EXPECT_NE(hidden.warnings[0].find("singular transform"), std::string::npos);
}

// The emissive triangles instances place are capped (kMaxInstancedEmitters: a triangle counted
// once per instance, numbered in 31 bits for the hits that find it): a prototype of 2^17
// emissive triangles placed 2^14 times is refused with the YAML object's line and the glTF
// node's pointer, before any light is made; at 2^14 - 1 placements it loads.
TEST(Instancing, TooManyInstancedEmittersAreRefusedWithWhere) {
    TempDir dir;
    const int n = 256; // a grid of n x n quads, 2n^2 = 2^17 triangles
    std::string obj;
    std::vector<float> pos;
    std::vector<uint32_t> idx;
    for (int y = 0; y <= n; ++y)
        for (int x = 0; x <= n; ++x) {
            obj += "v " + std::to_string(x) + " " + std::to_string(y) + " 0\n";
            pos.insert(pos.end(), {float(x), float(y), 0.0f});
        }
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const int v = y * (n + 1) + x + 1; // OBJ's 1-based index
            obj += "f " + std::to_string(v) + " " + std::to_string(v + 1) + " " +
                   std::to_string(v + n + 2) + " " + std::to_string(v + n + 1) + "\n";
            for (int c : {0, 1, n + 2, 0, n + 2, n + 1})
                idx.push_back(uint32_t(v - 1 + c));
        }
    dir.write("grid.obj", obj);
    const size_t cap = kMaxInstancedEmitters / (2 * n * n); // 2^14 - 1 placements
    std::string places;
    for (size_t i = 0; i <= cap; ++i)
        places += "      - {translation: [0, 0, " + std::to_string(-1.0 - double(i)) + "]}\n";
    const std::string head = "shaders: [{type: Emissive, emission: [1, 1, 1]}]\n"
                             "objects:\n  - filename: grid.obj\n    instances:\n";
    const std::string over = dir.write("over.yaml", head + places);
    EXPECT_EQ(loadError(over), over + ":5: the emissive triangles instances place, counted at each "
                                      "placement, are more than 2147483647");
    const size_t line = places.rfind("      - ");
    const Scene at = loadScene(dir.write("at.yaml", head + places.substr(0, line)));
    EXPECT_EQ(at.instances.size(), cap);

    GltfBuilder b;
    b.doc["materials"] = json::array({material(vec3(0.0f), 0.0f, 1.0f, vec3(1.0f))});
    const int grid = b.mesh({{"attributes", {{"POSITION", b.accessor(pos, 5126, "VEC3")}}},
                             {"indices", b.accessor(idx, 5125, "SCALAR")},
                             {"material", 0}});
    std::vector<int> roots;
    for (size_t i = 0; i <= cap; ++i)
        roots.push_back(b.node({{"mesh", grid}, {"translation", {0.0, 0.0, -1.0 - double(i)}}}));
    b.scene(roots);
    const std::string file = b.embedded(dir, "over.gltf");
    EXPECT_EQ(loadError(file), file + ": /nodes/" + std::to_string(cap) +
                                   "/mesh: the emissive triangles instances place, counted at "
                                   "each placement, are more than 2147483647");
}

} // namespace
} // namespace spw::test
